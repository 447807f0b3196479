"""The capacity curve α(d) with a finite compressive strength σ_c against its closed form.

Reference derived here (rigid geometry, rectangular stress block; docs/compressive.md and the
decision "a turned crushing joint keeps its length" in docs/decisions.md):

A block b × h (thickness t, weight W at its centroid G) stands on a rigid ground; the live load
is αW horizontal (+x) at G.  It turns clockwise by θ about its toe T = (b, 0) (the crushed zone's
own deformation is neglected: the toe stays where it is).  The turned joint keeps its length b
along the ground's face, ending at T, so its normal stays vertical and its reaction is N
vertical, V horizontal.  Vertical equilibrium gives N = W, so the stress block has the width
a = N / (σ_c t) = W / (σ_c t), and the largest multiplier places it against the toe: its
resultant acts at C = T − (a/2, 0).  The centroid is at

    G − T = (−b/2 cos θ + h/2 sin θ,  b/2 sin θ + h/2 cos θ).

Moments about C (the reaction passes through C; W acts down, αW to the right):

    α W (G_y − C_y) = W (C_x − G_x)
    α W (b/2 sin θ + h/2 cos θ) = W (b/2 cos θ − h/2 sin θ − a/2)

    α(θ) = (b cos θ − h sin θ − a) / (h cos θ + b sin θ).

At θ = 0 it is issue 34's α = (b − a)/h; σ_c → ∞ (a → 0) gives the rigid block's curve
(b cos θ − h sin θ)/(h cos θ + b sin θ).  α = 0 where G_x = C_x: the centroid has moved
d₀ = b/2 − a/2 = (b − a)/2, at θ₀ with b cos θ₀ − h sin θ₀ = a.  The tangential force V = αW
stays below f N = f W (f = 0.8 > α), so the block rocks and does not slide.  The centroid's
horizontal displacement d fixes θ (T does not move): d = r cos β − r cos(β + θ), r = ½√(b² + h²),
β = atan(h/b).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.push import push
from alma.push.motion import displaced

B, H, T, GAMMA = 240.0, 600.0, 120.0, 18.0
WEIGHT_N = B * H * T * GAMMA * 1e-6  # N (kN/m³ × mm³ = 1e-9 kN = 1e-6 N)


def _rect(x0, y0, w, h):
    return [[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]


def _scene(
    strength: float | None, *, dx: float = 0.0, dy: float = 0.0, reverse: bool = False, scale: float = 1.0
) -> alma.Scene:
    k = scale
    blocks = [
        {"id": "ground", "vertices": _rect(-2000 * k + dx, -100 * k + dy, 5000 * k, 100 * k), "fixed": True},
        {"id": "b1", "vertices": _rect(dx, dy, B * k, H * k)},
    ]
    data = {"thickness": T * k, "unit_weight": GAMMA, "friction": 0.8, "blocks": blocks[::-1] if reverse else blocks}
    if strength is not None:
        data["compressive_strength"] = strength
    return alma.Scene.from_dict(data)


def _width(strength: float) -> float:
    """The stress block's width a = W / (σ_c t), mm (W in N, σ_c in N/mm², t in mm)."""
    return WEIGHT_N / (strength * T)


def _alpha(theta: float, a: float) -> float:
    return (B * math.cos(theta) - H * math.sin(theta) - a) / (H * math.cos(theta) + B * math.sin(theta))


def _theta_of_d(d: float) -> float:
    r, beta = 0.5 * math.hypot(B, H), math.atan2(H, B)
    return math.acos((r * math.cos(beta) - d) / r) - beta


@pytest.fixture(scope="module")
def base():
    return push(_scene(0.05))


@pytest.fixture(scope="module", params=[0.05, 0.2])
def crushing(request):
    return request.param, push(_scene(request.param))


def test_curve_matches_the_stress_block_closed_form_at_every_step(crushing):
    strength, result = crushing
    a = _width(strength)
    assert result.status == alma.Status.OPTIMAL, result.message
    assert result.end["reason"] == "alpha_zero"
    assert len(result.curve) > 40 and not any(p.mechanism_changed for p in result.curve)
    assert result.curve[0].alpha == pytest.approx((B - a) / H, abs=1e-6)
    errors = [abs(p.alpha - _alpha(_theta_of_d(p.d), a)) for p in result.curve]
    assert max(errors) <= 1e-6


def test_the_block_turns_about_its_toe_and_d0_is_where_alpha_is_zero(crushing):
    strength, result = crushing
    a = _width(strength)
    assert result.d0 == pytest.approx((B - a) / 2, abs=1e-4)
    last = displaced(_scene(strength), result.curve[-1].pose).blocks[1].vertices
    assert np.allclose(last[1], [B, 0.0], atol=1e-6)  # the toe has not moved: no sinking, no lift
    theta0 = -result.curve[-1].pose.angle[1]
    assert B * math.cos(theta0) - H * math.sin(theta0) == pytest.approx(a, abs=1e-4)


def test_strong_blocks_recover_the_rigid_curve():
    strong = push(_scene(1e5))
    rigid = push(_scene(None))
    assert strong.status == rigid.status == alma.Status.OPTIMAL
    rigid_alpha = lambda d: _alpha(_theta_of_d(d), 0.0)  # noqa: E731
    assert max(abs(p.alpha - rigid_alpha(p.d)) for p in strong.curve) <= 1e-6
    assert strong.d0 == pytest.approx(rigid.d0, abs=1e-4)
    assert rigid.d0 == pytest.approx(B / 2, abs=1e-4)


@settings(max_examples=3, deadline=None)
@given(scale=st.sampled_from([0.1, 1.0, 25.4]), dx=st.floats(-5e3, 5e3), dy=st.floats(-5e3, 5e3), reverse=st.booleans())
def test_curve_does_not_depend_on_units_origin_or_block_order(base, scale, dx, dy, reverse):
    """The same structure k times larger (lengths and thickness × k) with σ_c × k has the same
    a/b (W ∝ k³, a = W/(σ_c t) ∝ k): the same α at d × k."""
    other = push(_scene(0.05 * scale, dx=dx, dy=dy, reverse=reverse, scale=scale))
    assert other.status == alma.Status.OPTIMAL
    assert np.allclose([p.d / scale for p in other.curve], [p.d for p in base.curve], rtol=1e-7, atol=1e-6)
    assert np.allclose([p.alpha for p in other.curve], [p.alpha for p in base.curve], atol=1e-7)
    assert other.d0 / scale == pytest.approx(base.d0, rel=1e-7)


def test_two_stacked_blocks_rock_as_one_body_on_their_base_stress_block():
    # 200 × 400 twice: one body b × h = 200 × 800 whose base joint carries both weights, so
    # a = 2 W₁/(σ_c t); θ is the bodies' turn (the control is the top block, not the centroid)
    strength = 0.05
    scene = alma.Scene.from_dict(
        {
            "thickness": T,
            "unit_weight": GAMMA,
            "friction": 0.8,
            "compressive_strength": strength,
            "blocks": [
                {"id": "ground", "vertices": _rect(-2000, -100, 5000, 100), "fixed": True},
                {"id": "low", "vertices": _rect(0, 0, 200, 400)},
                {"id": "top", "vertices": _rect(0, 400, 200, 400)},
            ],
        }
    )
    result = push(scene, steps=10)
    assert result.status == alma.Status.OPTIMAL and result.end["reason"] == "alpha_zero"
    a = 200 * 800 * T * GAMMA * 1e-6 / (strength * T)
    for p in result.curve:
        theta = -p.pose.angle[2]
        assert p.pose.angle[1] == pytest.approx(p.pose.angle[2], abs=1e-12)
        ref = (200 * math.cos(theta) - 800 * math.sin(theta) - a) / (800 * math.cos(theta) + 200 * math.sin(theta))
        assert p.alpha == pytest.approx(ref, abs=1e-6)


def test_a_joint_crushing_over_its_whole_length_ends_the_curve_and_is_named():
    # the portal of verification/test_push.py at σ_c = 0.03 MPa: the collapse turns the whole
    # frame about the left pier's crushing hinge while the right pier's base crushes whole
    # (N = σ_c l t) and sinks, which rigid geometry cannot follow: the curve must say so
    scene = alma.Scene.from_dict(
        {
            "thickness": T,
            "unit_weight": GAMMA,
            "friction": 0.8,
            "compressive_strength": 0.03,
            "blocks": [
                {"id": "ground", "vertices": _rect(-2000, -100, 5000, 100), "fixed": True},
                {"id": "pier_l", "vertices": _rect(0, 0, 200, 1000)},
                {"id": "pier_r", "vertices": _rect(800, 0, 200, 1000)},
                {"id": "lintel", "vertices": _rect(-100, 1000, 1200, 200)},
            ],
        }
    )
    result = push(scene)
    assert result.end["reason"] == "no_equilibrium" and math.isnan(result.d0)
    assert result.end["crushed_lost_joints"] == [["ground", "pier_r"]]
    assert "crushed over its whole length" in result.message
    # a step from the bracket's low end keeps the equilibrium, but the curve does not go on
    assert "low_end_step" in result.end and result.status == alma.Status.NOT_CONVERGED


def test_a_per_joint_strength_on_the_ground_joint_gives_the_same_curve(base):
    # only the ground joint has σ_c (SPEC §2 "joints" override): the turned joint keeps it
    data = _scene(None).to_dict()
    data["joints"] = [{"blocks": ["ground", "b1"], "compressive_strength": 0.05}]
    result = push(alma.Scene.from_dict(data))
    assert result.status == alma.Status.OPTIMAL
    assert np.allclose([p.alpha for p in result.curve], [p.alpha for p in base.curve], atol=1e-9)
    assert result.d0 == pytest.approx(base.d0, rel=1e-9)
