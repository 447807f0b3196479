"""The factor levels present in a results table, in the paper's Table 1 order, and their labels
on the figures' axes (:mod:`alma.stats.figures`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import pandas as pd

from alma.stats.anova import FACTOR_LEVELS


def levels(df: pd.DataFrame, col: str) -> list[Any]:
    """Levels of factor ``col`` present in ``df``, in Table 1 order first, unknown levels after (sorted)."""
    present = list(pd.unique(df[col]))
    known = [v for v in FACTOR_LEVELS[col] if _contains(present, v)]
    extra = sorted(v for v in present if not _contains(FACTOR_LEVELS[col], v))
    return [_match(present, v) for v in known] + extra


def _contains(values: Sequence[Any], v: Any) -> bool:
    if isinstance(v, float):
        return any(isinstance(x, (float, int)) and abs(float(x) - v) < 1e-9 for x in values)
    return v in values


def _match(values: Sequence[Any], v: Any) -> Any:
    if isinstance(v, float):
        return next(x for x in values if abs(float(x) - v) < 1e-9)
    return v


def level_label(col: str, v: Any) -> str:
    """The level ``v`` of factor ``col`` as an axis label (friction to two decimals, bonds capitalised)."""
    if col == "friction":
        return f"{float(v):.2f}"
    if col == "bond":
        return str(v).capitalize()
    return str(v)
