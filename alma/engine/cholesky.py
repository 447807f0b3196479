"""Sparse symmetric factorisations of the normal matrix K = H D Hᵀ behind one small interface.

A backend is created once per geometry on a :class:`~alma.engine.normal.NormalPattern`; its
first :meth:`Factoriser.factor` does the ordering and symbolic analysis, every later call only
the numeric factorisation on the same pattern.  Backends (measured in ``docs/engine.md``):

- ``pardiso``: Intel MKL Pardiso through ``pypardiso`` (optional extra ``alma[mkl]``), symmetric
  positive definite mode, METIS nested-dissection ordering;
- ``feral``: ``feral-solver`` (MIT, Rust), supernodal multifrontal LDLᵀ with threshold pivoting;
- ``qdldl``: QDLDL after AMD (Clarabel's own factorisation; a dependency of alma already).

:func:`make_factoriser` returns the first one importable in :data:`PREFERENCE` (or the named
one).  No backend decides anything from the clock.
"""

from __future__ import annotations

import functools
import importlib.util
from abc import ABC, abstractmethod
from typing import Any

import numpy as np
import scipy.sparse as sp

from .normal import NormalPattern, entry_order
from .types import IPMSettings

#: Fastest first, as measured on the walls and the largest paper panel (docs/engine.md).
PREFERENCE = ("pardiso", "feral", "qdldl")


#: feral's fill-reducing ordering (its own default): measured smallest factor on the walls.
FERAL_ORDERING = "amf"

#: Right-hand sides from which one block solve with feral beats single solves (a block of 2-8
#: columns costs ~2.5 single solves: 1.4 ms against 0.28 ms on the panel, 46 ms against 19 ms at
#: 20,000 blocks).
FERAL_BLOCK_SOLVE = 3


class FactorisationError(RuntimeError):
    """The numeric factorisation failed (e.g. a zero pivot); the caller regularises more."""


class Factoriser(ABC):
    """Factorise K (given by its upper-triangle values on a fixed pattern) and solve with it.

    With a ``border`` f (Eq. 10's live load f_L) :meth:`solve_bordered` solves the bordered
    system [K f; fᵀ 0]: by the Schur complement fᵀ K⁻¹ f here (K⁻¹ f solved with the first call
    after each factorisation), or by a factorisation of the bordered matrix itself where the
    backend does that (feral: no extra solve per factorisation).
    """

    name = "abstract"

    def __init__(self, pattern: NormalPattern, border: np.ndarray | None = None):
        self.pattern = pattern
        self.analysed = False
        self.border = None if border is None else np.asarray(border, dtype=float)
        self.columns = 0  # right-hand sides solved so far
        self._w: np.ndarray | None = None  # K⁻¹ f of the current factorisation
        self._schur = 1.0

    def factor(self, values: np.ndarray) -> None:
        """Numeric factorisation of K with these upper-triangle values (analysis on first call)."""
        self._w = None
        self._factor(values)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solve K x = rhs with the last factorisation; rhs is (n,) or (n, r)."""
        self.columns += 1 if rhs.ndim == 1 else rhs.shape[1]
        return self._solve(rhs)

    def solve_bordered(self, g: np.ndarray, h: float) -> tuple[np.ndarray, float]:
        """(x, a) with K x + f a = g and fᵀ x = h (f: the border), by the Schur complement."""
        f = self.border
        assert f is not None  # a bordered solve needs the border given at construction
        if self._w is None:
            both = self.solve(np.column_stack([f, g]))
            self._w, v = both[:, 0].copy(), both[:, 1].copy()
            self._schur = dot(f, self._w)
        else:
            v = self.solve(g)
        a = (dot(f, v) - h) / self._schur
        return v - a * self._w, a

    @abstractmethod
    def _factor(self, values: np.ndarray) -> None:
        """The backend's numeric factorisation (symbolic analysis on its first call)."""

    @abstractmethod
    def _solve(self, rhs: np.ndarray) -> np.ndarray:
        """The backend's solve with its last factorisation."""

    def close(self) -> None:  # noqa: B027  (a no-op default: only a backend holding native memory overrides it)
        """Release native memory (a no-op unless the backend holds some)."""


def dot(x: np.ndarray, y: np.ndarray) -> float:
    """xᵀy without BLAS: a threaded BLAS dot on a busy 2-core machine was measured at 8 ms for
    20,000 entries (thread hand-off), the plain reduction at 12 µs."""
    return float(np.multiply(x, y).sum())


def _lower_permutation(pattern: NormalPattern) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(indptr, indices, perm) of the lower triangle in CSC order, values = upper_values[perm].

    The lower triangle in CSC order is also the upper triangle in CSR order (Pardiso's input).
    """
    upper_cols = np.repeat(np.arange(pattern.n, dtype=np.int64), np.diff(pattern.indptr))
    indptr, indices, perm = entry_order(upper_cols, pattern.indices, (pattern.n, pattern.n), "csc")
    return indptr.astype(np.int64), indices.astype(np.int64), perm


class QdldlFactoriser(Factoriser):
    """QDLDL (Apache-2.0): LDLᵀ without pivoting after AMD; symbolic once, ``update`` after."""

    name = "qdldl"

    def __init__(self, pattern: NormalPattern, border: np.ndarray | None = None):
        super().__init__(pattern, border)
        self._solver: Any = None  # qdldl.Solver (untyped) after the first factorisation

    def _matrix(self, values: np.ndarray) -> sp.csc_matrix:
        p = self.pattern
        return sp.csc_matrix((values, p.indices, p.indptr), shape=(p.n, p.n))

    def _factor(self, values: np.ndarray) -> None:
        import qdldl

        try:
            if self._solver is None:
                self._solver = qdldl.Solver(self._matrix(values), upper=True)
                self.analysed = True
            else:
                self._solver.update(self._matrix(values), upper=True)
        except Exception as exc:  # qdldl raises ValueError on a zero pivot
            raise FactorisationError(f"qdldl: {exc}") from exc

    def _solve(self, rhs: np.ndarray) -> np.ndarray:
        if rhs.ndim == 2:
            return np.column_stack([self._solver.solve(np.ascontiguousarray(c)) for c in rhs.T])
        return self._solver.solve(np.ascontiguousarray(rhs))


class FeralFactoriser(Factoriser):
    """feral-solver (MIT): multifrontal LDLᵀ, cached symbolic analysis, ``refactor`` after.

    With a border f it factorises the bordered matrix [K f; fᵀ 0] itself (LDLᵀ with pivoting:
    the matrix is indefinite).  The ordering puts the dense last row last, so the factor grows by
    one row (n entries; measured 1,228,776 → 1,243,792 at 5,000 blocks) and every bordered solve
    is one solve: the Schur complement's K⁻¹ f, one solve per factorisation, is saved.
    """

    name = "feral"

    def __init__(self, pattern: NormalPattern, border: np.ndarray | None = None, *, factor_border: bool = True):
        super().__init__(pattern, border)
        import feral

        self._feral = feral
        self._bordered = factor_border and self.border is not None  # else the Schur complement
        indptr, indices, self._perm = _lower_permutation(pattern)
        size = pattern.n
        if self._bordered and self.border is not None:
            indptr, indices, self._perm, self._extra = _bordered_lower(indptr, indices, self._perm, self.border)
            size += 1
        cols = np.repeat(np.arange(size, dtype=np.int64), np.diff(indptr))
        self._matrix = feral.CscMatrix.from_triplet(size, indices, cols, np.ones(indices.size))
        # K + δ I is symmetric positive definite: feral's equilibration (scaling "auto") costs
        # 20-40 % of each numeric factorisation and is not needed; AMF gives the smallest factor
        # on the walls (6.2 M nonzeros at 20,000 blocks against 6.9 M with AMD; docs/engine.md).
        self._solver = feral.Solver(parallel=True, ordering=FERAL_ORDERING, scaling="none")

    def _factor(self, values: np.ndarray) -> None:
        if self._bordered:
            values = np.concatenate([values, self._extra])
        self._matrix.set_values(np.ascontiguousarray(values[self._perm]))
        try:
            status = (self._solver.refactor if self.analysed else self._solver.factor)(self._matrix)
        except self._feral.FeralError as exc:
            raise FactorisationError(f"feral: {exc}") from exc
        self.analysed = True
        if not feral_factored(self._feral, status):
            raise FactorisationError(f"feral: factor status {status}")

    def _solve(self, rhs: np.ndarray) -> np.ndarray:
        if self._bordered:
            raise RuntimeError("feral: this factorisation is of the bordered matrix; use solve_bordered")
        if rhs.ndim == 2 and rhs.shape[1] < FERAL_BLOCK_SOLVE:
            # feral's block solve costs about 2.5 single solves at any width from 2 to 8.
            return np.column_stack([self._solver.solve(np.ascontiguousarray(c)) for c in rhs.T])
        return np.asarray(self._solver.solve(np.ascontiguousarray(rhs)))

    def solve_bordered(self, g: np.ndarray, h: float) -> tuple[np.ndarray, float]:
        if not self._bordered:
            return super().solve_bordered(g, h)
        self.columns += 1
        x = np.asarray(self._solver.solve(np.concatenate([g, [h]])))
        return x[:-1], float(x[-1])


def feral_factored(feral, status) -> bool:
    """True when feral's ``factor``/``refactor`` status (a code, or a tuple led by one) leaves
    usable factors: success, or an inertia other than the one asked for (the factors are exact)."""
    code = status[0] if isinstance(status, tuple) else status
    return int(code) in (int(feral.FactorStatus.SUCCESS), int(feral.FactorStatus.WRONG_INERTIA))


def _bordered_lower(
    indptr: np.ndarray, indices: np.ndarray, perm: np.ndarray, border: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Lower CSC structure of [K f; fᵀ 0] from K's, and where its values come from.

    Returns (indptr, indices, perm, extra): the values of the bordered matrix in CSC order are
    ``concatenate([K_upper_values, extra])[perm]``, extra being f's nonzeros and the zero corner.
    """
    n, nnz = indptr.size - 1, int(perm.max(initial=-1)) + 1
    rows_f = np.flatnonzero(border)
    cols_k = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr))
    rows = np.concatenate([indices, np.full(rows_f.size + 1, n)])
    cols = np.concatenate([cols_k, rows_f, [n]])
    source = np.concatenate([perm, nnz + np.arange(rows_f.size + 1)])
    indptr, indices, order = entry_order(rows, cols, (n + 1, n + 1), "csc")
    extra = np.concatenate([border[rows_f], [0.0]])
    return indptr.astype(np.int64), indices.astype(np.int64), source[order], extra


class PardisoFactoriser(Factoriser):
    """MKL Pardiso (Intel Simplified Software License), called through the ctypes handle of
    ``pypardiso`` with the 1-based int32 structure converted once (pypardiso's own ``solve``
    converts it at every call, which costs more than the solve on the paper panels).

    Phases: 11 (METIS ordering, symbolic) once, 22 (numeric) per iteration, 33 (solve).  Matrix
    type 2 (real symmetric positive definite): K + δ I is positive definite, and a zero pivot
    raises :class:`FactorisationError` so the caller adds more δ.
    """

    name = "pardiso"

    def __init__(self, pattern: NormalPattern, border: np.ndarray | None = None):
        super().__init__(pattern, border)
        self._pardiso = _pardiso_function()
        indptr, indices, self._perm = _lower_permutation(pattern)
        self._ia = np.ascontiguousarray(indptr + 1, dtype=np.int32)
        self._ja = np.ascontiguousarray(indices + 1, dtype=np.int32)
        self._values = np.zeros(pattern.nnz)
        self._pt = np.zeros(64, dtype=np.int64)  # Pardiso's internal handle (64-bit pointers)
        self._iparm = np.zeros(64, dtype=np.int32)
        # iparm[0] = 1: the values below, zero (Pardiso's default) elsewhere.  Pardiso's own
        # defaults refine every solve twice, 3x the cost of a solve on the paper panel; the
        # interior point refines where it needs to itself.
        self._iparm[0] = 1
        self._iparm[1] = 2  # METIS nested-dissection ordering
        self._iparm[9] = 13  # pivot perturbation 1e-13 (a zero pivot is reported, not hidden)
        self._iparm[17] = -1  # report the factor's nonzeros
        self._no_perm = np.zeros(0, dtype=np.int32)

    def _call(self, phase: int, rhs: np.ndarray) -> np.ndarray:
        import ctypes

        rhs = np.asfortranarray(rhs, dtype=float)
        x = np.zeros_like(rhs)
        error = ctypes.c_int32(0)
        i32 = ctypes.POINTER(ctypes.c_int32)
        f64 = ctypes.POINTER(ctypes.c_double)
        one = ctypes.byref(ctypes.c_int32(1))
        self._pardiso(
            self._pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)),
            one,
            one,
            ctypes.byref(ctypes.c_int32(2)),
            ctypes.byref(ctypes.c_int32(phase)),
            ctypes.byref(ctypes.c_int32(self.pattern.n)),
            self._values.ctypes.data_as(f64),
            self._ia.ctypes.data_as(i32),
            self._ja.ctypes.data_as(i32),
            self._no_perm.ctypes.data_as(i32),
            ctypes.byref(ctypes.c_int32(1 if rhs.ndim == 1 else rhs.shape[1])),
            self._iparm.ctypes.data_as(i32),
            ctypes.byref(ctypes.c_int32(0)),
            rhs.ctypes.data_as(f64),
            x.ctypes.data_as(f64),
            ctypes.byref(error),
        )
        if error.value != 0:
            raise FactorisationError(f"pardiso phase {phase}: error {error.value}")
        return np.ascontiguousarray(x)

    def _factor(self, values: np.ndarray) -> None:
        np.take(values, self._perm, out=self._values)
        dummy = np.zeros(self.pattern.n)
        if not self.analysed:
            self._call(11, dummy)
            self.analysed = True
        self._call(22, dummy)

    def _solve(self, rhs: np.ndarray) -> np.ndarray:
        return self._call(33, rhs)

    def close(self) -> None:
        if self.analysed:
            self._call(-1, np.zeros(self.pattern.n))
            self.analysed = False


_BACKENDS: dict[str, tuple[str, type[Factoriser]]] = {
    "pardiso": ("pypardiso", PardisoFactoriser),
    "feral": ("feral", FeralFactoriser),
    "qdldl": ("qdldl", QdldlFactoriser),
}


@functools.lru_cache(maxsize=1)
def available_backends() -> tuple[str, ...]:
    """Names of the backends whose library can be loaded here, fastest first (looked up once)."""
    found = []
    for name in PREFERENCE:
        module, _ = _BACKENDS[name]
        if importlib.util.find_spec(module) is None:
            continue
        if name == "pardiso":
            try:
                _pardiso_function()
            except Exception:  # pypardiso installed without a loadable MKL runtime
                continue
        found.append(name)
    return tuple(found)


@functools.lru_cache(maxsize=1)
def _pardiso_function():
    """MKL's ``pardiso`` entry point with its ctypes signature, located once by pypardiso."""
    from pypardiso.pardiso_wrapper import PyPardisoSolver

    return PyPardisoSolver(mtype=2)._mkl_pardiso


def make_factoriser(
    pattern: NormalPattern,
    backend: str = "auto",
    border: np.ndarray | None = None,
    qdldl_max_rows: int = IPMSettings().qdldl_max_rows,
) -> Factoriser:
    """The named backend, or with ``auto`` the first available in :data:`PREFERENCE` (QDLDL
    before feral below ``qdldl_max_rows``, :attr:`alma.settings.IPMSettings.qdldl_max_rows`);
    ``border`` (f_L) enables :meth:`Factoriser.solve_bordered`."""
    if backend == "auto":
        names = available_backends()
        if not names:
            raise FactorisationError("no sparse factorisation backend is importable")
        backend = names[0]
        if backend == "feral" and pattern.n < qdldl_max_rows and "qdldl" in names:
            backend = "qdldl"
    if backend not in _BACKENDS:
        raise ValueError(f"unknown factorisation backend {backend!r}; known: {sorted(_BACKENDS)}")
    return _BACKENDS[backend][1](pattern, border)
