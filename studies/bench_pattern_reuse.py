"""The interior point's normal-equations pattern shared by the frictions of one geometry (issue 16, item 1).

For each running-bond wall of ``bench_scaling.py`` (``--walls``) the three frictions of the paper
(0.27, 0.6, 1.0) are solved one after another through the interior point, once with every model
building its own pattern ("fresh") and once sharing the pattern of the first friction through
one :class:`alma.engine.PatternCache` ("shared", what a study task does), alternated ``--repeat``
times in one process.  Prints the pattern and total seconds of each pass and checks that both give the
same iterations and α.

    python -m studies.bench_pattern_reuse [--walls 1000,5000,20000] [--repeat 2]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import alma
from alma.associative.lp import solve_lp
from alma.engine import PatternCache
from benchmarks.bench_scaling import wall_shape

ROOT = Path(__file__).resolve().parents[1]

FRICTIONS = (0.27, 0.6, 1.0)


def one_pass(geometry: alma.Model, shared: bool) -> tuple[float, float, list[tuple[int, float]]]:
    """(pattern seconds, total seconds, (iterations, α) per friction) of the three solves."""
    patterns = PatternCache()
    total = pattern = 0.0
    answers = []
    for friction in FRICTIONS:
        model = geometry.with_friction(friction)
        t0 = time.perf_counter()
        lp = solve_lp(model, engine="ipm", patterns=patterns if shared else None)
        total += time.perf_counter() - t0
        pattern += lp.engine["pattern_s"]
        answers.append((lp.iterations, lp.alpha))
    return pattern, total, answers


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--walls", default="1000,5000,20000")
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    for blocks in (int(x) for x in args.walls.split(",") if x):
        courses, per_course = wall_shape(blocks)
        geometry = alma.build_model(alma.wall("running", 240.0 * per_course, 60.0 * courses, 240.0))
        seen: dict[bool, list[tuple[int, float]]] = {}
        for _ in range(args.repeat):
            for shared in (False, True):
                pattern, total, answers = one_pass(geometry, shared)
                seen.setdefault(shared, answers)
                print(
                    f"{geometry.n_free} blocks {'shared' if shared else 'fresh '}: pattern {pattern:.3f} s, "
                    f"three solves {total:.3f} s, iterations {[a[0] for a in answers]}",
                    flush=True,
                )
        same = seen[False] == seen[True]
        print(f"{geometry.n_free} blocks: fresh and shared give the same iterations and alpha: {same}")


if __name__ == "__main__":
    main()
