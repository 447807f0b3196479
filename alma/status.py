"""The one status vocabulary of alma (SPEC §3), used by every layer.

Each backend maps its solver's own statuses onto these in one table (``alma.backends``); the
certificate, not a solver's flag, decides between them.
"""

from __future__ import annotations

from enum import StrEnum


class Status(StrEnum):
    """Outcome of an analysis.  A ``StrEnum``: each member equals its string (``"optimal"``)."""

    #: The bounds are closed (relative gap ≤ 1e-7): α is proven.
    OPTIMAL = "optimal"
    #: Non-associative only: a verified collapse state; α is an upper bound on the lowest
    #: collapse multiplier and ``bounds.lower`` is what is proven below it.
    FEASIBLE = "feasible"
    #: No mechanism lets the live load do positive work: the structure carries any α.
    NO_COLLAPSE = "no_collapse"
    #: The structure cannot carry even its dead load (α_c < 0).
    NO_EQUILIBRIUM = "no_equilibrium"
    #: A solver gave up: ``alpha`` holds the best value found, ``bounds`` what is proven.
    NOT_CONVERGED = "not_converged"
    #: A user's hard limit (wall clock) stopped the analysis before its work budget was spent.
    LIMIT_REACHED = "limit_reached"
    #: The input was refused (exit code 2; nothing is solved).
    INVALID_INPUT = "invalid_input"


#: Statuses whose ``alpha`` and mechanism are meaningful (a value was computed).
SOLVED = (Status.OPTIMAL, Status.FEASIBLE, Status.NOT_CONVERGED, Status.LIMIT_REACHED)
