"""Clarabel adapter: linear and quadratic programs ``min ½xᵀPx + qᵀx s.t. A x + s = b,
s ∈ {0}^e × R₊^k``, and the second-order cone programs of finite compressive strength
(:func:`solve_static_cone`).

Every Clarabel call of alma goes through this module: one settings factory (:func:`settings`)
and one status table (:data:`alma.backends.termination.CLARABEL`).  Each function returns an
:class:`~alma.backends.termination.SolverResult` whose ``form`` says how its termination reads
(a kinematic problem that is infeasible has no mechanism, a static one no stress field).
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import clarabel
import numpy as np
import scipy.sparse as sp

from alma.backends.termination import Form, SolverResult, termination

#: Iterative refinement's tolerances on the cone programs: near-rigid joints (σ_c l t ≫ N) leave
#: Clarabel's default steps 3e-9 off the optimum on the single block at σ_c = 1e7 MPa, 7e-10 with
#: this (docs/compressive.md).
REFINEMENT_TOLERANCE = 1e-14


def settings(
    tolerance: float,
    max_iter: int,
    *,
    time_limit: float | None = None,
    refine: bool = False,
    direct: str | None = "qdldl",
    presolve: bool = True,
) -> clarabel.DefaultSettings:
    """Clarabel's settings for alma's problems: silent, gap and feasibility ``tolerance``, at most
    ``max_iter`` iterations.

    ``direct``: the factorisation, QDLDL by default (None: Clarabel's own choice): Clarabel's
    "auto" switches to faer when the factor's flops per nonzero pass a threshold (running-bond
    walls from ~3,000 blocks), 3-5× slower per iteration here.  ``refine``: iterative
    refinement of each step (off for Eq. 10: the certificate, not Clarabel's residuals,
    decides; docs/decisions.md).  ``presolve`` off keeps the problem as given, for a solver
    whose data are updated between solves.  ``time_limit`` is a user's cap only.
    """
    s = clarabel.DefaultSettings()
    s.verbose = False
    s.tol_gap_abs = s.tol_gap_rel = s.tol_feas = float(tolerance)
    s.max_iter = int(max_iter)
    if direct is not None:
        s.direct_solve_method = direct
    s.iterative_refinement_enable = bool(refine)
    s.presolve_enable = bool(presolve)
    if time_limit is not None:
        s.time_limit = float(time_limit)
    return s


def _cones(n_zero: int, n_nonneg: int, n_soc3: int = 0, *, empty_nonneg: bool = True) -> list:
    """{0}^n_zero × R₊^n_nonneg × (Q³)^n_soc3; an empty {0} block is left out, an empty R₊ block
    only when ``empty_nonneg`` is False (the cone programs)."""
    nonneg = [clarabel.NonnegativeConeT(n_nonneg)] if n_nonneg or empty_nonneg else []
    return ([clarabel.ZeroConeT(n_zero)] if n_zero else []) + nonneg + [clarabel.SecondOrderConeT(3)] * n_soc3


def _result(sol, start: float, form: Form) -> SolverResult:
    raw = str(sol.status)
    return SolverResult(
        termination("clarabel", raw),
        raw,
        np.asarray(sol.x, dtype=float),
        np.asarray(sol.z, dtype=float),
        int(sol.iterations),
        time.perf_counter() - start,
        "Clarabel",
        form,
    )


def solve_conic_lp(
    q: np.ndarray,
    A: sp.spmatrix,
    b: np.ndarray,
    n_zero: int,
    n_nonneg: int,
    *,
    tolerance: float,
    max_iter: int,
    time_limit: float | None = None,
    refine: bool = False,
    quadratic: sp.spmatrix | None = None,
    direct: str | None = "qdldl",
    form: Form = "kinematic",
) -> SolverResult:
    """Solve ``min ½xᵀPx + qᵀx s.t. A x + s = b``, the first ``n_zero`` rows equalities.

    ``quadratic`` is P (default zero: an LP); ``direct``, ``refine``: see :func:`settings`;
    ``form``: the problem's form, for the result's status.  Returns the primal ``x`` and the
    duals ``z`` (one per row of A).
    """
    n = q.shape[0]
    P = sp.csc_matrix((n, n)) if quadratic is None else sp.csc_matrix(quadratic)
    start = time.perf_counter()
    sol = clarabel.DefaultSolver(
        P,
        np.asarray(q, dtype=float),
        sp.csc_matrix(A),
        np.asarray(b, dtype=float),
        _cones(n_zero, n_nonneg),
        settings(tolerance, max_iter, time_limit=time_limit, refine=refine, direct=direct),
    ).solve()
    return _result(sol, start, form)


def solve_static_cone(
    q: np.ndarray,
    A: sp.spmatrix,
    b: np.ndarray,
    n_zero: int,
    n_nonneg: int,
    n_soc3: int,
    *,
    tolerance: float,
    max_iter: int,
    time_limit: float | None = None,
    refine: bool = False,
) -> SolverResult:
    """Solve ``min qᵀx s.t. A x + s = b``, s ∈ {0}^n_zero × R₊^n_nonneg × (Q³)^n_soc3 (Q³ the
    second-order cone {(x, y, z): x ≥ ‖(y, z)‖}), a problem in static form.

    ``refine``: iterative refinement of each step to :data:`REFINEMENT_TOLERANCE`.  Returns the
    primal ``x``, the duals ``z`` (one per row of A) and the mapped status.
    """
    n = q.shape[0]
    s = settings(tolerance, max_iter, time_limit=time_limit, refine=refine)
    if refine:
        s.iterative_refinement_reltol = s.iterative_refinement_abstol = REFINEMENT_TOLERANCE
    start = time.perf_counter()
    cones = _cones(n_zero, n_nonneg, n_soc3, empty_nonneg=False)
    sol = clarabel.DefaultSolver(
        sp.csc_matrix((n, n)), np.asarray(q, dtype=float), sp.csc_matrix(A), np.asarray(b, dtype=float), cones, s
    ).solve()
    return _result(sol, start, "static")


class UpdatableQP:
    """A Clarabel problem ``min ½xᵀPx + qᵀx s.t. A x + s = b`` (the first ``n_zero`` rows
    equalities, the rest s ≥ 0) kept between solves, where only q and b change: presolve is off,
    so the data stay as given."""

    def __init__(
        self,
        quadratic: sp.spmatrix,
        q: np.ndarray,
        A: sp.spmatrix,
        b: np.ndarray,
        n_zero: int,
        n_nonneg: int,
        *,
        tolerance: float,
        max_iter: int,
        refine: bool = True,
        form: Form = "static",
    ) -> None:
        self._form = form
        self._solver = clarabel.DefaultSolver(
            sp.csc_matrix(quadratic),
            np.asarray(q, dtype=float),
            sp.csc_matrix(A),
            np.asarray(b, dtype=float),
            _cones(n_zero, n_nonneg),
            settings(tolerance, max_iter, refine=refine, presolve=False),
        )

    def solve(self, q: np.ndarray, b: Sequence[float] | np.ndarray) -> SolverResult:
        """Solve again with the linear cost ``q`` and the right-hand side ``b``."""
        start = time.perf_counter()
        self._solver.update(q=np.asarray(q, dtype=float), b=np.asarray(b, dtype=float))
        return _result(self._solver.solve(), start, self._form)
