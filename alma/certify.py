"""Global certification of the non-associative problem (Eq. 9) by mixed-integer LP.

The complementarity of Eq. 9 is written with binaries (big-M, solved with HiGHS
through ``scipy.optimize.milp``): at every contact point p

- closed (z_p = 1) or open (z_p = 0):   N_p ≤ M_N z_p,   ξ_p ≤ M_v (1 − z_p);
- slipping +t (y⁺_p = 1):   γ⁺_p ≤ M_v y⁺_p,   f N_p + T_p ≤ M_T (1 − y⁺_p);
- slipping −t (y⁻_p = 1):   γ⁻_p ≤ M_v y⁻_p,   f N_p − T_p ≤ M_T (1 − y⁻_p);

with equilibrium, yield |T| ≤ f N, no interpenetration ξ = normalᵀu ≥ 0, slip
γ = tangentᵀu = γ⁺ − γ⁻ and f_Lᵀu = n_free; objective min α over α ∈ [0, α_LP]
(Radenkovic: α_NL ≤ α_LP).

The big-M constants are derived per scene: M_N is the largest total normal force
of any statically admissible field with α in [0, α_LP] (an LP; unbounded →
no certificate), M_T = f M_N, and the mechanism is bounded by |u| ≤ U with U a
multiple of the candidate mechanisms' size.  The proven statement is therefore:
no collapse state with α below ``lower`` exists among mechanisms with
|u|∞ ≤ U (f_Lᵀu = n_free); the bound on u is reported, and whether it was
active at the optimum.
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

from .contact_points import ContactPoints
from .model import Model


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


def certify(model: Model, alpha_associative: float, mechanisms: list[np.ndarray], *,
            time_limit: float = 60.0, velocity_factor: float = 10.0, alpha_best: float | None = None,
            per_point_bounds: int = 400) -> Certificate:
    """Proven lower bound of the non-associative collapse multiplier (see module docstring)."""
    t0 = time.perf_counter()
    points = ContactPoints.from_model(model)
    P, n = points.count, model.dead.shape[0]
    if not np.isfinite(alpha_associative) or alpha_associative < 0:
        return Certificate("failed", "the associative bound is not finite and non-negative", 0.0, np.inf, np.inf,
                           time.perf_counter() - t0, np.nan, False, None)
    m_n = normal_force_bound(model, points, alpha_associative)
    if m_n is None:
        return Certificate("failed", "normal forces are unbounded (self-stress): no big-M bound exists",
                           0.0, np.inf, np.inf, time.perf_counter() - t0, np.nan, False, None)
    # Tighter big-M per point (one small LP each) on scenes with few contact points.
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

    # Variable layout.
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
    # equilibrium (Eq. 3)
    add({i_alpha: model.live[:, None], i_N: points.normal, i_T: points.tangent}, n, -model.dead, -model.dead)
    # yield (Eq. 5): T − fN ≤ 0, −T − fN ≤ 0
    add({i_N: -F, i_T: I}, P, -np.inf, 0.0)
    add({i_N: -F, i_T: -I}, P, -np.inf, 0.0)
    # kinematics: ξ = normalᵀu ≥ 0 and ≤ M_v (1 − z); γ = γ⁺ − γ⁻
    add({i_u: points.normal.T}, P, 0.0, np.inf)
    add({i_u: points.normal.T, i_z: m_v * I}, P, -np.inf, m_v)
    add({i_u: points.tangent.T, i_sp: -I, i_sm: I}, P, 0.0, 0.0)
    add({i_u: model.live[None, :]}, 1, float(model.n_free), float(model.n_free))
    # complementarity by big-M
    add({i_N: I, i_z: -sp.diags(m_n)}, P, -np.inf, 0.0)
    add({i_sp: I, i_yp: -m_v * I}, P, -np.inf, 0.0)
    add({i_sm: I, i_ym: -m_v * I}, P, -np.inf, 0.0)
    add({i_N: F, i_T: I, i_yp: sp.diags(m_t)}, P, -np.inf, m_t)
    add({i_N: F, i_T: -I, i_ym: sp.diags(m_t)}, P, -np.inf, m_t)
    add({i_yp: I, i_ym: I}, P, 0.0, 1.0)

    lower = np.zeros(nvar)
    upper = np.full(nvar, np.inf)
    # α above the best verified state cannot be the minimum: cap it there (prunes the search).
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
    with _stdout_to_stderr():  # HiGHS' MIP code prints debug lines on fd 1; keep --json stdout clean
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
    elif res.status == 2:  # infeasible: no collapse state with α ≤ the cap within the bounds
        lower_bound, gap, status = alpha_cap, 0.0, "proven"
        message = "no collapse state below the cap (best verified state / associative bound)"
    else:
        lower_bound, gap, status = 0.0, np.inf, "failed"
        message = f"MILP failed: {res.message}"
    return Certificate(status, message, float(lower_bound), best, float(gap), elapsed, U, active, u)
