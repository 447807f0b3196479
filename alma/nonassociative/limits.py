"""Work budgets of the search and the user's wall-clock cap.

A start spends a :class:`Work` budget counted in solver iterations, so it stops at the same
point on every machine.  The :class:`Cap` is the only clock: a user's hard limit, checked
between units of work; when it cuts the work, the search says so.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from alma.backends.linprog_backend import LPMethod
from alma.nonassociative.states import ExactLimits, Tally
from alma.settings import StateTolerances


@dataclass(frozen=True)
class Work:
    """What one iterative start may spend."""

    #: LP solves (iterations of the start's loop).
    iterations: int = 40
    #: Simplex (and interior-point) iterations of all its LPs together; None: no total.
    pivots: int | None = None
    #: Iteration cap of any one LP.
    lp_pivots: int = 200_000
    #: An LP never gets fewer iterations than this, even when the total is spent.
    floor_pivots: int = 2_000
    #: Clarabel iterations of one interior-point solve.
    interior_iterations: int = 200
    #: How the static LP of the exact states taken is solved: a HiGHS vertex, or Clarabel's field
    #: (with a vertex where the widest set is read or the field does not verify).
    exact_method: LPMethod = LPMethod.SIMPLEX
    #: When a state is verified, and how active sets are read (:attr:`alma.settings.SearchSettings.states`).
    tolerances: StateTolerances = field(default_factory=StateTolerances)
    #: A capped LP whose α is proven below this stops there, failed (−inf: none).
    alpha_floor: float = -float("inf")

    def spent(self, tally: Tally) -> bool:
        """Whether the total is used up."""
        return self.pivots is not None and tally.pivots >= self.pivots

    def lp_limit(self, tally: Tally) -> int:
        """Iterations the next LP may take: what is left of the total, within [floor, lp_pivots]."""
        if self.pivots is None:
            return self.lp_pivots
        return int(min(self.lp_pivots, max(self.floor_pivots, self.pivots - tally.pivots)))

    def exact_limits(self, tally: Tally) -> ExactLimits:
        """Caps of the LPs of an exact state taken now."""
        limit = self.lp_limit(tally)
        return ExactLimits(
            lp_pivots=limit,
            vertex_pivots=limit,
            interior_iterations=self.interior_iterations,
            tolerances=self.tolerances,
        )


class Cap:
    """A user's wall-clock cap in seconds (None: none).  ``hit`` turns True once it has passed."""

    def __init__(self, seconds: float | None) -> None:
        self.seconds = seconds
        self._deadline = None if seconds is None else time.perf_counter() + float(seconds)
        self.hit = False

    def expired(self) -> bool:
        """True (and from then on) once the cap has passed."""
        if not self.hit and self._deadline is not None and time.perf_counter() > self._deadline:
            self.hit = True
        return self.hit

    def remaining(self) -> float:
        """Seconds left (inf without a cap)."""
        return float("inf") if self._deadline is None else self._deadline - time.perf_counter()


def no_cap() -> Cap:
    """A :class:`Cap` without a time limit."""
    return Cap(None)
