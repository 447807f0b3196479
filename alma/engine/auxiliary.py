"""Auxiliary rows of Eq. 10 with bounded forces, eliminated from the normal equations.

With cohesion and ties (issue 17) the kinematic problem gains one dissipation variable v per
cohesive joint (v ≥ |γ|, cost c l t) and per tie (v ≥ max(0, elongation), cost its strength)::

    min  −f₀ᵀu + capᵀv   s.t.  f_Lᵀu = N,  Hᵀu ≥ 0,  Gᵀu + v ≥ 0 (per column of G),  v ≥ 0 (ties)

Written on x = (u, v) this is Eq. 10's form with H_aug = [[H, G, 0], [0, E, T]], whose duals are
(μ, τ, w): the static field H μ + G τ + f₀ + α f_L = 0 and τ + … = cap, i.e. 0 ≤ τ ≤ capacity.
Every column touches at most one v row, so the v block of K_aug = H_aug D H_augᵀ is diagonal,
C = V D Vᵀ, and the columns on one v row are parallel on the u rows (a cohesive joint's ±t, a
tie's single column).  The Schur complement of C is therefore again a weighted sum over the
u rows of the columns::

    K = U D Uᵀ − U D Vᵀ C⁻¹ V D Uᵀ = U diag(d_eff) Uᵀ,   d_eff_j = d_j (1 − σ_j S_r / C_r),

with σ_j = ±1 the column's orientation on its row r and S_r = Σ σ_j d_j.  K has the pattern of
the plain problem's H D Hᵀ (a cohesive joint couples the blocks its contact points couple), and
one bordered solve with it gives the exact Newton direction of the augmented system.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

#: Relative mismatch above which two columns of one auxiliary row are not taken as parallel.
PARALLEL_TOLERANCE = 1e-12


@dataclass(frozen=True)
class Auxiliary:
    """The v rows of H_aug and how each column enters them.

    Attributes
    ----------
    n_primary : int
        Rows of u (3 per free block); rows from here on are auxiliary.
    U : scipy.sparse.csc_matrix
        H_aug restricted to the u rows, (n_primary, k).
    row : numpy.ndarray
        (k,) v row of each column, −1 for a column without one.
    sign : numpy.ndarray
        (k,) σ_j: ±1 for a column parallel (anti-parallel) on the u rows to its row's first
        column, 0 for a column that is zero on the u rows (a tie's v ≥ 0) or has no v row.
    reference : scipy.sparse.csc_matrix
        (n_primary, n_aux) the first column of each v row on the u rows: U D Vᵀ = reference·diag(S).
    V_squared : scipy.sparse.csr_matrix
        V∘V with V the v rows of H_aug (one nonzero at most per column), so that C = V∘V · d.
    """

    n_primary: int
    U: sp.csc_matrix
    row: np.ndarray
    sign: np.ndarray
    reference: sp.csc_matrix
    V_squared: sp.csr_matrix

    @property
    def n_aux(self) -> int:
        return int(self.V_squared.shape[0])

    def weights(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(C, S, d_eff) of the module docstring for the column weights d = μ / s.

        C = V D Vᵀ (its diagonal), S_r = Σ σ_j d_j, and d_eff with K = U diag(d_eff) Uᵀ exactly.
        """
        c = self.V_squared @ d
        has = self.row >= 0
        r = self.row[has]
        s = np.bincount(r, weights=(self.sign * d)[has], minlength=self.n_aux)
        out = d.copy()
        out[has] = d[has] * (1.0 - self.sign[has] * s[r] / c[r])
        return c, s, np.maximum(out, 0.0)  # the maximum removes rounding only: d_eff_j ≥ 0

    def reduce(self, g: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
        """Right-hand side of the reduced system: g_u − U D Vᵀ C⁻¹ g_v."""
        return g[: self.n_primary] - self.reference @ (s * g[self.n_primary :] / c)

    def expand(self, du: np.ndarray, g: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
        """(Δu, Δv) with Δv = C⁻¹ (g_v − V D Uᵀ Δu)."""
        dv = (g[self.n_primary :] - s * (self.reference.T @ du)) / c
        return np.concatenate([du, dv])


def auxiliary_rows(H: sp.csc_matrix, n_primary: int) -> Auxiliary:
    """Split H_aug after its first ``n_primary`` rows and check the structure the elimination needs.

    Raises
    ------
    ValueError
        If a column touches more than one auxiliary row, or two columns of one auxiliary row
        are not parallel on the u rows.
    """
    H = sp.csc_matrix(H)
    U = H[:n_primary].tocsc()
    V = H[n_primary:].tocsc()
    k = H.shape[1]
    per_column = np.diff(V.indptr)
    if np.any(per_column > 1):
        raise ValueError("a column of H touches more than one auxiliary row")
    row = np.full(k, -1, dtype=np.int64)
    has = per_column == 1
    row[has] = V.indices[V.indptr[:-1][has]]
    sign, first = _orientation(U, row, V.shape[0])
    reference = sp.csc_matrix((n_primary, V.shape[0]))
    if first.size:
        reference = U[:, np.maximum(first, 0)].tocsc()
        reference = reference @ sp.diags((first >= 0).astype(float))  # a row without u part: 0
    return Auxiliary(
        n_primary=n_primary, U=U, row=row, sign=sign, reference=reference.tocsc(), V_squared=V.multiply(V).tocsr()
    )


def _orientation(U: sp.csc_matrix, row: np.ndarray, n_aux: int) -> tuple[np.ndarray, np.ndarray]:
    """σ_j of each column against the first nonzero column of its auxiliary row (vectorised),
    and that first column of each row (−1 where no column of the row is nonzero on u)."""
    k = U.shape[1]
    norm2 = np.asarray(U.multiply(U).sum(axis=0)).ravel()
    nonzero = (row >= 0) & (norm2 > 0)
    cols = np.flatnonzero(nonzero)
    first = np.full(n_aux, -1, dtype=np.int64)
    first[row[cols][::-1]] = cols[::-1]  # the lowest column index of each row wins
    ref = first[row[cols]]
    dots = np.asarray(U[:, cols].multiply(U[:, ref]).sum(axis=0)).ravel()
    sign = np.zeros(k)
    sign[cols] = np.sign(dots)
    mismatch = np.abs(np.abs(dots) - np.sqrt(norm2[cols] * norm2[ref]))
    if np.any(mismatch > PARALLEL_TOLERANCE * np.maximum(norm2[cols], 1.0)):
        raise ValueError("the columns of an auxiliary row are not parallel on the primary rows")
    return sign, first
