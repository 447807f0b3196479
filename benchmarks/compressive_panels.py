"""The paper's 108 panels with a finite compressive strength (issue 34): α against the rigid α.

For every panel of Table 1 (4 bonds × 3 panel ratios × 3 block ratios × 3 frictions) the
associative α with infinitely strong blocks and with σ_c = 2, 5, 10 MPa on every joint (the
ground joint included), each certified (status, bounds).  Rows are appended to a CSV as they are
computed, so an interrupted run resumes; ``--table`` writes the markdown table of docs/compressive.md.

    python benchmarks/compressive_panels.py [--out benchmarks/results/compressive_panels.csv]
                                            [--frictions 0.27,0.6,1.0] [--table docs/compressive_table.md]
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import sys
import time
from pathlib import Path

import alma
from alma.geometry.contacts import find_joints
from alma.geometry.panels import BLOCK_LENGTHS, BONDS, FRICTIONS, PANEL_HEIGHTS, paper_panel

STRENGTHS = (2.0, 5.0, 10.0)  # MPa
FIELDS = ("bond", "panel_ratio", "block_ratio", "friction", "sigma_mpa", "status", "alpha", "lower", "upper",
          "solve_s")


def run(out: Path, frictions: tuple[float, ...]) -> None:
    """Solve every panel missing from ``out`` and append its rows."""
    done = set()
    if out.exists():
        with out.open() as f:
            done = {(r["bond"], r["panel_ratio"], r["block_ratio"], float(r["friction"])) for r in csv.DictReader(f)}
    out.parent.mkdir(parents=True, exist_ok=True)
    new = not out.exists()
    with out.open("a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        if new:
            writer.writeheader()
        for bond in BONDS:
            for ratio in PANEL_HEIGHTS:
                for block in BLOCK_LENGTHS:
                    for friction in frictions:
                        if (bond, ratio, block, friction) in done:
                            continue
                        scene = paper_panel(bond, ratio, block, friction)
                        joints = find_joints(scene)
                        for sigma in (None,) + STRENGTHS:
                            s = scene if sigma is None else dataclasses.replace(scene, compressive_strength=sigma)
                            t0 = time.perf_counter()
                            r = alma.solve(s, joints=joints)
                            writer.writerow({"bond": bond, "panel_ratio": ratio, "block_ratio": block,
                                             "friction": friction, "sigma_mpa": "" if sigma is None else sigma,
                                             "status": str(r.status), "alpha": r.alpha, "lower": r.bounds.lower,
                                             "upper": r.bounds.upper, "solve_s": time.perf_counter() - t0})
                        f.flush()
                        print(f"{bond} {ratio} {block} {friction}", file=sys.stderr)


def table(rows: list[dict]) -> str:
    """Markdown: one line per panel, α rigid and α(σ_c)/α rigid for each strength."""
    by = {}
    for r in rows:
        by.setdefault((r["bond"], r["panel_ratio"], r["block_ratio"], float(r["friction"])), {})[r["sigma_mpa"]] = r
    head = ["bond", "panel", "block", "f", "α rigid"] + [f"α, σ_c = {s:g} MPa (ratio)" for s in STRENGTHS]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for key in sorted(by):
        cells = by[key]
        rigid = float(cells[""]["alpha"])
        out = [key[0], key[1], key[2], f"{key[3]:g}", f"{rigid:.6f}"]
        for s in STRENGTHS:
            c = cells.get(str(s))
            if c is None:
                out.append("—")
                continue
            mark = "" if c["status"] == "optimal" else f" ({c['status']})"
            out.append(f"{float(c['alpha']):.6f} ({float(c['alpha']) / rigid:.4f}){mark}")
        lines.append("| " + " | ".join(out) + " |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="benchmarks/results/compressive_panels.csv")
    parser.add_argument("--frictions", default=",".join(f"{f:g}" for f in FRICTIONS))
    parser.add_argument("--table", default=None, metavar="OUT.md", help="write the markdown table of the CSV")
    args = parser.parse_args()
    out = Path(args.out)
    run(out, tuple(float(x) for x in args.frictions.split(",")))
    if args.table:
        with out.open() as f:
            Path(args.table).write_text(table(list(csv.DictReader(f))))


if __name__ == "__main__":
    main()
