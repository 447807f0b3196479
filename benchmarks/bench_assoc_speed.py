"""Speed of the certified associative LP (Eq. 10) against plain Clarabel, in one process.

Three cases, the targets of the associative speed work:

1. the largest paper panel (english bond, panel 1:2, blocks 1:1, f = 0.6; 1,752 blocks,
   5,112 joints) end to end: ``alma.solve(scene)`` including joint detection and build;
2. the 108 panels of the paper's study solved one after the other in this process (each
   geometry built once and re-solved for its three frictions), and ``alma doe --workers 2``
   run as a subprocess (wall clock, fresh output folder each time);
3. running-bond walls (``alma.wall("running", ...)``, built as in bench_scaling.py).

Baselines, run in the same process right after each alma run so that the ratio is meaningful on
a shared machine: Clarabel on the same kinematic LP with default settings ("plain", no
certificate; its ``direct_solve_method="auto"`` picks faer on large walls) and with
QDLDL named explicitly ("plain qdldl").  Times are medians of ``--repeat`` runs (walls above
``--single-above`` blocks: one run).

    python -m benchmarks.bench_assoc_speed [--repeat 3] [--walls 1000,3000] [--doe]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from functools import partial
from pathlib import Path

import pandas as pd

import alma
from alma.geometry.panels import BLOCK_LENGTHS, BONDS, PANEL_HEIGHTS
from benchmarks.bench_lp import plain_clarabel_solution

ROOT = Path(__file__).resolve().parents[1]


def plain_clarabel(model, method: str = "auto", time_limit: float = 600.0) -> tuple[float, str, int]:
    """The kinematic LP of Eq. 10 straight into Clarabel (default tolerances), no certificate:
    (α, status, iterations)."""
    sol = plain_clarabel_solution(model, time_limit, method)
    return float(sol.obj_val), str(sol.status), int(sol.iterations)


def timed(fn):
    t0 = time.perf_counter()
    value = fn()
    return time.perf_counter() - t0, value


def largest_panel(repeat: int) -> pd.DataFrame:
    scene = alma.paper_panel("english", "1:2", "1:1", 0.6)
    model = alma.build_model(scene)
    t_alma, t_plain, t_qdldl, result, plain = [], [], [], None, None
    for _ in range(repeat):
        t, result = timed(lambda: alma.solve(scene))
        t_alma.append(t)
        t, plain = timed(lambda: plain_clarabel(model))
        t_plain.append(t)
        t, _plain_q = timed(lambda: plain_clarabel(model, "qdldl"))
        t_qdldl.append(t)
    assert result is not None and plain is not None, "repeat must be at least 1"
    alma_s, plain_s = statistics.median(t_alma), statistics.median(t_plain)
    return pd.DataFrame(
        [
            dict(
                case="english 1:2 1:1 f=0.6",
                blocks=model.n_free,
                joints=model.n_joints,
                status=result.status,
                alpha=result.alpha,
                gap=result.bounds.gap,
                iterations=result.extra["iterations"],
                solve_s=result.timings["solve_s"],
                certify_s=result.timings["certify_s"],
                alma_end_to_end_s=alma_s,
                plain_s=plain_s,
                plain_iterations=plain[2],
                plain_qdldl_s=statistics.median(t_qdldl),
                alma_over_plain=alma_s / plain_s,
            )
        ]
    )


def whole_table(repeat: int, doe: bool) -> pd.DataFrame:
    def run(solver) -> tuple[float, int, int]:
        t0, its, certified = time.perf_counter(), 0, 0
        for bond in BONDS:
            for pr in PANEL_HEIGHTS:
                for br in BLOCK_LENGTHS:
                    base = alma.build_model(alma.paper_panel(bond, pr, br, 0.27))
                    for f in (0.27, 0.6, 1.0):
                        out = solver(base.with_friction(f))
                        if isinstance(out, tuple):
                            its += out[2]
                        else:
                            its += int(out.extra["iterations"])
                            certified += out.status == "optimal"
        return time.perf_counter() - t0, its, certified

    alma_runs, plain_runs, doe_runs = [], [], []
    for _ in range(repeat):
        alma_runs.append(run(alma.solve))
        plain_runs.append(run(plain_clarabel))
        if doe:
            with tempfile.TemporaryDirectory() as tmp:
                t0 = time.perf_counter()
                subprocess.run(
                    [sys.executable, "-m", "alma.cli", "doe", "--workers", "2", "--out", tmp],
                    check=True,
                    cwd=ROOT,
                    capture_output=True,
                )
                doe_runs.append(time.perf_counter() - t0)
    alma_s = statistics.median(r[0] for r in alma_runs)
    plain_s = statistics.median(r[0] for r in plain_runs)
    row = dict(
        case="108 panels, one process",
        alma_s=alma_s,
        certified=alma_runs[0][2],
        iterations=alma_runs[0][1],
        plain_s=plain_s,
        plain_iterations=plain_runs[0][1],
        alma_over_plain=alma_s / plain_s,
    )
    if doe:
        row["doe_workers2_wall_s"] = statistics.median(doe_runs)
    return pd.DataFrame([row])


def walls(sizes: list[int], repeat: int, single_above: int, plain_limit: float) -> pd.DataFrame:
    from benchmarks.bench_scaling import wall_shape

    rows = []
    for n in sizes:
        courses, per_course = wall_shape(n)
        model = alma.build_model(alma.wall("running", 240.0 * per_course, 60.0 * courses, 240.0))
        runs = 1 if model.n_free > single_above else repeat
        t_alma, t_plain, result, plain = [], [], None, None
        for _ in range(runs):
            t, result = timed(partial(alma.solve, model))
            t_alma.append(t)
            t, plain = timed(partial(plain_clarabel, model, time_limit=plain_limit))
            t_plain.append(t)
        assert result is not None and plain is not None, "repeat must be at least 1"
        alma_s, plain_s = statistics.median(t_alma), statistics.median(t_plain)
        rows.append(
            dict(
                blocks=model.n_free,
                joints=model.n_joints,
                status=result.status,
                alpha=result.alpha,
                gap=result.bounds.gap,
                iterations=result.extra["iterations"],
                solve_s=result.timings["solve_s"],
                certify_s=result.timings["certify_s"],
                alma_s=alma_s,
                plain_s=plain_s,
                plain_status=plain[1],
                plain_iterations=plain[2],
                alma_over_plain=alma_s / plain_s,
                runs=runs,
            )
        )
    return pd.DataFrame(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--walls", default="1000,3000", help="wall sizes in blocks ('' for none)")
    parser.add_argument("--single-above", type=int, default=5000, help="walls above this: one run")
    parser.add_argument(
        "--plain-time-limit", type=float, default=120.0, help="time limit of the plain Clarabel baseline on walls [s]"
    )
    parser.add_argument("--doe", action="store_true", help="also time `alma doe --workers 2` (subprocess)")
    parser.add_argument("--skip-table", action="store_true")
    args = parser.parse_args()
    pd.set_option("display.width", 250)
    fmt = lambda x: f"{x:.4g}"  # noqa: E731
    print(f"== largest paper panel, end to end (median of {args.repeat}) ==")
    print(largest_panel(args.repeat).to_string(index=False, float_format=fmt), flush=True)
    if not args.skip_table:
        print(f"\n== 108 panels (median of {args.repeat}) ==")
        print(whole_table(args.repeat, args.doe).to_string(index=False, float_format=fmt), flush=True)
    sizes = [int(s) for s in args.walls.split(",") if s]
    if sizes:
        print(f"\n== running-bond walls (median of {args.repeat}; one run above {args.single_above} blocks) ==")
        table = walls(sizes, args.repeat, args.single_above, args.plain_time_limit)
        print(table.to_string(index=False, float_format=fmt), flush=True)


if __name__ == "__main__":
    main()
