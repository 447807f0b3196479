"""Joint detection's memory depends on the number of edges, not on the drawing's extent.

A wall plus one support far away (1e7 mm) must cost what the wall alone costs: the candidate
search once paired every edge of a course with every other (its slack grew with the distance
from the drawing's centre), so that 40,000 blocks and one far block needed > 17 GB.  Memory is
measured with tracemalloc (numpy's buffers are traced), not with the clock.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.geometry import contacts
from alma.geometry.contacts import Joints, find_joints
from alma.geometry.edges import contact_lengths, local_origin, scene_edges
from alma.geometry.scene import Scene


def _wall(far: float | None) -> Scene:
    data = alma.wall("running", 240.0 * 25, 60.0 * 40, 240.0).to_dict()
    if far is not None:
        data["blocks"].append(
            {"id": "far", "fixed": True, "vertices": [[far, 0], [far + 240, 0], [far + 240, 60], [far, 60]]}
        )
    return Scene.from_dict(data)


def _peak_bytes(scene: Scene) -> tuple[int, Joints]:
    tracemalloc.start()
    try:
        joints = find_joints(scene)
        return tracemalloc.get_traced_memory()[1], joints
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("far", [1e5, 1e7, -3e8])
def test_far_block_costs_no_memory(far):
    near_peak, near = _peak_bytes(_wall(None))
    far_peak, distant = _peak_bytes(_wall(far))
    assert far_peak <= 1.25 * near_peak, (far_peak, near_peak)
    # The same joints: the far block touches nothing.
    assert distant.count == near.count
    for field in ("block_a", "block_b", "start", "end", "normal"):
        assert np.array_equal(getattr(distant, field), getattr(near, field)), field


def _candidates(scene: Scene) -> int:
    """How many edge pairs the candidate search hands to the exact tests."""
    edges = scene_edges(scene, local_origin(scene))
    pairs = contacts._candidate_pairs(edges, *contact_lengths(scene, edges))
    return 0 if pairs is None else len(pairs[0])


_SMALL = alma.wall("running", 240.0 * 8, 60.0 * 10, 240.0)


@settings(max_examples=25, deadline=None)
@given(distance=st.floats(1e4, 1e9), angle=st.floats(0.0, 2 * np.pi), turn=st.floats(0.0, 2 * np.pi))
def test_candidates_and_joints_do_not_depend_on_a_far_block(distance, angle, turn):
    """Wherever a far block sits (any distance, direction, orientation), the wall's candidate
    pairs stay within its own count plus the far block's edges, and its joints are the same."""
    data = _SMALL.to_dict()
    c, s = np.cos(turn), np.sin(turn)
    square = np.array([[0, 0], [240, 0], [240, 60], [0, 60]]) @ np.array([[c, -s], [s, c]]).T
    far = square + distance * np.array([np.cos(angle), np.sin(angle)])
    data["blocks"].append({"id": "far", "fixed": True, "vertices": far.tolist()})
    scene = Scene.from_dict(data)
    assert _candidates(scene) <= _candidates(_SMALL) + 4
    near, distant = find_joints(_SMALL), find_joints(scene)
    assert distant.count == near.count
    for field in ("block_a", "block_b"):
        assert np.array_equal(getattr(distant, field), getattr(near, field)), field
    assert np.allclose(distant.start, near.start, rtol=0, atol=1e-9 * distance)
