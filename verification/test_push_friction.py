"""The capacity curve of the friction model (``alma.push(..., model="nonassociative")``).

At every displaced configuration the friction search (Eq. 9) runs on the displaced geometry,
whose opened joints are point contacts.  A mechanism of point hinges is a linkage: it moves
every block and no contact, so its state's relative velocities are round-off and are measured
against the blocks' own velocities (:attr:`alma.settings.StateTolerances.linkage`); the search
carries its states back at the push's fallback precision
(:attr:`alma.settings.PushSettings.friction_fallback_bits`).

References: the closed forms of ``verification/test_push.py`` (virtual work at finite rotation),
which hold for the friction model where no joint slides (friction high enough that every
mechanism rocks), and the associative curve of the same structure, which the friction curve must
follow where the same mechanism is the lowest.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import alma
from alma.push import push

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _rect(x0, y0, w, h):
    return [[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]


def _scene(blocks, friction=0.8):
    return alma.Scene.from_dict(
        {
            "thickness": 120,
            "unit_weight": 18,
            "friction": friction,
            "blocks": [{"id": "ground", "vertices": _rect(-2000, -100, 5000, 100), "fixed": True}, *blocks],
        }
    )


def _rocking_alpha(b, h, theta):
    return (b * math.cos(theta) - h * math.sin(theta)) / (h * math.cos(theta) + b * math.sin(theta))


def _theta_of_d(d, b, h):
    r, beta = 0.5 * math.hypot(b, h), math.atan2(h, b)
    return math.acos((r * math.cos(beta) - d) / r) - beta


# portal frame: two piers 200 × 1000 and a lintel, sway about four point hinges
PB, PH, SPAN, LT = 200.0, 1000.0, 1000.0, 200.0
PORTAL = _scene(
    [
        {"id": "pier_l", "vertices": _rect(0, 0, PB, PH)},
        {"id": "pier_r", "vertices": _rect(SPAN - PB, 0, PB, PH)},
        {"id": "lintel", "vertices": _rect(-100, PH, SPAN + 200, LT)},
    ]
)


def _portal_alpha(theta):
    """α = Σ W v_y / Σ W v_x of the sway at finite θ: each pier turns clockwise about its right
    toe, the lintel translates with the piers' top-left corners (arms from the toe)."""
    c, s = math.cos(theta), math.sin(theta)
    rot = np.array([[c, s], [-s, c]])
    centroid, corner = rot @ [-PB / 2, PH / 2], rot @ [-PB, PH]
    pier = np.array([centroid[1], -centroid[0]])  # clockwise unit rate about the toe
    lintel = np.array([corner[1], -corner[0]])
    weights = np.array([PB * PH, PB * PH, (SPAN + 200) * LT])
    v = np.array([pier, pier, lintel])
    return float(weights @ v[:, 1] / (weights @ v[:, 0]))


def _portal_theta(d):
    """θ that moves the lintel by d: d = b(1 − cos θ) + h sin θ (bisection)."""
    lo, hi = 0.0, 1.5
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if PB * (1 - math.cos(mid)) + PH * math.sin(mid) < d else (lo, mid)
    return 0.5 * (lo + hi)


def test_the_friction_curve_of_a_single_block_is_the_closed_form_to_its_zero():
    b, h = 240.0, 600.0
    result = push(_scene([{"id": "b1", "vertices": _rect(0, 0, b, h)}]), model="nonassociative", steps=8)
    assert result.status == alma.Status.FEASIBLE and result.end["reason"] == "alpha_zero"
    errors = [abs(p.alpha - _rocking_alpha(b, h, _theta_of_d(p.d, b, h))) for p in result.curve]
    assert max(errors) <= 1e-6
    assert result.d0 == pytest.approx(b / 2, abs=1e-4)


def test_the_friction_curve_of_the_portal_follows_its_four_point_hinges():
    # from the first step on, the opened joints are point hinges: a linkage whose contacts do not move
    result = push(PORTAL, model="nonassociative", steps=6)
    assert result.control == "lintel"
    checked = 0
    for p in result.curve:
        if p.mechanism_changed:
            break
        assert p.alpha == pytest.approx(_portal_alpha(_portal_theta(p.d)), abs=1e-6)
        checked += 1
    assert checked >= 5 and result.curve[checked - 1].d > 20.0


@pytest.mark.slow
def test_the_friction_curve_of_the_arch_ends_where_the_associative_one_does():
    # examples/arch.json rocks about four point hinges (f high enough that nothing slides): the
    # friction curve is the associative one, down to the same snap-through at d = 28.209 mm
    arch = alma.load_scene(EXAMPLES / "arch.json")
    friction = push(arch, model="nonassociative", steps=10)
    associative = push(arch, steps=10)
    assert friction.end["reason"] == associative.end["reason"] == "no_equilibrium"
    assert friction.end["bracket"] == pytest.approx(associative.end["bracket"], abs=1e-5)
    assert [p.d for p in friction.curve] == pytest.approx([p.d for p in associative.curve], abs=1e-5)
    assert [p.alpha for p in friction.curve] == pytest.approx([p.alpha for p in associative.curve], abs=1e-6)
    assert all(p.status == alma.Status.FEASIBLE for p in friction.curve)
