"""HiGHS adapter (highspy): a silenced solver instance and one status map.

HiGHS writes its banner and log to standard output unless told otherwise before its first
run, and highspy 1.16 prints its banner from C++ while ``Highs()`` is being constructed, before
any option can be set; alma's ``--json`` output must be the only thing on standard output, so
every instance is created here (:func:`new_highs`) with file descriptor 1 pointed at the null
device for the construction, and then with output switched off at the source.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass

import highspy
import numpy as np
import scipy.sparse as sp

from alma.backends.termination import SolverResult, termination

#: HiGHS's infinite bound.
INF = highspy.kHighsInf

#: One redirect at a time: file descriptor 1 belongs to the whole process.
_STDOUT_LOCK = threading.Lock()


def _c_library() -> ctypes.CDLL | None:
    """The process's C library, whose ``fflush`` empties the buffers C++ code writes through."""
    try:
        return ctypes.CDLL(None)
    except (OSError, TypeError):  # no handle on the running process (Windows): nothing to flush
        return None


_LIBC = _c_library()


def _flush_c_stdio() -> None:
    """Flush the C library's stdout buffer, so that text HiGHS buffered goes where fd 1 points now."""
    if _LIBC is not None:
        _LIBC.fflush(None)


@contextlib.contextmanager
def _stdout_silenced() -> Iterator[None]:
    """File descriptor 1 on the null device inside the block (what C++ writes there is dropped).

    Python's own ``sys.stdout`` is flushed first, so nothing alma printed before is lost.  The
    descriptor is 1 whatever object ``sys.stdout`` is now: that is where C++ writes.
    """
    fd = 1
    with _STDOUT_LOCK:
        if sys.stdout is not None:
            sys.stdout.flush()
        _flush_c_stdio()
        try:
            saved = os.dup(fd)
        except OSError:  # no descriptor 1 at all (a closed stdout): nothing to protect
            yield
            return
        try:
            with open(os.devnull, "wb") as null:
                os.dup2(null.fileno(), fd)
            yield
        finally:
            _flush_c_stdio()
            os.dup2(saved, fd)
            os.close(saved)


def new_highs() -> highspy.Highs:
    """A ``highspy.Highs`` constructed with standard output silenced (the banner of highspy ≥ 1.16)
    and its output switched off: the one place where alma creates HiGHS objects."""
    with _stdout_silenced():
        h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("log_to_console", False)
    return h


def quiet_highs(**options: bool | int | float | str) -> highspy.Highs:
    """A ``highspy.Highs`` that prints nothing, with ``options`` set (HiGHS option names)."""
    h = new_highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("log_to_console", False)
    for name, value in options.items():
        h.setOptionValue(name, value)
    return h


def _status_name(h: highspy.Highs) -> str:
    """HiGHS's model status name, e.g. ``kOptimal``."""
    return str(h.getModelStatus()).rsplit(".", 1)[-1]


def lp_model(
    cost: np.ndarray,
    col_lower: np.ndarray,
    col_upper: np.ndarray,
    A: sp.spmatrix,
    row_lower: np.ndarray,
    row_upper: np.ndarray,
) -> highspy.HighsLp:
    """``min costᵀx s.t. row_lower ≤ A x ≤ row_upper, col_lower ≤ x ≤ col_upper`` as a
    ``highspy.HighsLp`` (A stored column-wise; ±:data:`INF` for no bound)."""
    A = sp.csc_matrix(A)
    A.sort_indices()
    m, n = A.shape
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = n, m
    lp.col_cost_ = np.asarray(cost, dtype=float)
    lp.col_lower_, lp.col_upper_ = col_lower, col_upper
    lp.row_lower_, lp.row_upper_ = row_lower, row_upper
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = A.indptr, A.indices, A.data
    lp.a_matrix_.num_col_, lp.a_matrix_.num_row_ = n, m
    return lp


def conic_lp(q, A, b, n_eq: int) -> highspy.HighsLp:
    """``min qᵀx s.t. A x + s = b`` (s = 0 on the first ``n_eq`` rows, s ≥ 0 on the rest, x free)
    as a ``highspy.HighsLp``: rows ``b[:n_eq] ≤ A x ≤ b`` and ``A x ≤ b``."""
    m, n = A.shape
    return lp_model(
        q,
        np.full(n, -INF),
        np.full(n, INF),
        A,
        np.concatenate([b[:n_eq], np.full(m - n_eq, -INF)]),
        np.asarray(b, dtype=float),
    )


def _iterations(h: highspy.Highs) -> int:
    """Simplex, interior-point and crossover iterations of the last run."""
    info = h.getInfo()
    return int(info.simplex_iteration_count) + int(info.ipm_iteration_count) + int(info.crossover_iteration_count)


def solve_conic_form(
    q,
    A,
    b,
    n_eq: int,
    *,
    tolerance: float = 1e-10,
    iteration_limit: int = 1_000_000,
    time_limit: float | None = None,
    solver: str = "simplex",
) -> SolverResult:
    """``min qᵀx s.t. A x + s = b``, s = 0 on the first ``n_eq`` rows and s ≥ 0 on the rest (the
    form of :func:`alma.backends.clarabel_backend.solve_conic_lp`, kinematic), by HiGHS's dual
    simplex (``solver="ipm"``: its interior point with crossover).

    A vertex solution: exact where an interior point ends ill-conditioned on a degenerate face.
    The duals follow Clarabel's sign convention (q + Aᵀz = 0, z ≥ 0 on the inequality rows);
    ``iterations`` counts the simplex iterations.
    """
    start = time.perf_counter()
    lp = conic_lp(q, A, b, n_eq)
    h = quiet_highs(
        solver=solver,
        primal_feasibility_tolerance=tolerance,
        dual_feasibility_tolerance=tolerance,
        simplex_iteration_limit=iteration_limit,
    )
    if solver == "simplex":
        h.setOptionValue("simplex_strategy", 1)  # dual simplex
    else:
        h.setOptionValue("ipm_iteration_limit", iteration_limit)
        h.setOptionValue("run_crossover", "on")
    if time_limit is not None:
        h.setOptionValue("time_limit", float(time_limit))
    h.passModel(lp)
    h.run()
    name = _status_name(h)
    sol = h.getSolution()
    return SolverResult(
        termination("highs", name),
        name,
        np.asarray(sol.col_value, dtype=float),
        -np.asarray(sol.row_dual, dtype=float),
        int(h.getInfo().simplex_iteration_count),
        time.perf_counter() - start,
        f"HiGHS {solver}",
        "kinematic",
    )


# Column-wise models, warm-started objectives and the mixed-integer solve of ``alma.certify``.

#: The solver object's type, for annotations outside this module.
HighsModel = highspy.Highs

#: HiGHS model statuses of a MIP in the certificate's vocabulary: ``optimal`` (the tree closed on
#: a solution), ``pruned`` (closed without a solution below the objective bound), ``limit_reached``
#: (the user's wall-clock cap), ``node_limit`` (the work budget) and ``failed`` (anything else).
MILP_STATUS: dict[str, str] = {
    "kOptimal": "optimal",
    "kInfeasible": "pruned",
    "kObjectiveBound": "pruned",
    "kTimeLimit": "limit_reached",
    "kInterrupt": "node_limit",
    "kSolutionLimit": "node_limit",
    "kIterationLimit": "node_limit",
}


def new_model(
    cost, col_lo, col_hi, A, row_lo, row_hi, integrality=None, **options: bool | int | float | str
) -> highspy.Highs:
    """A quiet HiGHS (:func:`quiet_highs` with ``options``) holding min costᵀx over
    row_lo ≤ A x ≤ row_hi, col_lo ≤ x ≤ col_hi (A passed column-wise), with x_k integer where
    ``integrality`` is true (``None``: an LP)."""
    A = sp.csc_matrix(A)
    A.sort_indices()
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = int(A.shape[1]), int(A.shape[0])
    lp.col_cost_ = np.asarray(cost, dtype=float)
    lp.col_lower_ = np.asarray(col_lo, dtype=float)
    lp.col_upper_ = np.asarray(col_hi, dtype=float)
    lp.row_lower_ = np.asarray(row_lo, dtype=float)
    lp.row_upper_ = np.asarray(row_hi, dtype=float)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_ = A.indptr.astype(np.int32)
    lp.a_matrix_.index_ = A.indices.astype(np.int32)
    lp.a_matrix_.value_ = A.data.astype(float)
    if integrality is not None:
        lp.integrality_ = [
            highspy.HighsVarType.kInteger if v else highspy.HighsVarType.kContinuous for v in integrality
        ]
    h = quiet_highs(**options)
    h.passModel(lp)
    return h


def warm_maximum(h: highspy.Highs, objective, max_pivots: int) -> float | str:
    """max objectiveᵀx of the LP held by ``h`` (from :func:`new_model`), warm-started from its last
    basis and bounded by ``max_pivots`` simplex iterations; a message ("ended <HiGHS's model
    status>") when it does not end optimal (unbounded, infeasible, the iteration bound)."""
    c = np.asarray(objective, dtype=float)
    h.setOptionValue("simplex_iteration_limit", int(max_pivots))
    h.changeColsCost(c.size, np.arange(c.size, dtype=np.int32), -c)
    h.run()
    if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
        return f"ended {h.modelStatusToString(h.getModelStatus())}"
    return -float(h.getInfo().objective_function_value)


@dataclass(frozen=True)
class MilpOutcome:
    """One HiGHS MIP solve: ``status`` in :data:`MILP_STATUS`'s vocabulary, HiGHS's own word, the
    proven dual bound (−inf if none), the best solution (None if none) and the nodes explored."""

    status: str
    highs_status: str
    dual_bound: float
    x: np.ndarray | None
    nodes: int


def solve_milp(
    cost,
    col_lo,
    col_hi,
    A,
    row_lo,
    row_hi,
    integrality,
    *,
    node_limit: int,
    absolute_gap: float,
    relative_gap: float,
    integrality_tolerance: float,
    time_limit: float | None = None,
    objective_bound: float | None = None,
) -> MilpOutcome:
    """min costᵀx of a MIP (arguments as :func:`new_model`) by HiGHS's branch-and-bound.

    ``node_limit`` is the work budget; ``time_limit`` (s) a user's cap only; ``objective_bound``
    prunes every node whose bound reaches it (a known solution's value).
    """
    h = new_model(
        cost,
        col_lo,
        col_hi,
        A,
        row_lo,
        row_hi,
        integrality,
        mip_max_nodes=int(node_limit),
        mip_rel_gap=float(relative_gap),
        mip_abs_gap=float(absolute_gap),
        mip_feasibility_tolerance=float(integrality_tolerance),
    )
    if time_limit is not None:
        h.setOptionValue("time_limit", float(max(0.0, time_limit)))
    if objective_bound is not None:
        h.setOptionValue("objective_bound", float(objective_bound))
    h.run()
    name = str(h.getModelStatus()).rsplit(".", 1)[-1]
    info = h.getInfo()
    dual = float(info.mip_dual_bound) if np.isfinite(info.mip_dual_bound) else -np.inf
    x = None
    if info.primal_solution_status == 2 or name == "kOptimal":
        x = np.asarray(h.getSolution().col_value, dtype=float)
    return MilpOutcome(MILP_STATUS.get(name, "failed"), name, dual, x, int(info.mip_node_count))
