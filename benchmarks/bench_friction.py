"""The friction search (Eq. 9) per scene: its time against the associative solve, and who won.

For each scene: the associative solve's time (Eq. 10, certified), the search's time, their
ratio, the start whose state was kept, α_NL and a reference (the lowest α_NL recorded for it, where
one is). Scenes: the six Ferris & Tin-Loi walls, a 12-block stack-bond scene with cohesion and
joint overrides, LACT³'s three drawings when their folder is given, and with ``--panels`` the
paper's 108 panels.

    python -m benchmarks.bench_friction [--panels] [--lact3 FOLDER] [--perturb] [--out FILE.csv]

``--perturb``: every scene solved again with its data perturbed by 1e-12 relative (unit weight,
a translation, the block order reversed); the table then gives |Δα_NL| / α_NL.
"""

from __future__ import annotations

import argparse
import csv
import math
import statistics
import time
from collections import Counter
from pathlib import Path

import alma
from alma.geometry.scene import Scene
from alma.results.types import NonAssociativeResult

FRICTION = 0.65
_RUN = ([0.5, 1, 1, 1, 1, 0.5], [1] * 5)


def _courses(full_even, full_odd, window_odd, window_even, layout):
    table = {"E": full_even, "U": full_odd, "w": window_even, "u": window_odd}
    return [list(table[c]) for c in layout]


#: Ferris & Tin-Loi (2001)'s six walls as verification/test_ferris_tin_loi.py lays them.
WALLS = {
    1: [list(_RUN[i % 2]) for i in range(6)],
    2: [list(_RUN[i % 2]) for i in range(10)],
    3: _courses([1, 1, 1, 1], [0.5, 1, 1, 1, 0.5], [0.5, 1, -1, 1, 0.5], [1, 0.5, -1, 0.5, 1], "EUEuwuwuEUE"),
    4: _courses(
        [0.5, 1, 1, 1, 1, 0.5], [1] * 5, [1, -1, 1, -1, 1], [0.5, 0.5, -1, 0.5, 0.5, -1, 0.5, 0.5], "EUEuwuwuEUE"
    ),
    5: _courses([0.5, 1, 1, 0.5], [1] * 3, [1, -1, 1], [0.5, 0.5, -1, 0.5, 0.5], "EUEuwuwuEUEuwuwuEUE"),
    6: _courses(
        [0.5] + [1] * 6 + [0.5],
        [1] * 7,
        [0.5, 1, -1, 1, 1, -1, 1, 0.5],
        [1, 0.5, -1, 0.5, 1, 0.5, -1, 0.5, 1],
        "EUEUuwuwuUEUuwuwuUEUE",
    ),
}
#: The lowest α_NL alma recorded for each wall before the canonical search (issue 30's table).
WALL_REFERENCE = {1: 0.638982, 2: 0.557520, 3: 0.355817, 4: 0.263736, 5: 0.208629, 6: 0.295769}
#: LACT³'s drawings: (file, friction angle in degrees).
LACT3 = (("Portal.dxf", 30.0), ("wall.dxf", 26.0), ("arch_1.dxf", 30.0))


def stack_with_cohesion() -> Scene:
    """12 blocks in stack bond (3 wide, 4 high) with c = 0.5 kPa and two weaker joints."""
    blocks = [{"id": "ground", "vertices": [[-200, -100], [1100, -100], [1100, 0], [-200, 0]], "fixed": True}]
    for row in range(4):
        for col in range(3):
            x, y = 300 * col, 150 * row
            blocks.append({"id": f"b{row}{col}", "vertices": [[x, y], [x + 300, y], [x + 300, y + 150], [x, y + 150]]})
    return Scene.from_dict(
        {
            "name": "stack 3x4, cohesion",
            "thickness": 120,
            "unit_weight": 18,
            "friction": 0.6,
            "cohesion": 0.5,
            "blocks": blocks,
            "joints": [
                {"blocks": ["b10", "b11"], "friction": 0.4, "cohesion": 0.0},
                {"blocks": ["b21", "b22"], "friction": 0.5},
            ],
        }
    )


def scenes(args) -> list[tuple[str, Scene, float | None]]:
    out: list[tuple[str, Scene, float | None]] = [
        (
            f"F&TL wall {k}",
            alma.coursed_wall(WALLS[k], 400.0, 175.0, friction=FRICTION, thickness=1000.0, unit_weight=10.0),
            WALL_REFERENCE[k],
        )
        for k in WALLS
    ]
    out.append(("stack 3x4 cohesion", stack_with_cohesion(), None))
    if args.lact3:
        for name, phi in LACT3:
            scene = alma.load_scene(
                Path(args.lact3) / name,
                friction=math.tan(math.radians(phi)),
                thickness=1.0,
                unit_weight=25.0,
                supports="lowest",
            )
            out.append((f"LACT3 {name}", scene, None))
    if args.panels:
        for bond in ("running", "stack", "english", "flemish"):
            for pr in ("2:1", "1:1", "1:2"):
                for br in ("4:1", "2:1", "1:1"):
                    for f in (0.27, 0.6, 1.0):
                        out.append(
                            (
                                f"{bond} {pr} {br} f={f}",
                                alma.paper_panel(bond=bond, panel_ratio=pr, block_ratio=br, friction=f),
                                None,
                            )
                        )
    return out


def perturbed(scene: Scene) -> Scene:
    """The scene with its unit weight × (1 + 1e-12), moved by 1e-12 × its size, blocks reversed."""
    data = scene.to_dict()
    data["unit_weight"] = data["unit_weight"] * (1 + 1e-12)
    size = max(abs(c) for b in data["blocks"] for v in b["vertices"] for c in v)
    for b in data["blocks"]:
        b["vertices"] = [[x + 1e-12 * size, y - 1e-12 * size] for x, y in b["vertices"]]
    for load in data.get("loads", []):
        if "point" in load:
            load["point"] = [load["point"][0] + 1e-12 * size, load["point"][1] - 1e-12 * size]
    data["blocks"] = data["blocks"][::-1]
    return Scene.from_dict(data)


def _same_alpha(a: float, b: float) -> bool:
    """Equal, or both NaN (a search without a state)."""
    return a == b or (math.isnan(a) and math.isnan(b))


#: The walls whose searches issue 30 times against their associative solves, together.
WALLS_TIMED = ("F&TL wall 1", "F&TL wall 3", "F&TL wall 4", "F&TL wall 5")


def measure(name: str, scene: Scene, reference: float | None, perturb: bool, repeat: int = 1) -> dict:
    """One scene's row: the medians of ``repeat`` associative solves and searches (every search
    must give the same α and status), the start kept, α_NL and, with ``perturb``, Δα/α."""
    assoc, search, result = [], [], None
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        alma.solve(scene, model="associative")
        assoc.append(time.perf_counter() - t0)
        again = alma.solve(scene, model="nonassociative")
        assert isinstance(again, NonAssociativeResult)
        if result is None:
            result = again
        elif again.status != result.status or not _same_alpha(again.alpha, result.alpha):
            raise RuntimeError(f"{name}: a repeated search gave {again.alpha!r} ({again.status}), not {result.alpha!r}")
        search.append(again.timings.get("nonassociative_s", math.nan))
    assert result is not None
    assoc_s, search_s = statistics.median(assoc), statistics.median(search)
    row = {
        "scene": name,
        "blocks": result.n_blocks,
        "assoc_s": assoc_s,
        "search_s": search_s,
        "ratio": search_s / assoc_s,
        "start": result.start or "",
        "status": str(result.status),
        "alpha_nl": result.alpha,
        "reference": reference if reference is not None else math.nan,
        "starts": "; ".join(
            f"{r['start']}={r['alpha'] if r['alpha'] is not None else math.nan:.6f}"
            f"{'' if r['verified'] else '?'}/{r['time_s']:.2f}s"
            for r in result.starts
        ),
    }
    if perturb:
        other = alma.solve(perturbed(scene), model="nonassociative")
        row["perturbed_rel"] = abs(other.alpha - result.alpha) / max(abs(result.alpha), 1e-300)
    return row


def differences(rows: list[dict], path: str, tolerance: float = 1e-9) -> list[str]:
    """The scenes whose α_NL or status differ from the run written to ``path`` (relative ``tolerance``)."""
    with open(path, newline="") as handle:
        before = {row["scene"]: row for row in csv.DictReader(handle)}
    out = []
    for row in rows:
        old = before.get(row["scene"])
        if old is None:
            continue
        a, b = float(old["alpha_nl"]), row["alpha_nl"]
        same = (math.isnan(a) and math.isnan(b)) or abs(a - b) <= tolerance * max(abs(a), abs(b), 1e-300)
        if not same or old["status"] != row["status"]:
            out.append(f"{row['scene']}: {old['status']} {a:.9f} in {path}, {row['status']} {b:.9f} now")
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--panels", action="store_true", help="add the paper's 108 panels")
    parser.add_argument("--lact3", metavar="FOLDER", help="LACT³'s sample folder (Portal.dxf, wall.dxf, arch_1.dxf)")
    parser.add_argument("--perturb", action="store_true", help="solve each scene again perturbed by 1e-12")
    parser.add_argument("--only", metavar="TEXT", help="only scenes whose name contains TEXT")
    parser.add_argument("--out", metavar="CSV", help="also write the rows to this CSV file")
    parser.add_argument("--starts", action="store_true", help="print every start's α and time under its row")
    parser.add_argument("--repeat", type=int, default=1, metavar="K", help="the median time of K runs per scene")
    parser.add_argument("--against", metavar="CSV", help="exit 1 when a scene's α_NL or status differs from this run")
    args = parser.parse_args()
    rows = []
    cols = "| scene | blocks | assoc [s] | search [s] | ratio | start kept | status | α_NL | reference |"
    print(cols + (" perturbed Δα/α |" if args.perturb else ""))
    print("|---" * (9 + args.perturb) + "|")
    for name, scene, reference in scenes(args):
        if args.only and args.only not in name:
            continue
        row = measure(name, scene, reference, args.perturb, args.repeat)
        rows.append(row)
        line = (
            f"| {name} | {row['blocks']} | {row['assoc_s']:.3f} | {row['search_s']:.2f} | {row['ratio']:.0f} | "
            f"{row['start']} | {row['status']} | {row['alpha_nl']:.6f} | {row['reference']:.6f} |"
        )
        print(line + (f" {row['perturbed_rel']:.1e} |" if args.perturb else ""), flush=True)
        if args.starts:
            print("    " + row["starts"], flush=True)
    total_a, total_s = sum(r["assoc_s"] for r in rows), sum(r["search_s"] for r in rows)
    print(
        f"\ntotal: associative {total_a:.2f} s, search {total_s:.1f} s, ratio {total_s / total_a:.0f}; "
        f"median ratio {statistics.median(r['ratio'] for r in rows):.0f}"
    )
    walls = [r for r in rows if r["scene"] in WALLS_TIMED]
    if len(walls) == len(WALLS_TIMED):
        wall_a, wall_s = sum(r["assoc_s"] for r in walls), sum(r["search_s"] for r in walls)
        print(f"F&TL walls 1, 3, 4, 5: search {wall_s:.2f} s, associative {wall_a:.3f} s, ratio {wall_s / wall_a:.0f}")
    print("start kept:", dict(Counter(r["start"].split("(")[0] for r in rows).most_common()))
    if args.out:
        with open(args.out, "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    if args.against:
        changed = differences(rows, args.against)
        print(f"against {args.against}: {len(changed)} scene(s) differ" + "".join(f"\n  {c}" for c in changed))
        return 1 if changed else 0
    return 0


if __name__ == "__main__":
    main()
