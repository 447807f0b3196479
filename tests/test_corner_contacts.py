"""A block's corner resting on another block's face is a contact (alma.geometry.corners)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.geometry.contacts import find_joints
from alma.geometry.panels import paper_panel

B, H = 200.0, 400.0  # a tall block, mm


def _tilted(theta: float, order: int = 0, shift: tuple[float, float] = (0.0, 0.0)) -> alma.Scene:
    """A B × H block turned clockwise by ``theta`` about its bottom-right corner, which rests on
    a fixed ground's face (the block's bottom edge rises to the left)."""
    c, s = math.cos(-theta), math.sin(-theta)
    corners = np.array([[-B, 0.0], [0.0, 0.0], [0.0, H], [-B, H]])
    block = alma.Block("block", corners @ np.array([[c, -s], [s, c]]).T + np.array([B, 0.0]) + shift)
    floor = np.array([[-600.0, -100.0], [800.0, -100.0], [800.0, 0.0], [-600.0, 0.0]])
    ground = alma.Block("ground", floor + shift, fixed=True)
    blocks = (block, ground) if order == 0 else (ground, block)
    return alma.Scene(blocks=blocks, friction=0.6)


def _statics(theta: float) -> float:
    """α that holds the block on its corner: the horizontal push at the centroid balancing its
    weight about the corner, (B/2 cos θ − H/2 sin θ) / (B/2 sin θ + H/2 cos θ)."""
    return (B / 2 * math.cos(theta) - H / 2 * math.sin(theta)) / (B / 2 * math.sin(theta) + H / 2 * math.cos(theta))


def test_a_corner_on_a_face_is_a_joint_of_zero_length_with_the_face_normal():
    scene = _tilted(math.radians(10.0))
    joints = find_joints(scene)
    assert joints.count == 1
    assert joints.length[0] == 0.0
    assert joints.start[0] == pytest.approx([B, 0.0], abs=1e-9)
    # the normal points from block_a into block_b: from the block (0) down into the ground (1)
    a, b = int(joints.block_a[0]), int(joints.block_b[0])
    assert (a, b) == (0, 1)
    assert joints.normal[0] == pytest.approx([0.0, -1.0], abs=1e-12)


@pytest.mark.parametrize("degrees", [5.0, 10.0, 20.0])
def test_a_block_on_its_corner_stands_at_the_push_that_balances_it(degrees):
    theta = math.radians(degrees)
    result = alma.solve(_tilted(theta))
    assert result.status == alma.Status.OPTIMAL
    assert result.alpha == pytest.approx(_statics(theta), rel=1e-9)


def test_without_the_corner_contact_the_block_had_no_support():
    # the same block set down flat stands on a flat joint; turned, only the corner holds it
    assert find_joints(_tilted(0.0)).length.min() > 0
    assert find_joints(_tilted(math.radians(10.0))).count == 1


def test_a_corner_above_the_face_or_at_its_end_is_no_contact():
    tilted = _tilted(math.radians(10.0))
    block, ground = tilted.blocks
    raised = alma.Scene(blocks=(alma.Block("block", block.vertices + np.array([0.0, 1.0])), ground), friction=0.6)
    assert find_joints(raised).count == 0  # 1 mm above the face: apart
    beyond = alma.Scene(blocks=(alma.Block("block", block.vertices + np.array([600.0, 0.0])), ground), friction=0.6)
    assert find_joints(beyond).count == 0  # the corner at the face's end: corner on corner, no normal


def test_the_paper_panels_have_no_corner_contacts():
    for bond in ("running", "english", "flemish", "stack"):
        joints = find_joints(paper_panel(bond, "2:1", "2:1", 0.6))
        assert joints.length.min() > 0, bond


@settings(max_examples=25, deadline=None)
@given(
    degrees=st.floats(3.0, 25.0), order=st.integers(0, 1), shift=st.tuples(st.floats(-1e5, 1e5), st.floats(-1e5, 1e5))
)
def test_the_corner_contact_does_not_depend_on_order_or_origin(degrees, order, shift):
    theta = math.radians(degrees)
    result = alma.solve(_tilted(theta, order, shift))
    assert result.alpha == pytest.approx(_statics(theta), rel=1e-8)
