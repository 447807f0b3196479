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

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

#: A pattern is reused for an H holding at least this share of the entries it was built from.
REUSE_FILL = 0.9


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
    source : numpy.ndarray
        (2, nnz(M)) positions in ``H.data`` of the two factors of each entry of M, so that M of
        another H of the same structure (another friction) is two gathers and a product.
    structure : tuple
        H's shape and the sorted keys (column · rows + row) of its entries: :meth:`fits` accepts
        an H whose entries are among them (at some f an entry of Eq. 3 cancels to zero).
    """

    n: int
    indptr: np.ndarray
    indices: np.ndarray
    diagonal: np.ndarray
    gather: sp.csr_matrix
    source: np.ndarray
    structure: tuple

    def fits(self, H: sp.csc_matrix) -> bool:
        """True when every entry of ``H`` (canonical CSC) lies in the structure this pattern was
        built from, and H fills at least :data:`REUSE_FILL` of it (at f = 0 half of H's entries
        vanish: its own, smaller pattern factorises faster)."""
        return H.nnz >= REUSE_FILL * self.structure[1].size and self._positions(H) is not None

    def with_values(self, H: sp.csc_matrix) -> NormalPattern:
        """This pattern (K's structure and the positions of M) with M's values rebuilt from
        ``H``, which must :meth:`fits` it: Eq. 3 at another friction coefficient."""
        positions = self._positions(H)
        if positions is None:
            raise ValueError("H has entries outside the structure of this normal-equations pattern")
        data = np.zeros(self.structure[1].size)
        data[positions] = H.data
        values = data[self.source[0]] * data[self.source[1]]
        gather = sp.csr_matrix((values, self.gather.indices, self.gather.indptr), shape=self.gather.shape)
        return dataclasses.replace(self, gather=gather)

    def _positions(self, H: sp.csc_matrix) -> np.ndarray | None:
        """Where each entry of H sits among the pattern's H entries, or None if one does not."""
        shape, keys = self.structure
        if H.shape != shape or H.nnz > keys.size:
            return None
        mine = _keys(H)
        positions = np.searchsorted(keys, mine)
        if positions.size and (positions[-1] >= keys.size or not np.array_equal(keys[positions], mine)):
            return None
        return positions

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
    H = canonical(H)
    n, k = H.shape
    counts = np.diff(H.indptr)
    starts = H.indptr[:-1]
    rows_a, rows_b, cols, src_a, src_b = [], [], [], [], []
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
            src_a.append(ia[keep])
            src_b.append(ib[keep])
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
    del r, c, rows_a, rows_b
    # Each (position, column) occurs once: rows are unique within a column of canonical H.
    m_indptr, m_indices, taken = entry_order(position, np.concatenate(cols), (keys.size, k), "csr")
    del position, cols
    index = np.int32 if H.nnz < 2**31 else np.int64  # halves the map's memory on large walls
    source = np.stack([np.concatenate(src_a)[taken], np.concatenate(src_b)[taken]]).astype(index)
    del taken
    gather = sp.csr_matrix((H.data[source[0]] * H.data[source[1]], m_indices, m_indptr), shape=(keys.size, k))
    diag = np.arange(n, dtype=np.int64)
    diagonal = np.searchsorted(keys, diag * n + diag)
    return NormalPattern(
        n=n,
        indptr=indptr,
        indices=indices,
        diagonal=diagonal,
        gather=gather,
        source=source,
        structure=(H.shape, _keys(H)),
    )


def entry_order(
    rows: np.ndarray, cols: np.ndarray, shape: tuple[int, int], fmt: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Compressed structure (``fmt`` "csr" or "csc": indptr, indices) of a sparse matrix with
    one entry at each (rows[i], cols[i]), and ``order``: for each stored entry, the i it came
    from, so that values given per i are stored as ``values[order]``."""
    number = np.arange(1, rows.size + 1, dtype=float)  # exact below 2⁵³; no explicit zero
    matrix = (sp.csr_matrix if fmt == "csr" else sp.csc_matrix)((number, (rows, cols)), shape=shape)
    if matrix.nnz != rows.size:
        raise ValueError("entry_order: a (row, column) pair occurs more than once")
    matrix.sort_indices()
    return matrix.indptr, matrix.indices, matrix.data.astype(np.int64) - 1


def _keys(H: sp.csc_matrix) -> np.ndarray:
    """Sorted keys column · rows + row of the entries of a canonical CSC matrix."""
    columns = np.repeat(np.arange(H.shape[1], dtype=np.int64), np.diff(H.indptr))
    return columns * H.shape[0] + H.indices.astype(np.int64)


def canonical(H: sp.spmatrix) -> sp.csc_matrix:
    """H as CSC with sorted, summed indices and no stored zero (the form :class:`NormalPattern`
    indexes: every pair of entries of a column is then an entry of |H||H|ᵀ)."""
    H = sp.csc_matrix(H, copy=True)
    H.sum_duplicates()
    H.eliminate_zeros()
    return H
