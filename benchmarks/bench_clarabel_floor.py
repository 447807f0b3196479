"""How fast can the certified associative LP (Eq. 10) be with Clarabel?  A floor, measured.

The speed targets of the associative path (largest paper panel end to end ≤ 0.3 s, 20,000-block
wall ≤ 30 s) are set against what Clarabel costs per interior-point iteration.  For each case this
script measures, with alma's own Clarabel call (:func:`alma.associative.solve_lp`):

- ``joints_build_s``  joint detection and model build (median of ``--repeat``);
- ``setup_s``         Clarabel's setup (KKT assembly, equilibration, AMD ordering, symbolic and first
                      numeric factorisation): ``solve_lp(max_iter=0)``;
- ``per_iter_s``      the marginal cost of one iteration: (``max_iter=k`` − ``max_iter=0``) / k;
- ``factor_s``        one numeric LDLᵀ refactorisation of a KKT matrix with Clarabel's pattern
                      ([δI Aᵀ; A −D], QDLDL after AMD, the ``qdldl`` package Clarabel's solver is
                      ported from), to show what share of an iteration the factorisation is;
- for every tolerance of ``--tolerances``: Clarabel's iterations, alma's status (``optimal`` only
  when the certificate closes: relative gap ≤ 1e-7, residuals ≤ 1e-9) and the solve time;
- ``floor_s`` = joints_build + setup + (fewest iterations that certified) × per_iter + certify:
  what the end-to-end time would be if nothing outside Clarabel's own iterations cost anything.

    .venv/bin/python -m benchmarks.bench_clarabel_floor [--repeat 3] [--walls 3000,10000,20000]

Writes benchmarks/results/clarabel_floor.csv (one row per case and tolerance).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import qdldl
import scipy.sparse as sp

import alma
from alma.associative.lp import solve_lp
from alma.geometry.contacts import find_joints
from alma.mechanics.model import build_model
from benchmarks.bench_scaling import wall_shape
from benchmarks.harness import median_time

ROOT = Path(__file__).resolve().parents[1]

RESULTS = ROOT / "benchmarks" / "results"
TARGETS = {"largest paper panel": 0.3, "wall 20000": 30.0}


def kkt_factor_time(model, repeat: int) -> float:
    """One numeric refactorisation of a KKT matrix with the pattern of alma's Clarabel call."""
    H = model.equilibrium
    A = sp.vstack([sp.csr_matrix(model.live), -H.T]).tocsc()
    n, m = A.shape[1], A.shape[0]
    rng = np.random.default_rng(0)

    def kkt() -> sp.csc_matrix:  # a fresh diagonal scaling, as at every iteration
        return sp.bmat([[1e-8 * sp.eye(n), A.T], [None, -sp.diags(rng.uniform(0.1, 10.0, m))]]).tocsc()

    solver = qdldl.Solver(kkt(), upper=True)
    matrices = [kkt() for _ in range(repeat)]
    times = []
    for K in matrices:
        t0 = time.perf_counter()
        solver.update(K, upper=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def measure(case: str, scene, tolerances: list[float], repeat: int, probe_iterations: int) -> list[dict]:
    joints_build_s, model = median_time(lambda: build_model(scene, find_joints(scene)), repeat)
    setup_s = statistics.median(solve_lp(model, max_iter=0).solve_time for _ in range(repeat))
    probe_s = statistics.median(solve_lp(model, max_iter=probe_iterations).solve_time for _ in range(repeat))
    per_iter_s = (probe_s - setup_s) / probe_iterations
    factor_s = kkt_factor_time(model, repeat)
    rows: list[dict[str, Any]] = []
    for tol in tolerances:
        runs = [solve_lp(model, tolerance=tol) for _ in range(repeat)]
        sol = runs[-1]
        gap = (sol.upper - sol.lower) / max(1.0, abs(sol.upper))
        rows.append(
            dict(
                case=case,
                blocks=model.n_free,
                joints=model.n_joints,
                tolerance=tol,
                status=sol.status,
                iterations=sol.iterations,
                gap=gap,
                solve_s=statistics.median(r.solve_time for r in runs),
                certify_s=statistics.median(r.certify_time for r in runs),
                joints_build_s=joints_build_s,
                setup_s=setup_s,
                per_iter_s=per_iter_s,
                factor_s=factor_s,
                factor_share=factor_s / per_iter_s,
            )
        )
    certified = [r for r in rows if r["status"] == "optimal"]
    if certified:
        fewest = min(certified, key=lambda r: r["iterations"])
        floor = joints_build_s + setup_s + fewest["iterations"] * per_iter_s + fewest["certify_s"]
        for r in rows:
            r["fewest_certified_iterations"] = fewest["iterations"]
            r["floor_s"] = floor
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3, help="runs per figure (walls above 5,000 blocks: 1)")
    parser.add_argument("--walls", default="3000,10000,20000", help="running-bond wall sizes ('' for none)")
    parser.add_argument("--tolerances", default="1e-8,1e-9,1e-10,1e-11")
    parser.add_argument("--probe-iterations", type=int, default=10)
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    tolerances = [float(t) for t in args.tolerances.split(",")]
    cases = [("largest paper panel", alma.paper_panel("english", "1:2", "1:1", 0.6), args.repeat)]
    for n in (int(s) for s in args.walls.split(",") if s):
        courses, per_course = wall_shape(n)
        cases.append(
            (
                f"wall {n}",
                alma.wall("running", 240.0 * per_course, 60.0 * courses, 240.0),
                1 if n > 5000 else args.repeat,
            )
        )
    rows = []
    args.out.mkdir(parents=True, exist_ok=True)
    pd.set_option("display.width", 250)
    for case, scene, repeat in cases:
        rows += measure(case, scene, tolerances, repeat, args.probe_iterations)
        table = pd.DataFrame(rows)
        table.to_csv(args.out / "clarabel_floor.csv", index=False)  # written as each case finishes
        print(table[table.case == case].to_string(index=False, float_format=lambda x: f"{x:.4g}"), flush=True)
    table = pd.DataFrame(rows)
    print("\n== floor against target ==")
    for case, group in table.groupby("case", sort=False):
        first = group.iloc[0]
        target = TARGETS.get(case)
        floor = first.get("floor_s", float("nan"))
        verdict = "" if target is None else f" (target {target:g} s: {'below' if floor <= target else 'ABOVE'})"
        print(
            f"{case}: {int(first.blocks)} blocks, per iteration {first.per_iter_s:.4g} s "
            f"(KKT refactorisation {first.factor_s:.4g} s, {first.factor_share:.0%}), setup {first.setup_s:.4g} s, "
            f"fewest certified iterations {first.get('fewest_certified_iterations', float('nan')):.0f}, "
            f"floor {floor:.4g} s{verdict}"
        )


if __name__ == "__main__":
    main()
