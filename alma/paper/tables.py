"""Regenerate the paper's tables and figures with alma, next to the published values.

    alma paper --out DIR [--published DIR]      (or: python paper_tables/make_paper.py --out DIR)

Runs the 108-panel associative study (resumable: ``DIR/doe/results.csv``) and writes

- ``table5_comparison.csv`` — Table 5, the 108 collapse multipliers: published, alma, the
  difference, and whether they agree to the printed 4 decimals;
- ``table2_comparison.csv`` — Table 2, every printed cell: published, alma (printed digits and
  exact), the same ANOVA of the published Table 5, and whether they agree;
- ``table3_r2.csv`` — the R² figures of Table 3 (R², R²(pred); R²(adj) for information);
- ``figures/fig05_…png`` … ``fig10_…png`` — Figures 5–10 from alma's results (``_alma``) and
  from the published Table 5 (``_table5``), drawn by :mod:`alma.stats.figures`;
- ``figures/fig11a.png`` … ``fig15d.png`` — the collapse mechanisms of Figures 11–15 (same
  panels and captions, α in the title), drawn by ``alma.report.plot.plot_mechanism``, and
  ``mechanisms.csv`` with the α printed in the paper, Table 5's and alma's;
- ``comparison.md`` — every difference larger than the printed rounding, and why;
- with ``--nonassociative`` (``alma paper --nonassociative``): ``nonassociative/compare.md``,
  ``compare.csv`` and ``figures/`` — the report of ``alma compare`` on the same 108 panels,
  beyond the paper (the non-associative rows are added to ``doe/results.csv``, resumable).

The published values live in ``paper_tables/data/`` of the repository, never in the alma
package: :func:`make_paper` is given that folder (``published``).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import pandas as pd

import alma
from alma.paper.printed import TABLE5_DECIMALS, _printed
from alma.paper.report import write_report
from alma.report.plot import plot_mechanism
from alma.stats import figures as F
from alma.stats.anova import anova, load_results
from alma.study.compare import run_compare
from alma.study.doe import run_doe

#: The files of the published tables that ``published`` must hold.
PUBLISHED_FILES = (
    "table5_collapse_multipliers.csv",
    "table2_anova.csv",
    "table3_r2.csv",
    "figure_captions.csv",
    "figure_titles.csv",
)
FACTORS = ["panel_ratio", "block_ratio", "bond", "friction"]
#: Figs. 11-15 show one crisp mechanism of each optimal face, its macro-blocks and its crack.
CRISP = alma.Settings(associative=alma.AssociativeSettings(crisp_mechanism=True))
#: Table 2 columns and the decimals the paper prints.
TABLE2_DECIMALS = {"adj_ss": 4, "adj_ms": 4, "f_value": 2, "p_value": 3}


def _key(df: pd.DataFrame) -> pd.Series:
    return (
        df["panel_ratio"].astype(str)
        + "|"
        + df["block_ratio"].astype(str)
        + "|"
        + df["bond"].astype(str).str.lower()
        + "|"
        + df["friction"].astype(float).map(lambda f: f"{f:.2f}")
    )


# ------------------------------------------------------------------------------------------
# Table 5
# ------------------------------------------------------------------------------------------


def table5_comparison(ours: pd.DataFrame, published: pd.DataFrame) -> pd.DataFrame:
    pub = published.copy()
    pub["bond"] = pub["bond"].str.lower()
    mine = ours.set_index(_key(ours))
    rows = []
    for _, p in pub.iterrows():
        k = _key(p.to_frame().T).iloc[0]
        if k not in mine.index:
            raise RuntimeError(f"alma has no result for panel {k}")
        o = mine.loc[k]
        a = float(o["alpha_c"])
        rows.append(
            {
                "panel_ratio": p["panel_ratio"],
                "block_ratio": p["block_ratio"],
                "bond": p["bond"],
                "friction": float(p["friction"]),
                "alpha_published": _printed(float(p["alpha_c"]), TABLE5_DECIMALS),
                "alpha_alma": _printed(a, TABLE5_DECIMALS),
                "alpha_alma_exact": repr(a),
                "difference": a - float(p["alpha_c"]),
                "match": _printed(a, TABLE5_DECIMALS) == _printed(float(p["alpha_c"]), TABLE5_DECIMALS),
                "alpha_lower": float(o["alpha_lower"]),
                "alpha_upper": float(o["alpha_upper"]),
                "status": o["status"],
                "mechanism_class": o["mechanism_class"],
            }
        )
    return pd.DataFrame(rows)


# ------------------------------------------------------------------------------------------
# Table 2 and Table 3
# ------------------------------------------------------------------------------------------


def table2_comparison(ours_anova: Any, exact_anova: Any, t5_anova: Any, published: pd.DataFrame) -> pd.DataFrame:
    """Every printed cell of Table 2.

    ``alma``: ANOVA of alma's α rounded to the 4 decimals of Table 5 — the paper's input (its
    Table 2 is the ANOVA of the printed Table 5 values); ``alma_exact``: that number unrounded;
    ``alma_unrounded``: the ANOVA of alma's unrounded α, printed; ``from_table5``: the ANOVA of
    the published Table 5.
    """
    rows = []
    for _, p in published.iterrows():
        src = p["source"]
        mine, raw, theirs = ours_anova.row(src), exact_anova.row(src), t5_anova.row(src)
        rows.append(
            {
                "source": src,
                "column": "dof",
                "published": str(int(p["dof"])),
                "alma": str(mine.dof),
                "alma_exact": str(mine.dof),
                "alma_unrounded": str(raw.dof),
                "from_table5": str(theirs.dof),
                "match": int(p["dof"]) == mine.dof,
            }
        )
        for col, dec in TABLE2_DECIMALS.items():
            want = p[col]
            got = getattr(mine, col)
            want_s = "" if pd.isna(want) else _printed(float(want), dec)
            rows.append(
                {
                    "source": src,
                    "column": col,
                    "published": want_s,
                    "alma": _printed(got, dec),
                    "alma_exact": "" if got is None else repr(float(got)),
                    "alma_unrounded": _printed(getattr(raw, col), dec),
                    "from_table5": _printed(getattr(theirs, col), dec),
                    "match": want_s == _printed(got, dec),
                }
            )
    return pd.DataFrame(rows)


def table3_r2(ours_anova: Any, exact_anova: Any, t5_anova: Any, published: dict[str, float]) -> pd.DataFrame:
    """R², R²(adj), R²(pred) of alma's ANOVA beside the ``published`` percentages (R²(adj) is not printed)."""
    rows = []
    for name, attr in (("R2", "r2"), ("R2_adj", "r2_adj"), ("R2_pred", "r2_pred")):
        mine = 100.0 * getattr(ours_anova, attr)
        pub = published.get(name)
        rows.append(
            {
                "quantity": name,
                "published_percent": "" if pub is None else f"{pub:.2f}",
                "alma_percent": f"{mine:.2f}",
                "alma_exact": repr(mine),
                "alma_unrounded_percent": f"{100.0 * getattr(exact_anova, attr):.2f}",
                "from_table5_percent": f"{100.0 * getattr(t5_anova, attr):.2f}",
                "match": "" if pub is None else f"{mine:.2f}" == f"{pub:.2f}",
            }
        )
    return pd.DataFrame(rows)


# ------------------------------------------------------------------------------------------
# Figures
# ------------------------------------------------------------------------------------------


def statistics_figures(
    ours: pd.DataFrame, ours_anova: Any, t5: pd.DataFrame, t5_anova: Any, folder: Path
) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for tag, df, res in (("alma", ours, ours_anova), ("table5", t5, t5_anova)):
        written.append(F.main_effects_plot(df, folder / f"fig05_main_effects_{tag}.png"))
        written.append(F.interaction_plot_matrix(df, folder / f"fig06_interactions_{tag}.png"))
        written.append(F.pareto_chart(res, folder / f"fig07_pareto_{tag}.png"))
        written.append(F.residual_plots(df, res, folder / f"fig08_residuals_{tag}.png"))
        written.extend(
            F.scale_factor_plots(
                df, folder / f"fig09_scale_H_over_b_{tag}.png", folder / f"fig10_scale_B_over_b_{tag}.png"
            )
        )
    return [Path(p) for p in written]


def mechanism_figures(
    captions: pd.DataFrame, t5cmp: pd.DataFrame, titles: dict[int, str], folder: Path
) -> tuple[pd.DataFrame, str]:
    """Solve the panels of Figs. 11-15 and plot them; rows for mechanisms.csv."""
    note = ""
    folder.mkdir(parents=True, exist_ok=True)
    t5 = t5cmp.set_index(_key(t5cmp))
    rows = []
    for _, c in captions.iterrows():
        fig, sub = int(c["figure"]), str(c["panel"])
        friction = float(c["friction"])
        scene = alma.paper_panel(c["bond"], c["panel_ratio"], c["block_ratio"], friction)
        result = alma.solve(scene, model="associative", settings=CRISP)
        a = float(result.alpha)
        k = f"{c['panel_ratio']}|{c['block_ratio']}|{c['bond']}|{friction:.2f}"
        t5row = t5.loc[k]
        printed = c["alpha_printed"]
        dec = None if pd.isna(c["decimals"]) else int(c["decimals"])
        printed_s = "" if pd.isna(printed) else f"{float(printed):.{dec}f}"
        # plot_mechanism adds "α = ... (model, mechanism class)" below this title.
        title = (
            f"Fig. {fig}{sub}: {c['subcaption']} ({c['bond']}, panel {c['panel_ratio']}, "
            f"blocks {c['block_ratio']}, f = {friction:.2f})"
        )
        png = ""
        path = folder / f"fig{fig}{sub}.png"
        try:
            plot_mechanism(scene, result, path, title=title)
            png = str(path.relative_to(folder.parent))
        except Exception as exc:  # a plotting failure must not lose the comparison
            note = f"mechanism figure {fig}{sub} failed: {type(exc).__name__}: {exc}"
        rows.append(
            {
                "figure": fig,
                "panel": sub,
                "bond": c["bond"],
                "panel_ratio": c["panel_ratio"],
                "block_ratio": c["block_ratio"],
                "friction": friction,
                "caption": titles.get(fig, ""),
                "subcaption": c["subcaption"],
                "alpha_printed": printed_s,
                "printed_where": "" if pd.isna(c["printed_where"]) else c["printed_where"],
                "alpha_table5": t5row["alpha_published"],
                "alpha_alma": f"{a:.4f}",
                "alpha_alma_exact": repr(a),
                "match_printed": "" if not printed_s else f"{a:.{dec}f}" == printed_s,
                "match_table5": f"{a:.4f}" == t5row["alpha_published"],
                "mechanism_text": "" if pd.isna(c["mechanism_text"]) else c["mechanism_text"],
                "mechanism_alma": result.mechanism_class,
                "note": "" if pd.isna(c["note"]) else c["note"],
                "png": png,
            }
        )
    return pd.DataFrame(rows), note


# ------------------------------------------------------------------------------------------
# Driver
# ------------------------------------------------------------------------------------------


def _tables(ours: pd.DataFrame, t5: pd.DataFrame, DATA: Path, out: Path) -> tuple:
    """Tables 5, 2 and 3 of alma beside the published ones, written into ``out``."""
    t5_raw = pd.read_csv(DATA / "table5_collapse_multipliers.csv", dtype={"panel_ratio": str, "block_ratio": str})
    t2 = pd.read_csv(DATA / "table2_anova.csv", dtype={"source": str})
    t5cmp = table5_comparison(ours, t5_raw)
    t5cmp.to_csv(out / "table5_comparison.csv", index=False)

    # alma's values in Table 5 order (the observation order of Figure 8).
    mine = ours.set_index(_key(ours)).loc[_key(t5).to_numpy()].reset_index(drop=True)
    ours_t5order = t5[FACTORS].copy()
    ours_t5order["alpha_c"] = mine["alpha_c"].to_numpy(dtype=float)
    ours_t5order.to_csv(out / "alma_table5.csv", index=False, float_format="%.10g")
    # Table 2 is the ANOVA of Table 5 as printed (4 decimals): alma's Table 5, printed, is the
    # input that corresponds; the ANOVA of the unrounded values is reported beside it.
    ours_printed = ours_t5order.copy()
    ours_printed["alpha_c"] = [float(f"{a:.{TABLE5_DECIMALS}f}") for a in ours_t5order["alpha_c"]]
    ours_anova = anova(ours_printed, order=2)
    exact_anova = anova(ours_t5order, order=2)
    t5_anova = anova(t5, order=2)
    t2cmp = table2_comparison(ours_anova, exact_anova, t5_anova, t2)
    t2cmp.to_csv(out / "table2_comparison.csv", index=False)
    r2_published = {r.quantity: float(r.published_percent) for r in pd.read_csv(DATA / "table3_r2.csv").itertuples()}
    r2 = table3_r2(ours_anova, exact_anova, t5_anova, r2_published)
    r2.to_csv(out / "table3_r2.csv", index=False)
    (out / "table2_alma.txt").write_text(
        "ANOVA of alma's Table 5 as printed (4 decimals), the paper's input:\n\n"
        + ours_anova.format_table()
        + "\n\nANOVA of alma's unrounded collapse multipliers:\n\n"
        + exact_anova.format_table()
        + "\n",
        encoding="utf-8",
    )

    return t5cmp, t2cmp, r2, ours_t5order, ours_anova, exact_anova, t5_anova


def make_paper(
    out_dir: str | Path,
    published: str | Path,
    workers: int | None = None,
    progress: bool = True,
    nonassociative: bool = False,
    effort: str | None = None,
) -> dict[str, Any]:
    """Run the study (resumable) and write every comparison into ``out_dir``; returns a summary.

    ``published`` is the folder of the published tables (``paper_tables/data`` of the
    repository: :data:`PUBLISHED_FILES`).

    With ``nonassociative``, also the non-associative model on the same panels and the report
    of :func:`alma.compare.run_compare` in ``out_dir/nonassociative/``.
    """
    DATA = Path(published)
    missing = [name for name in PUBLISHED_FILES if not (DATA / name).is_file()]
    if missing:
        raise ValueError(
            f"the published tables folder {DATA} lacks {', '.join(missing)} (paper_tables/data of alma's repository)"
        )
    start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    ours = run_doe(out / "doe", model="associative", workers=workers, progress=progress)
    failed = ours[ours["status"] != "optimal"]
    if len(ours) != 108 or not failed.empty:
        raise RuntimeError(f"the study has {len(ours)} rows, {len(failed)} not optimal; see {out / 'doe'}")
    ours = ours.copy()
    ours["bond"] = ours["bond"].str.lower()

    t5 = load_results(DATA / "table5_collapse_multipliers.csv")
    t5cmp, t2cmp, r2, ours_t5order, ours_anova, exact_anova, t5_anova = _tables(ours, t5, DATA, out)
    captions = pd.read_csv(DATA / "figure_captions.csv", dtype=str)
    titles = {int(r.figure): r.caption for r in pd.read_csv(DATA / "figure_titles.csv").itertuples()}
    figs = statistics_figures(ours_t5order, exact_anova, t5, t5_anova, out / "figures")
    mech, mech_note = mechanism_figures(captions, t5cmp, titles, out / "figures")
    mech.to_csv(out / "mechanisms.csv", index=False)
    if mech_note:
        print(mech_note, file=sys.stderr)
    compare_report = None
    if nonassociative:
        compare_report = run_compare(
            out / "nonassociative", workers=workers, effort=effort, results_dir=out / "doe", progress=progress
        )
    elapsed = time.perf_counter() - start
    report = write_report(out, t5cmp, t2cmp, r2, mech, mech_note, figs, elapsed)
    if compare_report is not None:
        with open(report, "a", encoding="utf-8") as fh:
            fh.write(
                "\n## Beyond the paper: non-associative friction\n\n"
                f"The same 108 panels without dilatancy: [nonassociative/compare.md]"
                f"({compare_report.markdown.relative_to(out)}) (α_NL against α_LP, ANOVA of "
                "α_NL and of α_NL/α_LP, mechanisms side by side).\n"
            )
    return {
        "compare_report": str(compare_report.markdown) if compare_report is not None else "",
        "compare_failed": compare_report.failed if compare_report is not None else 0,
        "report": str(report),
        "table5_match": int(t5cmp["match"].sum()),
        "table5_rows": len(t5cmp),
        "table2_match": int(t2cmp["match"].sum()),
        "table2_cells": len(t2cmp),
        "r2": ours_anova.r2,
        "r2_pred": ours_anova.r2_pred,
        "mechanism_figures": int((mech["png"] != "").sum()),
        "seconds": elapsed,
    }
