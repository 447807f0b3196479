"""The certificate's regularised sparse solves with Gram matrices, by size: QDLDL or feral.

Both factorise G + ε I (symmetric positive definite) after a fill-reducing ordering.  QDLDL
(Clarabel's factorisation, Apache-2.0) is the faster on the paper panels; feral-solver (MIT,
supernodal multifrontal, the fast backend of :mod:`alma.engine`) from
:attr:`alma.settings.AssociativeSettings.feral_min_rows` rows on, where QDLDL's factorisation
grows much faster with the size (the certificate of a 20,000-block wall: 1.26 s against 0.52 s;
docs/engine.md).  The choice depends on the matrix's
size and the installed libraries only.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from alma.backends.qdldl_backend import regularised, regularised_solver as qdldl_solver
from alma.engine.cholesky import FERAL_ORDERING, feral_factored
from alma.settings import AssociativeSettings

#: The default of :attr:`alma.settings.AssociativeSettings.feral_min_rows`.
_FERAL_MIN_ROWS = AssociativeSettings().feral_min_rows


def regularised_solver(
    gram: sp.spmatrix, eps: float | None = None, *, feral_min_rows: int = _FERAL_MIN_ROWS
) -> Callable[[np.ndarray], np.ndarray]:
    """A solver for (G + ε I) x = b, G a Gram matrix; ε as in
    :func:`alma.backends.qdldl_backend.regularised_solver` (1e-12 max(1, max diag G) by default,
    1 on a zero diagonal entry); feral from ``feral_min_rows`` rows on, when it is installed."""
    if gram.shape[0] < feral_min_rows or importlib.util.find_spec("feral") is None:
        return qdldl_solver(gram, eps)
    return _feral_solver(sp.csc_matrix(gram), eps)


def _feral_solver(gram: sp.csc_matrix, eps: float | None) -> Callable[[np.ndarray], np.ndarray]:
    import feral

    lower = sp.tril(regularised(gram, eps)).tocsc()
    lower.sort_indices()
    cols = np.repeat(np.arange(lower.shape[0], dtype=np.int64), np.diff(lower.indptr))
    matrix = feral.CscMatrix.from_triplet(
        lower.shape[0], lower.indices.astype(np.int64), cols, np.ascontiguousarray(lower.data)
    )
    # G + ε I is positive definite: no equilibration (as for K in alma.engine.cholesky).
    solver = feral.Solver(parallel=True, ordering=FERAL_ORDERING, scaling="none")
    if not feral_factored(feral, solver.factor(matrix)):
        return qdldl_solver(gram, eps)  # the reference factorisation decides then
    return lambda b: np.asarray(solver.solve(np.ascontiguousarray(b, dtype=float)))
