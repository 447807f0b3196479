"""The SCIP certificate of Eq. 9 (``CertifySettings(backend="scip")``, SOS1 pairs), re-checked.

- On tiny scenes (≤ 3 joints) the proven bound equals the minimum over an enumeration of every
  active set (each point open or closed, each joint slipping +t, −t or sticking, each bounded
  force at its capacity, unloaded or between): per active set one static LP (min α) and one
  kinematic feasibility LP, by ``scipy.optimize.linprog``, none of alma's certification code.
  With cohesion and a tie too.
- The proven bound equals HiGHS's big-M proof on the scenes ``test_certify`` found by hypothesis.
- The state SCIP reports is a genuine collapse state (alma's exact-state verification).
- A node budget gives the same bound on every run, never above the best verified state, and a
  node-limited proof's bound is the result's ``bounds.lower`` (status ``feasible``).

Skipped with the reason when PySCIPOpt (the extra ``alma[scip]``) is not installed.
"""

from __future__ import annotations

import dataclasses

import pytest
from enumeration import enumerated_minimum
from test_certify import (
    BLOCK_BESIDE_SMALL_CUBE,
    COLUMN_BESIDE_SHORT_BLOCK,
    THREE_SIDE_BY_SIDE,
    columns_on_ground_scene,
    side_by_side,
)
from test_cohesion_ties_loads import _tied_block, _weight, block_scene

import alma
from alma.associative.lp import solve_lp
from alma.certify.milp import certify
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import build_model
from alma.nonassociative.exact_states import exact_state
from alma.nonassociative.search import solve_nonassociative
from alma.settings import CertifySettings

pytest.importorskip("pyscipopt", reason="PySCIPOpt is not installed (pip install 'alma[scip]')")

SCIP = CertifySettings(backend="scip")


def _inputs(scene: alma.Scene):
    model = build_model(scene)
    lp = solve_lp(model)
    sol = solve_nonassociative(model, lp.mechanism, lp.multipliers, effort="fast")
    best = sol.best.alpha if sol.best is not None else None
    return model, lp.alpha, [c.mechanism for c in sol.candidates] + [lp.mechanism], best


TINY = {
    "two side by side, f=1": side_by_side(2, 1.0),
    "two side by side, f=0.3": side_by_side(2, 0.3),
    "two stacked, f=0.6": alma.Scene.from_dict(columns_on_ground_scene(0.6, [100.0], [[80.0, 120.0]])),
    "block with base cohesion": block_scene(150.0, 300.0, 0.5, cohesion=2.0),
    "block with a tie": _tied_block(150.0, 400.0, 1.5, 300.0, 0.4 * _weight(150.0, 400.0)),
    "two stacked, cohesion on the upper joint only (override)": alma.Scene.from_dict(
        {
            **columns_on_ground_scene(0.6, [100.0], [[80.0, 160.0]]),
            "joints": [{"blocks": ["c0r0", "c0r1"], "cohesion": 3.0, "friction": 0.4}],
        }
    ),
}


#: Scenes whose enumeration takes more than ~10 s (1,728 or 1,296 active sets): marked slow.
SLOW = {"two side by side, f=1", "two side by side, f=0.3", "two stacked, cohesion on the upper joint only (override)"}


@pytest.mark.parametrize("name", [pytest.param(k, marks=pytest.mark.slow) if k in SLOW else k for k in TINY])
def test_scip_bound_equals_the_enumeration_of_all_active_sets(name):
    """Capped only by α_LP (no verified state given), SCIP's proven bound is the enumerated minimum."""
    model, alpha_lp, mechanisms, _ = _inputs(TINY[name])
    cert = certify(model, alpha_lp, mechanisms, settings=SCIP)
    assert cert.status == "proven" and not cert.velocity_bound_active, cert
    exact = enumerated_minimum(model, cert.velocity_bound)
    assert cert.lower == pytest.approx(min(exact, alpha_lp), abs=1e-6), (cert, exact)


@pytest.mark.parametrize("data", [COLUMN_BESIDE_SHORT_BLOCK, THREE_SIDE_BY_SIDE, BLOCK_BESIDE_SMALL_CUBE])
def test_scip_and_highs_prove_the_same_bound(data):
    model, alpha_lp, mechanisms, best = _inputs(alma.Scene.from_dict(data))
    highs = certify(model, alpha_lp, mechanisms, alpha_best=best)
    scip = certify(model, alpha_lp, mechanisms, alpha_best=best, settings=SCIP)
    assert highs.status == scip.status == "proven", (highs, scip)
    assert scip.lower == pytest.approx(highs.lower, abs=1e-6) and scip.lower <= best + 1e-12


def test_scip_state_is_a_verified_collapse_state():
    """Without a cap from the search, SCIP finds the rocking state at 0.5 below α_LP = 1 itself;
    alma's exact-state verification (residuals of equilibrium, yield and flow rule) accepts it."""
    model, alpha_lp, mechanisms, _ = _inputs(alma.Scene.from_dict(COLUMN_BESIDE_SHORT_BLOCK))
    cert = certify(model, alpha_lp, mechanisms, settings=SCIP)
    assert cert.status == "proven" and cert.upper == pytest.approx(0.5, abs=1e-6)
    assert cert.mechanism is not None
    state = exact_state(model, ContactPoints.from_model(model), cert.mechanism, "milp")
    assert state is not None and state.verified and state.alpha == pytest.approx(cert.upper, abs=1e-6)


@pytest.mark.slow  # ~13 s, the search on the wall most of it
def test_scip_node_budget_is_deterministic_and_below_the_verified_state():
    """A 10-block running-bond wall is not proven in 30 nodes: the same bound on every run, in
    [0, α_best], status node_limit."""
    model, alpha_lp, mechanisms, best = _inputs(alma.wall("running", 360.0, 180.0, 120.0, friction=0.6))
    assert model.n_free == 10
    budget = dataclasses.replace(SCIP, node_limit=30)
    cert = certify(model, alpha_lp, mechanisms, alpha_best=best, settings=budget)
    again = certify(model, alpha_lp, mechanisms, alpha_best=best, settings=budget)
    assert cert.status == "node_limit" and 0.0 <= cert.lower <= best + 1e-12
    assert (again.status, again.lower, again.nodes) == (cert.status, cert.lower, cert.nodes)


def test_without_pyscipopt_the_certificate_says_how_to_install(monkeypatch):
    from alma.backends import scip_backend

    monkeypatch.setattr(scip_backend, "pyscipopt", None)
    model, alpha_lp, mechanisms, best = _inputs(side_by_side(2, 1.0))
    cert = certify(model, alpha_lp, mechanisms, alpha_best=best, settings=SCIP)
    assert cert.status == "failed" and "alma[scip]" in cert.message and cert.lower == 0.0


@pytest.mark.slow  # ~13 s: two searches and two proofs
def test_a_node_limited_proof_is_the_results_lower_bound():
    """Six 1 × 2 blocks side by side, f = 1, SCIP stopped after 5 nodes: its positive bound (measured
    0.1105) is ``bounds.lower`` with status ``feasible`` and says it was stopped; it lies below the
    completed proof (HiGHS, 0.5 = the rocking state)."""
    scene = side_by_side(6, 1.0)
    budget = alma.Settings(certify=dataclasses.replace(SCIP, node_limit=5))
    result = alma.solve(scene, model="nonassociative", certify=True, effort="fast", settings=budget)
    cert = result.extra["certificate"]
    assert cert["status"] == "node_limit" and result.status == "feasible"
    assert 0.0 < result.bounds.lower == cert["lower"] < result.alpha
    assert result.bounds.lower_is == "proven bound (MILP certificate, SCIP, stopped by node limit)"
    full = alma.solve(scene, model="nonassociative", certify=True, effort="fast")
    assert full.status == "optimal" and full.bounds.lower == pytest.approx(0.5, abs=1e-6)
    assert result.bounds.lower <= full.bounds.lower
