"""Where ``engine="auto"`` should switch from Clarabel to alma's interior point.

Each of the 108 paper panels (Table 5) is solved and certified by both engines in one process,
the best of ``--repeat`` runs each, and the totals are binned by the number of free blocks.
``alma.engine.select.AUTO_MIN_BLOCKS`` is the bin edge from which the interior point is faster;
with ``--cohesion C`` (kPa on every joint) the same for the bounded-force problem
(``AUTO_MIN_BLOCKS_BOUNDED``).

    python -m studies.bench_engine_crossover [--repeat 2] [--cohesion 0]
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import time
from pathlib import Path

import numpy as np

from alma.associative.lp import solve_lp
from alma.mechanics.model import build_model
from benchmarks.harness import panel_geometry, table5

ROOT = Path(__file__).resolve().parents[1]

EDGES = (0, 200, 400, 700, 1000, 1400, 2000)


def measure(repeat: int, cohesion: float = 0.0) -> np.ndarray:
    """(n_free, ipm seconds, Clarabel seconds) per panel, the best of ``repeat`` runs each."""
    rows = []
    for bond, panel_ratio, block_ratio, friction, _ in table5():
        model = panel_geometry(bond, panel_ratio, block_ratio).with_friction(friction)
        if cohesion:
            model = build_model(dataclasses.replace(model.scene, cohesion=cohesion))
        best = {"ipm": np.inf, "clarabel": np.inf}
        for _ in range(repeat):
            for engine in best:  # alternated, so that machine load falls on both alike
                t0 = time.perf_counter()
                solve_lp(model, engine=engine)
                best[engine] = min(best[engine], time.perf_counter() - t0)
        rows.append((model.n_free, best["ipm"], best["clarabel"]))
    return np.array(rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--cohesion", type=float, default=0.0, help="cohesion on every joint, kPa")
    args = ap.parse_args(argv)
    a = measure(args.repeat, args.cohesion)
    print(f"{'free blocks':>12} {'panels':>6} {'ipm s':>7} {'Clarabel s':>10} {'Clarabel/ipm':>12}")
    for lo, hi in itertools.pairwise(EDGES):
        sel = (a[:, 0] >= lo) & (a[:, 0] < hi)
        if sel.any():
            ipm, cl = a[sel, 1].sum(), a[sel, 2].sum()
            print(f"{lo:>5}-{hi:<6} {int(sel.sum()):6d} {ipm:7.3f} {cl:10.3f} {cl / ipm:12.2f}")
    print(f"{'all':>12} {len(a):6d} {a[:, 1].sum():7.3f} {a[:, 2].sum():10.3f} {a[:, 2].sum() / a[:, 1].sum():12.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
