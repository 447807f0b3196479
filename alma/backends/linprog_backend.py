"""scipy's ``linprog`` adapter: the HiGHS LPs of the non-associative search (Eqs. 2, 3, 5).

These LPs go through the HiGHS that scipy bundles, not highspy: the friction search branches on
the vertices they return, the vertex of a degenerate LP depends on the HiGHS release
(docs/decisions.md), and the releases differ (scipy 1.17.1 bundles HiGHS 1.12.0, highspy is
1.15.1 here), so they stay here until a switch to highspy is shown to keep α_NL.  Every
call is bounded by an iteration count, never by the clock; the status is read through
:data:`alma.backends.termination.LINPROG`.
"""

from __future__ import annotations

import time
from enum import StrEnum

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

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
) -> SolverResult:
    """``min cᵀx s.t. A_ub x ≤ b_ub, A_eq x = b_eq, bounds`` by HiGHS through ``linprog``.

    ``max_iterations``: HiGHS's iteration cap (``maxiter``); ``tolerance``: its primal and dual
    feasibility tolerances (absolute; HiGHS's 1e-7 when None).  ``duals`` are those of the equality
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
