"""The markdown tables of ``alma compare``'s report (``compare.md``): ANOVA, solve time by start, the
gap and start rows, the panels whose models differ, and every panel (α dimensionless, times in s).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from alma.stats.effects import pareto_reference
from alma.study.compare_stats import _Anova, start_times
from alma.study.compare_table import DIFFER_TOLERANCE, SIGNIFICANCE, _panel_name


def _f(x: Any, fmt: str = ".4f") -> str:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x) if x not in (None, "") else "–"
    return format(v, fmt) if math.isfinite(v) else "–"


def _md_table(header: list[str], rows: list[list[Any]]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(x) for x in r) + " |" for r in rows]
    return out


def _anova_lines(a: _Anova) -> list[str]:
    lines = [f"### ANOVA of {a.label}", ""]
    if a.result is None:
        lines += [f"ANOVA of {a.label} {a.note}.", ""]
        return lines
    res = a.result
    if a.note:
        lines += [f"Note: {a.note}.", ""]
    lines += _md_table(
        ["Source", "DoF", "Adj SS", "Adj MS", "F-Value", "P-Value"],
        [
            [r.source, r.dof, _f(r.adj_ss, ".6g"), _f(r.adj_ms, ".6g"), _f(r.f_value, ".2f"), _f(r.p_value, ".3f")]
            for r in res.rows
        ],
    )
    lines.append("")
    lines.append(
        f"R² = {100 * res.r2:.2f} %, R²(adj) = {100 * res.r2_adj:.2f} %, "
        f"R²(pred) = {100 * res.r2_pred:.2f} % (S = {res.s:.4g}, {res.n} panels, DFE = {res.dfe})."
    )
    lines.append("")

    ref = pareto_reference(res.dfe, SIGNIFICANCE)
    order = " > ".join(f"{e.source} ({e.effect:.2f}{'*' if e.significant else ''})" for e in a.effects)
    lines.append(
        f"Pareto ordering of the standardized effects (* = beyond the reference "
        f"t = {ref:.3f}, α = {SIGNIFICANCE}): {order}."
    )
    lines.append("")
    return lines


def _time_by_start(t: pd.DataFrame) -> list[str]:
    """The report's section on where the search time goes, per start."""
    runs = start_times(t)
    lines = ["## Where the search time goes", ""]
    if runs.empty:
        return [*lines, "No per-start times recorded (results written by an older alma).", ""]
    total = float(runs["time_s"].sum())
    lost = float(runs.loc[~runs["panel_converged"], "time_s"].sum())
    lines.append(
        f"{total:.0f} s of search over {t['starts_nl'].astype(bool).sum()} panels; "
        f"{lost:.0f} s ({100 * lost / max(total, 1e-300):.0f} %) of it on the panels that ended "
        "without a verified state. Each start in the order of the search; a start that spent "
        "its work budget without a verified state counts all of it."
    )
    lines.append("")
    table = []
    for name, g in runs.groupby("start", sort=False):
        table.append(
            [
                name,
                len(g),
                f"{g['time_s'].sum():.1f}",
                f"{g['time_s'].median():.2f}",
                int(g["verified"].sum()),
                int(g["won"].sum()),
                f"{g.loc[~g['panel_converged'], 'time_s'].sum():.1f}",
            ]
        )
    lines += _md_table(
        ["Start", "Panels run", "Time [s]", "Median [s]", "Verified", "Won", "Time on unconverged panels [s]"], table
    )
    lines.append("")
    return lines


def _gap_rows(t: pd.DataFrame) -> list[list[Any]]:
    """How far α_NL lies below α_LP over the panels."""
    valid = t[np.isfinite(t["ratio"].to_numpy(dtype=float))]
    gap = 1.0 - valid["ratio"]
    summary: list[list[Any]] = []
    summary.append(["Panels", len(t)])
    summary.append(["Panels with both α (ratio defined)", len(valid)])
    n_diff = int((valid["ratio"] < 1.0 - DIFFER_TOLERANCE).sum())
    summary.append([f"Panels where α_NL < α_LP (relative gap > {DIFFER_TOLERANCE:g})", n_diff])
    if not valid.empty:
        i = gap.idxmax()
        r = t.loc[i]
        summary.append(
            [
                "Largest gap 1 − α_NL/α_LP",
                f"{gap.max():.4f} ({_panel_name(r)}: α_LP = {r.alpha_lp:.4f}, α_NL = {r.alpha_nl:.4f})",
            ]
        )
        summary.append(["Median gap (all panels with both α)", f"{float(gap.median()):.4f}"])
        if n_diff:
            summary.append(
                [
                    "Median gap (panels where the models differ)",
                    f"{float(gap[valid['ratio'] < 1.0 - DIFFER_TOLERANCE].median()):.4f}",
                ]
            )
        summary.append(["Mean ratio α_NL/α_LP", f"{float(valid['ratio'].mean()):.4f}"])
    return summary


def _start_rows(t: pd.DataFrame) -> list[list[Any]]:
    """What the multi-start adds over the candidate started from the LP mechanism."""
    summary: list[list[Any]] = []
    has_lp = t[t["lp_start_verified"].isin(["True", "False"])]
    lp_ok = t[t["lp_start_verified"] == "True"]
    gains = lp_ok["lp_start_gain"].to_numpy(dtype=float)
    tol = 1e-9 * np.maximum(1.0, np.abs(lp_ok["alpha_nl"].to_numpy(dtype=float)))
    improved = lp_ok[gains > tol]
    summary.append(["LP-started candidate ('lp') present / verified", f"{len(has_lp)} / {len(lp_ok)}"])
    if len(improved):
        g = improved["lp_start_gain"]
        rel = g / improved["alpha_lp_start"]
        summary.append(
            [
                "Multi-start below the verified LP-started candidate",
                f"{len(improved)} panels; by up to {g.max():.4f} ({100 * rel.max():.2f} %), median {g.median():.4f}",
            ]
        )
    else:
        summary.append(["Multi-start below the verified LP-started candidate", f"0 of {len(lp_ok)} panels"])
    no_lp = t[(t["lp_start_verified"] != "True") & np.isfinite(t["alpha_nl"].to_numpy(dtype=float))]
    summary.append(["Panels solved only by the other starts (no verified 'lp' candidate)", len(no_lp)])
    starts = t["start_nl"].replace("", np.nan).dropna().value_counts()
    summary.append(["Winning starts", ", ".join(f"{s} × {n}" for s, n in starts.items()) or "–"])
    return summary


def _differ_lines(mech: pd.DataFrame) -> list[str]:
    lines: list[str] = []
    lines += ["## Where the two models differ most", ""]
    if mech.empty:
        lines.append(
            "The two models give the same α (within the relative tolerance "
            f"{DIFFER_TOLERANCE:g}) on every panel: no mechanism figure."
        )
    else:
        lines += _md_table(
            ["Panel", "α_LP", "α_NL", "Ratio", "Mechanism LP → NL", "Winning start", "Figure"],
            [
                [
                    _panel_name(r),
                    _f(r.alpha_lp),
                    _f(r.alpha_nl),
                    _f(r.ratio),
                    f"{r.mechanism_lp} → {r.mechanism_nl}",
                    r.start_nl,
                    f"[png]({r.png})" if r.png else "–",
                ]
                for r in mech.itertuples()
            ],
        )
    lines.append("")

    return lines


def _all_panel_lines(t: pd.DataFrame) -> list[str]:
    lines: list[str] = []
    lines += ["## All panels", ""]
    lines += _md_table(
        [
            "Panel",
            "Block",
            "Bond",
            "f",
            "Blocks",
            "α_LP",
            "α_NL",
            "Ratio",
            "Mech. LP",
            "Mech. NL",
            "t_LP [s]",
            "t_NL [s]",
            "Winning start",
            "α 'lp' start",
            "Status NL",
        ],
        [
            [
                r.panel_ratio,
                r.block_ratio,
                r.bond,
                f"{float(r.friction):.2f}",
                _f(r.n_blocks, ".0f"),
                _f(r.alpha_lp),
                _f(r.alpha_nl),
                _f(r.ratio),
                r.mechanism_lp,
                r.mechanism_nl,
                _f(r.time_lp_s, ".3f"),
                _f(r.time_nl_s, ".2f"),
                r.start_nl or "–",
                (_f(r.alpha_lp_start) + ("" if r.lp_start_verified == "True" else " (not verified)"))
                if r.lp_start_verified
                else "none",
                r.status_nl,
            ]
            for r in t.itertuples()
        ],
    )
    lines.append("")
    return lines
