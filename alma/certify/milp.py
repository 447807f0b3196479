"""Global certification of the non-associative problem (Eq. 9) by mixed-integer LP.

The complementarity of Eq. 9 is written with binaries (big-M) and solved with
HiGHS (``highspy``).  The slip γ = tangentᵀu is the same at both end points of a
straight joint, so the slip state is one per joint j: slipping +t (s⁺_j = 1),
slipping −t (s⁻_j = 1) or not (s⁺_j + s⁻_j ≤ 1); each contact point p of joint j
is open (o_p = 1) or closed:

- N_p ≤ M_N,p (1 − o_p),            ξ_p = normal_pᵀu ≤ M_ξ,p o_p;
- γ⁺_j ≤ M_γ⁺,j s⁺_j,               γ⁻_j ≤ M_γ⁻,j s⁻_j,   γ_j = γ⁺_j − γ⁻_j;
- f N_p + T_p ≤ 2 f M_N,p (1 − s⁺_j),   f N_p − T_p ≤ 2 f M_N,p (1 − s⁻_j)
  (slipping: T = −f N sign γ; an open point carries nothing and satisfies both);

with equilibrium, yield |T| ≤ f N, no interpenetration ξ ≥ 0 and f_Lᵀu = n_free;
objective min α over α ∈ [0, α_cap], α_cap = min(α_LP, α_best) (Radenkovic:
α_NL ≤ α_LP; α_best is a verified collapse state, also given to HiGHS as the
objective cutoff).

Energy balance.  Every integer-feasible point has Nᵀξ = 0 and Tᵀγ = −Σ f N |γ|, so
the equilibrium dotted with u gives α n_free = −f₀ᵀu + Σ_j f N_j |γ_j| (N_j the
joint's total normal force).  With ℓ_j = min N_j over the admissible fields (an LP)
this yields the valid row α n_free ≥ −f₀ᵀu + Σ_j f ℓ_j (γ⁺_j + γ⁻_j), and with
α ≤ α_cap it bounds every mechanism that lifts weight or slips under load.

Big-M constants, derived per scene by warm-started LPs: M_N,p = max N_p over the
statically admissible fields with α ∈ [0, α_cap] (unbounded → no certificate);
M_ξ,p and M_γ±,j = the largest opening / slips over {ξ ≥ 0, f_Lᵀu = n_free,
|u|∞ ≤ U, −f₀ᵀu + Σ f ℓ_j |γ_j| ≤ α_cap n_free}, U a multiple of the candidate
mechanisms' size.  Points that carry no force in any admissible field need no
binary (they may open); points loaded in every admissible field never open.  The
proven statement is therefore: no collapse state with α below ``lower`` exists
among mechanisms with |u|∞ ≤ U (f_Lᵀu = n_free); the bound on u is reported, and
whether it was active at the optimum.

``formulation="classic"`` keeps the first formulation (one global velocity big-M,
three binaries per point, ``scipy.optimize.milp``) for comparison
(``benchmarks/bench_certify.py``).
"""
from __future__ import annotations

import contextlib
import os
import sys
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.optimize import Bounds, LinearConstraint, linprog, milp

from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model

#: Relative safety margin on every derived big-M (bounds come from LPs solved to ~1e-9).
BIG_M_MARGIN = 1.01
#: Absolute MIP gap: the proven bound is within this of the best state found.
MIP_ABSOLUTE_GAP = 1e-7
#: Integrality tolerance of the binaries.  HiGHS's default (1e-6) lets a binary sit 1e-6 from 0
#: or 1; times a big-M of |u|∞ ≤ 793 that released enough force for a two-block scene at f = 0.3
#: to settle at 0.2999932 instead of 0.3 (found by hypothesis, verification/test_certify.py).
MIP_INTEGRALITY_TOLERANCE = 1e-9


@contextlib.contextmanager
def _stdout_to_stderr():
    """Redirect the process's file descriptor 1 (C-level prints) to 2 for the duration."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


@dataclass(frozen=True)
class Certificate:
    status: str  # proven | time_limit | failed
    message: str
    lower: float  # proven lower bound of α over the searched set (0 when nothing is proven)
    upper: float  # best collapse state found by the MILP (inf if none)
    gap: float
    time_s: float
    velocity_bound: float
    velocity_bound_active: bool
    mechanism: np.ndarray | None
    formulation: str = "tight"
    binaries: int = 0
    nodes: int = 0
    bounds_s: float = 0.0  # time spent deriving the big-M constants


def normal_force_bound(model: Model, points: ContactPoints, alpha_max: float,
                       weights: np.ndarray | None = None) -> float | None:
    """max wᵀN over statically admissible fields with 0 ≤ α ≤ alpha_max (None if unbounded).

    With w = 1 this bounds every N_p at once; with w = e_p it is the tight bound of point p.
    """
    P = points.count
    A_eq, b_eq, A_ub = points.static_constraints(model, points.friction)
    c = np.concatenate([[0.0], -(np.ones(P) if weights is None else weights), np.zeros(P)])
    bounds = [(0.0, alpha_max)] + [(0, None)] * P + [(None, None)] * P
    res = linprog(c, A_ub=A_ub, b_ub=np.zeros(2 * P), A_eq=A_eq, b_eq=b_eq, bounds=bounds, method="highs")
    if res.status != 0:
        return None
    return float(-res.fun)


# --------------------------------------------------------------------------- highspy helpers
def _highs(quiet: bool = True):
    import highspy

    h = highspy.Highs()
    h.setOptionValue("output_flag", not quiet)
    return h


def _pass_model(h, cost: np.ndarray, col_lo: np.ndarray, col_hi: np.ndarray, A: sp.spmatrix,
                row_lo: np.ndarray, row_hi: np.ndarray, integrality: np.ndarray | None = None) -> None:
    import highspy

    A = sp.csc_matrix(A)
    A.sort_indices()
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = int(A.shape[1]), int(A.shape[0])
    lp.col_cost_ = np.asarray(cost, dtype=float)
    lp.col_lower_ = np.asarray(col_lo, dtype=float)
    lp.col_upper_ = np.asarray(col_hi, dtype=float)
    lp.row_lower_ = np.asarray(row_lo, dtype=float)
    lp.row_upper_ = np.asarray(row_hi, dtype=float)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_ = A.indptr.astype(np.int32)
    lp.a_matrix_.index_ = A.indices.astype(np.int32)
    lp.a_matrix_.value_ = A.data.astype(float)
    if integrality is not None:
        lp.integrality_ = [highspy.HighsVarType.kInteger if v else highspy.HighsVarType.kContinuous
                           for v in integrality]
    h.passModel(lp)


def _column_maxima(h, nvar: int, objectives: list[np.ndarray], deadline: float) -> np.ndarray | None:
    """max cᵀx of a passed LP for each c (warm-started simplex); None on any failure or timeout."""
    import highspy

    out = np.empty(len(objectives))
    idx = np.arange(nvar, dtype=np.int32)
    for k, c in enumerate(objectives):
        remaining = deadline - time.perf_counter()
        if remaining <= 0:
            return None
        h.setOptionValue("time_limit", float(remaining))
        h.changeColsCost(nvar, idx, -np.asarray(c, dtype=float))
        h.run()
        if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
            return None
        out[k] = -h.getInfo().objective_function_value
    return out


def _static_field_model(model: Model, points: ContactPoints, alpha_max: float):
    """A HiGHS model of the statically admissible fields (Eqs. 3, 5) over (α, N, T), 0 ≤ α ≤ alpha_max,
    with zero cost: the callers set one objective after another on it (warm re-solves)."""
    P = points.count
    A_eq, b_eq, A_ub = points.static_constraints(model, points.friction)
    A = sp.vstack([A_eq, A_ub])
    lo = np.concatenate([b_eq, np.full(2 * P, -np.inf)])
    hi = np.concatenate([b_eq, np.zeros(2 * P)])
    col_lo = np.concatenate([[0.0], np.zeros(P), np.full(P, -np.inf)])
    col_hi = np.concatenate([[alpha_max], np.full(2 * P, np.inf)])
    h = _highs()
    _pass_model(h, np.zeros(1 + 2 * P), col_lo, col_hi, A, lo, hi)
    return h


def static_point_bounds(model: Model, points: ContactPoints, alpha_max: float,
                        deadline: float = np.inf, minimise: bool = False) -> np.ndarray | None:
    """max N_p (min N_p with ``minimise``) over statically admissible fields with 0 ≤ α ≤ alpha_max,
    for every p (None if unbounded)."""
    P = points.count
    h = _static_field_model(model, points, alpha_max)
    sign = -1.0 if minimise else 1.0
    objectives = [sign * np.eye(1, 1 + 2 * P, 1 + p).ravel() for p in range(P)]
    values = _column_maxima(h, 1 + 2 * P, objectives, deadline)
    return None if values is None else sign * values


def joint_normal_minima(model: Model, points: ContactPoints, first: np.ndarray, alpha_max: float,
                        deadline: float = np.inf) -> np.ndarray | None:
    """min N_a + N_b of every joint (points first[j] and first[j] + 1) over statically admissible
    fields with 0 ≤ α ≤ alpha_max."""
    P = points.count
    h = _static_field_model(model, points, alpha_max)
    ends = np.r_[first[1:], P]
    objectives = []
    for a, b in zip(first, ends):
        c = np.zeros(1 + 2 * P)
        c[1 + a:1 + b] = -1.0  # maximise −(N_a + N_b)
        objectives.append(c)
    values = _column_maxima(h, 1 + 2 * P, objectives, deadline)
    return None if values is None else -values


def kinematic_point_bounds(model: Model, points: ContactPoints, U: float, deadline: float = np.inf, *,
                           alpha_max: float | None = None, slip_cost: np.ndarray | None = None,
                           first: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Largest opening ξ_p and slips ±γ_p over {ξ ≥ 0, f_Lᵀu = n_free, |u|∞ ≤ U}.

    With ``alpha_max`` the energy balance of a collapse state at α ≤ alpha_max is added:
    −f₀ᵀu + Σ_j slip_cost_j |γ_j| ≤ alpha_max n_free (slip_cost_j = f ℓ_j ≤ f N_j, joints
    starting at points ``first``), which bounds every mechanism that lifts weight or slips under load.
    """
    P, n = points.count, model.dead.shape[0]
    first = np.arange(0, P, 2) if first is None else first
    m = first.size
    tangent_j = points.tangent[:, first]
    # x = (u, γ⁺_j, γ⁻_j)
    rows = [sp.hstack([points.normal.T, sp.csr_matrix((P, 2 * m))]),
            sp.hstack([sp.csr_matrix(model.live[None, :]), sp.csr_matrix((1, 2 * m))]),
            sp.hstack([tangent_j.T, -sp.identity(m), sp.identity(m)])]
    lo = [np.zeros(P), [model.n_free], np.zeros(m)]
    hi = [np.full(P, np.inf), [model.n_free], np.zeros(m)]
    if alpha_max is not None:
        cost = np.zeros(m) if slip_cost is None else slip_cost
        rows.append(sp.csr_matrix(np.concatenate([-model.dead, cost, cost])[None, :]))
        lo.append([-np.inf])
        hi.append([alpha_max * model.n_free])
    A = sp.vstack(rows)
    h = _highs()
    nv = n + 2 * m
    col_lo = np.concatenate([np.full(n, -U), np.zeros(2 * m)])
    col_hi = np.concatenate([np.full(n, U), np.full(2 * m, np.inf)])
    _pass_model(h, np.zeros(nv), col_lo, col_hi, A, np.concatenate(lo), np.concatenate(hi))
    normal = points.normal.tocsc()
    objectives = [np.concatenate([normal[:, p].toarray().ravel(), np.zeros(2 * m)]) for p in range(P)]
    tangent_j = tangent_j.tocsc()
    objectives += [np.concatenate([tangent_j[:, j].toarray().ravel(), np.zeros(2 * m)]) for j in range(m)]
    objectives += [np.concatenate([-tangent_j[:, j].toarray().ravel(), np.zeros(2 * m)]) for j in range(m)]
    values = _column_maxima(h, nv, objectives, deadline)
    if values is None:
        return None
    values = np.maximum(values, 0.0)
    # per point: ξ_p, and the slips of its joint
    joint_of = np.searchsorted(first, np.arange(P), side="right") - 1
    return values[:P], values[P:P + m][joint_of], values[P + m:][joint_of]


# --------------------------------------------------------------------------- the certificate
def certify(model: Model, alpha_associative: float, mechanisms: list[np.ndarray], *,
            time_limit: float = 60.0, velocity_factor: float = 10.0, alpha_best: float | None = None,
            per_point_bounds: int = 400, formulation: str = "tight", energy_cut: bool = True,
            kinematic_bounds: bool = True, dissipation_cut: bool = True, cutoff: bool = True, quiet: bool = True,
            highs_options: dict | None = None) -> Certificate:
    """Proven lower bound of the non-associative collapse multiplier (see module docstring).

    ``formulation``: "tight" (default) or "classic" (the first formulation, for comparison).
    Scenes with more than ``per_point_bounds`` contact points get one global normal-force
    bound and row-norm velocity bounds instead of the per-point LPs.  ``energy_cut``,
    ``kinematic_bounds``, ``dissipation_cut``, ``cutoff`` and ``highs_options`` switch the
    ingredients of the tight formulation (for measurements); ``quiet=False`` shows the HiGHS log.
    """
    if formulation == "classic":
        return _certify_classic(model, alpha_associative, mechanisms, time_limit=time_limit,
                                velocity_factor=velocity_factor, alpha_best=alpha_best,
                                per_point_bounds=per_point_bounds)
    if formulation != "tight":
        raise ValueError(f"formulation must be 'tight' or 'classic', got {formulation!r}")
    import highspy

    t0 = time.perf_counter()
    deadline = t0 + time_limit
    points = ContactPoints.from_model(model)
    P, n = points.count, model.dead.shape[0]

    def fail(message: str) -> Certificate:
        return Certificate("failed", message, 0.0, np.inf, np.inf, time.perf_counter() - t0, np.nan, False, None)

    if not np.isfinite(alpha_associative) or alpha_associative < 0:
        return fail("the associative bound is not finite and non-negative")
    alpha_cap = alpha_associative if alpha_best is None else min(alpha_associative, alpha_best)
    if alpha_cap < 0:
        return fail("the best verified state has α < 0 (no_equilibrium): nothing to certify")
    # The cap itself must stay feasible (the verified state is at α_best, up to round-off).
    alpha_hi = alpha_cap + 1e-9 * max(1.0, alpha_cap)

    size = max([float(np.abs(u).max()) for u in mechanisms if u is not None] + [1.0])
    U = velocity_factor * size
    per_point = P <= per_point_bounds
    if per_point:
        m_n = static_point_bounds(model, points, alpha_hi, deadline)
    else:  # large scenes: one LP (the largest total normal force) bounds every point
        total = normal_force_bound(model, points, alpha_hi)
        m_n = None if total is None else np.full(P, total)
    if m_n is None:
        if time.perf_counter() >= deadline:
            return _timeout(t0, time_limit, U, "tight")
        return fail("normal forces are unbounded (self-stress): no big-M bound exists")
    m_n = BIG_M_MARGIN * np.maximum(m_n, 0.0) + 1e-9
    first = np.flatnonzero(np.r_[True, points.joint[1:] != points.joint[:-1]])
    ell = np.zeros(first.size)
    if dissipation_cut and per_point:
        ell = joint_normal_minima(model, points, first, alpha_hi, deadline)
        if ell is None:
            if time.perf_counter() >= deadline:
                return _timeout(t0, time_limit, U, "tight")
            return fail("the joint normal force LPs failed")
        ell = np.maximum(ell / BIG_M_MARGIN - 1e-9, 0.0)
    n_min = None
    if dissipation_cut and per_point:
        n_min = static_point_bounds(model, points, alpha_hi, deadline, minimise=True)
        if n_min is None:
            if time.perf_counter() >= deadline:
                return _timeout(t0, time_limit, U, "tight")
            return fail("the point normal force LPs failed")
    if kinematic_bounds and per_point:
        kin = kinematic_point_bounds(model, points, U, deadline, alpha_max=alpha_hi,
                                     slip_cost=points.friction[first] * ell, first=first)
        if kin is None:
            if time.perf_counter() >= deadline:
                return _timeout(t0, time_limit, U, "tight")
            return fail("the mechanism bound LPs failed")
        m_xi, m_gp, m_gm = (BIG_M_MARGIN * v + 1e-9 for v in kin)
    else:
        row_n = np.asarray(abs(points.normal).sum(axis=0)).ravel()
        row_t = np.asarray(abs(points.tangent).sum(axis=0)).ravel()
        m_xi, m_gp, m_gm = BIG_M_MARGIN * row_n * U, BIG_M_MARGIN * row_t * U, BIG_M_MARGIN * row_t * U

    f = points.friction
    # Points that can carry no force anywhere (M_N = 0 up to round-off) may always open: no binaries.
    carries = m_n > 1e-7 * max(1.0, float(m_n.max(initial=0.0)))
    B = np.flatnonzero(carries)
    nb = B.size
    # The slip γ = tangentᵀu is the same at both end points of a (straight) joint: one slip state per joint.
    joint_of = np.searchsorted(first, np.arange(P), side="right") - 1  # joint (row of `first`) of each point
    m = first.size
    tangent_j = points.tangent[:, first]
    same = abs(points.tangent - tangent_j[:, joint_of]).max() if P else 0.0
    if same > 1e-12:
        return fail("the two end points of a joint slip differently (curved joint?): not supported")
    J = np.unique(joint_of[B])  # joints with a point that can carry force need slip binaries
    mj = J.size
    m_gp_j = np.maximum.reduceat(m_gp, first) if P else m_gp
    m_gm_j = np.maximum.reduceat(m_gm, first) if P else m_gm
    bounds_s = time.perf_counter() - t0

    # Variable layout: α | N | T | u | γ⁺ | γ⁻ (per joint) | o (points in B) | s⁺ | s⁻ (joints in J).
    i_a, i_N, i_T, i_u = 0, 1, 1 + P, 1 + 2 * P
    i_gp = i_u + n
    i_gm = i_gp + m
    i_o = i_gm + m
    i_sp = i_o + nb
    i_sm = i_sp + mj
    nvar = i_sm + mj
    I = sp.identity(P, format="csr")
    Im = sp.identity(m, format="csr")
    S = sp.csr_matrix((np.ones(nb), (np.arange(nb), B)), shape=(nb, P))  # selects the points in B
    Sj = sp.csr_matrix((np.ones(mj), (np.arange(mj), J)), shape=(mj, m))  # selects the joints in J
    # point in B → its joint's position in J
    pos_in_J = np.searchsorted(J, joint_of[B])
    Bj = sp.csr_matrix((np.ones(nb), (np.arange(nb), pos_in_J)), shape=(nb, mj))
    rows, lo, hi = [], [], []

    def add(parts: dict[int, sp.spmatrix], count: int, low, high) -> None:
        blocks, last = [], 0
        for start in sorted(parts):
            mat = sp.csr_matrix(parts[start])
            if start > last:
                blocks.append(sp.csr_matrix((count, start - last)))
            blocks.append(mat)
            last = start + mat.shape[1]
        if last < nvar:
            blocks.append(sp.csr_matrix((count, nvar - last)))
        rows.append(sp.hstack(blocks).tocsr())
        lo.append(np.broadcast_to(np.asarray(low, dtype=float), (count,)))
        hi.append(np.broadcast_to(np.asarray(high, dtype=float), (count,)))

    F = sp.diags(f)
    add({i_a: model.live[:, None], i_N: points.normal, i_T: points.tangent}, n, -model.dead, -model.dead)
    add({i_N: -F, i_T: I}, P, -np.inf, 0.0)  # T − fN ≤ 0
    add({i_N: -F, i_T: -I}, P, -np.inf, 0.0)  # −T − fN ≤ 0
    add({i_u: points.normal.T}, P, 0.0, np.inf)  # ξ ≥ 0
    add({i_u: tangent_j.T, i_gp: -Im, i_gm: Im}, m, 0.0, 0.0)  # γ = γ⁺ − γ⁻
    add({i_u: model.live[None, :]}, 1, float(model.n_free), float(model.n_free))
    if energy_cut:
        # α n_free = −f₀ᵀu + Σ_j f N_j |γ_j| with N_j ≥ ℓ_j (an LP bound) and |γ_j| = γ⁺_j + γ⁻_j.
        fj = f[first]
        diss = (fj * ell)[None, :] if dissipation_cut else np.zeros((1, m))
        add({i_a: np.array([[float(model.n_free)]]), i_u: model.dead[None, :], i_gp: -diss, i_gm: -diss},
            1, 0.0, np.inf)
    if nb:
        # A point whose normal force is positive in every admissible field (min N_p > 0) never opens.
        col_fix = np.flatnonzero(n_min[B] > 1e-9) if n_min is not None else np.array([], dtype=int)
        mn, mx = m_n[B], m_xi[B]
        add({i_N: S, i_o: sp.diags(mn)}, nb, -np.inf, mn)  # N ≤ M_N (1 − o)
        add({i_u: S @ points.normal.T, i_o: -sp.diags(mx)}, nb, -np.inf, 0.0)  # ξ ≤ M_ξ o
        mgp, mgm = m_gp_j[J], m_gm_j[J]
        add({i_gp: Sj, i_sp: -sp.diags(mgp)}, mj, -np.inf, 0.0)  # γ⁺ ≤ M s⁺
        add({i_gm: Sj, i_sm: -sp.diags(mgm)}, mj, -np.inf, 0.0)  # γ⁻ ≤ M s⁻
        mt = 2.0 * f[B] * mn
        add({i_N: S @ F, i_T: S, i_sp: sp.diags(mt) @ Bj}, nb, -np.inf, mt)  # s⁺ ⇒ T = −fN
        add({i_N: S @ F, i_T: -S, i_sm: sp.diags(mt) @ Bj}, nb, -np.inf, mt)  # s⁻ ⇒ T = +fN
        add({i_sp: sp.identity(mj), i_sm: sp.identity(mj)}, mj, 0.0, 1.0)
    A = sp.vstack(rows).tocsc()
    row_lo, row_hi = np.concatenate(lo), np.concatenate(hi)

    col_lo = np.zeros(nvar)
    col_hi = np.full(nvar, np.inf)
    col_hi[i_a] = alpha_hi
    col_hi[i_N:i_N + P] = m_n
    col_lo[i_T:i_T + P], col_hi[i_T:i_T + P] = -f * m_n, f * m_n
    col_lo[i_u:i_u + n], col_hi[i_u:i_u + n] = -U, U
    col_hi[i_gp:i_gp + m] = m_gp_j
    col_hi[i_gm:i_gm + m] = m_gm_j
    col_hi[i_o:] = 1.0
    if nb and col_fix.size:
        col_hi[i_o + col_fix] = 0.0
    integrality = np.zeros(nvar, dtype=bool)
    integrality[i_o:] = True
    cost = np.zeros(nvar)
    cost[i_a] = 1.0

    h = _highs(quiet)
    _pass_model(h, cost, col_lo, col_hi, A, row_lo, row_hi, integrality)
    remaining = max(1.0, deadline - time.perf_counter())
    h.setOptionValue("time_limit", float(remaining))
    h.setOptionValue("mip_rel_gap", 1e-9)
    h.setOptionValue("mip_abs_gap", MIP_ABSOLUTE_GAP)
    h.setOptionValue("mip_feasibility_tolerance", MIP_INTEGRALITY_TOLERANCE)
    for key, value in (highs_options or {}).items():
        h.setOptionValue(key, value)
    if cutoff and alpha_best is not None:
        # The verified state at α_best acts as an incumbent: nodes whose bound reaches it are pruned.
        h.setOptionValue("objective_bound", float(alpha_hi))
    with _stdout_to_stderr():
        h.run()
    status_code = h.getModelStatus()
    info = h.getInfo()
    elapsed = time.perf_counter() - t0
    MS = highspy.HighsModelStatus
    dual = float(info.mip_dual_bound) if np.isfinite(info.mip_dual_bound) else 0.0
    has_solution = info.primal_solution_status == 2 or status_code == MS.kOptimal
    if has_solution:
        x = np.asarray(h.getSolution().col_value)
        best = float(x[i_a])
        u = x[i_u:i_u + n]
        active = bool(np.abs(u).max() >= 0.999 * U)
    else:
        best, u, active = np.inf, None, False
    nodes = int(info.mip_node_count)
    common = dict(velocity_bound=U, velocity_bound_active=active, mechanism=u, formulation="tight",
                  binaries=nb + 2 * mj, nodes=nodes, bounds_s=bounds_s)
    if status_code == MS.kOptimal:
        lower_bound = max(0.0, min(dual, best, alpha_cap))  # α_cap: a verified state exists there
        gap = best - lower_bound
        return Certificate("proven", f"optimal within mip gap {gap:.1e} (|u|∞ ≤ {U:.3g}"
                           f"{', bound active' if active else ''})", float(lower_bound), best, float(gap),
                           elapsed, **common)
    if status_code in (MS.kInfeasible, MS.kObjectiveBound):
        lower_bound = max(0.0, alpha_cap - MIP_ABSOLUTE_GAP)  # pruned against the cap within the MIP gap
        return Certificate("proven", f"no collapse state below the cap {alpha_cap:.9g} (best verified state / "
                           f"associative bound) within mip gap {MIP_ABSOLUTE_GAP:.0e} (|u|∞ ≤ {U:.3g})",
                           float(lower_bound), np.inf, float(alpha_cap - lower_bound), elapsed, **common)
    if status_code in (MS.kTimeLimit, MS.kInterrupt, MS.kSolutionLimit, MS.kIterationLimit):
        lower_bound = max(0.0, min(dual, alpha_cap))
        return Certificate("time_limit", f"time limit {time_limit:g} s reached; proven lower bound "
                           f"{lower_bound:.6g} (|u|∞ ≤ {U:.3g})", float(lower_bound), best,
                           float(alpha_cap - lower_bound), elapsed, **common)
    return Certificate("failed", f"MILP failed: {h.modelStatusToString(status_code)}", 0.0, np.inf, np.inf,
                       elapsed, **common)


def _timeout(t0: float, time_limit: float, U: float, formulation: str) -> Certificate:
    return Certificate("time_limit", f"time limit {time_limit:g} s reached while deriving the big-M bounds; "
                       "proven lower bound 0", 0.0, np.inf, np.inf, time.perf_counter() - t0, U, False, None,
                       formulation=formulation)


# --------------------------------------------------------------------------- first formulation
def _certify_classic(model: Model, alpha_associative: float, mechanisms: list[np.ndarray], *,
                     time_limit: float = 60.0, velocity_factor: float = 10.0, alpha_best: float | None = None,
                     per_point_bounds: int = 400) -> Certificate:
    """The first formulation (kept for comparison): closed/slip binaries, one velocity big-M, scipy milp.

    - closed (z_p = 1) or open (z_p = 0):   N_p ≤ M_N z_p,   ξ_p ≤ M_v (1 − z_p);
    - slipping +t (y⁺_p = 1):   γ⁺_p ≤ M_v y⁺_p,   f N_p + T_p ≤ M_T (1 − y⁺_p);
    - slipping −t (y⁻_p = 1):   γ⁻_p ≤ M_v y⁻_p,   f N_p − T_p ≤ M_T (1 − y⁻_p).
    """
    t0 = time.perf_counter()
    points = ContactPoints.from_model(model)
    P, n = points.count, model.dead.shape[0]
    if not np.isfinite(alpha_associative) or alpha_associative < 0:
        return Certificate("failed", "the associative bound is not finite and non-negative", 0.0, np.inf, np.inf,
                           time.perf_counter() - t0, np.nan, False, None, formulation="classic")
    m_n = normal_force_bound(model, points, alpha_associative)
    if m_n is None:
        return Certificate("failed", "normal forces are unbounded (self-stress): no big-M bound exists",
                           0.0, np.inf, np.inf, time.perf_counter() - t0, np.nan, False, None, formulation="classic")
    alpha_cap = alpha_associative if alpha_best is None else min(alpha_associative, alpha_best)
    if P <= per_point_bounds:
        per_point = np.array([normal_force_bound(model, points, alpha_cap, np.eye(1, P, p).ravel()) or m_n
                              for p in range(P)])
    else:
        per_point = np.full(P, m_n)
    m_n = 1.01 * per_point + 1e-9
    m_t = (points.friction + 1.0) * m_n
    size = max([float(np.abs(u).max()) for u in mechanisms if u is not None] + [1.0])
    U = velocity_factor * size
    row_norm_n = np.asarray(abs(points.normal).sum(axis=0)).ravel()
    row_norm_t = np.asarray(abs(points.tangent).sum(axis=0)).ravel()
    m_v = float(max(row_norm_n.max(initial=0.0), row_norm_t.max(initial=0.0))) * U * 1.01
    bounds_s = time.perf_counter() - t0

    i_alpha = 0
    i_N = 1
    i_T = i_N + P
    i_u = i_T + P
    i_sp = i_u + n
    i_sm = i_sp + P
    i_z = i_sm + P
    i_yp = i_z + P
    i_ym = i_yp + P
    nvar = i_ym + P
    I = sp.identity(P, format="csr")

    constraints = []

    def add(parts: dict[int, sp.spmatrix], rows: int, lo, hi) -> None:
        cols = []
        for start in sorted(parts):
            cols.append((start, sp.csr_matrix(parts[start])))
        pieces, last = [], 0
        for start, mat in cols:
            if start > last:
                pieces.append(sp.csr_matrix((rows, start - last)))
            pieces.append(mat)
            last = start + mat.shape[1]
        if last < nvar:
            pieces.append(sp.csr_matrix((rows, nvar - last)))
        constraints.append(LinearConstraint(sp.hstack(pieces).tocsr(), lo, hi))

    F = sp.diags(points.friction)
    add({i_alpha: model.live[:, None], i_N: points.normal, i_T: points.tangent}, n, -model.dead, -model.dead)
    add({i_N: -F, i_T: I}, P, -np.inf, 0.0)
    add({i_N: -F, i_T: -I}, P, -np.inf, 0.0)
    add({i_u: points.normal.T}, P, 0.0, np.inf)
    add({i_u: points.normal.T, i_z: m_v * I}, P, -np.inf, m_v)
    add({i_u: points.tangent.T, i_sp: -I, i_sm: I}, P, 0.0, 0.0)
    add({i_u: model.live[None, :]}, 1, float(model.n_free), float(model.n_free))
    add({i_N: I, i_z: -sp.diags(m_n)}, P, -np.inf, 0.0)
    add({i_sp: I, i_yp: -m_v * I}, P, -np.inf, 0.0)
    add({i_sm: I, i_ym: -m_v * I}, P, -np.inf, 0.0)
    add({i_N: F, i_T: I, i_yp: sp.diags(m_t)}, P, -np.inf, m_t)
    add({i_N: F, i_T: -I, i_ym: sp.diags(m_t)}, P, -np.inf, m_t)
    add({i_yp: I, i_ym: I}, P, 0.0, 1.0)

    lower = np.zeros(nvar)
    upper = np.full(nvar, np.inf)
    lower[i_alpha], upper[i_alpha] = 0.0, alpha_cap
    upper[i_N:i_N + P] = m_n
    lower[i_T:i_T + P], upper[i_T:i_T + P] = -m_t, m_t
    lower[i_u:i_u + n], upper[i_u:i_u + n] = -U, U
    upper[i_z:] = 1.0
    integrality = np.zeros(nvar)
    integrality[i_z:] = 1
    c = np.zeros(nvar)
    c[i_alpha] = 1.0
    remaining = max(1.0, time_limit - (time.perf_counter() - t0))
    with _stdout_to_stderr():
        res = milp(c, constraints=constraints, integrality=integrality, bounds=Bounds(lower, upper),
                   options={"time_limit": remaining, "mip_rel_gap": 1e-9})
    elapsed = time.perf_counter() - t0
    dual = getattr(res, "mip_dual_bound", None)
    dual = float(dual) if dual is not None and np.isfinite(dual) else 0.0
    if res.x is not None:
        best = float(res.x[i_alpha])
        u = res.x[i_u:i_u + n]
        active = bool(np.abs(u).max() >= 0.999 * U)
    else:
        best, u, active = np.inf, None, False
    common = dict(formulation="classic", binaries=3 * P, nodes=int(getattr(res, "mip_node_count", 0) or 0),
                  bounds_s=bounds_s)
    if res.status == 0:
        lower_bound = max(0.0, min(dual, best)) if np.isfinite(best) else 0.0
        gap = best - lower_bound
        status = "proven"
        message = f"optimal within mip gap {gap:.1e} (|u|∞ ≤ {U:.3g}{', bound active' if active else ''})"
    elif res.status == 1:
        lower_bound = max(0.0, dual)
        gap = best - lower_bound
        status = "time_limit"
        message = f"time limit {time_limit:g} s reached; proven lower bound {lower_bound:.6g}"
    elif res.status == 2:
        lower_bound, gap, status = alpha_cap, 0.0, "proven"
        message = "no collapse state below the cap (best verified state / associative bound)"
    else:
        lower_bound, gap, status = 0.0, np.inf, "failed"
        message = f"MILP failed: {res.message}"
    return Certificate(status, message, float(lower_bound), best, float(gap), elapsed, U, active, u, **common)
