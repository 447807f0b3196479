"""The MILP certification (and the ``milp`` start) with cohesion and ties (bounded forces).

The MILP of :mod:`alma.certify` writes each bounded column as 0 ≤ τ ≤ capacity with its flow
rule (d = −Gᵀu = d⁺ − d⁻; d⁺ > 0 ⇒ τ = capacity, d⁻ > 0 ⇒ τ = 0) by two binaries.  Checks:
the analytic single blocks (proven bound equal to min(f + c b t / W, b / h) and to the tie's
formula), the trap scene of ``test_certify`` with cohesion (the MILP alone finds the rocking state
below α_LP), cohesion → 0 recovering the cohesionless proof, random small cohesive and tied
assemblies (the proven bound equals the search's lowest verified state and lies between
Radenkovic's bound and α_LP), and the global big-M path.
"""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import HealthCheck, example, given, settings, strategies as st
from test_certify import COLUMN_BESIDE_SHORT_BLOCK, columns_on_ground, side_by_side
from test_cohesion_ties_loads import THICKNESS, _tied_block, _weight, block_scene

import alma
from alma.associative.lp import solve_lp
from alma.certify.milp import certify
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import build_model
from alma.nonassociative.exact_states import exact_state
from alma.nonassociative.search import solve_nonassociative
from alma.settings import CertifySettings


def _certified(scene: alma.Scene) -> alma.NonAssociativeResult:
    result = alma.solve(scene, model="nonassociative", certify=True)
    cert = result.extra["certificate"]
    assert cert["status"] == "proven" and not cert["velocity_bound_active"], cert
    return result


@pytest.mark.slow  # 8–16 s: `make test` keeps to 5 minutes; `make test-slow` (CI) runs it
@settings(max_examples=12, deadline=None)
@given(b=st.floats(60, 400), h=st.floats(40, 600), f=st.floats(0.1, 1.5), c=st.floats(0.5, 20.0))
def test_single_block_with_base_cohesion_is_proven(b, h, f, c):
    """The proven lower bound is α = min(f + c b t / W, b / h), and the status is optimal."""
    result = _certified(block_scene(b, h, f, cohesion=c))
    expected = min(f + c * b * THICKNESS * 1e-6 / _weight(b, h), b / h)
    assert result.status == "optimal"
    assert result.bounds.lower == pytest.approx(expected, rel=1e-7)
    assert result.bounds.lower <= result.alpha + 1e-12


@pytest.mark.slow  # 8–16 s: `make test` keeps to 5 minutes; `make test-slow` (CI) runs it
@settings(max_examples=12, deadline=None)
@given(
    b=st.floats(60, 300),
    h=st.floats(100, 600),
    f=st.floats(1.0, 3.0),
    y_frac=st.floats(0.3, 0.95),
    share=st.floats(0.0, 1.0),
)
def test_single_block_with_a_tie_is_proven(b, h, f, y_frac, share):
    """A tie at height y to a windward anchor, F = share · W: proven α = min(f + F/W, b/h + 2 F y / (W h))."""
    y, W = y_frac * h, _weight(b, h)
    result = _certified(_tied_block(b, h, f, y, share * W))
    assert result.status == "optimal"
    assert result.bounds.lower == pytest.approx(min(f + share, b / h + 2 * share * y / h), rel=1e-7)


def _with_cohesion(scene: alma.Scene, c: float) -> alma.Scene:
    return dataclasses.replace(scene, cohesion=c)


def test_milp_finds_the_trap_state_with_cohesion():
    """Three 100 × 200 mm blocks side by side, f = 1, cohesion c = 0.5 kPa (capacities 0.14 and 0.28
    of a block's weight): capped only by α_LP (1.138889), the MILP finds a verified state well below
    it and proves it; measured 0.738095, the search's lowest state."""
    scene = _with_cohesion(side_by_side(3, 1.0, b=100.0, h=200.0), 0.5)
    model = build_model(scene)
    lp = solve_lp(model)
    search = solve_nonassociative(model, lp.mechanism, lp.multipliers, effort="fast")
    cert = certify(model, lp.alpha, [c.mechanism for c in search.candidates] + [lp.mechanism])
    assert cert.status == "proven"
    assert cert.lower <= cert.upper + 1e-12 < lp.alpha - 1e-3
    assert cert.mechanism is not None
    state = exact_state(model, ContactPoints.from_model(model), cert.mechanism, "milp")
    assert state is not None and state.verified and state.alpha == pytest.approx(cert.upper, abs=1e-6)
    assert search.best is not None and cert.lower == pytest.approx(search.best.alpha, abs=1e-6)


def test_cohesion_to_zero_recovers_the_cohesionless_proof():
    """COLUMN_BESIDE_SHORT_BLOCK (test_certify): proven 0.5 without cohesion and with c = 10⁻⁹ kPa."""
    base = alma.Scene.from_dict(COLUMN_BESIDE_SHORT_BLOCK)
    plain = _certified(base).bounds.lower
    small = _certified(_with_cohesion(base, 1e-9)).bounds.lower
    assert plain == pytest.approx(0.5, abs=1e-6) and small == pytest.approx(plain, abs=1e-7)


@st.composite
def cohesive_columns(draw) -> alma.Scene:
    """The columns of ``test_certify`` with cohesion on every joint and, half the time, a tie from
    the first column's top block to a ground anchor point on the windward side."""
    data = draw(columns_on_ground())
    data["cohesion"] = draw(st.floats(0.05, 5.0))
    data["thickness"], data["unit_weight"] = 120.0, 18.0
    if draw(st.booleans()):
        top = [b for b in data["blocks"] if b["id"].startswith("c0r")][-1]
        corner, opposite = top["vertices"][0], top["vertices"][2]
        data["ties"] = [
            {
                "id": "t",
                "from": {"block": top["id"], "point": [corner[0], 0.5 * (corner[1] + opposite[1])]},
                "to": {"block": "ground", "point": [-25.0, -25.0]},
                "strength": draw(st.floats(0.0, 0.5)),
            }
        ]
    return alma.Scene.from_dict(data)


@pytest.mark.slow  # 20 cohesive MILP proofs: 49 s here
@given(scene=cohesive_columns())
@example(scene=_with_cohesion(alma.Scene.from_dict(COLUMN_BESIDE_SHORT_BLOCK), 0.3))
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_proven_bound_equals_the_search_on_random_cohesive_columns(scene):
    """The proven lower bound equals the lowest verified state (the search runs the ``milp`` start on
    scenes this small) and lies between Radenkovic's bound and α_LP."""
    both = alma.solve(scene, model="both", certify=True)
    nl, lp = both.nonassociative, both.associative
    assert nl.status in ("optimal", "feasible"), nl.message
    cert = nl.extra["certificate"]
    assert cert["status"] == "proven", cert
    assert cert["lower"] == pytest.approx(nl.alpha, abs=1e-6) and cert["lower"] <= nl.alpha + 1e-9
    assert nl.search["radenkovic_lower_bound"] - 1e-7 <= cert["lower"] <= lp.alpha + 1e-7


def test_global_big_m_path_gives_the_same_proof():
    """Above ``per_point_bounds`` the big-M constants come from row norms (the bounded columns'
    rates too): the same proven bound on a cohesive tied block."""
    scene = _tied_block(150.0, 400.0, 1.5, 300.0, 0.4 * _weight(150.0, 400.0))
    model = build_model(scene)
    lp = solve_lp(model)
    per_point = certify(model, lp.alpha, [lp.mechanism])
    global_m = certify(model, lp.alpha, [lp.mechanism], settings=CertifySettings(per_point_bounds=0))
    assert per_point.status == global_m.status == "proven"
    assert global_m.lower == pytest.approx(per_point.lower, abs=1e-7)
