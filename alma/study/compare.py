"""Associative against non-associative collapse multipliers: ``alma compare``.

The report is built on the study of :mod:`alma.study`: the design (the paper's 108 panels or
a design file) is run with ``model="both"`` into ``OUT/results.csv`` — append-only, keyed,
resumable after a kill, parallel — and everything else is derived from that file:

- ``OUT/compare.csv``: one row per panel, α of the associative LP (``alpha_lp``) and of the
  non-associative search (``alpha_nl``), their ratio, the mechanism class and solve time of
  each, the winning start of the search and the α of its start from the LP mechanism;
- ``OUT/compare.md``: the summary (gaps, what the multi-start adds over the LP-started
  candidate, failures, times), the two-way ANOVA (as Table 2 of the paper) of α_NL and of the
  ratio α_NL/α_LP with R², R²(adj), R²(pred) and the Pareto ordering of the terms, a paragraph
  on the factors whose effect changes without dilatancy (computed from those numbers), and
  the table of all panels;
- ``OUT/figures/``: the two mechanisms side by side for the panels where the models differ
  most, and the main-effects plots of α_NL, of the ratio and of both α.

A rerun solves nothing already in ``results.csv``; only the report and the figures of panels
whose results changed are redrawn.
"""

from __future__ import annotations

import json
import math
import os
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

import alma
from alma.report.plot import MechanismPicture, plot_side_by_side
from alma.study.compare_report import write_report
from alma.study.compare_stats import _statistics, start_times
from alma.study.compare_table import COMPARE_COLUMNS, DIFFER_TOLERANCE, CompareReport, _panel_name, compare_table
from alma.study.doe import PAPER_DESIGN, RESULTS_FILE, Design, load_design, picture_path, read_results, run_doe

__all__ = ["COMPARE_COLUMNS", "CompareReport", "compare_table", "run_compare", "start_times", "write_report"]


def run_compare(
    out_dir: str | os.PathLike[str],
    design: Design | str | os.PathLike[str] | None = None,
    workers: int | None = None,
    effort: str | None = None,
    *,
    scheduler: Any = None,
    results_dir: str | os.PathLike[str] | None = None,
    progress: bool = True,
    retry_errors: bool = False,
    n_figures: int = 6,
    time_limit: float | None = None,
) -> CompareReport:
    """Run (or resume) the study with both models and write the comparison report.

    ``results_dir`` holds ``results.csv`` (default ``out_dir``; ``alma paper`` points it at
    its associative study so that only the non-associative rows are new). ``n_figures``
    panels with the largest α_NL/α_LP gap are drawn side by side.  ``time_limit`` (s) bounds
    each non-associative search (``None``: ``alma.solve``'s 60 s).
    """
    start = time.perf_counter()
    if design is None:
        design = PAPER_DESIGN
    elif not isinstance(design, Design):
        design = load_design(design)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rdir = Path(results_dir) if results_dir is not None else out
    before: set[str] = set()
    if (rdir / RESULTS_FILE).is_file():
        try:
            before = set(read_results(rdir / RESULTS_FILE)["key"])
        except Exception:  # run_doe reports what is wrong with the file
            before = set()
    results = run_doe(
        rdir,
        model="both",
        workers=workers,
        scheduler=scheduler,
        design=design,
        progress=progress,
        retry_errors=retry_errors,
        effort=effort,
        time_limit=time_limit,
    )
    solve_wall = time.perf_counter() - start
    resumed = int(results["key"].isin(before).sum())
    table = compare_table(results)
    csv_path = out / "compare.csv"
    table.to_csv(csv_path, index=False)

    report = CompareReport(out=out, table=table, csv=csv_path, markdown=out / "compare.md")
    report.failed = int((results["status"] == "error").sum())
    figures_dir = out / "figures"
    stats = _statistics(table, figures_dir, report)
    mech = _mechanism_figures(table, figures_dir, n_figures, effort, report, time_limit, rdir)
    wall = time.perf_counter() - start
    write_report(
        report,
        design,
        stats,
        mech,
        effort=effort,
        time_limit=time_limit,
        wall=wall,
        solve_wall=solve_wall,
        resumed=resumed,
        n_results=len(results),
        results_path=rdir / RESULTS_FILE,
    )
    return report


def _mechanism_figures(
    table: pd.DataFrame,
    folder: Path,
    n: int,
    effort: str | None,
    report: CompareReport,
    time_limit: float | None,
    results_dir: Path,
) -> pd.DataFrame:
    """Side-by-side mechanisms of the ``n`` panels with the smallest ratio (ratio < 1 only)."""
    valid = table[np.isfinite(table["ratio"].to_numpy(dtype=float))]
    differ = valid[valid["ratio"] < 1.0 - DIFFER_TOLERANCE]
    chosen = differ.sort_values(["ratio", "n_blocks"], kind="stable").head(max(0, n))
    if chosen.empty:
        return chosen.assign(png="")
    folder.mkdir(parents=True, exist_ok=True)
    index_path = folder / "mechanisms.json"
    try:
        index = json.loads(index_path.read_text()) if index_path.is_file() else {}
    except (OSError, json.JSONDecodeError):
        index = {}
    pngs: list[Path | None] = []
    for r in chosen.itertuples():
        name = (f"mechanisms_{r.bond}_panel{r.panel_ratio}_blocks{r.block_ratio}_f{float(r.friction):.2f}.png").replace(
            ":", "-"
        )
        path = folder / name
        stamp = f"{r.key_lp}|{r.key_nl}"
        if index.get(name) == stamp and path.is_file():
            pngs.append(path)  # same results as when it was drawn
            continue
        try:
            _draw_pair(r, path, effort, report, time_limit, results_dir)
        except Exception as exc:  # a failed drawing must not lose the report
            report.notes.append(f"mechanism figure of {_panel_name(r)} failed: {type(exc).__name__}: {exc}")
            pngs.append(None)
            continue
        index[name] = stamp
        pngs.append(path)
    index_path.write_text(json.dumps(index, indent=1, sort_keys=True))
    report.figures.extend(p for p in pngs if p is not None)
    return chosen.assign(png=[str(p.relative_to(folder.parent)) if p is not None else "" for p in pngs])


def _draw_pair(
    r: Any, path: Path, effort: str | None, report: CompareReport, time_limit: float | None, results_dir: Path
) -> None:

    scene = alma.paper_panel(r.bond, r.panel_ratio, r.block_ratio, float(r.friction))
    stored = _stored_pictures(r, results_dir)
    if stored is not None:
        # The mechanisms the study computed (a search with a time limit need not find the same
        # state twice, so solving again could draw another one).
        lp, nl = stored
        start = r.start_nl
    else:  # a study from before the pictures were kept (or a picture lost): solve again
        built = alma.build_model(scene, alma.find_joints(scene))
        lp = alma.solve(built, model="associative")
        kwargs: dict[str, Any] = {"effort": effort} if effort else {}
        if time_limit is not None:
            kwargs["time_limit"] = time_limit
        nl = alma.solve(built, model="nonassociative", **kwargs)
        start = nl.extra.get("start")
        for label, res, stored in (("α_LP", lp, r.alpha_lp), ("α_NL", nl, r.alpha_nl)):
            if not (math.isfinite(res.alpha) and abs(res.alpha - stored) <= 1e-7 * max(1.0, abs(stored))):
                report.notes.append(
                    f"{_panel_name(r)}: re-solved {label} = {res.alpha:.9g} differs from "
                    f"results.csv ({stored:.9g}); the figure shows the re-solved state"
                )
    ratio = nl.alpha / lp.alpha if lp.alpha > 0 else math.nan
    plot_side_by_side(
        scene,
        [lp, nl],
        path,
        titles=["associative (dilatant sliding)", f"non-associative, start {start}"],
        suptitle=f"{_panel_name(r)}: α_LP = {lp.alpha:.4f}, α_NL = {nl.alpha:.4f}, α_NL/α_LP = {ratio:.3f}",
    )


def _stored_pictures(r: Any, results_dir: Path) -> tuple[Any, Any] | None:
    """The kept mechanisms of a panel's two rows, or None unless both load and match the rows."""

    pictures = []
    for key, alpha, status in ((r.key_lp, r.alpha_lp, r.status_lp), (r.key_nl, r.alpha_nl, r.status_nl)):
        try:
            picture = MechanismPicture.load(picture_path(results_dir, str(key)))
        except Exception:  # missing or unreadable: the caller solves again
            return None
        same_alpha = (picture.alpha == alpha) or (math.isnan(picture.alpha) and math.isnan(float(alpha)))
        if not same_alpha or picture.status != status:  # a file left from another run
            return None
        pictures.append(picture)
    return pictures[0], pictures[1]
