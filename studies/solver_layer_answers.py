"""Did a refactoring move an answer?  α_NL, its status, the start kept, every start's α, and the
associative α, bounds and status of 21 scenes, written to JSON, and two such files compared.

The friction search (Eq. 9) branches on LP vertices, so its answer hangs on the last bits of every
solve: issue 35's solver layer was checked with this (docs/decisions.md, "One solver layer").
Scenes: the quick and larger scenes of ``verification/test_friction_invariance.py``, the six
Ferris & Tin-Loi walls, the 12-block stack with cohesion, four paper panels.  About 6 minutes
on 2 idle cores; run it from the top of a clone, before and after the change:

    python -m studies.solver_layer_answers record before.json [--only TEXT]
    python -m studies.solver_layer_answers record after.json
    python -m studies.solver_layer_answers compare before.json after.json
"""

from __future__ import annotations

import argparse
import functools
import json
import sys
import time
from collections.abc import Callable, Iterator

import alma
from alma.geometry.scene import Scene
from benchmarks.bench_friction import FRICTION, WALLS, stack_with_cohesion
from verification.test_friction_invariance import QUICK, SLOW

PANELS = (
    ("running", "1:1", "2:1", 0.6),
    ("stack", "1:2", "1:1", 0.27),
    ("english", "2:1", "4:1", 0.6),
    ("flemish", "1:1", "1:1", 1.0),
)


def _from_dict(make: Callable[[], dict]) -> Scene:
    return Scene.from_dict(make())


def _wall(k: int) -> Scene:
    return alma.coursed_wall(WALLS[k], 400.0, 175.0, friction=FRICTION, thickness=1000.0, unit_weight=10.0)


def _panel(panel: tuple[str, str, str, float]) -> Scene:
    return alma.paper_panel(*panel)


def scenes() -> Iterator[tuple[str, Callable[[], Scene]]]:
    for name, make in QUICK.items():
        yield "Q " + name, functools.partial(_from_dict, make)
    for name, make in SLOW.items():
        yield "S " + name, functools.partial(_from_dict, make)
    for k in WALLS:
        yield f"FTL {k}", functools.partial(_wall, k)
    yield "stack cohesion", stack_with_cohesion
    for panel in PANELS:
        yield "panel " + " ".join(map(str, panel)), functools.partial(_panel, panel)


def record(path: str, only: str | None) -> None:
    out = {}
    for name, make in scenes():
        if only and only not in name:
            continue
        t0 = time.perf_counter()
        both = alma.solve(make(), model="both")
        a, n = both.associative, both.nonassociative
        assert a is not None and n is not None
        out[name] = {
            "assoc_alpha": repr(a.alpha),
            "assoc_status": str(a.status),
            "assoc_bounds": repr((a.bounds.lower, a.bounds.upper)),
            "nl_alpha": repr(n.alpha),
            "nl_status": str(n.status),
            "nl_start": n.start,
            "starts": [(s["start"], repr(s["alpha"]), s["verified"]) for s in n.starts],
        }
        print(f"{name}: {time.perf_counter() - t0:.1f} s, α_NL {n.alpha!r} {n.status} {n.start}", flush=True)
    with open(path, "w") as handle:
        json.dump(out, handle, indent=1)


def compare(before: str, after: str) -> int:
    with open(before) as a_file, open(after) as b_file:
        a, b = json.load(a_file), json.load(b_file)
    differences = [f"{name}: missing" for name in a if name not in b]
    differences += [
        f"{name} {key}: {a[name][key]} -> {b[name][key]}"
        for name in a
        if name in b
        for key in a[name]
        if a[name][key] != b[name][key]
    ]
    for line in differences:
        print(line)
    print(f"{len(a)} scenes compared, {len(differences)} differences (every float compared by repr)")
    return 1 if differences else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="solve the scenes and write their answers to JSON")
    rec.add_argument("out")
    rec.add_argument("--only", metavar="TEXT", help="only scenes whose name contains TEXT")
    cmp = sub.add_parser("compare", help="compare two recorded files")
    cmp.add_argument("before")
    cmp.add_argument("after")
    args = parser.parse_args()
    if args.command == "record":
        record(args.out, args.only)
        return 0
    return compare(args.before, args.after)


if __name__ == "__main__":
    sys.exit(main())
