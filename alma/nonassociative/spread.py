"""Fixed pseudo-random factors for the search's restarts: the same numbers on every machine.

Gilbert's iteration branches on which vertex of a degenerate capped LP the dual simplex meets,
and that depends on the start field's last digits: one unit in the last place of N_LP moved a
ninth of the paper panels' answers (docs/decisions.md).  A restart from N_LP with each point's
force scaled by 1 + w ξ, ξ ∈ [−1, 1), takes another path on purpose.  ξ is SplitMix64 (Steele,
Lea & Flood 2014) of the point's index and the restart's number, in unsigned 64-bit integer
arithmetic and one exact conversion to a double: it depends on neither NumPy's random streams
(not fixed across releases) nor the CPU, and the points are in the canonical order, so the
factors follow the structure, not the drawing.
"""

from __future__ import annotations

import numpy as np

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)


def splitmix64(keys: np.ndarray) -> np.ndarray:
    """SplitMix64's output for each state ``keys`` (uint64; products wrap modulo 2⁶⁴)."""
    z = keys.astype(np.uint64) + _GOLDEN
    z = (z ^ (z >> np.uint64(30))) * _MIX1
    z = (z ^ (z >> np.uint64(27))) * _MIX2
    return z ^ (z >> np.uint64(31))


def spread_factors(count: int, restart: int, width: float) -> np.ndarray:
    """Factors 1 + ``width`` ξᵢ, i < ``count``, of restart number ``restart`` (ξᵢ ∈ [−1, 1))."""
    index = np.arange(count, dtype=np.uint64) + np.uint64(restart) * np.uint64(1 << 32)
    unit = (splitmix64(index) >> np.uint64(11)).astype(np.float64) * 2.0**-53  # exact: 53 bits
    return 1.0 + width * (2.0 * unit - 1.0)
