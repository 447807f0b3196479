"""The study commands' inputs and failures: option types, the design file and its strength levels, a
study's rows for ``alma anova``, and the exit code of a failed run (2 bad input, 1 failed, 130
interrupted), its message on stderr.
"""

from __future__ import annotations

import argparse
import dataclasses
import io
import sys
from pathlib import Path
from typing import Any

from alma.study.design import PAPER_DESIGN, load_design


def _positive_int(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if n < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return n


def _guarded(run: Any) -> tuple[Any, int | None]:
    """``run()`` and None, or None and the exit code of its failure (130 interrupted, 2 bad
    input, 1 a failed run), the message on stderr."""
    try:
        return run(), None
    except KeyboardInterrupt:
        return None, 130
    except ValueError as exc:
        _error(str(exc))
        return None, 2
    except (RuntimeError, OSError) as exc:
        _error(str(exc))
        return None, 1


def _error(message: str) -> None:
    print(f"alma: error: {message}", file=sys.stderr)


def _design_argument(args: argparse.Namespace):
    """(design or None, failed): the ``--design`` file, its error printed if it cannot be read."""
    if not getattr(args, "design", None):
        return None, False
    try:
        return load_design(args.design), False
    except ValueError as exc:
        _error(str(exc))
        return None, True


def _with_strengths(design: Any, text: str) -> Any:
    """``design`` (default the paper's) with the compressive-strength levels of ``--compressive-strength``."""
    levels = [t.strip() for t in text.split(",")]
    if not all(levels):
        raise ValueError(f"--compressive-strength: expected MPa levels separated by commas, got {text!r}")
    try:
        values = tuple(float(t) for t in levels)
    except ValueError:
        raise ValueError(f"--compressive-strength: expected numbers (MPa), got {text!r}") from None
    try:
        return dataclasses.replace(design or PAPER_DESIGN, compressive_strength=values)
    except ValueError as exc:
        raise ValueError(f"--compressive-strength: {exc}") from None


def _study_rows_for_anova(path: Path, rows: Any, model: str | None, load_results: Any) -> Any:
    """The sound rows of a study's results file, of one contact model, checked as Table 5's."""
    models = [m for m in dict.fromkeys(rows["model"].str.strip()) if m]
    if model is None and len(models) > 1:
        raise ValueError(f"{path}: rows of several models ({', '.join(models)}); choose one with --model")
    if model is not None:
        if model not in models:
            raise ValueError(f"{path}: no rows of model {model!r} (found: {', '.join(models) or 'none'})")
        rows = rows[rows["model"].str.strip() == model]
    buf = io.StringIO(rows.to_csv(index=False))
    try:
        return load_results(buf)
    except ValueError as exc:
        raise ValueError(str(exc).replace(str(buf), str(path))) from None
