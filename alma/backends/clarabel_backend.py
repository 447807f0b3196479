"""Clarabel adapter: linear programs ``min qᵀx s.t. A x + s = b, s ∈ {0}^e × R₊^k``, and the
second-order cone programs of finite compressive strength (:func:`solve_static_cone`).

Every Clarabel call of alma goes through :func:`solve_conic_lp`: one settings factory and one
status map.  The map is written for problems in alma's *kinematic* form (a mechanism x with
f_Lᵀx fixed, as Eq. 10): a primal-infeasible kinematic problem has no mechanism (the structure
does not collapse), a dual-infeasible one has no static field (no equilibrium).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import clarabel
import numpy as np
import scipy.sparse as sp

from alma.status import Status

#: Clarabel's statuses for a problem in kinematic form, as alma's vocabulary.  ``Solved`` and
#: ``AlmostSolved`` are only candidates: the certificate decides whether they are ``optimal``.
KINEMATIC_STATUS: dict[str, Status] = {
    "Solved": Status.OPTIMAL,
    "AlmostSolved": Status.OPTIMAL,
    "PrimalInfeasible": Status.NO_COLLAPSE,
    "AlmostPrimalInfeasible": Status.NO_COLLAPSE,
    "DualInfeasible": Status.NO_EQUILIBRIUM,
    "AlmostDualInfeasible": Status.NO_EQUILIBRIUM,
    "MaxIterations": Status.NOT_CONVERGED,
    "MaxTime": Status.LIMIT_REACHED,
    "NumericalError": Status.NOT_CONVERGED,
    "InsufficientProgress": Status.NOT_CONVERGED,
    "CallbackTerminated": Status.LIMIT_REACHED,
}


@dataclass(frozen=True)
class ConicSolution:
    """Clarabel's answer: ``status`` in alma's words, ``raw_status`` in Clarabel's."""

    status: Status
    raw_status: str
    x: np.ndarray
    z: np.ndarray
    iterations: int
    solve_time: float


def settings(tolerance: float, max_iter: int, *, time_limit: float | None = None,
             refine: bool = False) -> clarabel.DefaultSettings:
    """Clarabel's settings for alma's LPs.

    QDLDL is named explicitly: Clarabel's "auto" switches to faer when the factor's flops per
    nonzero pass a threshold (running-bond walls from ~3,000 blocks), 3-5× slower per iteration
    here.  Iterative refinement is off by default: the certificate, not Clarabel's residuals,
    decides (docs/decisions.md).  ``time_limit`` is a user's cap only.
    """
    s = clarabel.DefaultSettings()
    s.verbose = False
    s.tol_gap_abs = s.tol_gap_rel = s.tol_feas = float(tolerance)
    s.max_iter = int(max_iter)
    s.direct_solve_method = "qdldl"
    s.iterative_refinement_enable = bool(refine)
    if time_limit is not None:
        s.time_limit = float(time_limit)
    return s


def solve_conic_lp(q: np.ndarray, A: sp.spmatrix, b: np.ndarray, n_zero: int, n_nonneg: int, *,
                   tolerance: float, max_iter: int, time_limit: float | None = None,
                   refine: bool = False, quadratic: sp.spmatrix | None = None) -> ConicSolution:
    """Solve ``min ½xᵀPx + qᵀx s.t. A x + s = b``, the first ``n_zero`` rows equalities.

    ``quadratic`` is P (default zero: an LP).  Returns the primal ``x``, the duals ``z`` (one
    per row of A) and the status mapped through :data:`KINEMATIC_STATUS`.
    """
    n = q.shape[0]
    P = sp.csc_matrix((n, n)) if quadratic is None else sp.csc_matrix(quadratic)
    cones = ([clarabel.ZeroConeT(n_zero)] if n_zero else []) + [clarabel.NonnegativeConeT(n_nonneg)]
    start = time.perf_counter()
    sol = clarabel.DefaultSolver(P, np.asarray(q, dtype=float), sp.csc_matrix(A), np.asarray(b, dtype=float),
                                 cones, settings(tolerance, max_iter, time_limit=time_limit, refine=refine)).solve()
    raw = str(sol.status)
    return ConicSolution(KINEMATIC_STATUS.get(raw, Status.NOT_CONVERGED), raw, np.asarray(sol.x, dtype=float),
                         np.asarray(sol.z, dtype=float), int(sol.iterations), time.perf_counter() - start)


#: Clarabel's statuses for a problem in *static* form (max α over stress fields, as the conic
#: problem of finite compressive strength): an infeasible static problem has no admissible stress
#: field for any α, an unbounded one carries any α.
STATIC_STATUS: dict[str, Status] = {
    **KINEMATIC_STATUS,
    "PrimalInfeasible": Status.NO_EQUILIBRIUM,
    "AlmostPrimalInfeasible": Status.NO_EQUILIBRIUM,
    "DualInfeasible": Status.NO_COLLAPSE,
    "AlmostDualInfeasible": Status.NO_COLLAPSE,
}


#: Iterative refinement's tolerances on the cone programs: near-rigid joints (σ_c l t ≫ N) leave
#: Clarabel's default steps 3e-9 off the optimum on the single block at σ_c = 1e7 MPa, 7e-10 with
#: this (docs/compressive.md).
REFINEMENT_TOLERANCE = 1e-14


def solve_static_cone(q: np.ndarray, A: sp.spmatrix, b: np.ndarray, n_zero: int, n_nonneg: int,
                      n_soc3: int, *, tolerance: float, max_iter: int,
                      time_limit: float | None = None, refine: bool = False) -> ConicSolution:
    """Solve ``min qᵀx s.t. A x + s = b``, s ∈ {0}^n_zero × R₊^n_nonneg × (Q³)^n_soc3 (Q³ the
    second-order cone {(x, y, z): x ≥ ‖(y, z)‖}), a problem in static form (:data:`STATIC_STATUS`).

    ``refine``: iterative refinement of each step to :data:`REFINEMENT_TOLERANCE`.  Returns the
    primal ``x``, the duals ``z`` (one per row of A) and the mapped status.
    """
    n = q.shape[0]
    cones = ([clarabel.ZeroConeT(n_zero)] if n_zero else []) + \
        ([clarabel.NonnegativeConeT(n_nonneg)] if n_nonneg else []) + [clarabel.SecondOrderConeT(3)] * n_soc3
    s = settings(tolerance, max_iter, time_limit=time_limit, refine=refine)
    if refine:
        s.iterative_refinement_reltol = s.iterative_refinement_abstol = REFINEMENT_TOLERANCE
    start = time.perf_counter()
    sol = clarabel.DefaultSolver(sp.csc_matrix((n, n)), np.asarray(q, dtype=float), sp.csc_matrix(A),
                                 np.asarray(b, dtype=float), cones, s).solve()
    raw = str(sol.status)
    return ConicSolution(STATIC_STATUS.get(raw, Status.NOT_CONVERGED), raw, np.asarray(sol.x, dtype=float),
                         np.asarray(sol.z, dtype=float), int(sol.iterations), time.perf_counter() - start)
