"""The ANOVA table's types (Table 2 of the paper): rows, and the result with R², R²(adj), R²(pred)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

#: Names of the groups of terms in Table 2, by interaction order.
_GROUP_NAMES = {1: "Linear", 2: "Two-Way Interactions", 3: "Three-Way Interactions"}

# --------------------------------------------------------------------------------------------
# Result types
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class AnovaRow:
    """One line of the ANOVA table (Table 2); ``None`` where the published table is blank."""

    source: str
    dof: int
    adj_ss: float
    adj_ms: float | None
    f_value: float | None
    p_value: float | None

    def to_dict(self) -> dict[str, Any]:
        return {
            "source": self.source,
            "dof": int(self.dof),
            "adj_ss": _plain(self.adj_ss),
            "adj_ms": _plain(self.adj_ms),
            "f_value": _plain(self.f_value),
            "p_value": _plain(self.p_value),
        }


@dataclass(frozen=True)
class AnovaResult:
    """ANOVA table plus model summary (R-sq, R-sq(adj), R-sq(pred)) as in the paper.

    ``rows`` are in the order of Table 2: Model, Linear, main effects, interaction group(s)
    and their terms, Error, Total. ``r2``, ``r2_adj`` and ``r2_pred`` are fractions (0..1);
    ``press`` is the prediction error sum of squares behind ``r2_pred``. ``fitted``,
    ``residuals``, ``leverage`` and ``std_residuals`` follow the row order of the input
    frame (the "observation order" of Figure 8).
    """

    response: str
    order: int
    n: int
    rows: tuple[AnovaRow, ...]
    r2: float
    r2_adj: float
    r2_pred: float
    press: float
    dfe: int
    mse: float
    n_params: int
    fitted: tuple[float, ...]
    residuals: tuple[float, ...]
    leverage: tuple[float, ...]
    std_residuals: tuple[float, ...]

    def row(self, source: str) -> AnovaRow:
        """The row named ``source`` (e.g. ``"Panel*Friction"``)."""
        for r in self.rows:
            if r.source == source:
                return r
        raise KeyError(f"no ANOVA row named {source!r}")

    @property
    def terms(self) -> tuple[AnovaRow, ...]:
        """Rows of the individual model terms (main effects and interactions)."""
        skip = {"Model", "Error", "Total", *_GROUP_NAMES.values()}
        return tuple(r for r in self.rows if r.source not in skip)

    @property
    def s(self) -> float:
        """Standard deviation of the error, S = sqrt(MSE) (Minitab's model summary)."""
        return math.sqrt(self.mse)

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``alma anova --json`` (SPEC section 3)."""
        return {
            "rows": [r.to_dict() for r in self.rows],
            "r2": float(self.r2),
            "r2_adj": float(self.r2_adj),
            "r2_pred": float(self.r2_pred),
        }

    def format_table(self) -> str:
        """Text table in the layout and rounding of Table 2 plus the R-sq lines (percent).

        Rounding as printed by the paper/Minitab: 4 decimals for Adj SS and Adj MS,
        2 for F-Value, 3 for P-Value.
        """
        width = max(len("Source"), *(len(r.source) for r in self.rows))
        head = f"{'Source':<{width}}  {'DoF':>4}  {'Adj SS':>8}  {'Adj MS':>8}  {'F-Value':>8}  {'P-Value':>7}"
        lines = [head]
        for r in self.rows:
            lines.append(
                f"{r.source:<{width}}  {r.dof:>4d}  {_fmt(r.adj_ss, 4):>8}  {_fmt(r.adj_ms, 4):>8}"
                f"  {_fmt(r.f_value, 2):>8}  {_fmt(r.p_value, 3):>7}".rstrip()
            )
        lines.append("")
        lines.append(f"S          = {self.s:.6f}")
        lines.append(f"R-sq       = {100.0 * self.r2:.2f}%")
        lines.append(f"R-sq(adj)  = {100.0 * self.r2_adj:.2f}%")
        lines.append(f"R-sq(pred) = {100.0 * self.r2_pred:.2f}%")
        return "\n".join(lines)


# --------------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------------


def _plain(x: float | None) -> float | None:
    return None if x is None else float(x)


def _fmt(x: float | None, decimals: int) -> str:
    return "" if x is None else f"{x:.{decimals}f}"
