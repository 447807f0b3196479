"""Run time against error for the non-associative search (Eq. 9), per start and per effort.

For every paper panel up to ``--max-blocks`` blocks (all three frictions), the associative LP is
solved once, then each method alone:

- ``lp``                     the exact state of the associative mechanism (its dilatant openings
                             read as slips), :func:`alma.nonassociative.exact_states.exact_state`;
- ``gilbert(s, r, k)``       one Gilbert iterative-LP run from N̄ = s·N_LP, relaxation r, k
                             slope-halving steps (every entry of ``SearchSettings.gilbert_fast``/``gilbert_thorough``/
                             ``gilbert_thorough_rows``, the last without the yield rows);
- ``effort=fast``, ``effort=thorough``  alma's default searches (all their starts, lowest
                             verified state), as :func:`alma.solve` runs them.

There is no proven optimum at these sizes (the MILP of ``alma.certify`` proves scenes of tens of
blocks, see ``bench_certify.py``), so the reference of a panel is the lowest verified α any method
found on it, and the error of a method is α − α_ref (≥ 0), or "failed" when it verified no state.
Times are medians of ``--repeat`` runs in one process (the machine is shared).

    .venv/bin/python -m benchmarks.bench_nonassociative [--max-blocks 300] [--repeat 1]

Writes benchmarks/results/nonassociative.csv (one row per panel and method),
nonassociative_summary.csv and nonassociative.png (median time against mean error).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd

import alma
from alma.associative.lp import solve_lp
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import build_model
from alma.nonassociative.exact_states import exact_state
from alma.nonassociative.gilbert import gilbert
from alma.nonassociative.search import solve_nonassociative
from alma.nonassociative.states import CollapseState
from alma.settings import SearchSettings

ROOT = Path(__file__).resolve().parents[1]

RESULTS = ROOT / "benchmarks" / "results"
FRICTIONS = (0.27, 0.6, 1.0)


def paper_geometries(max_blocks: int) -> list[tuple[int, str, str, str]]:
    rows = []
    for panel_ratio in ("1:2", "1:1", "2:1"):
        for block_ratio in ("1:1", "2:1", "4:1"):
            for bond in ("running", "stack", "english", "flemish"):
                n = len(alma.paper_panel(bond, panel_ratio, block_ratio, 0.6).blocks)
                if n <= max_blocks:
                    rows.append((n, panel_ratio, block_ratio, bond))
    return sorted(rows)


def methods(model, points, lp) -> dict[str, Callable[[], CollapseState | None]]:
    n_lp = lp.multipliers.reshape(-1, 2).sum(axis=1)
    out: dict[str, Callable[[], CollapseState | None]] = {
        "lp": lambda: exact_state(model, points, lp.mechanism, "lp", dilatant=True)
    }
    settings = SearchSettings()
    starts = dict.fromkeys(settings.gilbert_fast + settings.gilbert_thorough + settings.gilbert_thorough_rows)
    for scale, relaxation, steps in starts:
        out[f"gilbert({scale:g}, {relaxation:g}, {steps})"] = partial(
            _gilbert, model, points, scale * n_lp, relaxation, steps
        )
    for effort in ("fast", "thorough"):
        out[f"effort={effort}"] = partial(_search, model, lp, effort)
    return out


def _gilbert(model, points, normal, relaxation: float, steps: int) -> CollapseState | None:
    return gilbert(model, points, normal, relaxation=relaxation, slope_steps=steps)[0]


def _search(model, lp, effort: str) -> CollapseState | None:
    return solve_nonassociative(model, lp.mechanism, lp.multipliers, effort=effort).best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-blocks", type=int, default=300)
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    RESULTS.mkdir(parents=True, exist_ok=True)
    rows = []
    for n, panel_ratio, block_ratio, bond in paper_geometries(args.max_blocks):
        base = build_model(alma.paper_panel(bond, panel_ratio, block_ratio, 0.6))
        for friction in FRICTIONS:
            model = base.with_friction(friction)
            lp = solve_lp(model)
            points = ContactPoints.from_model(model)
            for name, run in methods(model, points, lp).items():
                times, state = [], None
                for _ in range(args.repeat):
                    t0 = time.perf_counter()
                    state = run()
                    times.append(time.perf_counter() - t0)
                ok = state is not None and state.verified
                rows.append(
                    dict(
                        bond=bond,
                        panel_ratio=panel_ratio,
                        block_ratio=block_ratio,
                        friction=friction,
                        blocks=n,
                        alpha_lp=lp.alpha,
                        method=name,
                        alpha=state.alpha if state is not None and ok else np.nan,
                        verified=ok,
                        time_s=statistics.median(times),
                    )
                )
            print(f"{bond:8s} {panel_ratio} {block_ratio} f={friction:<4g} {n:5d} blocks done", flush=True)
    table = pd.DataFrame(rows)
    keys = ["bond", "panel_ratio", "block_ratio", "friction"]
    table["alpha_ref"] = table.groupby(keys)["alpha"].transform("min")
    table["error"] = table["alpha"] - table["alpha_ref"]
    table.to_csv(RESULTS / "nonassociative.csv", index=False)
    summary = (
        table.groupby("method")
        .agg(
            panels=("verified", "size"),
            verified=("verified", "sum"),
            reaches_best=("error", lambda e: int((e <= 1e-6).sum())),
            mean_error=("error", "mean"),
            max_error=("error", "max"),
            median_time_s=("time_s", "median"),
            total_time_s=("time_s", "sum"),
        )
        .sort_values("total_time_s")
    )
    summary.to_csv(RESULTS / "nonassociative_summary.csv")
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(summary.to_string(float_format=lambda v: f"{v:.4g}"))
    above = table[table["verified"] & (table["alpha"] > table["alpha_lp"] + 1e-7)]
    print(f"states above the associative α (Radenkovic violated by a local state): {len(above)}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name, row in summary.iterrows():
        marker = "*" if name == "effort=fast" else ("s" if name == "effort=thorough" else "o")
        ax.scatter(row["median_time_s"], row["mean_error"] + 1e-6, marker=marker, s=80 if marker != "o" else 30)
        ax.annotate(
            f"{name} ({int(row['verified'])}/{int(row['panels'])})",
            (row["median_time_s"], row["mean_error"] + 1e-6),
            fontsize=7,
            xytext=(3, 3),
            textcoords="offset points",
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("median time per panel [s]")
    ax.set_ylabel("mean α − lowest verified α (+1e-6)")
    ax.set_title(f"Non-associative search, paper panels ≤ {args.max_blocks} blocks (★ default 'fast')")
    fig.tight_layout()
    fig.savefig(RESULTS / "nonassociative.png", dpi=120)
    print(f"wrote {RESULTS / 'nonassociative.csv'}, nonassociative_summary.csv, nonassociative.png")


if __name__ == "__main__":
    main()
