"""Comparing with printed values: a number agrees when it prints with the paper's digits."""

from __future__ import annotations

import math

#: Decimals of Table 5's collapse multipliers.
TABLE5_DECIMALS = 4


def _printed(x: float | None, decimals: int) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return ""
    return f"{x:.{decimals}f}"


def _distance_to_printed(value: float, printed: float, decimals: int) -> float:
    """How far ``value`` lies from the interval of numbers that print as ``printed``."""
    half = 0.5 * 10.0 ** (-decimals)
    lo, hi = printed - half, printed + half
    return 0.0 if lo <= value < hi else min(abs(value - lo), abs(value - hi))
