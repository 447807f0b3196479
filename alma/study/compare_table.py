"""The comparison table of ``alma compare``: one row per panel, both models side by side."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

FACTOR_COLUMNS = ("panel_ratio", "block_ratio", "bond", "friction")
#: Columns of ``compare.csv``, in order.
COMPARE_COLUMNS: tuple[str, ...] = (
    "panel_ratio",
    "block_ratio",
    "bond",
    "friction",
    "n_blocks",
    "alpha_lp",
    "alpha_nl",
    "ratio",
    "status_lp",
    "status_nl",
    "mechanism_lp",
    "mechanism_nl",
    "time_lp_s",
    "time_nl_s",
    "start_nl",
    "alpha_lp_start",
    "lp_start_verified",
    "lp_start_gain",
    "n_candidates",
    "n_verified",
    "effort",
    "message_nl",
    "key_lp",
    "key_nl",
    "starts_nl",
)
#: α_NL below α_LP by more than this (relative) counts as "the models differ".
DIFFER_TOLERANCE = 1e-6
#: Statuses of a verified non-associative state: a state (feasible), or the proven minimum (optimal).
VERIFIED = ("feasible", "optimal")
#: α_NL may exceed α_LP by this much (absolute) before it counts as a violation of α_NL ≤ α_LP.
BOUND_TOLERANCE = 1e-7
SIGNIFICANCE = 0.05
_LABELS = {"panel_ratio": "Panel", "block_ratio": "Block", "bond": "Bond", "friction": "Friction"}


@dataclass
class CompareReport:
    """What :func:`run_compare` wrote, and the numbers of its summary."""

    out: Path
    table: pd.DataFrame
    csv: Path
    markdown: Path
    figures: list[Path] = field(default_factory=list)
    failed: int = 0
    notes: list[str] = field(default_factory=list)


# ------------------------------------------------------------------------------------------
# The table
# ------------------------------------------------------------------------------------------


def compare_table(results: pd.DataFrame) -> pd.DataFrame:
    """One row per panel from the associative and non-associative rows of a study.

    ``ratio`` is α_NL/α_LP (NaN unless both are finite and α_LP > 0); ``time_lp_s`` is the
    LP solve and certification time of the associative row, ``time_nl_s`` the non-associative
    search of the other row (which starts from its own LP solution); ``lp_start_gain`` is
    α of the verified LP-started candidate minus α_NL (what the other starts added).
    """
    lp = results[results["model"] == "associative"].set_index(list(FACTOR_COLUMNS))
    nl = results[results["model"] == "nonassociative"].set_index(list(FACTOR_COLUMNS))
    order = list(dict.fromkeys(results.set_index(list(FACTOR_COLUMNS)).index))
    rows = []
    for idx in order:
        a = lp.loc[idx] if idx in lp.index else None
        n = nl.loc[idx] if idx in nl.index else None
        a = a.iloc[-1] if isinstance(a, pd.DataFrame) else a
        n = n.iloc[-1] if isinstance(n, pd.DataFrame) else n
        alpha_lp = float(a["alpha_c"]) if a is not None else math.nan
        alpha_nl = float(n["alpha_c"]) if n is not None else math.nan
        ok = math.isfinite(alpha_lp) and math.isfinite(alpha_nl) and alpha_lp > 0
        lp_alpha = float(n["alpha_lp_start"]) if n is not None else math.nan
        lp_verified = str(n["lp_start_verified"]) if n is not None else ""
        gain = lp_alpha - alpha_nl if lp_verified == "True" and math.isfinite(alpha_nl) else math.nan
        n_blocks = next(
            (float(r["n_blocks"]) for r in (a, n) if r is not None and math.isfinite(float(r["n_blocks"]))), math.nan
        )
        rows.append(
            {
                **dict(zip(FACTOR_COLUMNS, idx, strict=True)),
                "n_blocks": n_blocks,
                "alpha_lp": alpha_lp,
                "alpha_nl": alpha_nl,
                "ratio": alpha_nl / alpha_lp if ok else math.nan,
                "status_lp": a["status"] if a is not None else "missing",
                "status_nl": n["status"] if n is not None else "missing",
                "mechanism_lp": a["mechanism_class"] if a is not None else "",
                "mechanism_nl": n["mechanism_class"] if n is not None else "",
                "time_lp_s": float(a["solve_s"]) + float(a["certify_s"]) if a is not None else math.nan,
                "time_nl_s": float(n["nonassociative_s"]) if n is not None else math.nan,
                "start_nl": n["start"] if n is not None else "",
                "alpha_lp_start": lp_alpha,
                "lp_start_verified": lp_verified,
                "lp_start_gain": gain,
                "n_candidates": float(n["n_candidates"]) if n is not None else math.nan,
                "n_verified": float(n["n_verified"]) if n is not None else math.nan,
                "effort": n["effort"] if n is not None else "",
                "message_nl": n["message"] if n is not None else "",
                "key_lp": a["key"] if a is not None else "",
                "key_nl": n["key"] if n is not None else "",
                "starts_nl": n["starts"] if n is not None and "starts" in n.index else "",
            }
        )
    out = pd.DataFrame(rows, columns=list(COMPARE_COLUMNS))
    for col in ("n_blocks", "n_candidates", "n_verified"):
        out[col] = out[col].astype("Int64") if out[col].notna().all() else out[col]
    return out


def _panel_name(r: Any) -> str:
    return f"{r.bond}, panel {r.panel_ratio}, blocks {r.block_ratio}, f = {float(r.friction):.2f}"
