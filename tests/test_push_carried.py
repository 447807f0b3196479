"""alma.push.carried: tie ends carried by their blocks, and the rest length that makes a tie slack."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

import alma
from alma.geometry.loads import Tie
from alma.push.carried import tie_lengths, without_slack
from alma.push.motion import Pose, displaced


def _scene():
    return alma.Scene.from_dict(
        {
            "thickness": 100,
            "unit_weight": 20,
            "friction": 0.6,
            "blocks": [
                {"id": "ground", "vertices": [[-1000, -100], [1000, -100], [1000, 0], [-1000, 0]], "fixed": True},
                {"id": "b", "vertices": [[0, 0], [200, 0], [200, 500], [0, 500]]},
            ],
            "ties": [
                {
                    "id": "t",
                    "from": {"block": "b", "point": [0, 500]},
                    "to": {"block": "ground", "point": [-1000, 0]},
                    "strength": 1.0,
                }
            ],
        }
    )


def _with_lengths(scene, lengths):
    ties = tuple(Tie(f"t{k}", "b", (0.0, 0.0), "ground", (float(x), 0.0), 1.0) for k, x in enumerate(lengths))
    return dataclasses.replace(scene, ties=ties)


def test_a_tie_end_moves_as_its_block_and_the_anchor_end_stays():
    scene = _scene()
    pose = Pose(np.array([0.0, -0.3]), np.array([[0.0, 0.0], [40.0, -7.0]]))
    moved = displaced(scene, pose)
    assert moved.ties[0].to_point == scene.ties[0].to_point  # bit for bit on the fixed block
    # the drawn end is the block's top-left vertex: it is where that vertex went
    assert np.allclose(moved.ties[0].from_point, moved.blocks[1].vertices[3], atol=1e-12)
    assert moved.ties[0].strength == scene.ties[0].strength and moved.ties[0].id == "t"
    assert tie_lengths(moved.ties)[0] != tie_lengths(scene.ties)[0]


def test_a_tie_shorter_than_its_rest_length_is_left_out_and_a_longer_one_yields():
    scene = _scene()
    kept, rest = without_slack(_with_lengths(scene, [120.0, 99.0, 100.0 - 1e-12]), np.full(3, 100.0), 1e-9)
    assert [t.id for t in kept.ties] == ["t0", "t2"]
    assert np.array_equal(rest, [120.0, 100.0, 100.0])
    # a tie that yielded to 120 and shortened to 110 is slack, though longer than drawn
    kept, rest = without_slack(_with_lengths(scene, [110.0]), np.array([120.0]), 1e-9)
    assert kept.ties == () and rest[0] == 120.0
    # and taut again once stretched back to its rest length
    kept, _ = without_slack(_with_lengths(scene, [120.0]), np.array([120.0]), 1e-9)
    assert len(kept.ties) == 1


def test_leaving_a_tie_out_keeps_the_scene_validated_and_the_caller_s_scene_unchanged():
    scene = _scene()
    scene.validate()
    before = scene.ties
    kept, _ = without_slack(scene, np.array([math.inf]), 1e-9)
    assert kept.validated and kept.ties == () and scene.ties == before
