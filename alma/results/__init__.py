"""Typed results (:mod:`alma.results.types`), built from the solvers' solutions
(:mod:`alma.results.build`) with joint states and forces in physical units
(:mod:`alma.results.joints`)."""

from alma.results.types import (
    AssociativeResult,
    BlockMotion,
    Bounds,
    Comparison,
    JointResult,
    NonAssociativeResult,
    Result,
)

__all__ = ["AssociativeResult", "BlockMotion", "Bounds", "Comparison", "JointResult", "NonAssociativeResult", "Result"]
