"""The markdown report of ``alma compare`` (``compare.md``): its text; the tables are
:mod:`alma.study.compare_report_tables`."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

import alma
from alma.study.compare_report_tables import (
    _all_panel_lines,
    _anova_lines,
    _differ_lines,
    _f,
    _gap_rows,
    _md_table,
    _start_rows,
    _time_by_start,
)
from alma.study.compare_stats import _Anova
from alma.study.compare_table import (
    _LABELS,
    BOUND_TOLERANCE,
    FACTOR_COLUMNS,
    SIGNIFICANCE,
    VERIFIED,
    CompareReport,
    _panel_name,
)
from alma.study.design import Design


def _level_means(table: pd.DataFrame, col: str, response: str) -> pd.Series:
    return table.groupby(col, sort=False)[response].mean()


def _share(a: _Anova, name: str) -> float:
    """The term's share of the total adjusted sum of squares (NaN when not estimable)."""
    if a.result is None:
        return math.nan
    try:
        row = a.result.row(name)
    except KeyError:
        return math.nan
    total = a.result.row("Total").adj_ss
    return row.adj_ss / total if total > 0 else math.nan


def _rank(a: _Anova, name: str) -> int | None:
    names = [e.source for e in a.effects]
    return names.index(name) + 1 if name in names else None


def _p_value(a: _Anova, name: str) -> float:
    if a.result is None:
        return math.nan
    try:
        return float(a.result.row(name).p_value)
    except KeyError:
        return math.nan


def _factor_change(valid: pd.DataFrame, col: str, stats: dict[str, _Anova]) -> tuple[list[str], str]:
    """Why factor ``col`` changes its effect without dilatancy (empty: it does not), and its figures."""
    a_lp, a_nl, a_ratio = stats["alpha_lp"], stats["alpha_nl"], stats["ratio"]
    name = _LABELS[col]
    m_lp, m_nl = _level_means(valid, col, "alpha_lp"), _level_means(valid, col, "alpha_nl")
    m_r = _level_means(valid, col, "ratio")
    order_lp = [str(v) for v in m_lp.sort_values(ascending=False, kind="stable").index]
    order_nl = [str(v) for v in m_nl.sort_values(ascending=False, kind="stable").index]
    p_ratio = _p_value(a_ratio, name)
    reasons = []
    if math.isfinite(p_ratio) and p_ratio < SIGNIFICANCE:
        lo, hi = m_r.idxmin(), m_r.idxmax()
        reasons.append(
            f"it is significant for the ratio (p = {p_ratio:.3g}; mean ratio "
            f"{m_r[lo]:.3f} at {_lvl(col, lo)} against {m_r[hi]:.3f} at {_lvl(col, hi)})"
        )
    sig_lp = math.isfinite(_p_value(a_lp, name)) and _p_value(a_lp, name) < SIGNIFICANCE
    sig_nl = math.isfinite(_p_value(a_nl, name)) and _p_value(a_nl, name) < SIGNIFICANCE
    tested = a_lp.result is not None and a_nl.result is not None
    # The order of the level means of a factor without significant effect is noise.
    if order_lp != order_nl and (sig_lp or sig_nl or not tested):
        reasons.append(
            f"the order of its level means changes ({' > '.join(_lvl(col, v) for v in order_lp)} "
            f"with dilatancy, {' > '.join(_lvl(col, v) for v in order_nl)} without"
            + ("" if tested else "; no ANOVA to test it")
            + ")"
        )
    if tested and sig_lp != sig_nl:
        reasons.append("it is significant for α " + ("with dilatancy only" if sig_lp else "without dilatancy only"))
    detail = (
        f"effect range (largest minus smallest level mean) {float(m_lp.max() - m_lp.min()):.4f} → "
        f"{float(m_nl.max() - m_nl.min()):.4f}"
    )
    s_lp, s_nl = _share(a_lp, name), _share(a_nl, name)
    if math.isfinite(s_lp) and math.isfinite(s_nl):
        detail += f", share of the total sum of squares {100 * s_lp:.1f} % → {100 * s_nl:.1f} %"
    r_lp, r_nl = _rank(a_lp, name), _rank(a_nl, name)
    if r_lp and r_nl:
        detail += f", Pareto rank {r_lp} → {r_nl}"
    return reasons, detail


def _changes_paragraph(table: pd.DataFrame, stats: dict[str, _Anova]) -> list[str]:
    """Which factors change their effect without dilatancy: from the ANOVAs and level means."""
    a_ratio = stats["ratio"]
    valid = table[np.isfinite(table["ratio"].to_numpy(dtype=float))]
    if valid.empty:
        return ["No panel has both multipliers: nothing to compare."]
    factors = [c for c in FACTOR_COLUMNS if valid[c].nunique() >= 2]
    if not factors:
        return ["Every factor has a single level in this design: no factor effect to compare."]
    changed, unchanged = [], []
    for col in factors:
        reasons, detail = _factor_change(valid, col, stats)
        if reasons:
            changed.append(f"**{_LABELS[col]}** ({detail}): {'; '.join(reasons)}")
        else:
            unchanged.append(f"{_LABELS[col]} ({detail})")
    text = (
        "Without dilatancy, a factor changes its effect when it moves the ratio α_NL/α_LP (a "
        "factor without effect on the ratio scales both multipliers alike), when the order of "
        "its level means changes while it is significant (p < 0.05) in either model, or when it "
        "is significant in one model only. "
    )
    if changed:
        text += "By these tests the effect changes for " + "; ".join(changed) + ". "
    else:
        text += "By these tests no factor changes its effect. "
    if unchanged:
        text += "It is unchanged for " + "; ".join(unchanged) + " (values: with dilatancy → without). "
    inter = [e for e in a_ratio.effects if "*" in e.source and e.significant]
    if inter:
        text += (
            "Significant interactions for the ratio: "
            + ", ".join(f"{e.source} (p = {e.p_value:.3g})" for e in inter)
            + "."
        )
    elif a_ratio.result is not None and a_ratio.order >= 2:
        text += "No two-way interaction is significant for the ratio."
    return [text.strip()]


def _lvl(col: str, v: Any) -> str:
    return f"f = {float(v):.2f}" if col == "friction" else str(v)


def write_report(
    report: CompareReport,
    design: Design,
    stats: dict[str, Any],
    mech: pd.DataFrame,
    *,
    effort: str | None,
    wall: float,
    solve_wall: float,
    resumed: int,
    n_results: int,
    time_limit: float | None = None,
    results_path: Path,
) -> Path:
    """Write ``compare.md``: header, summary, times by start, where the models differ, the
    ANOVA, every panel."""
    t = report.table
    lines = _header_lines(report, design, effort, time_limit, results_path, n_results, resumed)
    lines += _summary_lines(report, wall, solve_wall)
    lines += _time_by_start(t)
    lines += _differ_lines(mech)
    lines += _anova_section(t, stats)
    lines += _all_panel_lines(t)
    report.markdown.write_text("\n".join(lines), encoding="utf-8")
    return report.markdown


def _header_lines(
    report: CompareReport,
    design: Design,
    effort: str | None,
    time_limit: float | None,
    results_path: Path,
    n_results: int,
    resumed: int,
) -> list[str]:
    t, out = report.table, report.out
    limit = f"time limit {time_limit:g} s per search" if time_limit is not None else "no time limit (work budgets)"
    lines = ["# Associative against non-associative collapse multipliers", ""]
    lines.append(
        f"alma {getattr(alma, '__version__', '?')}; {len(t)} panels "
        f"({' × '.join(str(len(getattr(design, c))) for c in FACTOR_COLUMNS)} design: "
        + "; ".join(
            f"{c} {', '.join(_lvl(c, v) if c == 'friction' else str(v) for v in getattr(design, c))}"
            for c in FACTOR_COLUMNS
        )
        + f"); non-associative effort {effort or 'auto'} (auto: thorough up to 200 blocks, fast above), "
        f"{limit}. "
        f"Results: `{_rel(results_path, out)}` ({n_results} rows, {resumed} resumed from an earlier run); "
        f"table: `compare.csv`."
    )
    lines.append("")
    lines.append(
        "α_LP: the associative LP (dilatant sliding, certified). α_NL: the lowest verified "
        "collapse state of the non-associative search (an upper bound of the frictional "
        "collapse multiplier, not proven global). Ratio = α_NL/α_LP ≤ 1."
    )
    lines.append("")

    return lines


def _summary_lines(report: CompareReport, wall: float, solve_wall: float) -> list[str]:
    t = report.table
    lines: list[str] = ["## Summary", ""]
    summary: list[list[Any]] = []
    summary += _gap_rows(t)
    above = t[(t["alpha_nl"] > t["alpha_lp"] + BOUND_TOLERANCE)]
    summary.append([f"Panels with α_NL > α_LP + {BOUND_TOLERANCE:g} (must be 0)", len(above)])
    summary += _start_rows(t)
    errors = t[(t["status_lp"] == "error") | (t["status_nl"] == "error")]
    summary.append(["Failures (status error)", len(errors)])
    unverified = t[t["status_nl"] == "not_converged"]
    summary.append(["Non-associative not converged (no verified state)", len(unverified)])
    summary.append(
        [
            "Non-associative verified states: feasible / optimal (proven minimum)",
            f"{int((t['status_nl'] == 'feasible').sum())} / {int((t['status_nl'] == 'optimal').sum())}",
        ]
    )
    other = t[~t["status_nl"].isin([*VERIFIED, "not_converged", "error"])]
    if len(other):
        summary.append(
            [
                "Other non-associative statuses",
                ", ".join(f"{s} × {n}" for s, n in other["status_nl"].value_counts().items()),
            ]
        )
    lp_not_opt = t[t["status_lp"] != "optimal"]
    if len(lp_not_opt):
        summary.append(
            [
                "Associative status not optimal",
                ", ".join(f"{s} × {n}" for s, n in lp_not_opt["status_lp"].value_counts().items()),
            ]
        )
    summary.append(["Mechanism class changes (LP → NL)", _class_changes(t)])
    tl, tn = t["time_lp_s"].to_numpy(dtype=float), t["time_nl_s"].to_numpy(dtype=float)
    summary.append(
        [
            "Solve time, associative LP (sum / median / max per panel)",
            f"{np.nansum(tl):.1f} s / {_f(np.nanmedian(tl) if np.isfinite(tl).any() else math.nan, '.3f')} s / "
            f"{_f(np.nanmax(tl) if np.isfinite(tl).any() else math.nan, '.3f')} s",
        ]
    )
    summary.append(
        [
            "Solve time, non-associative search (sum / median / max per panel)",
            f"{np.nansum(tn):.1f} s / {_f(np.nanmedian(tn) if np.isfinite(tn).any() else math.nan, '.3f')} s / "
            f"{_f(np.nanmax(tn) if np.isfinite(tn).any() else math.nan, '.3f')} s",
        ]
    )
    summary.append(
        [
            "Wall time of this run (study / report with figures)",
            f"{wall:.1f} s ({solve_wall:.1f} s / {wall - solve_wall:.1f} s)",
        ]
    )
    lines += _md_table(["Item", "Value"], summary)
    lines.append("")
    for r in errors.itertuples():
        lines.append(f"- error: {_panel_name(r)}: {r.message_nl or 'associative row failed'}")
    for r in unverified.itertuples():
        lines.append(f"- not converged: {_panel_name(r)}: {r.message_nl}")
    for r in above.itertuples():
        lines.append(f"- **α_NL > α_LP**: {_panel_name(r)}: α_LP = {r.alpha_lp:.9f}, α_NL = {r.alpha_nl:.9f}")
    if report.notes:
        lines.append("")
        lines += [f"- note: {n}" for n in report.notes]
    lines.append("")

    return lines


def _anova_section(t: pd.DataFrame, stats: dict[str, Any]) -> list[str]:
    lines: list[str] = []
    lines += [
        "## Beyond the paper: ANOVA without dilatancy",
        "",
        "The two-way ANOVA of Table 2 of the paper (main effects and two-way interactions, "
        "adjusted sums of squares) on the non-associative α and on the ratio α_NL/α_LP; the "
        "ANOVA of α_LP of the same panels is given for reference.",
        "",
    ]
    for key in ("alpha_nl", "ratio", "alpha_lp"):
        lines += _anova_lines(stats[key])
    lines += ["### Which factors change their effect when sliding has no dilatancy", ""]
    lines += _changes_paragraph(t, stats)
    lines.append("")
    lines += [
        "Main effects plots (as Fig. 5 of the paper): `figures/main_effects_alpha_nl.png`, "
        "`figures/main_effects_ratio.png`, both models on the same axes "
        "`figures/main_effects_lp_vs_nl.png`; Pareto charts `figures/pareto_alpha_nl.png`, "
        "`figures/pareto_ratio.png` (when the ANOVA is defined).",
        "",
    ]

    return lines


def _class_changes(t: pd.DataFrame) -> str:
    both = t[(t["mechanism_lp"] != "") & (t["mechanism_nl"] != "")]
    changed = both[both["mechanism_lp"] != both["mechanism_nl"]]
    if changed.empty:
        return f"none ({len(both)} panels with both classes)"
    counts = changed.groupby(["mechanism_lp", "mechanism_nl"]).size()
    return f"{len(changed)} of {len(both)}: " + ", ".join(f"{a} → {b} × {n}" for (a, b), n in counts.items())


def _rel(path: Path, base: Path) -> str:
    try:
        return str(Path(os.path.relpath(path, base)))
    except ValueError:
        return str(path)
