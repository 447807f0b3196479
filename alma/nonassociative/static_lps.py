"""The static and kinematic LPs of the non-associative search (Eqs. 2, 3, 5).

Every LP here is bounded by an iteration count (HiGHS's simplex iterations through
:mod:`alma.backends.linprog_backend`, Clarabel's through :mod:`alma.backends.clarabel_backend`):
a stalled LP counts as a failed attempt after the same work on every machine.

With bounded forces (cohesion, ties: :mod:`alma.nonassociative.bounded`) the static LPs gain
their columns G and forces 0 ≤ τ ≤ capacity (within an active set's bounds), and the kinematic
LP their rates' rows; a scene without them builds exactly the LPs it always did.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import cast

import numpy as np
import scipy.sparse as sp

from alma.backends.clarabel_backend import solve_conic_lp
from alma.backends.linprog_backend import LPMethod, solve_lp
from alma.backends.termination import SolverResult, Termination
from alma.floats import dot
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative import bounded as bf
from alma.settings import AssociativeSettings

#: The static LPs' default method: a vertex by HiGHS's simplex.
LP_METHOD = LPMethod.SIMPLEX
#: HiGHS's feasibility tolerances in the fixed-set static LP: its α is a state's α, and at
#: HiGHS's default 1e-7 a simplex vertex stopped 5e-7 above the LP's minimum on a paper panel.
FIXED_SET_TOLERANCE = 1e-10
#: Dual-simplex iterations of a kinematic LP before HiGHS's interior point takes it over: 99 % of
#: the paper panels' feasible ones take at most 151; of the runs that went on to 590–980, three
#: ended in numerical trouble after up to 30 ms a pivot.
KINEMATIC_PROBE_PIVOTS = 200


@dataclass(frozen=True)
class StaticLP:
    """Solution of a static LP over (α, N, T) at the contact points, with its mechanism."""

    status: Termination  # OPTIMAL, or why there is no field: UNBOUNDED, INFEASIBLE, ERROR
    alpha: float
    normal: np.ndarray
    shear: np.ndarray
    mechanism: np.ndarray | None  # f_Lᵀu = n_free
    pivots: int = 0  # simplex (or interior-point) iterations spent
    #: τ of the bounded forces (cohesion, ties), 0 ≤ τ ≤ capacity; empty without them.
    bounded: np.ndarray = field(default_factory=lambda: np.zeros(0))


def failed(status: Termination, count: int, pivots: int = 0, alpha: float = np.nan) -> StaticLP:
    """A StaticLP without a field (unbounded, infeasible or error)."""
    return StaticLP(status, alpha, np.zeros(count), np.zeros(count), None, pivots)


def with_bounded_columns(model: Model, A_eq: sp.csr_matrix, A_ub: sp.csr_matrix) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """The rows over x = (α, N, T) extended to x = (α, N, T, τ): G in equilibrium, τ nowhere else."""
    q = model.n_bounded
    return (sp.hstack([A_eq, model.bounded]).tocsr(), sp.hstack([A_ub, sp.csr_matrix((A_ub.shape[0], q))]).tocsr())


def _kept_generators(open_points: np.ndarray, slip_sign: np.ndarray) -> np.ndarray:
    """Which cone generators n ± f t of each point (columns (point, ±) of H) an active set keeps:
    an open point neither, a point slipping in +t (T = −f N) only n − f t, one slipping in −t
    only n + f t."""
    kept = np.empty(2 * open_points.size, dtype=bool)
    kept[0::2] = ~open_points & (slip_sign <= 0)
    kept[1::2] = ~open_points & (slip_sign >= 0)
    return kept


def static_lp(
    model: Model,
    points: ContactPoints,
    open_points: np.ndarray,
    slip_sign: np.ndarray,
    *,
    max_pivots: int = 200_000,
    method: LPMethod = LP_METHOD,
    bounded_signs: np.ndarray | None = None,
) -> StaticLP:
    """The smallest α with a fixed active set (Eqs. 3 and 5), a vertex by HiGHS.

    Written on the cone generators n ± f t of each point (:func:`_kept_generators`), every
    condition of the set a column bound:

        min α  s.t.  H μ + G τ + f_0 + α f_L = 0,   μ ≥ 0 (0 on the generators the set drops),

    so N = μ⁺ + μ⁻ and T = f (μ⁺ − μ⁻): N = 0 where open, T = −slip_sign f N where slipping,
    |T| ≤ f N elsewhere.  The same LP as with the yield conditions and the slips as rows, with
    only the equilibrium rows: HiGHS's interior point solves it about three times faster, its
    simplex about twice.  Forces in mean block weights.  ``method``: HiGHS's simplex or
    interior point with crossover (both give a vertex, re-solved on its basis so that it balances
    to round-off: :func:`alma.backends.linprog_backend.polished`); ``max_pivots``: its iteration cap.
    Bounded forces τ (if the model has them) lie in 0 ≤ τ ≤ capacity, or in the bounds of the
    active set ``bounded_signs`` (:func:`alma.nonassociative.bounded.force_bounds`).
    """
    P = points.count
    q = model.n_bounded
    kept = _kept_generators(open_points, slip_sign)
    blocks = [sp.csc_matrix(model.live[:, None]), model.equilibrium, *([model.bounded] if q else [])]
    A_eq = sp.hstack(blocks).tocsc()
    bounds = np.zeros((1 + 2 * P + q, 2))
    bounds[0] = (-np.inf, np.inf)
    bounds[1 : 1 + 2 * P, 1] = np.where(kept, np.inf, 0.0)
    if q:
        bounds[1 + 2 * P :, 0], bounds[1 + 2 * P :, 1] = bf.force_bounds(model, bounded_signs)
    c = np.zeros(1 + 2 * P + q)
    c[0] = 1.0
    sol = solve_lp(
        c,
        A_ub=None,
        b_ub=None,
        A_eq=A_eq,
        b_eq=-model.dead,
        bounds=bounds,
        method=method,
        max_iterations=max_pivots,
        tolerance=FIXED_SET_TOLERANCE,
        polish=True,
    )
    pivots = sol.iterations
    if sol.termination is Termination.UNBOUNDED:
        return failed(Termination.UNBOUNDED, P, pivots, -np.inf)
    if sol.termination is Termination.INFEASIBLE:
        return failed(Termination.INFEASIBLE, P, pivots)
    if sol.termination is not Termination.OPTIMAL:
        return failed(Termination.ERROR, P, pivots)
    mu = np.maximum(sol.x[1 : 1 + 2 * P], 0.0)
    plus, minus = mu[0::2], mu[1::2]
    tau = np.clip(sol.x[1 + 2 * P :], bounds[1 + 2 * P :, 0], bounds[1 + 2 * P :, 1]) if q else np.zeros(0)
    return StaticLP(
        Termination.OPTIMAL, float(sol.x[0]), plus + minus, points.friction * (plus - minus), None, pivots, tau
    )


def fixed_set_static_interior(
    model: Model,
    points: ContactPoints,
    open_points: np.ndarray,
    slip_sign: np.ndarray,
    *,
    max_iter: int = 200,
    tolerance: float = 1e-12,
) -> StaticLP:
    """The smallest α with a fixed active set (as :func:`static_lp` there), by Clarabel.

    Written on the cone generators n ± f t of each point (Eq. 5): an open point keeps neither,
    a point slipping in +t (T = −f N) keeps only n − f t, one slipping in −t only n + f t.  Then

        min α  s.t.  H_S μ + f_0 + α f_L = 0,  μ ≥ 0

    is solved through its kinematic dual, min f_0ᵀv s.t. f_Lᵀv = c, H_Sᵀv ≤ 0 (the shape and
    size of Eq. 10), and (α, μ) are read from its duals.  An interior point of the optimal face
    rather than a vertex, which is enough: with the set fixed, any optimal field complements a
    mechanism with that set.  ``max_iter``: Clarabel's iteration cap.
    """
    P = points.count
    columns = np.flatnonzero(_kept_generators(open_points, slip_sign))
    H = model.equilibrium[:, columns]
    A = sp.vstack([sp.csr_matrix(model.live[None, :]), H.T]).tocsc()
    b = np.zeros(1 + columns.size)
    b[0] = AssociativeSettings().normalisation * float(model.n_free)
    sol = solve_conic_lp(model.dead, A, b, 1, columns.size, tolerance=tolerance, max_iter=max_iter, refine=False)
    used = sol.iterations
    if sol.termination is Termination.UNBOUNDED:  # the kinematic side unbounded: no static field has this set
        return failed(Termination.INFEASIBLE, P, used)
    if sol.termination is Termination.INFEASIBLE:  # no mechanism: α unbounded below
        return failed(Termination.UNBOUNDED, P, used, -np.inf)
    if not sol.termination.solved:
        return failed(Termination.ERROR, P, used)
    z = sol.duals
    mu = np.zeros(2 * P)
    mu[columns] = np.maximum(z[1:], 0.0)
    plus, minus = mu[0::2], mu[1::2]
    return StaticLP(Termination.OPTIMAL, float(z[0]), plus + minus, points.friction * (plus - minus), None, used)


def static_lp_clarabel(
    model: Model,
    points: ContactPoints,
    *,
    slope: np.ndarray,
    cap: np.ndarray,
    max_iter: int = 200,
    tolerance: float = 1e-9,
) -> StaticLP:
    """``static_lp`` (maximise α, no fixed active set) with Clarabel's interior point.

    Much faster than simplex on large scenes; its mechanism is the interior-point
    one (a blend on degenerate faces), so states built from it are always passed
    through :func:`alma.nonassociative.exact_states.exact_state` before they count.
    """
    P, k = points.count, model.n_bounded
    n = model.dead.shape[0]
    A_eq, b_eq, A_ub = points.static_constraints(model, slope)
    non_negative = sp.hstack([sp.csr_matrix((P, 1)), -sp.identity(P), sp.csr_matrix((P, P))])  # −N ≤ 0
    rows, rhs = [A_eq, A_ub, non_negative], [b_eq, cap, cap, np.zeros(P)]
    if k:  # 0 ≤ τ ≤ capacity
        A_eq, A_ub = with_bounded_columns(model, A_eq, A_ub)
        eye = sp.identity(k, format="csr")
        rows = [
            A_eq,
            A_ub,
            sp.hstack([non_negative, sp.csr_matrix((P, k))]),
            sp.hstack([sp.csr_matrix((k, 1 + 2 * P)), -eye]),
            sp.hstack([sp.csr_matrix((k, 1 + 2 * P)), eye]),
        ]
        rhs += [np.zeros(k), model.capacity]
    A = sp.vstack(rows).tocsc()
    b = np.concatenate(rhs)
    q = np.zeros(1 + 2 * P + k)
    q[0] = -1.0
    # Clarabel's own choice of factorisation here, and its default iterative refinement.
    sol = solve_conic_lp(
        q, A, b, n, 3 * P + 2 * k, tolerance=tolerance, max_iter=max_iter, refine=True, direct=None, form="static"
    )
    used = sol.iterations
    if sol.termination is Termination.UNBOUNDED:
        return failed(Termination.UNBOUNDED, P, used, np.inf)
    if sol.termination is Termination.INFEASIBLE:
        return failed(Termination.INFEASIBLE, P, used)
    if not sol.termination.solved:
        return failed(Termination.ERROR, P, used)
    x = sol.x
    y = sol.duals[:n]  # equality duals: the mechanism, up to sign and scale
    work = dot(model.live, y)
    mechanism = y * (model.n_free / work) if work > 0 else None
    if k:
        return StaticLP(
            Termination.OPTIMAL,
            float(x[0]),
            np.maximum(x[1 : 1 + P], 0.0),
            x[1 + P : 1 + 2 * P],
            mechanism,
            used,
            np.clip(x[1 + 2 * P :], 0.0, model.capacity),
        )
    return StaticLP(Termination.OPTIMAL, float(x[0]), np.maximum(x[1 : 1 + P], 0.0), x[1 + P :], mechanism, used)


def kinematic_lp(
    model: Model,
    points: ContactPoints,
    open_points: np.ndarray,
    slip_sign: np.ndarray,
    *,
    max_pivots: int = 200_000,
    free_slip: np.ndarray | None = None,
    bounded_allowed: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray | None, int]:
    """A mechanism with a prescribed active set (Eq. 2), or None; and the simplex iterations spent.

    Closed points do not open (ξ = 0), open points do not interpenetrate (ξ ≥ 0),
    sticking points do not slip (γ = 0), slipping points slip only in their sign's
    direction (s γ ≥ 0); f_Lᵀu = n_free.  Any such u complements every force field of
    the same active set, so it removes the round-off of the candidate's small velocities.
    ``bounded_allowed``: (may_grow, may_shrink) of each bounded column's rate d = −Gᵀu
    (:func:`alma.nonassociative.bounded.kinematic_rows`); required when the model has bounded forces.
    """
    closed = ~open_points
    free = np.zeros(points.count, dtype=bool) if free_slip is None else free_slip
    sticking = closed & (slip_sign == 0) & ~free
    slipping = closed & (slip_sign != 0) & ~free
    normal_t = points.normal.T.tocsr()
    tangent_t = points.tangent.T.tocsr()
    A_eq = sp.vstack(
        [sp.csr_matrix(model.live[None, :]), normal_t[np.flatnonzero(closed)], tangent_t[np.flatnonzero(sticking)]]
    ).tocsr()
    b_eq = np.zeros(A_eq.shape[0])
    b_eq[0] = float(model.n_free)
    A_ub = sp.vstack(
        [-normal_t[np.flatnonzero(open_points)], -sp.diags(slip_sign[slipping]) @ tangent_t[np.flatnonzero(slipping)]]
    ).tocsr()
    if model.n_bounded:
        # bounded_allowed is required when the model has bounded forces (docstring).
        equal, below = bf.kinematic_rows(model, *cast("tuple[np.ndarray, np.ndarray]", bounded_allowed))
        A_eq, A_ub = sp.vstack([A_eq, equal]).tocsr(), sp.vstack([A_ub, below]).tocsr()
        b_eq = np.concatenate([b_eq, np.zeros(equal.shape[0])])
    return _feasible_point(A_eq, b_eq, A_ub, max_pivots)


def _feasible_point(
    A_eq: sp.csr_matrix, b_eq: np.ndarray, A_ub: sp.csr_matrix, max_pivots: int
) -> tuple[np.ndarray | None, int]:
    """A vertex of ``A_eq u = b_eq, A_ub u ≤ 0`` (u free) by HiGHS's dual simplex, or None; and the
    iterations spent.

    A run still going after :data:`KINEMATIC_PROBE_PIVOTS` iterations goes to HiGHS's interior
    point with crossover instead, within ``max_pivots``: its vertex when it finds one, None when it
    proves the LP infeasible; only when it decides neither does the simplex run on.  Any vertex
    serves (the caller verifies the pair); the simplex's long runs ended in numerical trouble.
    """
    rows = A_ub.shape[0]

    def run(method: LPMethod, cap: int) -> SolverResult:
        return solve_lp(
            np.zeros(A_eq.shape[1]),
            A_ub=A_ub if rows else None,
            b_ub=np.zeros(rows) if rows else None,
            A_eq=A_eq,
            b_eq=b_eq,
            bounds=(None, None),
            method=method,
            max_iterations=cap,
            form="kinematic",
        )

    probe = min(max_pivots, KINEMATIC_PROBE_PIVOTS)
    sol = run(LP_METHOD, probe)
    spent = sol.iterations
    if sol.termination is Termination.ITERATION_LIMIT and probe < max_pivots:
        check = run(LPMethod.IPM, max_pivots)
        spent += check.iterations
        if check.termination is Termination.OPTIMAL:
            return check.x, spent
        if check.termination is Termination.INFEASIBLE:
            return None, spent
        sol = run(LP_METHOD, max_pivots)
        spent += sol.iterations
    return (sol.x if sol.termination is Termination.OPTIMAL else None), spent
