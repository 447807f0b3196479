"""The outcome of a certification run (:func:`alma.certify.milp.certify`), whatever the backend."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Certificate:
    """Outcome of :func:`~alma.certify.milp.certify`; α values dimensionless, ``time_s`` in seconds.

    ``lower`` is the proven lower bound of α over the searched set (0 when nothing is proven, and
    never above the cap min(α_LP, α_best)); ``upper`` the best collapse state the MIP found itself
    (inf if none); ``backend`` the MIP solver that proved it ("highs" or "scip").
    """

    status: str  # proven | node_limit | limit_reached (the user's cap) | failed
    message: str
    lower: float
    upper: float
    gap: float
    time_s: float
    velocity_bound: float
    velocity_bound_active: bool
    mechanism: np.ndarray | None
    binaries: int = 0
    nodes: int = 0
    bounds_s: float = 0.0  # time spent deriving the big-M constants (variable bounds for SCIP)
    backend: str = "highs"
