"""The capacity curve of the friction model (``alma.push(..., model="nonassociative")``).

At every displaced configuration the friction search (Eq. 9) runs on the displaced geometry,
whose opened joints are point contacts.  A mechanism of point hinges is a linkage: it moves
every block and no contact, so its state's relative velocities are round-off and are measured
against the blocks' own velocities (:attr:`alma.settings.StateTolerances.linkage`), on the
canonical drawing and on the displaced drawing its states are carried back to alike.

References: the closed forms of ``verification/push_references.py`` (virtual work at finite rotation),
which hold for the friction model where no joint slides (friction high enough that every
mechanism rocks), and the associative curve of the same structure, which the friction curve must
follow where the same mechanism is the lowest.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pytest
from push_references import PORTAL, portal_alpha, portal_theta, rect, rocking_alpha, scene, theta_of_d

import alma
from alma.push import push
from benchmarks.bench_friction import FRICTION, WALLS

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_the_friction_curve_of_a_single_block_is_the_closed_form_to_its_zero():
    b, h = 240.0, 600.0
    result = push(scene([{"id": "b1", "vertices": rect(0, 0, b, h)}]), model="nonassociative", steps=8)
    assert result.status == alma.Status.FEASIBLE and result.end["reason"] == "alpha_zero"
    errors = [abs(p.alpha - rocking_alpha(b, h, theta_of_d(p.d, b, h))) for p in result.curve]
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
        assert p.alpha == pytest.approx(portal_alpha(portal_theta(p.d)), abs=1e-6)
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


@pytest.mark.slow
def test_the_friction_curve_of_ferris_and_tin_lois_wall_3_runs_to_its_zero():
    # the wall's friction mechanism keeps its contacts closed over finite steps; every point is a
    # verified state, the first the search's own α_NL
    wall = alma.coursed_wall(WALLS[3], 400.0, 175.0, friction=FRICTION, thickness=1000.0, unit_weight=10.0)
    curve = push(wall, model="nonassociative", steps=20)
    assert curve.status == alma.Status.FEASIBLE and curve.end["reason"] == "alpha_zero", curve.message
    assert all(p.status == alma.Status.FEASIBLE for p in curve.curve)
    assert curve.curve[0].alpha == alma.solve(wall, model="nonassociative").alpha
    assert len(curve.curve) >= 10 and abs(curve.curve[-1].alpha) <= 1e-6 < curve.curve[0].alpha
    assert curve.d0_bracket is not None and curve.d0_bracket[0] <= curve.d0 <= curve.d0_bracket[1]


@pytest.mark.slow
def test_ferris_and_tin_lois_wall_1_opens_a_locked_hinge_and_moves_on():
    # its friction mechanism's hinges close only to first order (three collinear among three
    # bodies): with every hinge kept closed the curve stopped at d = 0; one hinge opens now
    # (docs/seismic.md), and every point after it is a verified state of the displaced wall
    wall = alma.coursed_wall(WALLS[1], 400.0, 175.0, friction=FRICTION, thickness=1000.0, unit_weight=10.0)
    curve = push(wall, model="nonassociative", steps=20)
    assert len(curve.curve) >= 3 and curve.curve[-1].d > 10.0, curve.message
    assert all(p.status == alma.Status.FEASIBLE for p in curve.curve)
    assert "cannot stay closed" not in curve.message
    # it ends where the lowest verified state's mechanism (a sliding one) leaves the control block
    # still: a finding, stated as such, which bounds the ultimate displacement of the check
    assert curve.status == alma.Status.FEASIBLE and curve.end["reason"] == "control_still", curve.message
    assert curve.end["d"] == curve.curve[-1].d
    site = tomllib.loads((EXAMPLES / "site.toml").read_text())
    checked = alma.seismic(wall, site, curve=curve)
    assert checked.nonlinear["d0_extrapolated"] and math.isfinite(checked.nonlinear["safety_index"])
