"""The solver layer: one result type, one table of terminations per solver, one meaning per form."""

from __future__ import annotations

import clarabel
import highspy
import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings, strategies as st

from alma.backends.clarabel_backend import UpdatableQP, solve_conic_lp
from alma.backends.highs_backend import INF, lp_model, solve_conic_form
from alma.backends.highs_warm import WarmLP
from alma.backends.linprog_backend import LPMethod, polished, solve_lp
from alma.backends.termination import (
    CLARABEL,
    HIGHS,
    KINEMATIC_MEANING,
    STATIC_MEANING,
    Termination,
    meaning,
    termination,
)
from alma.status import Status


def test_tables_name_real_statuses():
    """No typo in a table: every key is a status the installed solver has."""
    clarabel_names = {n for n in dir(clarabel.SolverStatus) if not n.startswith("_")}
    highs_names = {n for n in dir(highspy.HighsModelStatus) if n.startswith("k")}
    assert set(CLARABEL) <= clarabel_names
    assert set(HIGHS) <= highs_names
    assert clarabel_names <= set(CLARABEL)  # every Clarabel status is read, none falls to ERROR


def test_unknown_status_is_an_error():
    assert termination("highs", "kLoadError") is Termination.ERROR
    assert termination("clarabel", "SomethingNew") is Termination.ERROR


@pytest.mark.parametrize("term", list(Termination))
def test_every_termination_means_something_in_both_forms(term):
    assert meaning(term, "kinematic") in Status and meaning(term, "static") in Status
    assert (meaning(term, "kinematic") == Status.OPTIMAL) == term.solved


def test_infeasible_and_unbounded_swap_between_forms():
    assert KINEMATIC_MEANING[Termination.INFEASIBLE] is Status.NO_COLLAPSE
    assert STATIC_MEANING[Termination.INFEASIBLE] is Status.NO_EQUILIBRIUM
    assert KINEMATIC_MEANING[Termination.UNBOUNDED] is Status.NO_EQUILIBRIUM
    assert STATIC_MEANING[Termination.UNBOUNDED] is Status.NO_COLLAPSE
    with pytest.raises(ValueError, match="form"):
        meaning(Termination.OPTIMAL, "dynamic")  # type: ignore[arg-type]  # the bad form under test


# min x0 + 2 x1  s.t.  x0 + x1 = 1,  x ≥ 0   (rows: the equality, then −x ≤ 0)
Q = np.array([1.0, 2.0])
A = sp.csc_matrix(np.array([[1.0, 1.0], [-1.0, 0.0], [0.0, -1.0]]))
B = np.array([1.0, 0.0, 0.0])


@pytest.mark.parametrize(
    "solve",
    [
        lambda q, b: solve_conic_lp(q, A, b, 1, 2, tolerance=1e-10, max_iter=100),
        lambda q, b: solve_conic_form(q, A, b, 1),
        lambda q, b: solve_conic_form(q, A, b, 1, solver="ipm"),
    ],
)
def test_conic_adapters_agree(solve):
    """Clarabel and HiGHS give the same x and the same duals (q + Aᵀz = 0) on one LP, and read an
    infeasible and an unbounded one alike."""
    sol = solve(Q, B)
    assert sol.termination.solved and sol.status is Status.OPTIMAL
    assert np.allclose(sol.x, [1.0, 0.0], atol=1e-8)
    assert np.allclose(Q + A.T @ sol.duals, 0.0, atol=1e-8)
    assert solve(Q, np.array([-1.0, 0.0, 0.0])).termination in (
        Termination.INFEASIBLE,
        Termination.INFEASIBLE_OR_UNBOUNDED,
    )
    A_ray = sp.csc_matrix(np.array([[1.0, -1.0], [-1.0, 0.0], [0.0, -1.0]]))  # x0 = x1 ≥ 0: a ray
    ray = {
        "Clarabel": lambda: solve_conic_lp(-Q, A_ray, np.zeros(3), 1, 2, tolerance=1e-10, max_iter=100),
        "HiGHS": lambda: solve_conic_form(-Q, A_ray, np.zeros(3), 1),
    }[sol.solver.split()[0]]()
    assert ray.termination is Termination.UNBOUNDED and ray.status is Status.NO_EQUILIBRIUM


def test_linprog_adapter_duals_follow_the_conic_convention():
    sol = solve_lp(
        Q,
        A_ub=None,
        b_ub=None,
        A_eq=sp.csr_matrix(np.array([[1.0, 1.0]])),
        b_eq=np.array([1.0]),
        bounds=[(0, None), (0, None)],
        method=LPMethod.SIMPLEX,
        max_iterations=100,
    )
    assert sol.termination is Termination.OPTIMAL and np.allclose(sol.x, [1.0, 0.0])
    assert np.allclose(sol.duals, [-1.0])  # q₀ + 1 · z = 0 on the active column x0
    infeasible = solve_lp(
        Q,
        A_ub=None,
        b_ub=None,
        A_eq=sp.csr_matrix(np.array([[1.0, 1.0]])),
        b_eq=np.array([-1.0]),
        bounds=[(0, None), (0, None)],
        max_iterations=100,
    )
    assert infeasible.termination is Termination.INFEASIBLE and infeasible.status is Status.NO_EQUILIBRIUM
    with pytest.raises(ValueError, match="linprog"):
        solve_lp(
            Q,
            A_ub=None,
            b_ub=None,
            A_eq=sp.csr_matrix(np.ones((1, 2))),
            b_eq=np.ones(1),
            bounds=None,
            method=LPMethod.CLARABEL,
            max_iterations=10,
        )


def test_warm_lp_resolves_as_a_cold_one():
    """A bound changed on a kept HiGHS model gives what a new model gives."""
    lp = lp_model(Q, np.zeros(2), np.full(2, INF), sp.csc_matrix(np.array([[1.0, 1.0]])), np.ones(1), np.ones(1))
    warm = WarmLP(lp)
    first = warm.run(100)
    assert first.termination is Termination.OPTIMAL and np.allclose(first.x, [1.0, 0.0])
    warm.change_col_bounds(np.array([0], dtype=np.int32), np.zeros(1), np.array([0.25]))
    again = warm.run(100)
    assert again.termination is Termination.OPTIMAL and np.allclose(again.x, [0.25, 0.75])
    assert np.allclose(again.duals, [-2.0])
    warm.change_row_bounds(np.array([0], dtype=np.int32), np.array([-1.0]), np.array([-1.0]))
    assert warm.run(100).termination is Termination.INFEASIBLE


def test_updatable_qp_follows_its_data():
    """min ½x² − t x, x ≥ 0 (one row −x ≤ 0): x = max(t, 0) as t changes between solves."""
    qp = UpdatableQP(
        sp.csc_matrix(np.eye(1)),
        np.zeros(1),
        sp.csc_matrix(np.array([[-1.0]])),
        np.zeros(1),
        0,
        1,
        tolerance=1e-10,
        max_iter=100,
    )
    for t in (2.0, -1.0, 0.5):
        sol = qp.solve(np.array([-t]), np.zeros(1))
        assert sol.termination.solved and abs(sol.x[0] - max(t, 0.0)) < 1e-7


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(3, 8), st.integers(0, 6))
def test_a_vertex_polished_balances_and_keeps_its_basis(seed, rows, extra):
    """A vertex whose basic values are off by 1e-9 (as HiGHS's crossover can leave them) is
    re-solved on its basis: the rows balance to round-off and the vertex is HiGHS's own."""
    rng = np.random.default_rng(seed)
    A = sp.csc_matrix(rng.uniform(-1.0, 1.0, (rows, rows + 1 + extra)))
    b = A @ rng.uniform(0.5, 2.0, A.shape[1])
    bounds = np.column_stack([np.zeros(A.shape[1]), np.full(A.shape[1], np.inf)])
    vertex = solve_lp(
        rng.uniform(0.1, 1.0, A.shape[1]), A_ub=None, b_ub=None, A_eq=A, b_eq=b, bounds=bounds, max_iterations=1000
    ).x
    off = vertex + np.where(vertex > 0, 1e-9 * rng.uniform(-1.0, 1.0, vertex.size), 0.0)
    fixed = polished(A, b, bounds, off)
    assert np.abs(A @ fixed - b).max() <= 1e-12 * max(1.0, np.abs(b).max())
    np.testing.assert_allclose(fixed, vertex, rtol=0, atol=1e-10 * max(1.0, np.abs(vertex).max()))
    assert np.array_equal(fixed == 0, vertex == 0)


def test_a_point_that_is_not_a_vertex_is_kept():
    """More columns off their bounds than rows (an interior point): no basis to re-solve on."""
    A = sp.csc_matrix(np.array([[1.0, 1.0, 1.0]]))
    bounds = np.array([[0.0, np.inf]] * 3)
    x = np.array([0.3, 0.3, 0.4 + 1e-9])
    assert polished(A, np.array([1.0]), bounds, x) is x


def test_a_basis_whose_values_leave_their_bounds_is_kept():
    """x₁ + x₂ = 1 with x₂ at its upper bound 0.5: re-solved on the basis {x₁}, x₁ = 0.5 would
    leave its bounds [0, 0.2], so the point is kept as given."""
    A = sp.csc_matrix(np.array([[1.0, 1.0]]))
    bounds = np.array([[0.0, 0.2], [0.0, 0.5]])
    x = np.array([0.1, 0.5])
    assert polished(A, np.array([1.0]), bounds, x) is x
