"""Command-line subcommands of the design of experiments: ``alma doe``, ``alma anova``,
``alma paper`` and ``alma compare``.

``register(subparsers)`` adds them to the ``alma`` parser (``parser.add_subparsers()``); each
subparser's ``func`` is a handler ``handler(args) -> int`` returning the exit code:

- 0: done; 1: some panels failed (rows with status ``error``, or panels lost to a crashed
  worker) or the paper run failed; 2: bad input (design file, results CSV, options);
  130: interrupted with Ctrl-C (everything finished is on disk; rerun to resume).
"""

from __future__ import annotations

import argparse
import io
import sys
from pathlib import Path
from typing import Any

from alma.cli.json_output import dumps
from alma.cli.study_inputs import (
    _design_argument,
    _error,
    _guarded,
    _positive_int,
    _study_rows_for_anova,
    _with_strengths,
)
from alma.settings import EFFORTS

__all__ = ["anova_handler", "compare_handler", "doe_handler", "paper_handler", "register"]


def register(subparsers: Any) -> None:
    """Add ``doe``, ``anova``, ``paper`` and ``compare`` to an argparse ``add_subparsers()`` object."""
    _register_doe(subparsers)
    _register_anova(subparsers)
    _register_paper(subparsers)
    _register_compare(subparsers)


def _register_doe(subparsers: Any) -> None:
    """Add ``alma doe``: the full-factorial study of Table 1, resumable."""
    p = subparsers.add_parser(
        "doe",
        help="run (or resume) the paper's 108-panel full-factorial study",
        description="Run the full-factorial design of Table 1 (108 panels by default). Every "
        "finished panel is appended to OUT/results.csv at once; panels already "
        "there are skipped, so an interrupted study resumes where it stopped.",
    )
    p.add_argument(
        "--out", default="doe_results", metavar="DIR", help="output folder holding results.csv (default: doe_results)"
    )
    p.add_argument(
        "--model",
        default="associative",
        choices=("associative", "nonassociative", "both"),
        help="contact model(s) (default: associative)",
    )
    p.add_argument(
        "--workers", type=_positive_int, default=None, metavar="N", help="local worker processes (default: all cores)"
    )
    p.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="address of an existing Dask distributed scheduler, e.g. tcp://host:8786 "
        "(alma must be installed on its workers)",
    )
    p.add_argument(
        "--design",
        default=None,
        metavar="FILE",
        help="TOML or JSON file of factor levels (panel_ratio, block_ratio, bond, "
        "friction, and chain: strengths in kN of a chain across the top course, "
        "with chain_height and chain_anchored); default: the paper's Table 1",
    )
    p.add_argument(
        "--compressive-strength",
        default=None,
        metavar="MPA[,MPA...]",
        help="levels of the blocks' compressive strength σ_c in MPa on every joint, e.g. "
        "0,2,5,10 (0: infinitely strong blocks; associative model only); replaces "
        "the design's compressive_strength levels (default: 0)",
    )
    p.add_argument("--retry-errors", action="store_true", help="solve again the panels whose stored status is 'error'")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=doe_handler)


def _register_anova(subparsers: Any) -> None:
    """Add ``alma anova``: the ANOVA of a results CSV (Table 2)."""
    p = subparsers.add_parser(
        "anova",
        help="ANOVA of a results CSV (Table 2 of the paper)",
        description="ANOVA (main effects and interactions up to --order) of a results CSV with "
        "columns panel_ratio, block_ratio, bond, friction, alpha_c.",
    )
    p.add_argument("results", metavar="RESULTS.csv")
    p.add_argument(
        "--order",
        type=int,
        default=2,
        choices=(1, 2, 3),
        help="highest interaction order in the model (default: 2, as in Table 2)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--model", default=None, help="rows of this contact model only, when the CSV holds several")
    p.set_defaults(func=anova_handler)


def _register_paper(subparsers: Any) -> None:
    """Add ``alma paper``: the paper's tables and figures beside the published ones."""
    p = subparsers.add_parser(
        "paper",
        help="regenerate the paper's tables and figures beside the published ones",
        description="Run the associative study (resumable) and write Table 5, Table 2, the R² "
        "of Table 3, Figures 5-15 and comparison.md into DIR.",
    )
    p.add_argument("--out", required=True, metavar="DIR")
    p.add_argument(
        "--published",
        default=None,
        metavar="DIR",
        help="folder of the published tables (paper_tables/data of alma's repository; default: ./paper_tables/data)",
    )
    p.add_argument(
        "--workers",
        type=_positive_int,
        default=None,
        metavar="N",
        help="local worker processes for the study (default: all cores)",
    )
    p.add_argument(
        "--nonassociative",
        action="store_true",
        help="also run the non-associative model on the same panels and write the "
        "comparison report of `alma compare` into DIR/nonassociative/",
    )
    p.add_argument(
        "--effort",
        default=None,
        choices=EFFORTS,
        help="non-associative search effort with --nonassociative (default: auto)",
    )
    p.set_defaults(func=paper_handler)


def _register_compare(subparsers: Any) -> None:
    """Add ``alma compare``: associative against non-associative α, with ANOVA."""
    p = subparsers.add_parser(
        "compare",
        help="associative against non-associative α on the paper's panels, with ANOVA",
        description="Run the study with both contact models (resumable, like `alma doe`: "
        "DIR/results.csv) and write DIR/compare.csv, DIR/compare.md (gaps, "
        "multi-start, failures, times, the two-way ANOVA of α_NL and of "
        "α_NL/α_LP) and DIR/figures/ (mechanisms side by side where the models "
        "differ most, main-effects plots).",
    )
    p.add_argument("--out", required=True, metavar="DIR")
    p.add_argument(
        "--design",
        default=None,
        metavar="FILE",
        help="TOML or JSON file of factor levels (default: the paper's 108 panels)",
    )
    p.add_argument(
        "--workers", type=_positive_int, default=None, metavar="N", help="local worker processes (default: all cores)"
    )
    p.add_argument(
        "--effort",
        default=None,
        choices=EFFORTS,
        help="non-associative search effort (default: auto = thorough up to 200 blocks)",
    )
    p.add_argument(
        "--time-limit",
        type=float,
        default=None,
        metavar="S",
        help="time limit of each non-associative search, s (default: none; part of the "
        "results' keys, so a different limit solves the panels again)",
    )
    p.add_argument(
        "--scheduler", default=None, metavar="ADDRESS", help="address of an existing Dask distributed scheduler"
    )
    p.add_argument(
        "--figures",
        type=int,
        default=6,
        metavar="N",
        help="draw the N panels where the models differ most (default: 6; 0: none)",
    )
    p.add_argument("--retry-errors", action="store_true", help="solve again the panels whose stored status is 'error'")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=compare_handler)


# ------------------------------------------------------------------------------------------
# alma doe
# ------------------------------------------------------------------------------------------


def doe_handler(args: argparse.Namespace) -> int:
    from alma.study.doe import RESULTS_FILE, run_doe

    design, failed = _design_argument(args)
    if failed:
        return 2
    if getattr(args, "compressive_strength", None) is not None:
        try:
            design = _with_strengths(design, args.compressive_strength)
        except ValueError as exc:
            _error(str(exc))
            return 2
    df, code = _guarded(
        lambda: run_doe(
            args.out,
            model=args.model,
            workers=args.workers,
            scheduler=args.scheduler,
            design=design,
            progress=not getattr(args, "quiet", False),
            retry_errors=getattr(args, "retry_errors", False),
        )
    )
    if code is not None:
        return code
    path = Path(args.out) / RESULTS_FILE
    failed = int((df["status"] == "error").sum())
    counts = ", ".join(f"{n} {s}" for s, n in df["status"].value_counts().items())
    print(f"{len(df)} results in {path} ({counts})")
    if failed:
        first = df.loc[df["status"] == "error", "message"].iloc[0]
        print(f"{failed} failed, e.g.: {first}", file=sys.stderr)
        return 1
    return 0


# ------------------------------------------------------------------------------------------
# alma anova
# ------------------------------------------------------------------------------------------


def anova_handler(args: argparse.Namespace) -> int:
    import pandas as pd

    from alma.stats.anova import anova, load_results

    path = Path(args.results)
    if not path.is_file():
        _error(f"{path}: no such file")
        return 2
    try:
        df = _load_for_anova(path, getattr(args, "model", None), pd, load_results)
        result = anova(df, order=args.order)
    except (ValueError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        _error(str(exc))
        return 2
    if args.json:
        print(dumps(result.to_dict()))
    else:
        print(result.format_table())
    return 0


def _load_for_anova(path: Path, model: str | None, pd: Any, load_results: Any) -> Any:
    """Table-5-like frame of one contact model (a doe results.csv may hold two)."""
    from alma.study.store import is_results_file, read_results

    if is_results_file(path):  # a study's file: its damaged rows are reported and left out
        return _study_rows_for_anova(path, read_results(path), model, load_results)
    try:
        head = pd.read_csv(path, nrows=0)
    except pd.errors.EmptyDataError:
        raise ValueError(f"{path}: empty results file") from None
    if "model" not in head.columns:
        if model is not None:
            raise ValueError(f"{path}: no 'model' column, --model cannot select rows")
        return load_results(path)
    raw = pd.read_csv(path, dtype=str, keep_default_na=False)
    models = [m for m in dict.fromkeys(raw["model"].str.strip()) if m]
    if model is None:
        if len(models) > 1:
            raise ValueError(f"{path}: rows of several models ({', '.join(models)}); choose one with --model")
        return load_results(path)
    if model not in models:
        raise ValueError(f"{path}: no rows of model {model!r} (found: {', '.join(models) or 'none'})")
    if "key" in raw.columns:
        raw = raw.drop_duplicates("key", keep="last")
    buf = io.StringIO(raw[raw["model"].str.strip() == model].to_csv(index=False))
    try:
        return load_results(buf)
    except ValueError as exc:
        raise ValueError(str(exc).replace(str(buf), f"{path} (model {model})")) from None


# ------------------------------------------------------------------------------------------
# alma paper
# ------------------------------------------------------------------------------------------


def paper_handler(args: argparse.Namespace) -> int:
    from alma.paper.tables import make_paper

    published = Path(args.published) if args.published else Path("paper_tables") / "data"
    if not published.is_dir():
        _error(
            f"the published tables are not in {published}: pass --published DIR, the "
            "paper_tables/data folder of alma's repository (the package holds no published value)"
        )
        return 2
    kwargs: dict[str, Any] = {}
    if getattr(args, "nonassociative", False):
        kwargs = {"nonassociative": True, "effort": getattr(args, "effort", None)}
    try:
        summary = make_paper(args.out, published, workers=getattr(args, "workers", None), **kwargs)
    except KeyboardInterrupt:
        return 130
    except (RuntimeError, ValueError, OSError) as exc:
        _error(str(exc))
        return 1
    if isinstance(summary, dict) and summary.get("report"):
        s = summary
        if "table5_match" in s:
            print(
                f"Table 5: {s['table5_match']}/{s['table5_rows']} agree to 4 decimals; "
                f"Table 2: {s['table2_match']}/{s['table2_cells']} cells; "
                f"R² = {100 * s['r2']:.2f} %, R²(pred) = {100 * s['r2_pred']:.2f} %"
            )
        print(f"report: {s['report']}")
        if s.get("compare_report"):
            print(f"non-associative comparison: {s['compare_report']}")
        if s.get("compare_failed"):
            print(f"{s['compare_failed']} non-associative result(s) failed; see {s['compare_report']}", file=sys.stderr)
            return 1
    return 0


# ------------------------------------------------------------------------------------------
# alma compare
# ------------------------------------------------------------------------------------------


def compare_handler(args: argparse.Namespace) -> int:
    from alma.study.compare import run_compare

    design, failed = _design_argument(args)
    if failed:
        return 2
    if getattr(args, "figures", 6) < 0:
        _error("--figures must be >= 0")
        return 2
    report, code = _guarded(
        lambda: run_compare(
            args.out,
            design=design,
            workers=args.workers,
            effort=args.effort,
            scheduler=getattr(args, "scheduler", None),
            progress=not getattr(args, "quiet", False),
            retry_errors=getattr(args, "retry_errors", False),
            n_figures=getattr(args, "figures", 6),
            time_limit=getattr(args, "time_limit", None),
        )
    )
    if code is not None:
        return code
    t = report.table
    ratio = t["ratio"].dropna()
    gap = f", largest gap 1 - α_NL/α_LP = {1 - ratio.min():.4f}" if len(ratio) else ""
    print(
        f"{len(t)} panels{gap}; table {report.csv}; report {report.markdown}; "
        f"{len(report.figures)} figures in {report.out / 'figures'}"
    )
    if report.failed:
        print(f"{report.failed} result(s) failed; see {report.markdown}", file=sys.stderr)
        return 1
    return 0
