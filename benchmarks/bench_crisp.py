"""What the crisp mechanism costs (issue 19): the crisp LP against the certified solve.

For every paper panel (or ``--largest`` only): the certified solve of Eq. 10 (``solve_lp``)
and the crisp mechanism of its optimal face (``alma.associative.crisp``), timed in the same
process; which form found a vertex, or why none.  The target of issue 19 is a crisp mechanism
for at most 20 % of the solve on the largest paper panel.

    python -m benchmarks.bench_crisp [--largest] [--out benchmarks/results/crisp.csv]   (make bench-crisp)
"""

from __future__ import annotations

import argparse
import itertools
import time
from pathlib import Path

import pandas as pd

import alma
from alma.associative.crisp import crisp_mechanism
from alma.associative.lp import solve_lp
from alma.geometry.panels import BONDS
from alma.settings import AssociativeSettings

LARGEST = ("english", "1:2", "1:1", 0.6)


def run(case: tuple) -> dict:
    s = AssociativeSettings()
    model = alma.build_model(alma.paper_panel(*case))
    t0 = time.perf_counter()
    lp = solve_lp(model)
    t1 = time.perf_counter()
    u, why = crisp_mechanism(
        model, lp.upper, s.gap_tolerance * 5e-3, lp.multipliers, lp.mechanism, max_blocks_capped=s.crisp_capped_blocks
    )
    t2 = time.perf_counter()
    return {
        "bond": case[0],
        "panel": case[1],
        "blocks": case[2],
        "friction": case[3],
        "free_blocks": model.n_free,
        "solve_s": t1 - t0,
        "crisp_s": t2 - t1,
        "found": u is not None,
        "how": why,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--largest", action="store_true", help="only the largest paper panel")
    parser.add_argument("--out", type=Path, default=Path("benchmarks/results/crisp.csv"))
    args = parser.parse_args()
    cases = (
        [LARGEST]
        if args.largest
        else list(itertools.product(BONDS, ["2:1", "1:1", "1:2"], ["4:1", "2:1", "1:1"], [0.27, 0.6, 1.0]))
    )
    rows = []
    for case in cases:
        rows.append(run(case))
        r = rows[-1]
        print(
            f"{' '.join(map(str, case)):28s} {r['free_blocks']:5d} blocks  solve {r['solve_s']:.3f} s  "
            f"crisp {r['crisp_s']:.3f} s  {r['how']}",
            flush=True,
        )
    table = pd.DataFrame(rows)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out, index=False)
    print(
        f"solve {table.solve_s.sum():.2f} s, crisp {table.crisp_s.sum():.2f} s "
        f"({table.crisp_s.sum() / table.solve_s.sum():.2f}x), a vertex on {int(table.found.sum())} of {len(table)}"
    )


if __name__ == "__main__":
    main()
