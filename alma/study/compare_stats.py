"""The ANOVA of ``alma compare``: Table 2's model on α_NL, on the ratio and on α_LP."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from alma.stats import figures as F
from alma.stats.anova import anova, varying_factors
from alma.stats.effects import standardized_effects
from alma.study.compare_table import _LABELS, FACTOR_COLUMNS, SIGNIFICANCE, VERIFIED, CompareReport


@dataclass
class _Anova:
    response: str
    label: str
    result: Any = None
    effects: tuple = ()
    note: str = ""
    order: int = 2


def _balanced(table: pd.DataFrame) -> bool:
    levels = [table[c].nunique() for c in FACTOR_COLUMNS]
    return len(table) == int(np.prod(levels)) and not table.duplicated(list(FACTOR_COLUMNS)).any()


def _run_anova(table: pd.DataFrame, response: str, label: str, keep: np.ndarray | None = None, why: str = "") -> _Anova:
    """ANOVA of one response over the panels of a full factorial that have it (or ``keep``).

    Panels left out (no verified state, or not in ``keep``: ``why`` says) make the analysis
    unbalanced: adjusted (Type III) sums of squares and R²(pred) from the leverages, and a note
    with the count, since the panels that fail are not a random sample of the design."""

    out = _Anova(response, label)
    if not _balanced(table):
        out.note = "not computed: the panels do not form a full factorial"
        return out
    y = table[response].to_numpy(dtype=float)
    keep = np.isfinite(y) if keep is None else keep & np.isfinite(y)
    notes = []
    if not keep.all():
        notes.append(
            f"unbalanced: {int(keep.sum())} of {len(table)} panels, "
            + (why or f"the others have no {label} (no verified state)")
        )
        table, y = table[keep], y[keep]
    factors = varying_factors(table)
    if not factors:
        out.note = "not computed: every factor has a single level"
        return out
    if float(np.ptp(y)) <= 1e-12 * max(1.0, float(np.abs(y).max())):
        out.note = f"not computed: {label} is the same on every panel ({y[0]:.6g}), nothing to explain"
        return out
    for order in range(min(2, len(factors)), 0, -1):
        try:
            out.result = anova(table, response=response, order=order, factors=factors)
        except ValueError as exc:
            out.note = f"not computed: {exc}"
            continue
        out.order = order
        if order != 2:
            notes.append("main effects only: the two-way interactions are not estimable on these panels")
        if len(factors) < 4:
            fixed = [_LABELS[c] for c in FACTOR_COLUMNS if c not in factors]
            notes.append(f"fixed by the design: {', '.join(fixed)}")
        out.note = "; ".join(notes)
        out.effects = standardized_effects(out.result, SIGNIFICANCE)
        break
    return out


def _statistics(table: pd.DataFrame, figures_dir: Path, report: CompareReport) -> dict[str, Any]:
    valid_rows = np.isfinite(table["ratio"].to_numpy(dtype=float))
    # α_LP on the panels that have α_NL, so that both models are compared on the same panels
    # (the paper's full-design ANOVA of α_LP is `alma anova` / `alma paper`).
    stats = {
        "alpha_lp": _run_anova(
            table,
            "alpha_lp",
            "α_LP",
            keep=valid_rows,
            why="those with α_NL, so that both models are compared on the same panels",
        ),
        "alpha_nl": _run_anova(table, "alpha_nl", "α_NL"),
        "ratio": _run_anova(table, "ratio", "α_NL/α_LP"),
    }
    figures_dir.mkdir(parents=True, exist_ok=True)
    valid = table[valid_rows]
    if valid.empty:
        report.notes.append("statistics figures skipped: no panel has both multipliers")
        return stats
    try:
        report.figures.append(
            F.main_effects_plot(
                valid,
                figures_dir / "main_effects_alpha_nl.png",
                "alpha_nl",
                ylabel=r"mean $\alpha_{NL}$",
                title="Main effects plot for α_NL (non-associative)",
            )
        )
        report.figures.append(
            F.main_effects_plot(
                valid,
                figures_dir / "main_effects_ratio.png",
                "ratio",
                ylabel=r"mean $\alpha_{NL}/\alpha_{LP}$",
                title="Main effects plot for the ratio α_NL/α_LP",
            )
        )
        report.figures.append(
            F.main_effects_overlay(
                valid,
                figures_dir / "main_effects_lp_vs_nl.png",
                {"alpha_lp": "associative (LP)", "alpha_nl": "non-associative"},
                ylabel=r"mean $\alpha_c$",
                title="Main effects of both contact models",
            )
        )
        for key in ("alpha_nl", "ratio"):
            if stats[key].result is not None:
                report.figures.append(F.pareto_chart(stats[key].result, figures_dir / f"pareto_{key}.png"))
    except Exception as exc:  # a figure must not lose the report
        report.notes.append(f"a statistics figure failed: {type(exc).__name__}: {exc}")
    return stats


def start_times(table: pd.DataFrame) -> pd.DataFrame:
    """Time and outcome of each start of the non-associative searches, one row per start run.

    Read from the ``starts_nl`` column (JSON ``[[start, seconds, verified, α], ...]``; α, of the
    start's state or null, is missing in rows of an older alma and then NaN); panels solved by an
    alma that did not record the column contribute nothing.
    """
    rows = []
    for r in table.itertuples():
        text = getattr(r, "starts_nl", "") or ""
        try:
            runs = json.loads(text) if isinstance(text, str) and text.strip() else []
        except ValueError:
            runs = []
        for run in runs:
            if isinstance(run, list) and len(run) in (3, 4):
                alpha = run[3] if len(run) == 4 and run[3] is not None else math.nan
                rows.append(
                    {
                        "start": str(run[0]),
                        "time_s": float(run[1]),
                        "verified": bool(run[2]),
                        "alpha": float(alpha),
                        "won": str(run[0]) == r.start_nl,
                        "panel_converged": r.status_nl in VERIFIED,
                        "n_blocks": r.n_blocks,
                    }
                )
    return pd.DataFrame(rows, columns=["start", "time_s", "verified", "alpha", "won", "panel_converged", "n_blocks"])
