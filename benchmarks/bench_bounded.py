"""What cohesion and ties cost: the associative solve of the largest paper panel with and without.

The target (issue 17): cohesion and ties cost ≤ 10 % more solve time than the plain LP on the
largest paper panel (english 1:2 1:1, f = 0.6, 1,752 blocks).  Medians of ``--repeat`` runs of
``alma.solve`` end to end, all cases in one process, ratios against the plain panel.

    python benchmarks/bench_bounded.py [--repeat 5]      (make bench-bounded)
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import alma
from alma.geometry.chains import with_chain

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_lp import median_time  # noqa: E402


def cases() -> dict[str, alma.Scene]:
    panel = alma.paper_panel("english", "1:2", "1:1", 0.6)
    data = panel.to_dict()
    cohesive = alma.Scene.from_dict({**data, "cohesion": 5.0})
    chained = panel
    for height in (690.0, 1410.0, 2130.0, 2850.0):
        chained = with_chain(chained, height, 5.0)
    chained.validate()
    both = alma.Scene.from_dict({**chained.to_dict(), "cohesion": 5.0})
    return {"plain": panel, "cohesion 5 kPa": cohesive, "4 chains": chained, "cohesion + chains": both}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    rows = []
    for name, scene in cases().items():
        model = alma.build_model(scene)
        seconds, result = median_time(lambda m=model: alma.solve(m), args.repeat)
        rows.append((name, seconds, result))
    base = rows[0][1]
    print(f"{'case':<20} {'median s':>9} {'x plain':>8} {'iterations':>10} {'status':>9} {'alpha':>10}")
    for name, seconds, result in rows:
        print(f"{name:<20} {seconds:9.3f} {seconds / base:8.2f} {result.iterations:10d} {result.status!s:>9} "
              f"{result.alpha:10.6f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
