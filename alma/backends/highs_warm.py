"""A HiGHS model kept between solves (:class:`WarmLP`), whose runs are bounded by HiGHS's own counts.

The Gilbert iteration's capped LP (:mod:`alma.nonassociative.cap_lp`) changes only bounds and a
few coefficients between solves; HiGHS keeps its basis, so each re-solve is a short dual-simplex
run.  Every run is bounded by iteration counts and by the simplex's bailout checks
(:class:`_Checks`), and by the clock only where a user's hard cap asks for it.
"""

from __future__ import annotations

import time
from typing import Any

import highspy
import numpy as np

from alma.backends.highs_backend import INF, _iterations, _status_name, quiet_highs
from alma.backends.termination import SolverResult, Termination, termination


class _Checks:
    """The simplex's bailout checks of one run, stopped past the run's iteration limit (at least
    ``floor``) or once they stall: on numerically singular bases HiGHS can loop there without
    counting an iteration (a displaced panel: 56,000 checks in 6,300 iterations; another, 9,000
    checks at 8 ms each for 100 iterations).  HiGHS checks about once per iteration, so a healthy
    run's checks exceed its iterations by a few per cent (docs/decisions.md); a run whose excess passes ``floor`` plus
    ``stall_share`` of its iterations is rebuilding instead of pivoting, and stops as an iteration
    limit (the count is HiGHS's own, so the stop does not depend on the clock)."""

    #: Checks any run may make: a short run's own rebuilds stay well below it.
    floor = 1000
    #: Checks beyond the iterations allowed per iteration, above ``floor``: above the excess of
    #: healthy runs on the paper panels (1.4–8.3 %), a tenth of a stalled run's (about 1 a check).
    stall_share = 0.1

    def __init__(self) -> None:
        self.calls, self.limit, self.spent = 0, 0, False

    def reset(self, limit: int) -> None:
        """A new run with max(``limit``, ``floor``) checks allowed."""
        self.calls, self.limit, self.spent = 0, max(int(limit), self.floor), False

    def count(self, event: Any) -> None:
        """HiGHS's simplex interrupt callback: one check; interrupt past the limit or at a stall (set
        every time: HiGHS keeps the flag from one run to the next)."""
        self.calls += 1
        iterations = int(event.data_out.simplex_iteration_count)
        stalled = self.calls - iterations > self.floor + self.stall_share * iterations
        self.spent = self.calls > self.limit or stalled
        event.interrupt(self.spent)


class WarmLP:
    """A HiGHS model kept between solves, whose bounds and coefficients change and whose basis
    carries over: each re-solve is a short dual-simplex run from the last vertex.

    Built silent (:func:`quiet_highs`) with ``options`` (HiGHS option names); every run is
    bounded by iteration counts, and by the clock only where a user's hard cap asks for it.
    """

    def __init__(self, lp: highspy.HighsLp, **options: bool | int | float | str) -> None:
        self._h = quiet_highs(**options)
        self._h.passModel(lp)
        self._checks = _Checks()
        self._h.cbSimplexInterrupt.subscribe(self._checks.count)

    def set_option(self, name: str, value: bool | int | float | str) -> None:
        """Set one HiGHS option (kept for the later runs)."""
        self._h.setOptionValue(name, value)

    def change_col_bounds(self, cols: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> None:
        """New bounds of the columns ``cols``."""
        self._h.changeColsBounds(len(cols), cols, lower, upper)

    def change_row_bounds(self, rows: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> None:
        """New bounds of the rows ``rows``."""
        self._h.changeRowsBounds(len(rows), rows, lower, upper)  # type: ignore[attr-defined]  # not in highspy's stubs

    def change_coeff(self, row: int | np.integer, col: int | np.integer, value: float | np.floating) -> None:
        """A new coefficient of the constraint matrix."""
        self._h.changeCoeff(int(row), int(col), float(value))

    def basis(self) -> Any:
        """The current basis (a ``highspy.HighsBasis``), for :meth:`set_basis` of a model with the
        same rows and columns."""
        return self._h.getBasis()

    def set_basis(self, basis: Any) -> None:
        """Start the next run from ``basis``."""
        self._h.setBasis(basis)

    def clear_solver(self) -> None:
        """Forget the basis and factorisation (the next run starts cold)."""
        self._h.clearSolver()

    def run(self, iteration_limit: int, *, then: str | None = None, seconds: float = INF) -> SolverResult:
        """One solve within ``iteration_limit`` simplex (and interior-point) iterations, by the
        solver option in force; ``then``: the solver option for the runs after this one;
        ``seconds``: what is left of a user's hard cap (inf: none).

        ``iterations`` counts simplex, interior-point and crossover iterations; ``duals`` are the
        rows' (q + Aᵀz = 0).  On any termination but an optimal one, x and duals are empty.
        """
        start = time.perf_counter()
        self._h.setOptionValue("simplex_iteration_limit", int(iteration_limit))
        self._h.setOptionValue("ipm_iteration_limit", int(iteration_limit))
        # HiGHS's run clock adds up over the runs of one model: the cap is what is left of it now.
        limit = self._h.getRunTime() + max(float(seconds), 0.0) if np.isfinite(seconds) else INF
        self._h.setOptionValue("time_limit", limit)
        self._checks.reset(iteration_limit)
        self._h.run()
        if then is not None:
            self._h.setOptionValue("solver", then)
        name = _status_name(self._h)
        term = Termination.ITERATION_LIMIT if self._checks.spent else termination("highs", name)
        x = duals = np.zeros(0)
        if term is Termination.OPTIMAL:
            sol = self._h.getSolution()
            x, duals = np.asarray(sol.col_value), -np.asarray(sol.row_dual)
        return SolverResult(term, name, x, duals, _iterations(self._h), time.perf_counter() - start, "HiGHS", "static")
