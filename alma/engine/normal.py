"""The normal-equations matrix K = H D Hᵀ of Eq. 10's interior point, on a fixed pattern.

Each column j of H (one cone generator of one contact point, Eq. 3) touches at most two free
blocks, so it adds D_j h_j h_jᵀ to at most a 6 × 6 set of entries of K (3 rows per free block:
u, v, θ).  The map from D to the values of K's upper triangle is therefore linear and fixed by
the geometry: ``values = M D`` with M a sparse (nnz(K) × k) matrix built once.  No sparse
matrix product is formed per iteration, and the pattern (hence the ordering and the symbolic
factorisation) does not depend on D nor on the friction coefficient f (f only changes the
values of H, not where they are).

The pattern always holds the whole diagonal, so a regularisation δ I is added in place.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp


@dataclass(frozen=True)
class NormalPattern:
    """Upper triangle of H D Hᵀ in CSC order and the linear map D → its values.

    Attributes
    ----------
    n : int
        Order of K (3 × free blocks).
    indptr, indices : numpy.ndarray
        CSC structure of the upper triangle (row ≤ column), diagonal included.
    diagonal : numpy.ndarray
        Position of each diagonal entry in the value array.
    gather : scipy.sparse.csr_matrix
        (nnz × k) matrix M with ``values = M @ D``.
    """

    n: int
    indptr: np.ndarray
    indices: np.ndarray
    diagonal: np.ndarray
    gather: sp.csr_matrix

    @property
    def nnz(self) -> int:
        return int(self.indices.shape[0])

    def values(self, d: np.ndarray, shift: float = 0.0) -> np.ndarray:
        """Values of the upper triangle of H diag(d) Hᵀ + shift·I (dimensionless)."""
        out = self.gather @ d
        if shift:
            out[self.diagonal] += shift
        return out

    def matrix(self, d: np.ndarray, shift: float = 0.0) -> sp.csc_matrix:
        """The upper triangle as a scipy CSC matrix (tests and diagnostics)."""
        return sp.csc_matrix((self.values(d, shift), self.indices, self.indptr), shape=(self.n, self.n))


def normal_pattern(H: sp.csc_matrix) -> NormalPattern:
    """Build the fixed pattern of H D Hᵀ and its gather map (once per geometry).

    Parameters
    ----------
    H : scipy.sparse.csc_matrix
        Equilibrium matrix of Eq. 3, shape (3 n_free, k), dimensionless.
    """
    H = sp.csc_matrix(H)
    H.sum_duplicates()
    n, k = H.shape
    counts = np.diff(H.indptr)
    starts = H.indptr[:-1]
    rows_a, rows_b, cols, vals = [], [], [], []
    # Every ordered pair (a, b) of nonzeros within one column with row_a ≤ row_b: a column
    # holds at most 6 nonzeros (two blocks), so at most 36 vectorised passes.
    width = int(counts.max(initial=0))
    for a in range(width):
        for b in range(width):
            ok = (counts > a) & (counts > b)
            j = np.flatnonzero(ok)
            ia, ib = starts[j] + a, starts[j] + b
            ra, rb = H.indices[ia], H.indices[ib]
            keep = ra <= rb
            rows_a.append(ra[keep])
            rows_b.append(rb[keep])
            cols.append(j[keep])
            vals.append(H.data[ia[keep]] * H.data[ib[keep]])
    # The pattern itself from one symbolic product |H||H|ᵀ (plus the diagonal), then each
    # contribution's position by a search in the sorted keys (column-major) of that pattern.
    absH = abs(H)
    upper = sp.triu(absH @ absH.T + sp.identity(n, format="csc"), format="csc")
    upper.sort_indices()
    indptr = upper.indptr.astype(np.int64)
    indices = upper.indices.astype(np.int64)
    entry_col = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr))
    keys = entry_col * n + indices  # sorted: by column, then row
    r = np.concatenate(rows_a).astype(np.int64)
    c = np.concatenate(rows_b).astype(np.int64)
    position = np.searchsorted(keys, c * n + r)
    gather = sp.csr_matrix((np.concatenate(vals), (position, np.concatenate(cols))), shape=(keys.size, k))
    gather.sum_duplicates()
    diag = np.arange(n, dtype=np.int64)
    diagonal = np.searchsorted(keys, diag * n + diag)
    return NormalPattern(n=n, indptr=indptr, indices=indices, diagonal=diagonal, gather=gather)
