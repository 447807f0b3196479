"""Ties in the capacity curve: their end points move with their blocks (``alma.push``).

Reference written here from virtual work on the displaced geometry.  A block b × h on the ground
rocks clockwise by θ about its right toe O = (b, 0).  A point drawn at O + r₀ is then at
O + r(θ), r(θ) = R(−θ) r₀, and moves at v = (r_y, −r_x) per unit clockwise rate.  With the dead
load −W ŷ and the live load αW x̂ at the centroid G, and a yielding tie pulling its end C with
its strength S along its current direction e = (A − C)/|A − C| towards its anchor A:

    α W v_x(G) − W v_y(G) + S e · v(C) = 0   ⇒   α(θ) = −(W r_x(G) + S e · v(C)) / (W r_y(G)),

which at θ = 0, for a horizontal tie from the top-left corner (e = (−1, 0)), is b/h + 2 S / W.
A tie whose end comes closer to its anchor than drawn is slack and carries nothing; the bare
block's α(θ) = (b cos θ − h sin θ)/(h cos θ + b sin θ) then holds (verification/test_push.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.push import push
from alma.push.motion import displaced
from alma.settings import PushSettings

B, H, T, GAMMA = 400.0, 1000.0, 120.0, 18.0
W = B * H * T * GAMMA * 1e-9  # kN (mm³ · kN/m³)
S = 0.1  # kN
FAR = (-3000.0, H)  # the anchor point of the horizontal tie, far to the left


def _rect(x0, y0, w, h):
    return [[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]


def _scene(anchor, corner=(0.0, H), strength=S, friction=0.8):
    ax, ay = anchor
    return alma.Scene.from_dict(
        {
            "thickness": T,
            "unit_weight": GAMMA,
            "friction": friction,
            "blocks": [
                {"id": "ground", "vertices": _rect(-4000, -100, 8000, 100), "fixed": True},
                {"id": "anchor", "vertices": _rect(ax - 100, ay - 50, 100, 100), "fixed": True},
                {"id": "b1", "vertices": _rect(0, 0, B, H)},
            ],
            "ties": [
                {
                    "id": "chain",
                    "from": {"block": "b1", "point": list(corner)},
                    "to": {"block": "anchor", "point": [ax, ay]},
                    "strength": strength,
                }
            ],
        }
    )


def _turned(r0, theta):
    """r₀ turned clockwise by θ."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([c * r0[0] + s * r0[1], -s * r0[0] + c * r0[1]])


def _alpha(theta, anchor, force):
    """α(θ) of the block on its toe with the tie's force ``force`` (kN) along its current line."""
    toe = np.array([B, 0.0])
    rg = _turned((-B / 2, H / 2), theta)
    rc = _turned((-B, H), theta)
    e = np.asarray(anchor) - (toe + rc)
    e /= np.hypot(*e)
    vc = np.array([rc[1], -rc[0]])
    return float(-(W * rg[0] + force * e @ vc) / (W * rg[1]))


def _bare(theta):
    return (B * math.cos(theta) - H * math.sin(theta)) / (H * math.cos(theta) + B * math.sin(theta))


@pytest.fixture(scope="module")
def far():
    return push(_scene(FAR))


def test_alpha_at_rest_is_the_limit_analysis_and_the_closed_form(far):
    solved = alma.solve(_scene(FAR))
    assert far.curve[0].alpha == pytest.approx(float(solved.alpha), abs=1e-9)
    assert float(solved.alpha) == pytest.approx(B / H + 2 * S / W, abs=1e-7)


def test_a_horizontal_tie_follows_the_displaced_geometry_at_every_step(far):
    assert far.status == alma.Status.OPTIMAL and far.control == "b1"
    assert not any(p.mechanism_changed for p in far.curve)
    thetas = [-p.pose.angle[2] for p in far.curve]
    errors = [abs(p.alpha - _alpha(t, FAR, S)) for p, t in zip(far.curve, thetas, strict=True)]
    assert len(far.curve) > 40 and max(errors) <= 1e-6
    # the closed form can tell: a tie left where it was drawn (direction, lever arm) is off by far more
    # (its pull (−S, 0) at the drawn point (0, h), whose velocity about the toe is (h, b))
    drawn = max(
        abs(p.alpha + (W * _turned((-B / 2, H / 2), t)[0] - S * H) / (W * _turned((-B / 2, H / 2), t)[1]))
        for p, t in zip(far.curve, thetas, strict=True)
    )
    assert drawn > 1e-2
    # d₀: the root of the closed form (bisection), to the stated accuracy
    lo, hi = 0.0, 1.2
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _alpha(mid, FAR, S) > 0 else (lo, mid)
    tolerance = PushSettings().d0_tolerance * math.sqrt(B * H)
    assert far.d0 == pytest.approx(_turned((-B / 2, H / 2), lo)[0] + B / 2, abs=tolerance)
    # d is the centroid's horizontal displacement at that rotation
    for p, t in zip(far.curve, thetas, strict=True):
        assert p.d == pytest.approx(_turned((-B / 2, H / 2), t)[0] + B / 2, abs=1e-6)


def test_the_tie_end_moves_rigidly_with_its_block_and_the_anchor_stays(far):
    last = far.curve[-1]
    moved = displaced(_scene(FAR), last.pose)
    tie = moved.ties[0]
    corner = np.array([B, 0.0]) + _turned((-B, H), -last.pose.angle[2])
    assert np.allclose(tie.from_point, corner, atol=1e-9) and tie.to_point == FAR
    assert np.allclose(tie.from_point, moved.blocks[2].vertices[3], atol=1e-9)


# an anchor up and to the right of the corner's path: the corner first comes closer (the tie is
# slack), passes its nearest point at θ = 0.15 and is back at the drawn length at θ = 0.30
_R = math.hypot(B, H)
_PHI = math.atan2(H, -B) - 0.15
NEAR = (B + 2 * _R * math.cos(_PHI), 2 * _R * math.sin(_PHI))


def test_a_tie_that_shortened_is_slack_until_it_is_back_at_its_drawn_length():
    result = push(_scene(NEAR, strength=0.3))
    assert result.status == alma.Status.OPTIMAL
    slack = taut = 0
    for p in result.curve:
        theta = -p.pose.angle[2]
        if 1e-3 < theta < 0.3 - 1e-3:
            assert p.alpha == pytest.approx(_bare(theta), abs=1e-6)
            slack += 1
        elif theta > 0.3 + 1e-3:
            assert p.alpha == pytest.approx(_alpha(theta, NEAR, 0.3), abs=1e-6)
            taut += 1
    assert slack >= 5 and taut >= 5
    # taut, the tie holds the block beyond the bare block's θ₀ = atan(b/h)
    assert -result.curve[-1].pose.angle[2] > math.atan(B / H) + 0.05


# ------------------------------------------------------------------ invariance
@settings(max_examples=3, deadline=None)
@given(dx=st.floats(-1e4, 1e4), dy=st.floats(-1e4, 1e4), reverse=st.booleans())
def test_the_curve_does_not_depend_on_origin_or_block_order(far, dx, dy, reverse):
    data = _scene(FAR).to_dict()
    for block in data["blocks"]:
        block["vertices"] = (np.array(block["vertices"]) + np.array([dx, dy])).tolist()
    for tie in data["ties"]:
        for end in ("from", "to"):
            tie[end]["point"] = (np.array(tie[end]["point"]) + np.array([dx, dy])).tolist()
    if reverse:
        data["blocks"] = data["blocks"][::-1]
    other = push(alma.Scene.from_dict(data))
    assert other.control == far.control and len(other.curve) == len(far.curve)
    assert np.allclose([p.alpha for p in other.curve], [p.alpha for p in far.curve], atol=1e-7)
    assert np.allclose([p.d for p in other.curve], [p.d for p in far.curve], rtol=1e-7, atol=1e-6)
    assert other.d0 == pytest.approx(far.d0, rel=1e-6)
