"""Rows and columns of the certification MILP (see :mod:`alma.certify.milp`), built vectorised.

Variable layout: α | N | T | u | γ⁺ | γ⁻ (per joint) | o (points that can carry force) |
s⁺ | s⁻ (joints with such a point) | τ | d⁺ | d⁻ | q⁺ | q⁻ (per bounded column: cohesion, ties).
Forces in mean block weights, f_Lᵀu = n_free.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import cast

import numpy as np
import scipy.sparse as sp

from alma.certify.bigm import BigM
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model


@dataclass(frozen=True)
class MilpData:
    """The MILP in HiGHS's form: cost, column bounds, A with row bounds, integrality."""

    cost: np.ndarray
    col_lo: np.ndarray
    col_hi: np.ndarray
    A: sp.csc_matrix
    row_lo: np.ndarray
    row_hi: np.ndarray
    integrality: np.ndarray
    alpha_column: int
    velocity_columns: slice
    binaries: int


class _Rows:
    """Row blocks over ``nvar`` columns, each given as {first column: matrix}."""

    def __init__(self, nvar: int) -> None:
        self.nvar = nvar
        self.rows: list[sp.csr_matrix] = []
        self.lo: list[np.ndarray] = []
        self.hi: list[np.ndarray] = []

    def add(self, parts: dict[int, sp.spmatrix], count: int, low, high) -> None:
        blocks, last = [], 0
        for start in sorted(parts):
            mat = sp.csr_matrix(parts[start])
            if start > last:
                blocks.append(sp.csr_matrix((count, start - last)))
            blocks.append(mat)
            last = start + mat.shape[1]
        if last < self.nvar:
            blocks.append(sp.csr_matrix((count, self.nvar - last)))
        self.rows.append(sp.hstack(blocks).tocsr())
        self.lo.append(np.broadcast_to(np.asarray(low, dtype=float), (count,)))
        self.hi.append(np.broadcast_to(np.asarray(high, dtype=float), (count,)))


@dataclass(frozen=True)
class _Layout:
    """Column offsets (``i_<block>``, ``nvar`` in all) and the binary index sets."""

    P: int
    n: int
    m: int
    B: np.ndarray  # points that can carry force (an open/closed binary each)
    J: np.ndarray  # joints with such a point (two slip binaries each)
    q: int = 0  # bounded columns (force τ, rates d⁺ and d⁻, binaries q⁺ and q⁻ each)
    i_T: int = field(init=False)
    i_u: int = field(init=False)
    i_gp: int = field(init=False)
    i_gm: int = field(init=False)
    i_o: int = field(init=False)
    i_sp: int = field(init=False)
    i_sm: int = field(init=False)
    i_tau: int = field(init=False)
    i_dp: int = field(init=False)
    i_dm: int = field(init=False)
    i_qp: int = field(init=False)
    i_qm: int = field(init=False)
    nvar: int = field(init=False)

    def __post_init__(self) -> None:
        blocks = (
            ("alpha", 1),
            ("N", self.P),
            ("T", self.P),
            ("u", self.n),
            ("gp", self.m),
            ("gm", self.m),
            ("o", self.B.size),
            ("sp", self.J.size),
            ("sm", self.J.size),
            ("tau", self.q),
            ("dp", self.q),
            ("dm", self.q),
            ("qp", self.q),
            ("qm", self.q),
        )
        offset = 0
        for name, size in blocks:
            if name not in ("alpha", "N"):  # α is column 0 and N starts at 1
                object.__setattr__(self, f"i_{name}", offset)
            offset += size
        object.__setattr__(self, "nvar", offset)


def _continuous_rows(
    rows: _Rows, L: _Layout, model: Model, points: ContactPoints, first: np.ndarray, ell: np.ndarray
) -> None:
    """Equilibrium (Eq. 3), yield (Eq. 5), ξ ≥ 0, γ = γ⁺ − γ⁻, d = d⁺ − d⁻, f_Lᵀu = n_free and the
    energy cut."""
    P, m, f, q = L.P, L.m, points.friction, L.q
    Ip, Im, F = sp.identity(P, format="csr"), sp.identity(m, format="csr"), sp.diags(f)
    equilibrium = {0: model.live[:, None], 1: points.normal, L.i_T: points.tangent}
    if q:
        equilibrium[L.i_tau] = model.bounded
    rows.add(equilibrium, L.n, -model.dead, -model.dead)
    rows.add({1: -F, L.i_T: Ip}, P, -np.inf, 0.0)  # T − fN ≤ 0
    rows.add({1: -F, L.i_T: -Ip}, P, -np.inf, 0.0)  # −T − fN ≤ 0
    rows.add({L.i_u: points.normal.T}, P, 0.0, np.inf)  # ξ ≥ 0
    rows.add({L.i_u: points.tangent[:, first].T, L.i_gp: -Im, L.i_gm: Im}, m, 0.0, 0.0)  # γ = γ⁺ − γ⁻
    if q:  # −Gᵀu = d⁺ − d⁻
        g = cast(sp.csc_matrix, model.bounded)  # q > 0: the model has its bounded columns
        rows.add({L.i_u: g.T, L.i_dp: sp.identity(q), L.i_dm: -sp.identity(q)}, q, 0.0, 0.0)
    rows.add({L.i_u: model.live[None, :]}, 1, float(model.n_free), float(model.n_free))
    # α n_free = −f₀ᵀu + Σ_j f N_j |γ_j| + Σ_i τ_i d_i with N_j ≥ ℓ_j (an LP bound), |γ_j| = γ⁺_j + γ⁻_j
    # and τ_i d_i = cap_i d⁺_i on the bounded columns' flow rule.
    diss = (f[first] * ell)[None, :]
    cut = {0: np.array([[float(model.n_free)]]), L.i_u: model.dead[None, :], L.i_gp: -diss, L.i_gm: -diss}
    if q:
        cut[L.i_dp] = -model.capacity[None, :]
    rows.add(cut, 1, 0.0, np.inf)


def _bounded_rows(rows: _Rows, L: _Layout, model: Model, big_m: BigM) -> None:
    """The flow rule of the bounded columns: d⁺ > 0 ⇒ τ = cap (q⁺ = 1), d⁻ > 0 ⇒ τ = 0 (q⁻ = 1)."""
    q, cap = L.q, model.capacity
    rows.add({L.i_dp: sp.identity(q), L.i_qp: -sp.diags(big_m.rate_plus)}, q, -np.inf, 0.0)  # d⁺ ≤ M q⁺
    rows.add({L.i_dm: sp.identity(q), L.i_qm: -sp.diags(big_m.rate_minus)}, q, -np.inf, 0.0)  # d⁻ ≤ M q⁻
    rows.add({L.i_tau: sp.identity(q), L.i_qp: -sp.diags(cap)}, q, 0.0, np.inf)  # τ ≥ cap q⁺
    rows.add({L.i_tau: sp.identity(q), L.i_qm: sp.diags(cap)}, q, -np.inf, cap)  # τ ≤ cap (1 − q⁻)


def _complementarity_rows(
    rows: _Rows,
    L: _Layout,
    points: ContactPoints,
    big_m: BigM,
    joint_of: np.ndarray,
    m_gp_j: np.ndarray,
    m_gm_j: np.ndarray,
) -> None:
    """The big-M rows of the binaries: open ⇒ N = 0, closed ⇒ ξ = 0, slip ⇒ T = −f N sign γ."""
    B, J, nb, mj = L.B, L.J, L.B.size, L.J.size
    S = sp.csr_matrix((np.ones(nb), (np.arange(nb), B)), shape=(nb, L.P))  # selects the points in B
    Sj = sp.csr_matrix((np.ones(mj), (np.arange(mj), J)), shape=(mj, L.m))  # selects the joints in J
    Bj = sp.csr_matrix((np.ones(nb), (np.arange(nb), np.searchsorted(J, joint_of[B]))), shape=(nb, mj))
    F = sp.diags(points.friction)
    mn, mx = big_m.normal[B], big_m.opening[B]
    rows.add({1: S, L.i_o: sp.diags(mn)}, nb, -np.inf, mn)  # N ≤ M_N (1 − o)
    rows.add({L.i_u: S @ points.normal.T, L.i_o: -sp.diags(mx)}, nb, -np.inf, 0.0)  # ξ ≤ M_ξ o
    rows.add({L.i_gp: Sj, L.i_sp: -sp.diags(m_gp_j[J])}, mj, -np.inf, 0.0)  # γ⁺ ≤ M s⁺
    rows.add({L.i_gm: Sj, L.i_sm: -sp.diags(m_gm_j[J])}, mj, -np.inf, 0.0)  # γ⁻ ≤ M s⁻
    mt = 2.0 * points.friction[B] * mn
    rows.add({1: S @ F, L.i_T: S, L.i_sp: sp.diags(mt) @ Bj}, nb, -np.inf, mt)  # s⁺ ⇒ T = −fN
    rows.add({1: S @ F, L.i_T: -S, L.i_sm: sp.diags(mt) @ Bj}, nb, -np.inf, mt)  # s⁻ ⇒ T = +fN
    rows.add({L.i_sp: sp.identity(mj), L.i_sm: sp.identity(mj)}, mj, 0.0, 1.0)


def _columns(
    L: _Layout,
    big_m: BigM,
    model: Model,
    points: ContactPoints,
    alpha_hi: float,
    U: float,
    m_gp_j: np.ndarray,
    m_gm_j: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Column bounds: α ∈ [0, α_hi], 0 ≤ N ≤ M_N, |T| ≤ f M_N, |u| ≤ U, slips, 0 ≤ τ ≤ cap, rates
    and binaries."""
    P, n, m = L.P, L.n, L.m
    col_lo, col_hi = np.zeros(L.nvar), np.full(L.nvar, np.inf)
    col_hi[0] = alpha_hi
    col_hi[1 : 1 + P] = big_m.normal
    col_lo[L.i_T : L.i_T + P], col_hi[L.i_T : L.i_T + P] = (
        -points.friction * big_m.normal,
        points.friction * big_m.normal,
    )
    col_lo[L.i_u : L.i_u + n], col_hi[L.i_u : L.i_u + n] = -U, U
    col_hi[L.i_gp : L.i_gp + m] = m_gp_j
    col_hi[L.i_gm : L.i_gm + m] = m_gm_j
    col_hi[L.i_o : L.i_tau] = 1.0
    if L.q:
        col_hi[L.i_tau : L.i_dp] = model.capacity
        col_hi[L.i_dp : L.i_dm], col_hi[L.i_dm : L.i_qp] = big_m.rate_plus, big_m.rate_minus
        col_hi[L.i_qp :] = 1.0
        # A column of capacity 0 carries no force and dissipates nothing: its rates are free.
        idle = np.flatnonzero(model.capacity <= 0.0)
        col_lo[L.i_qp + idle] = col_lo[L.i_qm + idle] = 1.0
    if L.B.size and big_m.point_minimum is not None:
        # A point whose normal force is positive in every admissible field (min N_p > 0) never opens.
        col_hi[L.i_o + np.flatnonzero(big_m.point_minimum[L.B] > 1e-9)] = 0.0
    return col_lo, col_hi


def milp_data(
    model: Model, points: ContactPoints, big_m: BigM, first: np.ndarray, alpha_hi: float, U: float
) -> MilpData | str:
    """The certification MILP of a scene, or a message saying why it cannot be written."""
    P, n, m = points.count, model.dead.shape[0], first.size
    joint_of = np.searchsorted(first, np.arange(P), side="right") - 1  # joint (row of `first`) of each point
    tangent_j = points.tangent[:, first]
    if P and abs(points.tangent - tangent_j[:, joint_of]).max() > 1e-12:
        return "the two end points of a joint slip differently (curved joint?): not supported"
    # Points that can carry no force anywhere (M_N = 0 up to round-off) may always open: no binaries.
    B = np.flatnonzero(big_m.normal > 1e-7 * max(1.0, float(big_m.normal.max(initial=0.0))))
    L = _Layout(P, n, m, B, np.unique(joint_of[B]), model.n_bounded)
    m_gp_j = np.maximum.reduceat(big_m.slip_plus, first) if P else big_m.slip_plus
    m_gm_j = np.maximum.reduceat(big_m.slip_minus, first) if P else big_m.slip_minus
    rows = _Rows(L.nvar)
    _continuous_rows(rows, L, model, points, first, big_m.joint_minimum)
    if B.size:
        _complementarity_rows(rows, L, points, big_m, joint_of, m_gp_j, m_gm_j)
    if L.q:
        _bounded_rows(rows, L, model, big_m)
    col_lo, col_hi = _columns(L, big_m, model, points, alpha_hi, U, m_gp_j, m_gm_j)
    integrality = np.zeros(L.nvar, dtype=bool)
    integrality[L.i_o : L.i_tau] = True
    integrality[L.i_qp :] = True
    cost = np.zeros(L.nvar)
    cost[0] = 1.0
    return MilpData(
        cost,
        col_lo,
        col_hi,
        sp.vstack(rows.rows).tocsc(),
        np.concatenate(rows.lo),
        np.concatenate(rows.hi),
        integrality,
        0,
        slice(L.i_u, L.i_u + n),
        B.size + 2 * L.J.size + 2 * L.q,
    )
