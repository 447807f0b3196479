"""Timing of the associative path: joints, build, solve, certification.

Cases: the four largest paper panels (1440 × 2880 mm, 60 × 60 blocks), the whole
108-panel table, and running-bond walls up to 10,000+ blocks (joint detection and
build). Each figure is the median of several runs; the baseline is a plain Clarabel
solve of the same LP with default settings, run in the same process, so the ratio is
meaningful on a shared, noisy machine.

    python -m benchmarks.bench_lp [--repeat 3] [--out benchmarks/results]
"""

from __future__ import annotations

import argparse
import statistics
import time
from functools import partial
from pathlib import Path

import clarabel
import numpy as np
import pandas as pd
import scipy.sparse as sp

import alma
from alma.geometry.contacts import find_joints
from alma.geometry.panels import BLOCK_LENGTHS, BONDS, PANEL_HEIGHTS, wall
from alma.mechanics.model import build_model
from benchmarks.harness import median_time


def plain_clarabel_solution(model, time_limit: float | None = None, method: str = "auto"):
    """Baseline: the kinematic LP straight into Clarabel, default settings (``method`` = its
    ``direct_solve_method``), no certification.  Returns Clarabel's solution object."""
    H = model.equilibrium
    n, k = H.shape
    A = sp.vstack([sp.csr_matrix(model.live), -H.T]).tocsc()
    b = np.zeros(1 + k)
    b[0] = 1.0
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.direct_solve_method = method
    if time_limit is not None:
        settings.time_limit = float(time_limit)
    return clarabel.DefaultSolver(
        sp.csc_matrix((n, n)), -model.dead, A, b, [clarabel.ZeroConeT(1), clarabel.NonnegativeConeT(k)], settings
    ).solve()


def plain_clarabel(model, time_limit: float | None = None) -> tuple[float, str]:
    """The baseline's (α, Clarabel status)."""
    sol = plain_clarabel_solution(model, time_limit)
    return float(sol.obj_val), str(sol.status)


def largest_panels(repeat: int) -> pd.DataFrame:
    rows = []
    for bond in BONDS:
        scene = alma.paper_panel(bond, "1:2", "1:1", 0.6)
        t_joints, joints = median_time(partial(find_joints, scene), repeat)
        t_build, model = median_time(partial(build_model, scene, joints), repeat)
        t_alma, result = median_time(partial(alma.solve, model), repeat)
        t_plain, _ = median_time(partial(plain_clarabel, model), repeat)
        rows.append(
            dict(
                bond=bond,
                blocks=model.n_free,
                joints=model.n_joints,
                alpha=result.alpha,
                gap=result.bounds.gap,
                status=result.status,
                joints_s=t_joints,
                build_s=t_build,
                solve_s=result.timings["solve_s"],
                certify_s=result.timings["certify_s"],
                alma_total_s=t_joints + t_build + t_alma,
                plain_clarabel_s=t_plain,
                ratio=(t_joints + t_build + t_alma) / t_plain,
            )
        )
    return pd.DataFrame(rows)


def whole_table(repeat: int) -> pd.DataFrame:
    """The 108 panels: each geometry built once, re-solved for its three frictions."""

    def run(solver) -> float:
        t0 = time.perf_counter()
        for bond in BONDS:
            for pr in PANEL_HEIGHTS:
                for br in BLOCK_LENGTHS:
                    model = build_model(alma.paper_panel(bond, pr, br, 0.27))
                    for f in (0.27, 0.6, 1.0):
                        solver(model.with_friction(f))
        return time.perf_counter() - t0

    alma_s = statistics.median(run(alma.solve) for _ in range(repeat))
    plain_s = statistics.median(run(plain_clarabel) for _ in range(repeat))
    return pd.DataFrame(
        [
            dict(
                case="108 panels, associative, certified",
                alma_s=alma_s,
                plain_clarabel_s=plain_s,
                ratio=alma_s / plain_s,
            )
        ]
    )


def walls(repeat: int) -> pd.DataFrame:
    rows = []
    for courses, per_course in ((10, 10), (50, 40), (100, 100), (200, 100)):
        scene = wall("running", 240.0 * per_course, 60.0 * courses, 240.0)
        t_joints, joints = median_time(partial(find_joints, scene), repeat)
        t_build, model = median_time(partial(build_model, scene, joints), repeat)
        t_solve, result = median_time(partial(alma.solve, model), 1)
        rows.append(
            dict(
                blocks=model.n_free,
                joints=model.n_joints,
                joints_s=t_joints,
                build_s=t_build,
                solve_and_certify_s=t_solve,
                status=result.status,
                alpha=result.alpha,
                build_fraction=(t_joints + t_build) / t_solve,
            )
        )
    return pd.DataFrame(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", default="benchmarks/results")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    pd.set_option("display.width", 200)
    for name, fn in (("largest_panels", largest_panels), ("whole_table", whole_table), ("walls", walls)):
        table = fn(args.repeat)
        table.to_csv(out / f"{name}.csv", index=False)
        print(f"\n== {name} (median of {args.repeat}) ==")
        print(table.to_string(index=False, float_format=lambda x: f"{x:.4g}"))


if __name__ == "__main__":
    main()
