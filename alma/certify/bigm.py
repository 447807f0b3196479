"""Big-M constants of the certification MILP, derived per scene by warm-started LPs.

M_N,p = max N_p over the statically admissible fields (Eqs. 3, 5) with α ∈ [0, α_cap]
(unbounded → no certificate); ℓ_j = min N_j of each joint over the same fields (for the
energy-balance cut); M_ξ,p, M_γ±,j and M_d±,i = the largest opening / slips / rates of the
bounded columns over {ξ ≥ 0, f_Lᵀu = n_free, |u|∞ ≤ U, −f₀ᵀu + Σ f ℓ_j |γ_j| + Σ cap_i max(0, d_i)
≤ α_cap n_free} (d = −Gᵀu; :mod:`alma.nonassociative.bounded`).  Bounded forces (cohesion, ties)
enter the static fields as 0 ≤ τ ≤ capacity.  Every LP is bounded by a simplex iteration count;
the user's wall-clock cap is checked between them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from alma.backends import highs_backend
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.limits import Cap
from alma.nonassociative.static_lps import with_bounded_columns

#: Relative safety margin on every derived big-M (bounds come from LPs solved to ~1e-9).
BIG_M_MARGIN = 1.01


class BoundsFailed(Exception):
    """A big-M LP failed (message), or the user's cap stopped the derivation (``by_cap``)."""

    def __init__(self, message: str, by_cap: bool = False) -> None:
        super().__init__(message)
        self.by_cap = by_cap


@dataclass(frozen=True)
class BigM:
    """The big-M constants of one scene (per point p and per joint j; dimensionless)."""

    normal: np.ndarray  # M_N,p
    opening: np.ndarray  # M_ξ,p
    slip_plus: np.ndarray  # M_γ⁺ of each point's joint
    slip_minus: np.ndarray  # M_γ⁻ of each point's joint
    joint_minimum: np.ndarray  # ℓ_j ≤ N_j in every admissible field
    point_minimum: np.ndarray | None  # min N_p (None: not derived)
    rate_plus: np.ndarray = field(default_factory=lambda: np.zeros(0))  # M_d⁺,i: largest d_i = −g_iᵀu
    rate_minus: np.ndarray = field(default_factory=lambda: np.zeros(0))  # M_d⁻,i: largest −d_i


def _column_maxima(h: highs_backend.HighsModel, objectives: list[np.ndarray], max_pivots: int, cap: Cap) -> np.ndarray:
    """max cᵀx of an LP held by ``h`` for each c (warm-started simplex, ``max_pivots`` iterations each)."""
    out = np.empty(len(objectives))
    for k, c in enumerate(objectives):
        if cap.expired():
            raise BoundsFailed("the time limit passed while deriving the big-M bounds", by_cap=True)
        value = highs_backend.warm_maximum(h, c, max_pivots)
        if isinstance(value, str):
            raise BoundsFailed(f"a big-M LP {value}")
        out[k] = value
    return out


def _static_field_model(model: Model, points: ContactPoints, alpha_max: float) -> highs_backend.HighsModel:
    """A HiGHS model of the statically admissible fields (Eqs. 3, 5) over (α, N, T, τ), 0 ≤ α ≤ alpha_max
    and 0 ≤ τ ≤ capacity, with zero cost: the callers set one objective after another on it (warm
    re-solves)."""
    P, q = points.count, model.n_bounded
    A_eq, b_eq, A_ub = points.static_constraints(model, points.friction)
    if q:
        A_eq, A_ub = with_bounded_columns(model, A_eq, A_ub)
    lo = np.concatenate([b_eq, np.full(2 * P, -np.inf)])
    hi = np.concatenate([b_eq, np.zeros(2 * P)])
    col_lo = np.concatenate([[0.0], np.zeros(P), np.full(P, -np.inf), np.zeros(q)])
    col_hi = np.concatenate([[alpha_max], np.full(2 * P, np.inf), model.capacity])
    return highs_backend.new_model(np.zeros(1 + 2 * P + q), col_lo, col_hi, sp.vstack([A_eq, A_ub]), lo, hi)


def static_point_bounds(
    model: Model,
    points: ContactPoints,
    alpha_max: float,
    *,
    max_pivots: int,
    cap: Cap,
    minimise: bool = False,
    weights: np.ndarray | None = None,
) -> np.ndarray:
    """max N_p (min N_p with ``minimise``) over statically admissible fields with 0 ≤ α ≤ alpha_max,
    for every p; with ``weights`` (rows w), max wᵀN for each row instead."""
    P, q = points.count, model.n_bounded
    h = _static_field_model(model, points, alpha_max)
    sign = -1.0 if minimise else 1.0
    rows = np.eye(P) if weights is None else np.atleast_2d(weights)
    objectives = [np.concatenate([[0.0], sign * w, np.zeros(P + q)]) for w in rows]
    return sign * _column_maxima(h, objectives, max_pivots, cap)


def joint_normal_minima(
    model: Model, points: ContactPoints, first: np.ndarray, alpha_max: float, *, max_pivots: int, cap: Cap
) -> np.ndarray:
    """min N_a + N_b of every joint (points first[j] to first[j + 1] − 1) over statically admissible
    fields with 0 ≤ α ≤ alpha_max."""
    P = points.count
    weights = np.zeros((first.size, P))
    weights[np.searchsorted(first, np.arange(P), side="right") - 1, np.arange(P)] = 1.0  # joint of each point
    return static_point_bounds(model, points, alpha_max, max_pivots=max_pivots, cap=cap, minimise=True, weights=weights)


def kinematic_point_bounds(
    model: Model,
    points: ContactPoints,
    U: float,
    first: np.ndarray,
    alpha_max: float,
    slip_cost: np.ndarray,
    *,
    max_pivots: int,
    cap: Cap,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Largest opening ξ_p, slips ±γ (per point, of its joint) and rates ±d_i of the bounded columns
    over {ξ ≥ 0, f_Lᵀu = n_free, |u|∞ ≤ U} and the energy balance of a state at α ≤ alpha_max:
    −f₀ᵀu + Σ_j slip_cost_j |γ_j| + Σ_i cap_i max(0, d_i) ≤ alpha_max n_free (slip_cost_j = f ℓ_j ≤
    f N_j), which bounds every mechanism that lifts weight, slips under load or works a bounded force."""
    P, n, m, q = points.count, model.dead.shape[0], first.size, model.n_bounded
    tangent_j = points.tangent[:, first]
    g_t = _bounded(model).T
    # x = (u, γ⁺_j, γ⁻_j, d⁺_i, d⁻_i) with γ = γ⁺ − γ⁻ and d = −Gᵀu = d⁺ − d⁻
    A = sp.vstack(
        [
            sp.hstack([points.normal.T, sp.csr_matrix((P, 2 * m + 2 * q))]),
            sp.hstack([sp.csr_matrix(model.live[None, :]), sp.csr_matrix((1, 2 * m + 2 * q))]),
            sp.hstack([tangent_j.T, -sp.identity(m), sp.identity(m), sp.csr_matrix((m, 2 * q))]),
            sp.hstack([g_t, sp.csr_matrix((q, 2 * m)), sp.identity(q), -sp.identity(q)]),
            sp.csr_matrix(np.concatenate([-model.dead, slip_cost, slip_cost, model.capacity, np.zeros(q)])[None, :]),
        ]
    )
    lo = np.concatenate([np.zeros(P), [model.n_free], np.zeros(m + q), [-np.inf]])
    hi = np.concatenate([np.full(P, np.inf), [model.n_free], np.zeros(m + q), [alpha_max * model.n_free]])
    nv = n + 2 * m + 2 * q
    col_lo = np.concatenate([np.full(n, -U), np.zeros(2 * m + 2 * q)])
    col_hi = np.concatenate([np.full(n, U), np.full(2 * m + 2 * q, np.inf)])
    h = highs_backend.new_model(np.zeros(nv), col_lo, col_hi, A, lo, hi)
    g_dense = g_t.toarray().T if q else np.zeros((n, 0))
    directions = np.hstack([points.normal.toarray(), tangent_j.toarray(), -tangent_j.toarray(), -g_dense, g_dense])
    objectives = [np.concatenate([directions[:, k], np.zeros(2 * m + 2 * q)]) for k in range(directions.shape[1])]
    values = np.maximum(_column_maxima(h, objectives, max_pivots, cap), 0.0)
    joint_of = np.searchsorted(first, np.arange(P), side="right") - 1
    k = P + 2 * m
    return values[:P], values[P : P + m][joint_of], values[P + m : k][joint_of], values[k : k + q], values[k + q :]


def derive_big_m(
    model: Model,
    points: ContactPoints,
    alpha_hi: float,
    U: float,
    first: np.ndarray,
    *,
    per_point: bool,
    max_pivots: int,
    cap: Cap,
) -> BigM:
    """All big-M constants (see module docstring), with the margin :data:`BIG_M_MARGIN`.

    Scenes above the per-point size (``per_point`` False) get one global normal-force bound and
    row-norm velocity bounds instead of per-point LPs.  Raises :class:`BoundsFailed`.
    """
    P = points.count
    limits: dict[str, Any] = dict(max_pivots=max_pivots, cap=cap)
    try:
        if per_point:
            m_n = static_point_bounds(model, points, alpha_hi, **limits)
        else:  # one LP (the largest total normal force) bounds every point
            m_n = np.full(P, static_point_bounds(model, points, alpha_hi, weights=np.ones(P), **limits)[0])
    except BoundsFailed as error:
        if error.by_cap:
            raise
        raise BoundsFailed("normal forces are unbounded (self-stress): no big-M bound exists") from error
    m_n = BIG_M_MARGIN * np.maximum(m_n, 0.0) + 1e-9
    if not per_point:
        row_n, row_t, row_g = (
            BIG_M_MARGIN * np.asarray(abs(a).sum(axis=0)).ravel() * U
            for a in (points.normal, points.tangent, _bounded(model))
        )
        return BigM(m_n, row_n, row_t, row_t, np.zeros(first.size), None, row_g, row_g)
    ell = joint_normal_minima(model, points, first, alpha_hi, **limits)
    ell = np.maximum(ell / BIG_M_MARGIN - 1e-9, 0.0)
    n_min = static_point_bounds(model, points, alpha_hi, minimise=True, **limits)
    kin = kinematic_point_bounds(model, points, U, first, alpha_hi, points.friction[first] * ell, **limits)
    m_xi, m_gp, m_gm, m_dp, m_dm = (BIG_M_MARGIN * v + 1e-9 for v in kin)
    return BigM(m_n, m_xi, m_gp, m_gm, ell, n_min, m_dp, m_dm)


def _bounded(model: Model) -> sp.csc_matrix:
    """G of the bounded columns ((3 n_free, 0) without them)."""
    return model.bounded if model.n_bounded else sp.csc_matrix((model.dead.shape[0], 0))
