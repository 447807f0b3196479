"""Cost of a capacity curve (``alma.push``) against one associative solve (issue 33).

The target: a 40-step curve of a 444-block panel (english 1:1 2:1, f = 0.6) in at most 40 times
one associative solve, one solve a configuration.  Both are timed in the same run (ratios, not
absolute times, are what a shared machine can measure); the curve's LP solves, its status and
its cost per configuration (in single solves: ``per_configuration``, the target's 1) are printed
beside them, since a curve that loses its equilibrium early has few configurations (that
panel's ends at 0.49 mm; ``--bond stack --block-ratio 1:1 --friction 0.27``, 576 blocks, rocks
to α = 0 over 40 steps; ``--bond running --panel-ratio 1:2 --block-ratio 1:1 --friction 0.27``,
1,176 blocks, loses its equilibrium at 71 mm after 22 configurations).
With ``--model nonassociative`` each step and each single solve is the friction search.

    python benchmarks/bench_push.py [--bond english --panel-ratio 1:1 --block-ratio 2:1 --steps 40]
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import alma
from alma.push import PUSH_MODELS


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bond", default="english")
    parser.add_argument("--panel-ratio", default="1:1")
    parser.add_argument("--block-ratio", default="2:1")
    parser.add_argument("--friction", type=float, default=0.6)
    parser.add_argument("--steps", type=int, default=40)
    parser.add_argument("--repeat", type=int, default=3, help="single solves timed (the median is used)")
    parser.add_argument("--model", default="associative", choices=PUSH_MODELS)
    args = parser.parse_args(argv)
    panel = alma.paper_panel(
        bond=args.bond, panel_ratio=args.panel_ratio, block_ratio=args.block_ratio, friction=args.friction
    )
    n = sum(not b.fixed for b in panel.blocks)
    singles = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        alma.solve(panel, model=args.model)
        singles.append(time.perf_counter() - t0)
    single = sorted(singles)[len(singles) // 2]
    t0 = time.perf_counter()
    curve = alma.push(panel, steps=args.steps, model=args.model)
    total = time.perf_counter() - t0
    out = {
        "panel": f"{args.bond} {args.panel_ratio} {args.block_ratio} f={args.friction}",
        "model": args.model,
        "free_blocks": n,
        "single_solve_s": round(single, 3),
        "curve_s": round(total, 3),
        "ratio": round(total / single, 1),
        "per_configuration": round(total / single / len(curve.curve), 2),
        "target_ratio": args.steps,
        "solves": curve.solves,
        "points": len(curve.curve),
        "status": str(curve.status),
        "d0_mm": curve.d0 if curve.d0 == curve.d0 else None,
        "end": curve.end.get("reason"),
        "alpha_c": curve.alpha_c,
        "mechanism_changes": sum(p.mechanism_changed for p in curve.curve),
        "message": curve.message,
    }
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
