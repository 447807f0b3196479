"""Scaling of the associative path with the number of blocks (SPEC §6: benchmarks).

Running-bond walls of 240 × 60 mm blocks on a fixed ground, from 10 to 20,000 blocks (and
100,000 blocks for joint detection and model build only).  Each size runs in its own
subprocess so that its peak resident memory (``resource.getrusage().ru_maxrss``) is its own:
the table gives the memory after the imports, after the build and after the solve.

Timed parts: joint detection (``alma.contacts.find_joints``), model build
(``alma.build_model(scene, joints)``) — median of ``--repeat`` runs — and the solve and the
certification (``result.timings['solve_s']``, ``['certify_s']`` of ``alma.solve(model)``) —
median of 3 runs up to 3,000 blocks, 1 run above.  Exponents are log–log least-squares slopes
of time (or memory above the import baseline) against the number of blocks, fitted on the
sizes ≥ 100 blocks (below that fixed per-call costs dominate).

    .venv/bin/python -m benchmarks.bench_scaling [--sizes 10,30,...] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import statistics
import time
from pathlib import Path
from typing import Any

from benchmarks.harness import run_worker

ROOT = Path(__file__).resolve().parents[1]
SIZES = (10, 30, 100, 300, 1000, 3000, 10000, 20000)
BUILD_ONLY = (100000,)
FIT_FROM = 100


def wall_shape(n: int) -> tuple[int, int]:
    """(courses, blocks per full course) of a running-bond wall with about n blocks."""
    courses = max(1, round(math.sqrt(n)))
    per_course = max(2, round((n - courses // 2) / courses))
    return courses, per_course


def maxrss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: kB


def worker(n: int, repeat: int, solve_runs: int) -> dict:
    """Measure one size (run in a fresh subprocess)."""
    import alma
    from alma.geometry.contacts import find_joints

    base = maxrss_mb()
    courses, per_course = wall_shape(n)
    scene = alma.wall("running", 240.0 * per_course, 60.0 * courses, 240.0)
    times_j, times_b = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        joints = find_joints(scene)
        t1 = time.perf_counter()
        model = alma.build_model(scene, joints)
        t2 = time.perf_counter()
        times_j.append(t1 - t0)
        times_b.append(t2 - t1)
    built = maxrss_mb()
    out: dict[str, Any] = dict(
        target=n,
        blocks=model.n_free,
        joints=model.n_joints,
        courses=courses,
        per_course=per_course,
        joints_s=statistics.median(times_j),
        build_s=statistics.median(times_b),
        rss_base_mb=base,
        rss_build_mb=built,
        solve_runs=solve_runs,
    )
    if solve_runs:
        solve, certify, total = [], [], []
        for _ in range(solve_runs):
            t0 = time.perf_counter()
            result = alma.solve(model)
            total.append(time.perf_counter() - t0)
            solve.append(result.timings["solve_s"])
            certify.append(result.timings["certify_s"])
        out.update(
            solve_s=statistics.median(solve),
            certify_s=statistics.median(certify),
            solve_total_s=statistics.median(total),
            status=result.status,
            alpha=result.alpha,
            gap=result.bounds.gap,
            iterations=result.extra.get("iterations"),
            rss_solve_mb=maxrss_mb(),
        )
    return out


def fit(x, y) -> float:
    import numpy as np

    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = (x >= FIT_FROM) & np.isfinite(y) & (y > 0)
    if ok.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)))
    parser.add_argument(
        "--build-only",
        default=",".join(map(str, BUILD_ONLY)),
        help="sizes timed for joints and build only ('' for none)",
    )
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results"))
    parser.add_argument("--worker", type=int, help=argparse.SUPPRESS)
    parser.add_argument("--solve-runs", type=int, default=1, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(worker(args.worker, args.repeat, args.solve_runs)))
        return

    import pandas as pd

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    sizes = [int(s) for s in args.sizes.split(",") if s]
    build_only = [int(s) for s in args.build_only.split(",") if s]
    rows = []
    t_start = time.perf_counter()
    for n in sizes + build_only:
        solve_runs = 0 if n in build_only and n not in sizes else (3 if n <= 3000 else 1)
        row = run_worker(
            "benchmarks.bench_scaling",
            ["--worker", str(n), "--repeat", str(args.repeat), "--solve-runs", str(solve_runs)],
        )
        if "error" in row:
            print(f"size {n}: worker failed: {row['error']}", flush=True)
            rows.append(dict(target=n, status="worker failed"))
            continue
        rows.append(row)
        print(
            f"[{time.perf_counter() - t_start:6.0f} s] {row['blocks']:6d} blocks: joints {row['joints_s']:.3g} s, "
            f"build {row['build_s']:.3g} s"
            + (
                f", solve {row['solve_s']:.3g} s, certify {row['certify_s']:.3g} s, {row['status']}"
                if solve_runs
                else ""
            ),
            flush=True,
        )
    df = pd.DataFrame(rows)
    df["joints_build_s"] = df.joints_s + df.build_s
    df["build_fraction_of_solve"] = df.joints_build_s / (df.solve_s + df.certify_s)
    df["rss_build_above_base_mb"] = df.rss_build_mb - df.rss_base_mb
    df["rss_solve_above_base_mb"] = df.rss_solve_mb - df.rss_base_mb
    df.to_csv(out / "scaling.csv", index=False)

    solved = df[df.solve_runs > 0]
    exps = {
        "joints_s": fit(df.blocks, df.joints_s),
        "build_s": fit(df.blocks, df.build_s),
        "solve_s": fit(solved.blocks, solved.solve_s),
        "certify_s": fit(solved.blocks, solved.certify_s),
        "solve+certify": fit(solved.blocks, solved.solve_s + solved.certify_s),
        "peak memory after build (above import)": fit(df.blocks, df.rss_build_above_base_mb),
        "peak memory after solve (above import)": fit(solved.blocks, solved.rss_solve_above_base_mb),
    }
    exp_df = pd.DataFrame([dict(quantity=k, exponent=v) for k, v in exps.items()])
    exp_df.to_csv(out / "scaling_exponents.csv", index=False)

    pd.set_option("display.width", 250)
    cols = [
        "blocks",
        "joints",
        "joints_s",
        "build_s",
        "solve_s",
        "certify_s",
        "build_fraction_of_solve",
        "status",
        "gap",
        "iterations",
        "rss_base_mb",
        "rss_build_mb",
        "rss_solve_mb",
    ]
    print(
        f"\n== scaling, running-bond walls (joints/build: median of {args.repeat}; solve: median of 3 up to "
        f"3,000 blocks, else 1 run) =="
    )
    print(df[[c for c in cols if c in df]].to_string(index=False, float_format=lambda x: f"{x:.3g}"))
    print(f"\n== fitted exponents (time or memory ∝ blocks^k, least squares on log–log, sizes ≥ {FIT_FROM}) ==")
    print(exp_df.to_string(index=False, float_format=lambda x: f"{x:.2f}"))
    plot(df, exps, out / "scaling.png")
    print(f"\nwritten: {out / 'scaling.csv'}, {out / 'scaling_exponents.csv'}, {out / 'scaling.png'}")


def plot(df, exps, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5))
    for col, label in (
        ("joints_s", "joint detection"),
        ("build_s", "model build"),
        ("solve_s", "solve (Clarabel)"),
        ("certify_s", "certification"),
    ):
        d = df[df[col].notna()] if col in df else df.iloc[:0]
        ax.loglog(d.blocks, d[col], "o-", label=f"{label} (k = {exps.get(col, float('nan')):.2f})")
    ax.set_xlabel("blocks")
    ax.set_ylabel("time [s]")
    ax.set_title("Running-bond walls: time per phase")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax2.loglog(df.blocks, df.rss_build_mb, "o-", label="peak RSS after build")
    if "rss_solve_mb" in df:
        d = df[df.rss_solve_mb.notna()]
        ax2.loglog(d.blocks, d.rss_solve_mb, "s-", label="peak RSS after solve")
    ax2.loglog(df.blocks, df.rss_base_mb, ":", color="0.5", label="after imports")
    ax2.set_xlabel("blocks")
    ax2.set_ylabel("peak resident memory [MB]")
    ax2.set_title("Memory (one subprocess per size)")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=130)


if __name__ == "__main__":
    main()
