"""The certificate's solver calls go through ``alma/backends/`` (one adapter per solver).

- No module of ``alma/certify/`` imports a solver package (highspy, pyscipopt, scipy.optimize)
  or another package's solver helpers (``alma.nonassociative.solvers``).
- The MILP functions of the HiGHS adapter (``new_model``, ``warm_maximum``, ``solve_milp``) on
  tiny problems whose answers are known (by enumeration or scipy's ``linprog``): an optimum, a
  problem with no solution below a bound (``pruned``), HiGHS's ``objective_bound`` option (which
  does not prune these problems in HiGHS 1.15), an LP that ends unbounded, a node budget that
  stops the tree before it closes.
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import TypedDict

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import linprog

from alma.backends import highs_backend

CERTIFY = Path(__file__).resolve().parents[1] / "alma" / "certify"
SOLVER_MODULES = ("highspy", "pyscipopt", "scipy.optimize", "clarabel", "casadi", "alma.nonassociative.solvers")


def _imports(path: Path) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


@pytest.mark.parametrize("path", sorted(CERTIFY.glob("*.py")), ids=lambda p: p.name)
def test_certify_imports_no_solver_package(path):
    bad = {
        name for name in _imports(path) for solver in SOLVER_MODULES if name == solver or name.startswith(solver + ".")
    }
    assert not bad, f"{path.name} imports {sorted(bad)}: solver calls belong in alma/backends/"


Problem = tuple[np.ndarray, np.ndarray, np.ndarray, sp.csr_matrix, np.ndarray, np.ndarray]


def _knapsack() -> Problem:
    """max 5a + 4b + 3c s.t. 2a + 3b + c ≤ 5, 4a + b + 2c ≤ 11, 3a + 4b + 2c ≤ 8, a, b, c ∈ {0..5}:
    optimum 13 at (2, 0, 1) (checked by enumeration below), as a minimisation of −(…)."""
    cost = -np.array([5.0, 4.0, 3.0])
    A = sp.csr_matrix(np.array([[2.0, 3.0, 1.0], [4.0, 1.0, 2.0], [3.0, 4.0, 2.0]]))
    return cost, np.zeros(3), np.full(3, 5.0), A, np.full(3, -np.inf), np.array([5.0, 11.0, 8.0])


def _enumerated_optimum() -> float:
    cost, _, _, A, _, hi = _knapsack()
    grid = np.array(np.meshgrid(*[np.arange(6)] * 3)).reshape(3, -1).T.astype(float)
    feasible = (A @ grid.T <= hi[:, None] + 1e-12).all(axis=0)
    return float((grid[feasible] @ cost).min())


class MipOptions(TypedDict):
    """The keyword arguments of :func:`highs_backend.solve_milp` these tests set."""

    node_limit: int
    absolute_gap: float
    relative_gap: float
    integrality_tolerance: float


MIP: MipOptions = dict(node_limit=10_000, absolute_gap=1e-9, relative_gap=1e-9, integrality_tolerance=1e-9)


def test_solve_milp_proves_the_enumerated_optimum():
    out = highs_backend.solve_milp(*_knapsack(), np.ones(3, dtype=bool), **MIP)
    assert out.status == "optimal"
    assert _enumerated_optimum() == -13.0
    assert out.x is not None and float(_knapsack()[0] @ out.x) == pytest.approx(-13.0, abs=1e-9)
    assert out.dual_bound == pytest.approx(-13.0, abs=1e-8)


def test_solve_milp_without_a_solution_below_a_bound_is_pruned():
    # The objective as a row ≤ −14 (the optimum is −13): the tree closes without a solution.
    cost, lo, hi, A, row_lo, row_hi = _knapsack()
    A = sp.vstack([A, sp.csr_matrix(cost[None, :])])
    out = highs_backend.solve_milp(
        cost, lo, hi, A, np.r_[row_lo, -np.inf], np.r_[row_hi, -14.0], np.ones(3, dtype=bool), **MIP
    )
    assert out.status == "pruned" and out.x is None


def test_the_objective_bound_option_does_not_change_the_optimum():
    # HiGHS 1.15 reports the optimum −13 even with objective_bound = −14 (it does not prune by
    # it on this problem): callers bound the objective by a column or row bound as well.
    out = highs_backend.solve_milp(*_knapsack(), np.ones(3, dtype=bool), objective_bound=-14.0, **MIP)
    assert out.status in ("optimal", "pruned")
    if out.status == "optimal":
        assert float(_knapsack()[0] @ out.x) == pytest.approx(-13.0, abs=1e-9)


def test_solve_milp_node_budget_is_reported():
    # A 0-1 multi-knapsack (30 items, 10 rows, seeded) whose tree needs 13 nodes with the budget
    # open: one node stops it, with the node budget named and a dual bound below the optimum.
    rng = np.random.default_rng(0)
    A = sp.csr_matrix(rng.integers(1, 20, (10, 30)).astype(float))
    cost, hi = -rng.integers(1, 30, 30).astype(float), A.sum(axis=1).A1 / 3
    problem = (cost, np.zeros(30), np.ones(30), A, np.full(10, -np.inf), hi, np.ones(30, dtype=bool))
    full = highs_backend.solve_milp(*problem, **MIP)
    assert full.status == "optimal" and full.nodes > 1
    one_node: MipOptions = {**MIP, "node_limit": 1}
    cut = highs_backend.solve_milp(*problem, **one_node)
    assert cut.status == "node_limit" and cut.nodes <= 1
    assert cut.dual_bound <= float(cost @ full.x) + 1e-9


def test_warm_maximum_solves_one_objective_after_another():
    cost, lo, hi, A, row_lo, row_hi = _knapsack()
    h = highs_backend.new_model(np.zeros(3), lo, hi, A, row_lo, row_hi)
    # LP maxima of single coordinates over the knapsack polytope (by hand: a ≤ 5/2 from row 1,
    # a ≤ 11/4 from row 2, a ≤ 8/3 from row 3 → 2.5; b ≤ 5/3 (row 1), b ≤ 2 (row 3) → 5/3).
    assert highs_backend.warm_maximum(h, np.array([1.0, 0.0, 0.0]), 1000) == pytest.approx(2.5)
    assert highs_backend.warm_maximum(h, np.array([0.0, 1.0, 0.0]), 1000) == pytest.approx(5.0 / 3.0)
    reference = -linprog(cost, A_ub=A.toarray(), b_ub=row_hi, bounds=list(zip(lo, hi, strict=True))).fun
    assert highs_backend.warm_maximum(h, -cost, 1000) == pytest.approx(reference, abs=1e-9)


def test_warm_maximum_says_when_an_lp_is_unbounded():
    h = highs_backend.new_model(
        np.zeros(2), np.zeros(2), np.full(2, np.inf), sp.csr_matrix([[1.0, -1.0]]), np.array([-np.inf]), np.array([1.0])
    )
    message = highs_backend.warm_maximum(h, np.array([1.0, 1.0]), 1000)
    assert isinstance(message, str) and message.startswith("ended ") and "nbounded" in message
