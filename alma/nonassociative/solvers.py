"""Solver objects of the search, created silent and bounded by work, never by the clock.

Every HiGHS object is created with its output switched off before anything is passed to it
or run (highspy 1.16 prints a banner on stdout at the first run otherwise, which breaks
``--json``); every Clarabel solve is bounded by an iteration count.
"""
from __future__ import annotations

import highspy

from alma.backends.highs_backend import new_highs


def quiet_highs() -> highspy.Highs:
    """A ``highspy.Highs`` that writes nothing to stdout or a log file."""
    h = new_highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("log_to_console", False)
    return h


def clarabel_settings(tolerance: float, max_iter: int, *, qdldl: bool = True, presolve: bool = True):
    """Clarabel settings: silent, gap and feasibility ``tolerance``, at most ``max_iter`` iterations."""
    import clarabel

    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tolerance
    settings.max_iter = int(max_iter)
    settings.presolve_enable = presolve
    if qdldl:
        settings.direct_solve_method = "qdldl"
    return settings
