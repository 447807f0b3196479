"""The paper's 108 panels with a finite compressive strength (issue 34): α against the rigid α.

The rows come from the study itself (``alma doe``, resumable)::

    alma doe --out compressive_study --compressive-strength 0,2,5,10 --workers 1
    python -m benchmarks.compressive_panels compressive_study/results.csv --table docs/compressive_table.md

Level 0 is the panel with infinitely strong blocks; every other level puts σ_c (MPa) on every
joint, the ground joint included.  The markdown has one line per panel (α rigid, then α at each
strength with α / α rigid, marked when not ``optimal``) and a summary per strength: panels
certified, the least, mean and largest α / α rigid, and the solver's seconds.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from alma.study.doe import read_results

FACTORS = ["bond", "panel_ratio", "block_ratio", "friction"]
TITLE = "# The 108 paper panels with finite compressive strength\n"


def _ratios(df: pd.DataFrame) -> tuple[pd.DataFrame, list[float]]:
    """The associative rows with the rigid α of their panel beside them, and the strengths > 0."""
    rows = df[df["model"] == "associative"].copy()
    rigid = rows[rows["compressive_strength"] == 0].set_index(FACTORS)["alpha_c"].rename("rigid")
    rows = rows.join(rigid, on=FACTORS)
    rows["ratio"] = rows["alpha_c"] / rows["rigid"]
    strengths = sorted(s for s in rows["compressive_strength"].unique() if s > 0)
    return rows, strengths


def panel_table(df: pd.DataFrame) -> str:
    """Markdown: one line per panel, α rigid and α(σ_c) (α / α rigid) for each strength."""
    rows, strengths = _ratios(df)
    head = ["bond", "panel", "block", "f", "α rigid"] + [f"α, σ_c = {s:g} MPa (ratio)" for s in strengths]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for key, panel in rows.groupby(FACTORS, sort=True):
        by = panel.set_index("compressive_strength")
        rigid = by.loc[0.0]
        out = [
            key[0],
            key[1],
            key[2],
            f"{key[3]:g}",
            f"{rigid['alpha_c']:.6f}" + ("" if rigid["status"] == "optimal" else f" ({rigid['status']})"),
        ]
        for s in strengths:
            if s not in by.index:
                out.append("—")
                continue
            cell = by.loc[s]
            mark = "" if cell["status"] == "optimal" else f" ({cell['status']})"
            out.append(f"{cell['alpha_c']:.6f} ({cell['ratio']:.4f}){mark}")
        lines.append("| " + " | ".join(out) + " |")
    return "\n".join(lines) + "\n"


def summary_table(df: pd.DataFrame) -> str:
    """Markdown: per strength, the panels certified, α / α rigid (min, mean, max), solver seconds."""
    rows, strengths = _ratios(df)
    lines = [
        "| σ_c | certified (`optimal`) | α / α rigid: min | mean | max | solve + certificate, total s |",
        "|---|---|---|---|---|---|",
    ]
    for s in [0.0, *strengths]:
        part = rows[rows["compressive_strength"] == s]
        seconds = float((part["solve_s"] + part["certify_s"]).sum())
        certified = f"{int((part['status'] == 'optimal').sum())} of {len(part)}"
        if s == 0:
            lines.append(f"| rigid | {certified} | — | — | — | {seconds:.0f} |")
        else:
            r = part["ratio"]
            cells = f"{r.min():.4f} | {r.mean():.4f} | {r.max():.4f}"
            lines.append(f"| {s:g} MPa | {certified} | {cells} | {seconds:.0f} |")
    return "\n".join(lines) + "\n"


def document(df: pd.DataFrame) -> str:
    """The whole docs/compressive_table.md."""
    return (
        TITLE + "\nα (associative, certified unless marked) with infinitely strong blocks and with σ_c on "
        "every joint; in brackets α / α rigid.  Produced by `alma doe --compressive-strength 0,2,5,10` and "
        "`python -m benchmarks.compressive_panels RESULTS.csv --table docs/compressive_table.md` "
        "(docs/compressive.md).\n\n" + summary_table(df) + "\n" + panel_table(df)
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", metavar="RESULTS.csv", help="results.csv of `alma doe --compressive-strength`")
    parser.add_argument("--table", default=None, metavar="OUT.md", help="write the markdown here (default: stdout)")
    args = parser.parse_args()
    text = document(read_results(args.results))
    if args.table:
        Path(args.table).write_text(text)
    else:
        print(text, end="")


if __name__ == "__main__":
    main()
