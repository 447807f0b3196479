"""SCIP adapter (PySCIPOpt, the optional extra ``alma[scip]``): one silenced MIP solve and one
termination map.

The certification of Eq. 9 (:mod:`alma.certify.sos1`) writes its complementarity as SOS1 pairs
(at most one of two non-negative variables is non-zero), which SCIP branches on directly: no
big-M row stands for a complementarity.  SCIP prints its banner and log to standard output
unless told otherwise, so every model is created here with output switched off at the source
(``--json`` must be the only thing on standard output).
"""

from __future__ import annotations

import ctypes
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

try:  # optional: ``pip install alma[scip]``
    import pyscipopt
except ImportError:  # pragma: no cover — exercised only where PySCIPOpt is absent
    pyscipopt = None  # type: ignore[assignment]  # every entry point checks it and raises INSTALL_HINT

#: What to tell a user who asks for SCIP without it.
INSTALL_HINT = "the SCIP certification backend needs PySCIPOpt: install alma[scip] (pip install 'alma[scip]')"

#: SCIP's termination (``Model.getStatus()``) in the certificate's vocabulary: ``proven`` (the
#: tree is closed: optimal, or no solution below the objective limit), ``node_limit`` (the work
#: budget stopped it), ``limit_reached`` (the user's wall-clock cap) and ``failed``.
TERMINATION: dict[str, str] = {
    "optimal": "proven",
    "infeasible": "proven",
    "gaplimit": "proven",
    "nodelimit": "node_limit",
    "totalnodelimit": "node_limit",
    "stallnodelimit": "node_limit",
    "timelimit": "limit_reached",
    "userinterrupt": "limit_reached",
    "memlimit": "failed",
    "sollimit": "node_limit",
    "bestsollimit": "node_limit",
    "restartlimit": "node_limit",
    "unbounded": "failed",
    "inforunbd": "failed",
    "unknown": "failed",
}


@contextmanager
def _stdout_to_stderr() -> Iterator[None]:
    """Send what C code writes on file descriptor 1 to standard error meanwhile: SoPlex writes
    some warnings (e.g. "Cannot set feasibility tolerance ...") to standard output even when
    SCIP's output is hidden, and ``--json`` must stay the only thing there."""
    sys.stdout.flush()
    libc = ctypes.CDLL(None)
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        libc.fflush(None)  # C stdio buffers written while redirected go to standard error
        os.dup2(saved, 1)
        os.close(saved)


def available() -> bool:
    """True when PySCIPOpt is installed."""
    return pyscipopt is not None


def version() -> str:
    """SCIP's version as ``major.minor`` (or ``"absent"``)."""
    return str(pyscipopt.Model().version()) if pyscipopt is not None else "absent"


@dataclass(frozen=True)
class MipOutcome:
    """One SCIP run: ``status`` in :data:`TERMINATION`'s vocabulary, SCIP's own word, the proven
    dual bound (−inf if none), the best solution's objective (inf if none) and its values."""

    status: str
    scip_status: str
    dual_bound: float
    primal: float
    x: np.ndarray | None
    nodes: int


def solve_mip(
    cost: np.ndarray,
    col_lo: np.ndarray,
    col_hi: np.ndarray,
    A: sp.spmatrix,
    row_lo: np.ndarray,
    row_hi: np.ndarray,
    integrality: np.ndarray,
    sos1: np.ndarray,
    *,
    node_limit: int,
    bilinear: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    objective_limit: float | None = None,
    time_limit: float | None = None,
    absolute_gap: float = 1e-7,
    feasibility_tolerance: float = 1e-9,
    parameters: tuple[tuple[str, object], ...] = (),
) -> MipOutcome:
    """min costᵀx over ``row_lo ≤ A x ≤ row_hi``, ``col_lo ≤ x ≤ col_hi``, x_k integer where
    ``integrality`` and, for each row (a, b) of ``sos1``, x_a x_b = 0 (an SOS1 pair).  With
    ``bilinear = (c, pairs, w)`` also the quadratic equality cᵀx + Σ_k w_k x_a x_b = 0 (pairs
    k × 2), which SCIP relaxes by McCormick rows that tighten as branching narrows the bounds.

    ``node_limit`` is the work budget; ``objective_limit`` prunes every node whose bound reaches
    it (a known state); ``time_limit`` (s) is a user's cap only; ``parameters`` are further SCIP
    parameters ``(name, value)`` set last.  Raises ``ModuleNotFoundError``
    with :data:`INSTALL_HINT` when PySCIPOpt is absent.
    """
    if pyscipopt is None:
        raise ModuleNotFoundError(INSTALL_HINT)
    m = pyscipopt.Model()
    m.hideOutput(True)
    m.setParam("limits/nodes", int(node_limit))
    m.setParam("limits/absgap", float(absolute_gap))
    m.setParam("limits/gap", 1e-9)
    m.setParam("numerics/feastol", float(feasibility_tolerance))
    m.setParam("randomization/randomseedshift", 0)  # one structure, one answer
    m.setParam("parallel/maxnthreads", 1)
    if time_limit is not None:
        m.setParam("limits/time", float(max(time_limit, 0.0)))
    for name, value in parameters:
        m.setParam(name, value)
    inf = m.infinity()
    vtype = np.where(np.asarray(integrality, dtype=bool), "I", "C")
    lo = np.where(np.isfinite(col_lo), col_lo, -inf)
    hi = np.where(np.isfinite(col_hi), col_hi, inf)
    x = [
        m.addVar(name=f"x{k}", vtype=vtype[k], lb=float(lo[k]), ub=float(hi[k]), obj=float(cost[k]))
        for k in range(len(cost))
    ]
    R = sp.csr_matrix(A)
    # PySCIPOpt takes one constraint per call: a loop over the MILP's rows (its data is built vectorised).
    for i in range(R.shape[0]):
        cols, vals = R.indices[R.indptr[i] : R.indptr[i + 1]], R.data[R.indptr[i] : R.indptr[i + 1]]
        expr = pyscipopt.quicksum(float(v) * x[c] for c, v in zip(cols, vals, strict=True))
        lhs = float(row_lo[i]) if np.isfinite(row_lo[i]) else None
        rhs = float(row_hi[i]) if np.isfinite(row_hi[i]) else None
        m.addCons(pyscipopt.scip.ExprCons(expr, lhs=lhs, rhs=rhs), name=f"r{i}")
    if bilinear is not None:
        c, quad, w = bilinear
        lin = pyscipopt.quicksum(float(c[k]) * x[k] for k in np.flatnonzero(c))
        products = pyscipopt.quicksum(
            float(wk) * x[a] * x[b] for (a, b), wk in zip(np.asarray(quad, dtype=int), w, strict=True)
        )
        m.addCons(lin + products == 0.0, name="energy")
    for a, b in np.asarray(sos1, dtype=int).reshape(-1, 2):
        m.addConsSOS1([x[a], x[b]])
    if objective_limit is not None:
        m.setObjlimit(float(objective_limit))
    try:
        with _stdout_to_stderr():
            m.optimize()
    except Exception as error:  # SCIP raises on unresolved numerical trouble in its LPs
        return MipOutcome("failed", f"error ({error})", -np.inf, np.inf, None, int(m.getNTotalNodes()))
    word = str(m.getStatus())
    values, primal = None, np.inf
    if m.getNSols() > 0:
        best = m.getBestSol()
        values = np.array([m.getSolVal(best, v) for v in x])
        primal = float(m.getSolObjVal(best))
    dual = float(m.getDualbound())
    return MipOutcome(
        TERMINATION.get(word, "failed"),
        word,
        dual if np.isfinite(dual) and abs(dual) < inf else -np.inf,
        primal,
        values,
        int(m.getNTotalNodes()),
    )
