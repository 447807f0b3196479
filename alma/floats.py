"""Floating-point sums that give the same bits on every machine.

NumPy hands a dense product (``x @ y``, ``np.dot``, a matrix with few columns times a vector) to
BLAS, and OpenBLAS picks its kernel by the CPU: its FMA and vector width change the rounding of
each sum.  A search that branches on the last bits of its data (a degenerate LP's vertex, an
active set read at a threshold) then gives another answer on another CPU (docs/decisions.md,
"The same answer on another CPU").  These helpers write the same sums as elementwise products
and NumPy's own reductions, whose order does not depend on the CPU.  Sparse products
(scipy.sparse) do not use BLAS and need no helper.  ``alma.engine`` keeps its own ``dot`` (the
same sum): it imports nothing of alma.
"""

from __future__ import annotations

import numpy as np


def dot(x: np.ndarray, y: np.ndarray) -> float:
    """xᵀy of two dense vectors, without BLAS: a NumPy float, so that dividing by a zero one gives
    inf or NaN, as ``x @ y`` did, not an exception."""
    return np.float64(np.multiply(x, y).sum())


def rows_dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Row by row xᵢᵀyᵢ of two (n, k) arrays (or an (n, k) array and a (k,) vector), without BLAS."""
    return np.multiply(x, y).sum(axis=-1)


def times(points: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """``points @ matrix`` for an (n, k) or (k,) array and a (k, m) matrix with few rows (k),
    without BLAS: a sum of k elementwise products, in order."""
    points = np.asarray(points, dtype=float)
    matrix = np.asarray(matrix, dtype=float)
    out = points[..., 0, None] * matrix[0]
    for i in range(1, matrix.shape[0]):
        out = out + points[..., i, None] * matrix[i]
    return out


def least_squares(a: np.ndarray, b: np.ndarray, rcond: float = 1e-12) -> np.ndarray:
    """The x that minimises ‖a x − b‖ for a tall (n, k) ``a`` of few columns, without LAPACK.

    Modified Gram–Schmidt with BLAS-free dots, twice (re-orthogonalisation); a column whose part
    outside the earlier ones is below ``rcond`` × the largest column norm adds nothing (its x is
    0), as LAPACK's least squares drops the directions below its cut-off.
    """
    a = np.asarray(a, dtype=float)
    k = a.shape[1]
    q: list[np.ndarray] = []
    kept: list[int] = []
    r = np.zeros((k, k))
    top = max((np.sqrt(dot(a[:, j], a[:, j])) for j in range(k)), default=0.0)
    for j in range(k):
        v = a[:, j].copy()
        for _ in range(2):
            for i, qi in zip(kept, q, strict=True):
                c = dot(qi, v)
                r[i, j] += c
                v = v - c * qi
        norm = np.sqrt(dot(v, v))
        if not norm > rcond * top:
            continue
        r[j, j] = norm
        q.append(v / norm)
        kept.append(j)
    x = np.zeros(k)
    rhs = [dot(qi, b) for qi in q]
    for pos in range(len(kept) - 1, -1, -1):
        j = kept[pos]
        later = sum((r[j, kept[p]] * x[kept[p]] for p in range(pos + 1, len(kept))), 0.0)
        x[j] = (rhs[pos] - later) / r[j, j]
    return x
