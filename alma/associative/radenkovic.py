"""Radenkovic's lower bound on the non-associative collapse multiplier.

Radenkovic's second theorem: the collapse multiplier of a body whose plastic flow does not
follow the normality rule is bounded below by that of a *standard* (associative) body whose
yield surface lies inside the actual one and has the flow's normals (the first theorem gives the
upper bound: the associative problem with the actual surface, Eq. 10).  For masonry joints whose
opening and hinging are associative and whose sliding does not dilate, that inner surface is
the joint with |T| ≤ c l t in place of |T| ≤ f N + c l t: the associative LP with friction 0
and the same cohesion, ties and loads (docs/radenkovic.md).
"""

from __future__ import annotations

from alma.associative.lp import solve_lp
from alma.engine.pattern_cache import PatternCache
from alma.mechanics.model import Model
from alma.settings import AssociativeSettings
from alma.status import Status


def radenkovic_lower_bound(
    model: Model, settings: AssociativeSettings | None = None, patterns: PatternCache | None = None
) -> float:
    """A proven lower bound on α of Eq. 9: the certified static value of Eq. 10 at friction 0.

    −∞ when that LP proves nothing (not certified, or no equilibrium without a finite value);
    +∞ when nothing collapses even without friction.
    """
    lp = solve_lp(model.with_friction(0.0), settings, patterns=patterns)
    if lp.status in (Status.OPTIMAL, Status.NO_COLLAPSE, Status.NO_EQUILIBRIUM):
        return float(lp.lower)  # under no_equilibrium a certified negative value, or −∞
    return float("-inf")
