"""The paper's comparison report (``comparison.md``): alma against the published values."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pandas as pd

import alma
from alma.paper.printed import TABLE5_DECIMALS, _distance_to_printed


def _md_table(header: list[str], rows: list[list[Any]]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(x) for x in r) + " |" for r in rows]
    return out


def _table5_reason(r: Any) -> str:
    a = float(r.alpha_alma_exact)
    pub = float(r.alpha_published)
    dist = _distance_to_printed(a, pub, TABLE5_DECIMALS)
    lo, hi = float(r.alpha_lower), float(r.alpha_upper)
    certified = (
        f"alma's bounds [{lo:.7f}, {hi:.7f}] are certified (both exclude every value printing as {pub:.4f})"
        if not (pub - 5e-5 <= lo < pub + 5e-5 or pub - 5e-5 <= hi < pub + 5e-5)
        else f"alma's bounds [{lo:.7f}, {hi:.7f}] straddle the rounding boundary"
    )
    if dist < 2e-5:
        return (
            f"alma's α = {a:.6f} lies only {dist:.1e} beyond the values that print as {pub:.4f}: "
            f"a difference of the order of an LP solver's stopping tolerance (most likely the "
            f"original solver's; the geometry and the model give every other panel to 4 "
            f"decimals); {certified}"
        )
    return f"alma's α = {a:.6f} differs by {a - pub:+.6f}; {certified}; not explained"


def write_report(
    out: Path,
    t5cmp: pd.DataFrame,
    t2cmp: pd.DataFrame,
    r2: pd.DataFrame,
    mech: pd.DataFrame,
    mech_note: str,
    figs: list[Path],
    elapsed: float,
) -> Path:
    """Write ``comparison.md``: every comparison with the published values, and why they differ."""
    lines = _summary_lines(t5cmp, t2cmp, r2, mech, elapsed)
    lines += _table5_lines(t5cmp)
    lines += _table2_lines(t5cmp, t2cmp)
    lines += _table3_lines(r2)
    lines += _mechanism_lines(mech, mech_note)
    lines += _figure_lines(out, figs)
    path = out / "comparison.md"
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


def _summary_lines(
    t5cmp: pd.DataFrame, t2cmp: pd.DataFrame, r2: pd.DataFrame, mech: pd.DataFrame, elapsed: float
) -> list[str]:
    lines: list[str] = ["# alma against the published values of the paper", ""]
    n5 = int(t5cmp["match"].sum())
    lines.append(
        f"alma {getattr(alma, '__version__', '?')}, associative LP (Eq. 10), "
        f"{len(t5cmp)} panels; run time {elapsed:.0f} s."
    )
    lines.append("")
    lines.append("Every value is compared after rounding to the digits the paper prints.")
    lines.append("")
    lines.append("## Summary")
    lines.append("")
    n2 = int(t2cmp["match"].sum())
    r2p = r2[r2["published_percent"] != ""]
    lines += _md_table(
        ["Item", "Agree to the printed digits", "File"],
        [
            ["Table 5, collapse multipliers", f"{n5} / {len(t5cmp)}", "table5_comparison.csv"],
            ["Table 2, ANOVA cells", f"{n2} / {len(t2cmp)}", "table2_comparison.csv"],
            ["Table 3, R² and R²(pred)", f"{int(r2p['match'].astype(bool).sum())} / {len(r2p)}", "table3_r2.csv"],
            [
                "Figs. 11-15, printed α",
                f"{int((mech['match_printed'] == True).sum())} / "  # noqa: E712
                f"{int((mech['alpha_printed'] != '').sum())}",
                "mechanisms.csv",
            ],
            ["Figs. 11-15, α against Table 5", f"{int(mech['match_table5'].sum())} / {len(mech)}", "mechanisms.csv"],
        ],
    )
    lines.append("")
    return lines


def _table5_lines(t5cmp: pd.DataFrame) -> list[str]:
    lines: list[str] = []
    lines.append("## Table 5: differences larger than the rounding (4 decimals)")
    lines.append("")
    bad5 = t5cmp[~t5cmp["match"]]
    if bad5.empty:
        lines.append("None: all 108 collapse multipliers agree to the printed 4 decimals.")
    else:
        lines += _md_table(
            ["Panel", "Block", "Bond", "f", "Published", "alma", "alma (exact)", "Why"],
            [
                [
                    r.panel_ratio,
                    r.block_ratio,
                    r.bond,
                    f"{r.friction:.2f}",
                    r.alpha_published,
                    r.alpha_alma,
                    f"{float(r.alpha_alma_exact):.7f}",
                    _table5_reason(r),
                ]
                for r in bad5.itertuples()
            ],
        )
    lines.append("")

    return lines


def _table2_lines(t5cmp: pd.DataFrame, t2cmp: pd.DataFrame) -> list[str]:
    lines: list[str] = []
    n5 = int(t5cmp["match"].sum())
    bad5 = t5cmp[~t5cmp["match"]]
    lines.append("## Table 2: differences larger than the rounding (SS, MS 4 decimals; F 2; P 3)")
    lines.append("")
    n_unrounded = int((t2cmp["alma_unrounded"] == t2cmp["published"]).sum())
    n_t5 = int((t2cmp["from_table5"] == t2cmp["published"]).sum())
    lines.append(
        f"Table 2 is the ANOVA of Table 5 *as printed* (4 decimals): the ANOVA of the published "
        f"Table 5 gives {n_t5} / {len(t2cmp)} printed cells, whereas the ANOVA of unrounded "
        f"multipliers — alma's, which agree with Table 5 to 4 decimals in {n5} of 108 panels — "
        f"gives only {n_unrounded} / {len(t2cmp)}: with an error mean square of ~0.003, the "
        f"rounding of the 108 inputs (up to 5e-5 each) moves the last printed digit of several "
        f"SS and F values. alma's Table 5, rounded to the same 4 decimals, is therefore the input "
        f"compared here (column `alma`); the unrounded ANOVA is in column `alma_unrounded` of "
        f"table2_comparison.csv and in table2_alma.txt."
    )
    lines.append("")
    bad2 = t2cmp[~t2cmp["match"]]
    if bad2.empty:
        lines.append("No difference: every printed cell of Table 2 is reproduced from alma's own results.")
    else:
        rows = []
        for r in bad2.itertuples():
            if r.from_table5 == r.published and not bad5.empty:
                why = (
                    f"alma's Table 5, printed, differs from the published one only in the "
                    f"{len(bad5)} panel(s) listed above (4th decimal), and the ANOVA of the "
                    f"published Table 5 gives the printed value: the difference comes from "
                    f"those α values, not from the statistics"
                )
            elif r.from_table5 == r.published:
                why = "the ANOVA of the published Table 5 gives the printed value"
            else:
                why = "the ANOVA of the published Table 5 does not give the printed value either"
            rows.append([r.source, r.column, r.published, r.alma, f"{float(r.alma_exact):.6g}", r.from_table5, why])
        lines += _md_table(["Source", "Column", "Published", "alma", "alma (more digits)", "From Table 5", "Why"], rows)
    lines.append("")

    return lines


def _table3_lines(r2: pd.DataFrame) -> list[str]:
    lines: list[str] = []
    lines.append("## Table 3: R²")
    lines.append("")
    lines += _md_table(
        ["Quantity", "Published %", "alma %", "alma, unrounded α %", "From Table 5 %", "Agree"],
        [
            [
                r.quantity,
                r.published_percent or "(not printed)",
                r.alma_percent,
                r.alma_unrounded_percent,
                r.from_table5_percent,
                r.match,
            ]
            for r in r2.itertuples()
        ],
    )
    lines.append("")

    return lines


def _mechanism_lines(mech: pd.DataFrame, mech_note: str) -> list[str]:
    lines: list[str] = []
    lines.append("## Figures 11-15: collapse mechanisms")
    lines.append("")
    if mech_note:
        lines.append(f"**Note:** {mech_note}")
        lines.append("")
    rows = []
    for r in mech.itertuples():
        printed = f"{r.alpha_printed} ({r.printed_where})" if r.alpha_printed else "(not in the text)"
        rows.append(
            [
                f"{r.figure}{r.panel}",
                r.subcaption,
                f"{r.bond}, {r.panel_ratio}, {r.block_ratio}, f = {r.friction:.2f}",
                printed,
                r.alpha_table5,
                r.alpha_alma,
                r.mechanism_text or "-",
                r.mechanism_alma,
                f"![]({r.png})" if r.png else "-",
            ]
        )
    lines += _md_table(
        [
            "Fig.",
            "Sub-caption",
            "Panel",
            "Printed α",
            "Table 5",
            "alma",
            "Mechanism (text)",
            "Mechanism (alma)",
            "Figure",
        ],
        rows,
    )
    lines.append("")
    lines.append("### Differences in the figures")
    lines.append("")
    diffs = mech[(mech["match_printed"] == False) | (~mech["match_table5"])]  # noqa: E712
    if diffs.empty:
        lines.append("None.")
    for r in diffs.itertuples():
        what = []
        if r.match_printed is False:
            digits = len(r.alpha_printed.split(".")[-1])
            what.append(f"printed {r.alpha_printed}, alma {float(r.alpha_alma_exact):.{digits}f}")
        if not r.match_table5:
            what.append(f"Table 5 {r.alpha_table5}, alma {r.alpha_alma}")
        why = r.note or "not explained"
        lines.append(
            f"- **Fig. {r.figure}{r.panel}** ({r.bond}, {r.panel_ratio}, {r.block_ratio}, "
            f"f = {r.friction:.2f}): {'; '.join(what)} (exact {float(r.alpha_alma_exact):.6f}). {why}"
        )
    mech_diff = mech[(mech["mechanism_text"] != "") & (mech["mechanism_text"] != mech["mechanism_alma"])]
    if not mech_diff.empty:
        lines.append("")
        lines.append(
            "Mechanism class described in the text and alma's class (alma calls a mechanism "
            "`mixed` as soon as one joint slides while others hinge, and `rocking` only when "
            "no joint slides; the paper's words are qualitative):"
        )
        lines.append("")
        for r in mech_diff.itertuples():
            lines.append(f"- Fig. {r.figure}{r.panel}: text {r.mechanism_text}, alma {r.mechanism_alma}.")
    lines.append("")

    return lines


def _figure_lines(out: Path, figs: list[Path]) -> list[str]:
    lines: list[str] = []
    lines.append("## Figures 5-10")
    lines.append("")
    lines.append(
        "Drawn from alma's results (`_alma`) and from the published Table 5 (`_table5`), "
        "side by side; the published bitmaps are not part of the text version of the paper."
    )
    lines.append("")
    for p in figs:
        lines.append(f"- [{p.name}]({p.relative_to(out)})")
    lines.append("")
    return lines
