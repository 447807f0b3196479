"""scipy's ``linprog`` adapter: the HiGHS LPs of the non-associative search (Eqs. 2, 3, 5).

These LPs go through the HiGHS that scipy bundles, not highspy: the friction search branches on
the vertices they return, the vertex of a degenerate LP depends on the HiGHS release
(docs/decisions.md), and the releases differ (scipy 1.17.1 bundles HiGHS 1.12.0, highspy is
1.15.1 here), so they stay here until a switch to highspy is shown to keep α_NL.  Every
call is bounded by an iteration count, never by the clock; the status is read through
:data:`alma.backends.termination.LINPROG`.  :func:`polished` re-solves an optimal vertex on its
own basis, so that its values do not depend on how far HiGHS left it inside its tolerances.
"""

from __future__ import annotations

import time
from enum import StrEnum

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from alma.backends.qdldl_backend import least_squares_solver
from alma.backends.termination import Form, SolverResult, termination


class LPMethod(StrEnum):
    """How an LP of the search is solved: HiGHS's own choice for an LP (its dual simplex: a
    vertex), HiGHS's interior point with crossover (a vertex, faster on large scenes), or
    Clarabel's interior point (a point inside the optimal face; :mod:`alma.nonassociative`)."""

    SIMPLEX = "simplex"
    IPM = "ipm"
    CLARABEL = "clarabel"


#: ``linprog``'s method for each HiGHS path.
_LINPROG_METHOD = {LPMethod.SIMPLEX: "highs", LPMethod.IPM: "highs-ipm"}


def solve_lp(
    c: np.ndarray,
    *,
    A_ub: sp.spmatrix | None,
    b_ub: np.ndarray | None,
    A_eq: sp.spmatrix,
    b_eq: np.ndarray,
    bounds,
    method: LPMethod = LPMethod.SIMPLEX,
    max_iterations: int,
    tolerance: float | None = None,
    form: Form = "static",
    polish: bool = False,
) -> SolverResult:
    """``min cᵀx s.t. A_ub x ≤ b_ub, A_eq x = b_eq, bounds`` by HiGHS through ``linprog``.

    ``max_iterations``: HiGHS's iteration cap (``maxiter``); ``tolerance``: its primal and dual
    feasibility tolerances (absolute; HiGHS's 1e-7 when None).  ``polish``: an optimal vertex is
    re-solved on its own basis (:func:`polished`; ``bounds`` an (n, 2) array).  ``duals`` are those of the equality
    rows in the conic convention (c + A_eqᵀ duals + … = 0, i.e. −∂ objective/∂ b_eq); empty when
    ``linprog`` gives none.
    """
    if method not in _LINPROG_METHOD:
        raise ValueError(f"linprog solves by {sorted(_LINPROG_METHOD)}, got {method!r}")
    start = time.perf_counter()
    options: dict[str, float | int] = {"maxiter": int(max_iterations)}
    if tolerance is not None:
        options.update(primal_feasibility_tolerance=tolerance, dual_feasibility_tolerance=tolerance)
    res = linprog(
        c,
        A_ub=A_ub,
        b_ub=b_ub,
        A_eq=A_eq,
        b_eq=b_eq,
        bounds=bounds,
        method=_LINPROG_METHOD[LPMethod(method)],
        options=options,
    )
    marginals = getattr(getattr(res, "eqlin", None), "marginals", None)
    duals = -np.asarray(marginals) if marginals is not None else np.zeros(0)
    x = np.asarray(res.x) if res.x is not None else np.zeros(0)
    if polish and res.status == 0:
        x = polished(A_eq, b_eq, np.asarray(bounds, dtype=float), x)
    return SolverResult(
        termination("linprog", int(res.status)),
        f"{res.status}: {res.message}",
        x,
        duals,
        int(getattr(res, "nit", 0) or 0),
        time.perf_counter() - start,
        f"HiGHS {method} (linprog)",
        form,
    )


def polished(A_eq: sp.spmatrix, b_eq: np.ndarray, bounds: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The vertex ``x`` of ``A_eq x = b_eq, bounds`` re-solved exactly on its own basis.

    HiGHS's interior point with crossover can end at a vertex that it calls optimal while its
    rows balance only to its feasibility tolerance (2.98e-9 of the largest force on a paper
    panel, against 3e-16 for the same vertex after a round-off perturbation of the data).  The
    columns off their bounds are the basis B (independent at a vertex, so x_B is unique);
    ``B x_B = b_eq − A_N x_N`` is solved in the least-squares sense by QDLDL on the augmented
    system with three refinement steps (exact for a square B and for a degenerate vertex's tall
    one), so the vertex's values depend on its basis only, and on no CPU's BLAS.  ``x`` is kept
    when B is wider than the rows, when QDLDL fails, when the re-solved values leave their bounds
    or are not finite, or when they balance worse (as where B is numerically singular).
    """
    A = sp.csc_matrix(A_eq)
    lower, upper = bounds[:, 0], bounds[:, 1]
    basic = np.flatnonzero((x != lower) & (x != upper))
    if basic.size == 0 or basic.size > A.shape[0]:
        return x
    fixed = x.copy()
    fixed[basic] = 0.0
    rhs = b_eq - A @ fixed
    B = A[:, basic]
    try:
        solve = least_squares_solver(B)
    except (ValueError, RuntimeError):  # no factorisation: not a basis
        return x
    xb = solve(rhs)
    for _ in range(3):
        xb = xb + solve(rhs - B @ xb)
    if not np.isfinite(xb).all():
        return x
    y = x.copy()
    y[basic] = xb
    inside = bool(np.all(xb >= lower[basic]) and np.all(xb <= upper[basic]))
    if not inside or not np.abs(A @ y - b_eq).max() <= np.abs(A @ x - b_eq).max():
        return x
    return y
