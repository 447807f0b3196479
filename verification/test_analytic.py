"""Closed-form cases: a single block on the ground and a column of square blocks.

A b × h block on a rigid ground, pushed horizontally by α times its weight W, collapses by
sliding when f < b/h (α_c = f; with the associative flow rule the block slides up the friction
angle: u = (1, f, 0)) and by rocking about its leeward bottom corner otherwise (α_c = b/h,
the corner (b, 0) stays still).  A column of k equal square blocks overturns as a whole about
its base corner: α_c = 1/k when friction is high.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st

import alma

from helpers import assert_bounds_bracket, column_scene, single_block_scene

REL = 1e-7

lengths = st.floats(min_value=10.0, max_value=2000.0, allow_nan=False, allow_infinity=False)
frictions = st.floats(min_value=0.05, max_value=2.0, allow_nan=False, allow_infinity=False)


def _weight(b: float, h: float) -> float:
    return b * h * 120.0 * 18.0 * 1e-9  # kN


@settings(max_examples=60, deadline=None)
@given(b=lengths, h=lengths, f=frictions)
def test_single_block_multiplier_and_mechanism(b, h, f):
    assume(abs(f - b / h) >= 1e-3)
    result = alma.solve(single_block_scene(b, h, f))
    assert result.status == "optimal", result.message
    expected = min(f, b / h)
    assert result.alpha == pytest.approx(expected, rel=REL, abs=0.0)
    assert_bounds_bracket(result)
    assert result.bounds.gap <= 1e-7
    assert result.residuals["static_equilibrium"] <= 1e-9
    assert result.residuals["kinematic_flow_rule"] <= 1e-9

    (motion,) = result.blocks
    u, v, theta = motion.u
    assert motion.id == "b1"
    # mechanism normalised so the live load (= the weight, along +x) does unit work: u = 1 mm
    assert u == pytest.approx(1.0, rel=1e-7)
    (joint,) = result.joints
    assert set(joint.blocks) == {"ground", "b1"}
    W = _weight(b, h)
    assert joint.N == pytest.approx(W, rel=1e-7)
    assert abs(joint.T) == pytest.approx(expected * W, rel=1e-7)
    if f < b / h:
        assert result.mechanism_class == "sliding"
        assert joint.state == "sliding"
        # translation, with the dilatant lift of the associative flow rule
        assert abs(theta) * max(b, h) <= 1e-7
        assert v == pytest.approx(f * u, rel=1e-7, abs=1e-9)
    else:
        assert result.mechanism_class == "rocking"
        assert joint.state == "hinging"
        # rotation about the leeward (+x) bottom corner (b, 0): its velocity vanishes
        r = np.array([b / 2.0, -h / 2.0])  # corner relative to the centroid
        corner = np.array([u - theta * r[1], v + theta * r[0]])
        assert np.abs(corner).max() <= 1e-7 * max(1.0, abs(u)), corner
        assert theta < 0  # clockwise: the block tips towards +x
        assert theta == pytest.approx(-2.0 / h, rel=1e-7)


@pytest.mark.parametrize(
    "b,h,f,expected,klass",
    [
        (240.0, 60.0, 0.6, 0.6, "sliding"),  # squat block: slides
        (60.0, 240.0, 0.6, 0.25, "rocking"),  # slender block: rocks
        (100.0, 100.0, 0.3, 0.3, "sliding"),
        (100.0, 100.0, 1.5, 1.0, "rocking"),
        (120.0, 60.0, 0.0, 0.0, "sliding"),  # frictionless joint: any push slides it
    ],
)
def test_single_block_examples(b, h, f, expected, klass):
    result = alma.solve(single_block_scene(b, h, f))
    assert result.status == "optimal", result.message
    assert result.alpha == pytest.approx(expected, rel=REL, abs=1e-12)
    assert result.mechanism_class == klass


@pytest.mark.parametrize("k", range(1, 9))
def test_column_of_square_blocks(k):
    result = alma.solve(column_scene(k, size=100.0, f=2.0))
    assert result.status == "optimal", result.message
    assert result.alpha == pytest.approx(1.0 / k, rel=REL, abs=0.0)
    assert_bounds_bracket(result)
    assert result.bounds.gap <= 1e-7
    assert result.mechanism_class == "rocking"
    # the whole column turns as one body about (100, 0): every block has the same rotation
    thetas = np.array([m.u[2] for m in result.blocks])
    assert np.allclose(thetas, thetas[0], rtol=1e-6, atol=0.0)
    states = {j.blocks: j.state for j in result.joints}
    assert states[("ground", "c0")] == "hinging"


@pytest.mark.parametrize("k", [2, 4, 8])
def test_column_low_friction_slides_at_base(k):
    """With f below 1/k the column slides on the ground as one body: α_c = f."""
    f = 0.5 / k
    result = alma.solve(column_scene(k, size=100.0, f=f))
    assert result.status == "optimal", result.message
    assert result.alpha == pytest.approx(f, rel=REL)
    assert result.mechanism_class == "sliding"
