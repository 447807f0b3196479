"""The certification of Eq. 9 with its complementarity as SOS1 pairs, solved by SCIP.

The same continuous part as the big-M MILP (:mod:`alma.certify.rows`: equilibrium Eq. 3, yield
Eq. 5, ξ ≥ 0, γ = γ⁺ − γ⁻, d = d⁺ − d⁻, f_Lᵀu = n_free and the energy cut), plus the slacks

    ξ_p = normal_pᵀu,   r⁺_p = f N_p + T_p,   r⁻_p = f N_p − T_p,   s_i = cap_i − τ_i   (all ≥ 0),

and the complementarity of Eq. 9 written exactly, as pairs of which at most one is non-zero:

- (N_p, ξ_p): a point carries force or opens;
- (r⁺_p, γ⁺_j), (r⁻_p, γ⁻_j) for the points p of joint j: a slip +t needs T = −f N at every
  point of the joint (the flow rule of a non-associative Coulomb joint), a slip −t T = +f N;
- (γ⁺_j, γ⁻_j): one slip direction per joint (a valid strengthening: when both were positive,
  every point would carry T = −fN = +fN, i.e. nothing);
- (s_i, d⁺_i), (τ_i, d⁻_i): a bounded force (cohesion, tie) works only at its capacity and a
  closing rate leaves it unloaded.

No big-M constant stands for a complementarity; the LP-derived constants of
:mod:`alma.certify.bigm` enter as variable bounds only (they bound N, ξ, γ and d over the
admissible sets, the same validity argument as there).  Forces in mean block weights.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import scipy.sparse as sp

from alma.backends import scip_backend
from alma.certify.bigm import BigM
from alma.certify.certificate import Certificate
from alma.certify.rows import MilpData, _columns, _continuous_rows, _Layout, _Rows
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.limits import Cap
from alma.settings import CertifySettings


def sos1_data(
    model: Model, points: ContactPoints, big_m: BigM, first: np.ndarray, alpha_hi: float, U: float
) -> tuple[MilpData, np.ndarray, tuple] | str:
    """The SOS1 form of the certification problem: its data (no integer column), the pairs
    (k × 2 column indices) and the energy balance (:func:`_energy`), or a message saying why it
    cannot be written."""
    P, n, m, q = points.count, model.dead.shape[0], first.size, model.n_bounded
    joint_of = np.searchsorted(first, np.arange(P), side="right") - 1
    if P and abs(points.tangent - points.tangent[:, first][:, joint_of]).max() > 1e-12:
        return "the two end points of a joint slip differently (curved joint?): not supported"
    B = np.flatnonzero(big_m.normal > 1e-7 * max(1.0, float(big_m.normal.max(initial=0.0))))
    J = np.unique(joint_of[B])
    empty = np.zeros(0, dtype=int)
    L = _Layout(P, n, m, empty, empty, q)
    i_xi, i_rp = L.nvar, L.nvar + P
    i_rm, i_s = i_rp + P, i_rp + 2 * P
    nvar = i_s + q
    rows = _Rows(nvar)
    _continuous_rows(rows, L, model, points, first, big_m.joint_minimum)
    Ip, F = sp.identity(P, format="csr"), sp.diags(points.friction)
    rows.add({L.i_u: -points.normal.T, i_xi: Ip}, P, 0.0, 0.0)  # ξ = normalᵀu
    rows.add({1: -F, L.i_T: -Ip, i_rp: Ip}, P, 0.0, 0.0)  # r⁺ = f N + T
    rows.add({1: -F, L.i_T: Ip, i_rm: Ip}, P, 0.0, 0.0)  # r⁻ = f N − T
    if q:
        rows.add({L.i_tau: sp.identity(q), i_s: sp.identity(q)}, q, model.capacity, model.capacity)  # s = cap − τ
    col_lo, col_hi = _columns(L, big_m, model, points, alpha_hi, U, *_joint_slip_bounds(big_m, first, P))
    col_lo[L.i_qp :], col_hi[L.i_qp :] = 0.0, 0.0  # the big-M model's binaries q± are not used here
    col_lo = np.concatenate([col_lo, np.zeros(3 * P + q)])
    r_max = 2.0 * points.friction * big_m.normal
    xi_max = big_m.opening.copy()
    if big_m.point_minimum is not None:  # loaded in every admissible field: never opens
        xi_max[big_m.point_minimum > 1e-9] = 0.0
    col_hi = np.concatenate([col_hi, xi_max, r_max, r_max, model.capacity])
    pairs = [
        np.column_stack([1 + B, i_xi + B]),
        np.column_stack([i_rp + B, L.i_gp + joint_of[B]]),
        np.column_stack([i_rm + B, L.i_gm + joint_of[B]]),
        np.column_stack([L.i_gp + J, L.i_gm + J]),
    ]
    if q:
        k = np.arange(q)
        pairs += [np.column_stack([i_s + k, L.i_dp + k]), np.column_stack([L.i_tau + k, L.i_dm + k])]
    cost = np.zeros(nvar)
    cost[0] = 1.0
    data = MilpData(
        cost,
        col_lo,
        col_hi,
        sp.vstack(rows.rows).tocsc(),
        np.concatenate(rows.lo),
        np.concatenate(rows.hi),
        np.zeros(nvar, dtype=bool),
        0,
        slice(L.i_u, L.i_u + n),
        0,
    )
    return data, np.vstack(pairs).astype(int), _energy(L, model, points, B, joint_of, nvar)


def _energy(
    L: _Layout, model: Model, points: ContactPoints, B: np.ndarray, joint_of: np.ndarray, nvar: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The energy balance of a collapse state as ``(c, pairs, w)``: cᵀx + Σ w x_a x_b = 0 with

        α n_free + f₀ᵀu − Σ_p f_p N_p (γ⁺_j(p) + γ⁻_j(p)) − Σ_i cap_i d⁺_i = 0

    (equilibrium dotted with u; N_p ξ_p = 0, T_p γ = −f N_p |γ| and τ_i d_i = cap_i d⁺_i on the
    complementarity).  The big-M model's energy cut is its relaxation with N_p ≥ ℓ."""
    c = np.zeros(nvar)
    c[0] = float(model.n_free)
    c[L.i_u : L.i_u + model.dead.shape[0]] = model.dead
    if L.q:
        c[L.i_dp : L.i_dp + L.q] = -model.capacity
    N = 1 + B
    pairs = np.vstack([np.column_stack([N, L.i_gp + joint_of[B]]), np.column_stack([N, L.i_gm + joint_of[B]])])
    w = -np.concatenate([points.friction[B], points.friction[B]])
    return c, pairs, w


def _joint_slip_bounds(big_m: BigM, first: np.ndarray, P: int) -> tuple[np.ndarray, np.ndarray]:
    """M_γ⁺ and M_γ⁻ per joint (the largest over its points)."""
    if not P:
        return big_m.slip_plus, big_m.slip_minus
    return np.maximum.reduceat(big_m.slip_plus, first), np.maximum.reduceat(big_m.slip_minus, first)


def scip_certificate(
    data: MilpData,
    pairs: np.ndarray,
    energy: tuple,
    alpha_cap: float,
    alpha_hi: float,
    alpha_best: float | None,
    U: float,
    settings: CertifySettings,
    cap: Cap,
    t0: float,
    bounds_s: float,
) -> Certificate:
    """Solve the SOS1 problem by SCIP within the node budget and read the proven bound.

    The verified state at ``alpha_best`` acts as the objective limit (nodes whose bound reaches it
    are pruned); a closed tree without a state below it proves α ≥ the cap up to the MIP gap.
    """
    out = scip_backend.solve_mip(
        data.cost,
        data.col_lo,
        data.col_hi,
        data.A,
        data.row_lo,
        data.row_hi,
        data.integrality,
        pairs,
        node_limit=settings.node_limit,
        bilinear=energy if settings.scip_energy else None,
        objective_limit=alpha_hi if alpha_best is not None else None,
        time_limit=cap.remaining() if cap.seconds is not None else None,
        absolute_gap=settings.absolute_gap,
        feasibility_tolerance=settings.scip_feasibility,
        parameters=settings.scip_parameters,
    )
    best, u, active = out.primal, None, False
    if out.x is not None:
        best, u = float(out.x[data.alpha_column]), out.x[data.velocity_columns]
        active = bool(np.abs(u).max() >= 0.999 * U)
    common: dict[str, Any] = dict(
        velocity_bound=U,
        velocity_bound_active=active,
        mechanism=u,
        binaries=len(pairs),
        nodes=out.nodes,
        bounds_s=bounds_s,
        time_s=time.perf_counter() - t0,
        backend="scip",
    )
    scope = f"|u|∞ ≤ {U:.3g}{', bound active' if active else ''}; SCIP {out.scip_status}, {len(pairs)} SOS1 pairs"
    if out.status == "proven" and out.x is not None:
        lower = max(0.0, min(out.dual_bound, best, alpha_cap))
        return Certificate(
            "proven",
            f"optimal within mip gap {best - lower:.1e} ({scope})",
            float(lower),
            best,
            float(best - lower),
            **common,
        )
    if out.status == "proven":  # closed without a state below the limit α_hi: every state lies above it
        lower = max(0.0, alpha_cap - (alpha_hi - alpha_cap))  # the cap, less the round-off margin of α_hi
        return Certificate(
            "proven",
            f"no collapse state below the cap {alpha_cap:.9g} (best verified state / "
            f"associative bound) up to {alpha_hi - alpha_cap:.0e} ({scope})",
            float(lower),
            np.inf,
            float(alpha_cap - lower),
            **common,
        )
    if out.status in ("node_limit", "limit_reached"):
        lower = max(0.0, min(out.dual_bound, alpha_cap))
        why = "time limit reached" if out.status == "limit_reached" else f"node limit {out.nodes} reached"
        return Certificate(
            out.status,
            f"{why}; proven lower bound {lower:.6g} ({scope})",
            float(lower),
            best,
            float(alpha_cap - lower),
            **common,
        )
    return Certificate("failed", f"SCIP ended {out.scip_status}", 0.0, np.inf, np.inf, **common)
