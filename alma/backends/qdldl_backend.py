"""QDLDL adapter: the regularised sparse LDLᵀ solves of the certificate (Gram matrices)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import qdldl
import scipy.sparse as sp


def regularised_solver(gram: sp.spmatrix, eps: float | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """A solver for (G + ε I) x = b, G a Gram matrix; ε only guards against rank deficiency.

    ``eps`` defaults to 1e-12 max(1, max diag G); a zero diagonal entry (a variable G does not
    touch) gets 1 instead, so that variable's solution component is 0.  G + ε I is symmetric
    positive definite, so an LDLᵀ factorisation without pivoting after an approximate minimum
    degree ordering (QDLDL, the factorisation inside Clarabel) is stable and keeps the factor
    small.
    """
    return qdldl.Solver(regularised(gram, eps)).solve


def regularised(gram: sp.spmatrix, eps: float | None = None) -> sp.csc_matrix:
    """G + ε I as :func:`regularised_solver` factorises it (ε on the nonzero diagonal, 1 on a
    zero one)."""
    gram = sp.csc_matrix(gram)
    diag = gram.diagonal()
    if eps is None:
        eps = 1e-12 * max(float(diag.max(initial=1.0)), 1.0)
    return (gram + sp.diags(np.where(diag > 0, eps, 1.0))).tocsc()


def least_squares_solver(matrix: sp.spmatrix, delta: float | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """A solver for min ‖B x − r‖ (B = ``matrix``, m × n, m ≥ n) by the augmented system

        [ I    B  ] [s]   [r]
        [ Bᵀ  −δI ] [x] = [0],

    quasi-definite for δ > 0, so QDLDL's LDLᵀ without pivoting is stable for any ordering and its
    accuracy follows the condition of B, not of BᵀB.  It returns the solution of
    (BᵀB + δI) x = Bᵀr: a caller that needs the exact one refines (each step multiplies the error
    by about δ / σ_min(B)²).  ``delta`` defaults to 1e-14 max(1, max ‖column‖²).  Plain C without
    BLAS: the same bits on every CPU, unlike SuperLU (which calls BLAS).
    """
    B = sp.csc_matrix(matrix)
    m, n = B.shape
    if delta is None:
        delta = 1e-14 * max(float(np.asarray(B.multiply(B).sum(axis=0)).max(initial=1.0)), 1.0)
    kkt = sp.bmat([[sp.identity(m), B], [B.T, -delta * sp.identity(n)]], format="csc")
    solver = qdldl.Solver(kkt)

    def solve(r: np.ndarray) -> np.ndarray:
        return np.asarray(solver.solve(np.concatenate([np.asarray(r, dtype=float), np.zeros(n)])))[m:]

    return solve
