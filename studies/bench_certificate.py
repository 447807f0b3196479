"""The certificate's Gram solves by QDLDL against feral on the walls (issue 16, item 2).

For each running-bond wall of ``bench_scaling.py`` (``--walls``) the interior point solves Eq. 10
once; its pair is then certified (``alma.associative.lp._certified``) with the Gram
factorisations forced to QDLDL and to feral in turn, ``--repeat`` times each, alternated in one
process.  Medians, the ratio, and the bounds of each (they must agree to round-off).

    python -m studies.bench_certificate [--walls 5000,10000,20000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time
from pathlib import Path

import alma
import alma.associative.lp as lp_module
from alma.backends.termination import SolverResult, Termination
from alma.engine.select import solve_with_engine
from alma.settings import AssociativeSettings
from benchmarks.bench_scaling import wall_shape

ROOT = Path(__file__).resolve().parents[1]

BACKENDS = {"qdldl": 10**12, "feral": 1}  # AssociativeSettings.feral_min_rows forcing each


def measure(blocks: int, repeat: int) -> list[dict]:
    courses, per_course = wall_shape(blocks)
    model = alma.build_model(alma.wall("running", 240.0 * per_course, 60.0 * courses, 240.0))
    s = AssociativeSettings()
    ans = solve_with_engine(model.equilibrium, model.dead, model.live, s.normalisation * model.n_free)
    pair = SolverResult(Termination.OPTIMAL, ans.status, ans.x, ans.duals, ans.iterations, 0.0, ans.label)
    times: dict[str, list[float]] = {name: [] for name in BACKENDS}
    last = {}
    for _ in range(repeat):
        for name, rows in BACKENDS.items():  # alternated: machine load falls on both alike
            forced = dataclasses.replace(s, feral_min_rows=rows)
            t0 = time.perf_counter()
            last[name] = lp_module._certified(model, model.equilibrium, forced, pair, "ipm", "", {})
            times[name].append(time.perf_counter() - t0)
    return [
        dict(
            blocks=model.n_free,
            gram=name,
            certify_s=statistics.median(times[name]),
            status=str(last[name].status),
            lower=last[name].lower,
            upper=last[name].upper,
        )
        for name in BACKENDS
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--walls", default="5000,10000,20000")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"{'blocks':>7} {'gram':>6} {'certify s':>10} {'status':>8} {'lower':>14} {'upper':>14}")
    for blocks in (int(w) for w in args.walls.split(",") if w):
        rows = measure(blocks, args.repeat)
        for r in rows:
            print(
                f"{r['blocks']:7d} {r['gram']:>6} {r['certify_s']:10.3f} {r['status']:>8} "
                f"{r['lower']:14.11f} {r['upper']:14.11f}",
                flush=True,
            )
        print(f"{'':7} qdldl/feral {rows[0]['certify_s'] / rows[1]['certify_s']:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
