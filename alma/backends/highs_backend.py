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
from typing import Iterator

import highspy

from alma.status import Status

#: HiGHS model statuses as alma's vocabulary, for a problem in static form (maximise α): an
#: unbounded static problem carries any load (no collapse), an infeasible one has no field.
STATIC_STATUS: dict[str, Status] = {
    "kOptimal": Status.OPTIMAL,
    "kUnbounded": Status.NO_COLLAPSE,
    "kInfeasible": Status.NO_EQUILIBRIUM,
    "kUnboundedOrInfeasible": Status.NO_EQUILIBRIUM,
    "kIterationLimit": Status.NOT_CONVERGED,
    "kSolutionLimit": Status.NOT_CONVERGED,
    "kObjectiveBound": Status.NOT_CONVERGED,
    "kObjectiveTarget": Status.NOT_CONVERGED,
    "kTimeLimit": Status.LIMIT_REACHED,
    "kInterrupt": Status.LIMIT_REACHED,
}


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


def quiet_highs(**options: object) -> highspy.Highs:
    """A ``highspy.Highs`` that prints nothing, with ``options`` set (HiGHS option names)."""
    h = new_highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("log_to_console", False)
    for name, value in options.items():
        h.setOptionValue(name, value)
    return h


def static_status(h: highspy.Highs) -> Status:
    """The model status of ``h`` in alma's words (:data:`STATIC_STATUS`)."""
    name = str(h.getModelStatus()).rsplit(".", 1)[-1]
    return STATIC_STATUS.get(name, Status.NOT_CONVERGED)


def conic_lp(q, A, b, n_eq: int) -> highspy.HighsLp:
    """``min qᵀx s.t. A x + s = b`` (s = 0 on the first ``n_eq`` rows, s ≥ 0 on the rest, x free)
    as a ``highspy.HighsLp``: rows ``b[:n_eq] ≤ A x ≤ b`` and ``A x ≤ b``, A stored column-wise."""
    import numpy as np
    import scipy.sparse as sp

    A = sp.csc_matrix(A)
    A.sort_indices()
    m, n = A.shape
    inf = highspy.kHighsInf
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = n, m
    lp.col_cost_ = np.asarray(q, dtype=float)
    lp.col_lower_, lp.col_upper_ = np.full(n, -inf), np.full(n, inf)
    lp.row_lower_ = np.concatenate([b[:n_eq], np.full(m - n_eq, -inf)])
    lp.row_upper_ = np.asarray(b, dtype=float)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = A.indptr, A.indices, A.data
    lp.a_matrix_.num_col_, lp.a_matrix_.num_row_ = n, m
    return lp


def solve_conic_form(q, A, b, n_eq: int, *, tolerance: float = 1e-10, iteration_limit: int = 1_000_000,
                     time_limit: float | None = None, solver: str = "simplex"):
    """``min qᵀx s.t. A x + s = b``, s = 0 on the first ``n_eq`` rows and s ≥ 0 on the rest (the
    form of :func:`alma.backends.clarabel_backend.solve_conic_lp`), by HiGHS's dual simplex.

    A vertex solution: exact where an interior point ends ill-conditioned on a degenerate face.
    Returns a :class:`~alma.backends.clarabel_backend.ConicSolution` with Clarabel's sign
    convention for the duals (q + Aᵀz = 0, z ≥ 0 on the inequality rows).
    """
    import time

    import numpy as np
    import scipy.sparse as sp

    from alma.backends.clarabel_backend import ConicSolution

    start = time.perf_counter()
    lp = conic_lp(q, A, b, n_eq)
    h = quiet_highs(solver=solver, primal_feasibility_tolerance=tolerance,
                    dual_feasibility_tolerance=tolerance, simplex_iteration_limit=iteration_limit)
    if solver == "simplex":
        h.setOptionValue("simplex_strategy", 1)  # dual simplex
    else:
        h.setOptionValue("ipm_iteration_limit", iteration_limit)
        h.setOptionValue("run_crossover", "on")
    if time_limit is not None:
        h.setOptionValue("time_limit", float(time_limit))
    h.passModel(lp)
    h.run()
    name = str(h.getModelStatus()).rsplit(".", 1)[-1]
    status = KINEMATIC_STATUS.get(name, Status.NOT_CONVERGED)
    sol = h.getSolution()
    x = np.asarray(sol.col_value, dtype=float)
    z = -np.asarray(sol.row_dual, dtype=float)
    iterations = int(h.getInfo().simplex_iteration_count)
    return ConicSolution(status, f"HiGHS {name}", x, z, iterations, time.perf_counter() - start)


#: HiGHS model statuses for a problem in kinematic form (minimise the dead load's work): an
#: infeasible one has no mechanism (no collapse), an unbounded one no static field.
KINEMATIC_STATUS: dict[str, Status] = {
    **STATIC_STATUS,
    "kUnbounded": Status.NO_EQUILIBRIUM,
    "kInfeasible": Status.NO_COLLAPSE,
    "kUnboundedOrInfeasible": Status.NOT_CONVERGED,
}
