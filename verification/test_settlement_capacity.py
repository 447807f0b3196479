"""Settlement capacity (issue 33, item 4) against closed forms written here from the geometry.

Each case grows the scene's ``settlement`` by a factor s, moves the blocks with large
displacements, and finds s_u where the displaced structure can no longer carry its dead load
(alma.settlement_capacity).  The accuracy stated by the analysis is the bracket of s_u:
``PushSettings.d0_tolerance`` (1e-7) times the abscissa's scale (1 rad for a rotation, L =
√(free area) for a translation); every reference below is met to 1e-6 relative.

1. A block b × h on a support that rotates clockwise about a point (a tilting table driven
   as a settlement): the block moves with its support, and under a horizontal α W at its
   centroid on a base tilted by θ, rocking about the downhill toe needs
   α = (b cos θ − h sin θ)/(h cos θ + b sin θ) = tan(atan(b/h) − θ), sliding α = tan(φ − θ)
   (f = tan φ; the associative sliding of one flat joint gives the same value).  So
   α(θ) = tan(min(atan(b/h), φ) − θ) at every step and s_u = min(atan(b/h), φ).
2. Two stacked blocks of one width b (heights h₁, h₂) on that support: the column rocks as one
   before the top block does (b/(h₁ + h₂) < b/h₂), s_u = atan(b/(h₁ + h₂)) for f > b/(h₁ + h₂).
3. A lintel over a sinking pier: a block b × h (corners (0, 0) and (b, h)) rests on a fixed
   support under x ≤ c and on a frictionless pier under x ≥ c that drops (translation
   (0, −1)), with c < b/2 so that its weight leans on the pier.  The block turns about the
   fixed support's corner (c, 0) while its corner (b, 0) slides on the pier's top: at rotation θ
   the pier has dropped s = (b − c) sin θ.  Its equilibrium: the pier's reaction is vertical
   (frictionless), so the fixed corner's must be vertical too, at the angle θ from the block
   face's normal: it stands while tan θ ≤ f, and s_u = (b − c) f / √(1 + f²).  (The pier's
   reaction W g_x / ((b − c) cos θ) stays below W for these sizes, so no other limit comes first.)
4. Case 1 with a support that also translates (a finite rigid motion whose path is not a circle
   about one centre): the tilt at s_u is still atan(b/h).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.geometry.loads import Settlement
from alma.settle import SettleError
from alma.status import Status
from benchmarks.bench_settle_capacity import lintel, tilting  # the scenes, written once for both

REL = 1e-6


@pytest.mark.parametrize(("b", "h", "f"), [(200.0, 600.0, 1.0), (200.0, 600.0, 0.2), (400.0, 300.0, 0.9)])
def test_block_on_a_tilting_support(b: float, h: float, f: float) -> None:
    result = alma.settlement_capacity(tilting(b, h, f))
    limit = min(math.atan(b / h), math.atan(f))
    assert result.status == Status.OPTIMAL, result.message
    assert result.unit == "rad" and result.support == "ground"
    assert result.s_u == pytest.approx(limit, rel=REL)
    assert result.bracket[0] <= limit <= result.bracket[1] or abs(result.s_u - limit) <= REL * limit
    for point in result.curve.curve:  # the whole curve, the step past s_u (α < 0) included
        assert point.alpha == pytest.approx(math.tan(limit - point.d), abs=REL)
    assert result.cracks[0] == ()  # the block moves with its support: nothing cracks


def test_a_support_that_turns_and_translates() -> None:
    """The settlement (translation (3, −4) mm, rotation −0.01 rad about a far point) is followed
    exactly, not along its instantaneous centre's circle: the block still falls at a tilt of
    atan(b/h), at s = 5 mm of translation per 0.01 rad, and α(θ) holds at every step."""
    scene = tilting(200.0, 600.0, 1.0)
    ground = dataclasses.replace(scene.blocks[0], settlement=Settlement((3.0, -4.0), -0.01, (-250.0, -50.0)))
    scene = dataclasses.replace(scene, blocks=(ground, *scene.blocks[1:]), validated=False)
    result = alma.settlement_capacity(scene)
    limit = math.atan(200.0 / 600.0)
    assert result.status == Status.OPTIMAL and result.unit == "mm", result.message
    assert result.factor_u * 0.01 == pytest.approx(limit, rel=REL)
    assert result.s_u == pytest.approx(5.0 * limit / 0.01, rel=REL)
    for point in result.curve.curve:
        assert point.alpha == pytest.approx(math.tan(limit - point.d / 5.0 * 0.01), abs=REL)


def test_two_stacked_blocks_rock_as_one_column() -> None:
    b, h1, h2 = 200.0, 300.0, 250.0
    result = alma.settlement_capacity(tilting(b, h1, 1.0, (h2,)))
    assert result.status == Status.OPTIMAL, result.message
    assert result.s_u == pytest.approx(math.atan(b / (h1 + h2)), rel=REL)


@pytest.mark.parametrize("f", [0.3, 0.5, 1.0])
def test_lintel_over_a_sinking_pier(f: float) -> None:
    result = alma.settlement_capacity(lintel(f))
    exact = 300.0 * f / math.hypot(1.0, f)
    assert result.status == Status.OPTIMAL, result.message
    assert result.unit == "mm" and result.support == "pier"
    assert result.s_u == pytest.approx(exact, rel=REL)
    # the lintel cracks off both supports' faces from the first step: it turns about the corner
    assert ("lintel", "support") in result.cracks[1] or ("support", "lintel") in result.cracks[1]
    assert result.curve.curve[-1].alpha <= 0 < result.curve.curve[-2].alpha


@functools.cache
def _reference() -> alma.SettlementCapacity:
    return alma.settlement_capacity(lintel(0.5))


@pytest.mark.slow  # 10–15 s: CI runs it with the slow part
@settings(max_examples=4, deadline=None)
@given(
    unit=st.sampled_from([0.1, 1.0, 25.4, 1000.0]),
    origin=st.tuples(st.floats(-5e3, 5e3, allow_nan=False), st.floats(-5e3, 5e3, allow_nan=False)),
    reverse=st.booleans(),
)
def test_units_origin_and_block_order_do_not_change_s_u(
    unit: float, origin: tuple[float, float], reverse: bool
) -> None:
    """s_u (in the drawing's units) × the unit is the same settlement in mm, wherever the
    drawing lies and in whichever order its blocks are listed."""
    result = alma.settlement_capacity(lintel(0.5, unit=unit, origin=origin, reverse=reverse))
    assert result.status == Status.OPTIMAL, result.message
    assert result.s_u * unit == pytest.approx(300.0 * 0.5 / math.hypot(1.0, 0.5), rel=REL)
    reference = _reference()
    assert len(result.curve.curve) == len(reference.curve.curve)  # the same steps, relative to L
    assert np.allclose(
        [p.d * unit for p in result.curve.curve], [p.d for p in reference.curve.curve], rtol=1e-6, atol=1e-9
    )


def test_a_scene_that_cannot_stand_before_settling_says_so() -> None:
    """A block whose centroid overhangs its support's edge (b/2 beyond it): no curve, no s_u."""
    scene = alma.Scene.from_dict(
        {
            "name": "overhang",
            "thickness": 100,
            "unit_weight": 20,
            "friction": 0.6,
            "live_load": {"direction": [-1, 0]},
            "blocks": [
                {
                    "id": "g",
                    "vertices": [[-300, -100], [0, -100], [0, 0], [-300, 0]],
                    "fixed": True,
                    "settlement": {"translation": [0, -1]},
                },
                {"id": "b", "vertices": [[-100, 0], [300, 0], [300, 100], [-100, 100]]},
            ],
        }
    )
    result = alma.settlement_capacity(scene)
    assert result.status == Status.NO_EQUILIBRIUM and math.isnan(result.s_u) and result.curve.curve == ()
    assert json.loads(json.dumps(result.to_dict()))["s_u"] is None


def test_no_settlement_is_a_clear_error() -> None:
    scene = alma.Scene.from_dict(
        {
            "name": "no settlement",
            "blocks": [
                {"id": "g", "vertices": [[-300, -100], [600, -100], [600, 0], [-300, 0]], "fixed": True},
                {"id": "b", "vertices": [[0, 0], [200, 0], [200, 600], [0, 600]]},
            ],
        }
    )
    with pytest.raises(SettleError, match="settlement"):
        alma.settlement_capacity(scene)


def test_spreading_arch_s_u_does_not_depend_on_block_order() -> None:
    """The symmetric arch's two crown hinges tie; the simplex breaks the tie by the blocks'
    order, so the curve α(s) differs, but the loss of the dead load's equilibrium does not
    (the two crack patterns are mirror images, the spread relative)."""
    data = json.loads((Path(__file__).resolve().parents[1] / "examples" / "spreading_arch.json").read_text())
    ahead = alma.settlement_capacity(alma.Scene.from_dict(data))
    behind = alma.settlement_capacity(alma.Scene.from_dict({**data, "blocks": data["blocks"][::-1]}))
    assert ahead.status == behind.status == Status.OPTIMAL
    assert behind.s_u == pytest.approx(ahead.s_u, rel=REL)


@pytest.mark.slow
@pytest.mark.parametrize(("b", "h", "f"), [(200.0, 600.0, 1.0), (200.0, 600.0, 0.2)])
def test_the_friction_model_meets_the_tilting_block_closed_form(b: float, h: float, f: float) -> None:
    # rocking about the downhill toe and sliding of one flat joint give the same α with and without
    # dilatancy, so case 1 holds for Eq. 9's search as well: α(θ) = tan(min(atan(b/h), φ) − θ)
    result = alma.settlement_capacity(tilting(b, h, f), model="nonassociative", steps=10)
    limit = min(math.atan(b / h), math.atan(f))
    assert result.status == Status.FEASIBLE, result.message
    assert result.curve.model == "nonassociative" and result.to_dict()["model"] == "nonassociative"
    assert result.s_u == pytest.approx(limit, rel=REL)
    for point in result.curve.curve:
        assert point.alpha == pytest.approx(math.tan(limit - point.d), abs=REL)


def test_the_friction_model_finds_the_lintel_already_at_its_limit() -> None:
    # case 3 has no friction capacity: the lintel's centroid is over the frictionless pier, so a
    # field carries it wholly on the pier (nothing on the support) and a horizontal slide costs
    # nothing: Eq. 9's lowest state is α = 0 (its certificate closes), before any settlement
    result = alma.settlement_capacity(lintel(0.5), model="nonassociative", steps=10)
    assert result.status == Status.NO_EQUILIBRIUM and "before any settlement" in result.message
    assert abs(result.curve.first.alpha) <= 1e-12 and math.isnan(result.s_u)
