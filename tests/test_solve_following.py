"""The mechanism a capacity curve follows on a sliding wall (alma.solve.solve_following)."""

from __future__ import annotations

import pytest

import alma
from alma.geometry.contacts import find_joints
from alma.geometry.panels import paper_panel
from alma.mechanics.model import build_model
from alma.solve import solve_following


@pytest.fixture(scope="module")
def sliding():
    scene = paper_panel("running", "2:1", "2:1", 0.27).validate()
    return scene, build_model(scene, find_joints(scene))


def test_a_sliding_wall_moves_one_part_that_carries_the_control_block(sliding):
    # at α = f every part above a bed joint can slide: the interior point moves each of the 150
    # blocks at its own rate (150 macro-blocks); the followed vertex moves rigid parts (here
    # the control block sliding on the 149 others, which slide on the base)
    scene, built = sliding
    blend = alma.solve(built)
    control = scene.block_ids.index("b150")
    followed = solve_following(built, None, control, 1.0)
    assert followed.status == blend.status == alma.Status.OPTIMAL
    assert followed.alpha == blend.alpha and followed.bounds == blend.bounds
    assert len(blend.macro_blocks) == 150 and len(followed.macro_blocks) <= 2
    assert all(m.motion == "translation" for m in followed.macro_blocks)
    assert next(b for b in followed.blocks if b.id == "b150").u[0] > 0


def test_a_mechanism_that_turns_is_the_interior_points(sliding):
    # only translations are followed; a rocking or mixed mechanism is the solve's own
    scene = paper_panel("running", "1:1", "1:1", 0.6).validate()
    built = build_model(scene, find_joints(scene))
    plain = alma.solve(built)
    assert plain.mechanism_class != "sliding"
    moving = next(i for i, b in enumerate(scene.blocks) if not b.fixed)
    followed = solve_following(built, None, moving, 1.0)
    assert [b.u for b in followed.blocks] == [b.u for b in plain.blocks]
