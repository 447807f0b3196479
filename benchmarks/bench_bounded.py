"""What cohesion and ties cost: the associative solve of the largest paper panel with and without.

The target (issue 17): cohesion and ties cost ≤ 10 % more solve time than the plain LP on the
largest paper panel (english 1:2 1:1, f = 0.6, 1,752 blocks).  Medians of ``--repeat`` runs of
``solve_lp`` (solve and certificate), every case and engine in one process, ratios against the
plain panel on the same engine (``auto``: the default choice for each), and the time per
iteration, which separates what the formulation costs (more columns per iteration) from what the
problem costs (more iterations).

``--sweep`` adds the cohesion sweep: how the iteration count of each engine follows c.

    python -m benchmarks.bench_bounded [--repeat 5] [--sweep]      (make bench-bounded)
"""

from __future__ import annotations

import argparse
from functools import partial

import alma
from alma.associative.lp import solve_lp
from alma.geometry.chains import with_chain
from benchmarks.harness import median_time

#: "auto" is what a user gets by default: Clarabel for the plain panel (< AUTO_MIN_BLOCKS), the
#: interior point with cohesion or ties (>= AUTO_MIN_BLOCKS_BOUNDED).
ENGINES = ("ipm", "clarabel", "auto")
SWEEP = (0.001, 0.1, 1.0, 5.0, 50.0)  # kPa


def _cohesive(scene: alma.Scene, c: float) -> alma.Scene:
    return alma.Scene.from_dict({**scene.to_dict(), "cohesion": c})


def cases() -> dict[str, alma.Scene]:
    panel = alma.paper_panel("english", "1:2", "1:1", 0.6)
    chained = panel
    for height in (690.0, 1410.0, 2130.0, 2850.0):
        chained = with_chain(chained, height, 5.0)
    chained = chained.validate()
    return {
        "plain": panel,
        "cohesion 5 kPa": _cohesive(panel, 5.0),
        "4 chains": chained,
        "cohesion + chains": _cohesive(chained, 5.0),
    }


def _table(scenes: dict[str, alma.Scene], repeat: int) -> list[tuple]:
    rows = []
    for engine in ENGINES:
        base = None
        for name, scene in scenes.items():
            model = alma.build_model(scene)
            seconds, lp = median_time(partial(solve_lp, model, engine=engine), repeat)
            base = base or (seconds, lp.iterations)
            rows.append(
                (
                    engine,
                    name,
                    seconds,
                    seconds / base[0],
                    lp.iterations,
                    lp.iterations / base[1],
                    1e3 * seconds / max(lp.iterations, 1),
                    str(lp.status),
                    lp.alpha,
                )
            )
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--sweep", action="store_true", help="also cohesion 0.001–50 kPa on the same panel")
    args = ap.parse_args(argv)
    scenes = cases()
    if args.sweep:
        scenes.update({f"c = {c:g} kPa": _cohesive(scenes["plain"], c) for c in SWEEP})
    print(
        f"{'engine':<9} {'case':<20} {'median s':>9} {'x plain':>8} {'iterations':>10} {'x plain':>8} "
        f"{'ms/iter':>8} {'status':>9} {'alpha':>10}"
    )
    for engine, name, s, rs, it, ri, ms, status, alpha in _table(scenes, args.repeat):
        print(f"{engine:<9} {name:<20} {s:9.3f} {rs:8.2f} {it:10d} {ri:8.2f} {ms:8.2f} {status:>9} {alpha:10.6f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
