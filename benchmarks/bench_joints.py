"""Joint detection alone: time and peak memory of ``alma.find_joints`` on running-bond walls.

The walls are those of ``bench_scaling.py`` (240 × 60 mm blocks on a fixed ground).  Each size
runs in its own subprocess so that its peak resident memory is its own; the table gives the
median time of ``--repeat`` calls and the peak RSS above the one after building the scene.
``--alma`` points the subprocesses at another copy of the package (e.g. an older commit
exported with ``git archive``) to compare implementations on the same machine.  ``--far D``
adds one fixed block D mm to the right of the wall: the cost must not depend on the extent.
``--panel BOND:PANEL:BLOCK`` times one paper panel instead of the walls (e.g.
``english:1:2:1:1``, the largest, 1,753 blocks).  Where the copy has ``alma.geometry.snap``,
the vertex snapping's own work (``snap_edges``: merging and T-junctions; the candidate search
it shares with joint detection left out) is timed too, with its share of ``find_joints``; time
a copy without it (``--alma``) for the whole difference.

    .venv/bin/python -m benchmarks.bench_joints [--sizes 1000,3000,...] [--repeat 5] [--alma DIR] [--far D]
    .venv/bin/python -m benchmarks.bench_joints --panel english:1:2:1:1 [--repeat 5]
    .venv/bin/python -m benchmarks.bench_joints [--sizes 1000,3000,...] [--repeat 5] [--alma DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import time
from pathlib import Path

from benchmarks.harness import run_worker

ROOT = Path(__file__).resolve().parents[1]
SIZES = (1000, 3000, 10000, 20000, 100000)


def worker(n: int, repeat: int, far: float = 0.0, panel: str = "") -> dict:
    import alma
    from alma.geometry.contacts import find_joints
    from benchmarks.bench_scaling import wall_shape

    if panel:
        bond, p1, p2, b1, b2 = panel.split(":")
        scene = alma.paper_panel(bond, f"{p1}:{p2}", f"{b1}:{b2}", 0.6)
    else:
        courses, per_course = wall_shape(n)
        scene = alma.wall("running", 240.0 * per_course, 60.0 * courses, 240.0)
    if far:
        data = scene.to_dict()
        x = 240.0 * per_course + far
        data["blocks"].append({"id": "far", "fixed": True, "vertices": [[x, 0], [x + 240, 0], [x + 240, 60], [x, 60]]})
        scene = alma.Scene.from_dict(data)
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        joints = find_joints(scene)
        times.append(time.perf_counter() - t0)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return dict(
        target=n,
        blocks=len(scene.blocks),
        joints=joints.count,
        joints_s=statistics.median(times),
        min_s=min(times),
        rss_scene_mb=base,
        rss_peak_mb=peak,
        rss_above_scene_mb=peak - base,
        snap_s=_snap_time(scene, repeat),
        alma=str(Path(alma.__file__).parent),
    )


def _snap_time(scene, repeat: int) -> float | None:
    """Median time of the vertex snapping's own work (merging and T-junctions), the candidate
    search it shares with joint detection left out (None where the timed copy has no snapping)."""
    try:
        from alma.geometry.snap import snap_edges
    except ImportError:
        return None
    from alma.geometry.contacts import _pair_indices
    from alma.geometry.edges import CONTACT, contact_lengths, local_origin, scene_edges

    edges = scene_edges(scene, local_origin(scene))
    snap, band = contact_lengths(scene, edges)
    reach = (CONTACT.vertex_merge + 1.0) * snap
    pairs = _pair_indices(edges, reach, max(band, reach))
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        snap_edges(scene, edges, snap, lambda merged: pairs)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)))
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--alma", default=str(ROOT), help="directory holding the alma package to time")
    parser.add_argument("--far", type=float, default=0.0, help="mm: one fixed block this far from the wall")
    parser.add_argument("--panel", default="", help="BOND:PANEL:BLOCK ratios, e.g. english:1:2:1:1")
    parser.add_argument("--worker", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(worker(args.worker, args.repeat, args.far, args.panel)))
        return
    # The copy of alma to time first on the path, this clone after it for the benchmarks package;
    # the worker starts in that copy's folder (python -m puts its working folder first).
    alma_dir = Path(args.alma).resolve()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(alma_dir), str(ROOT)]))
    sizes = [1] if args.panel else [int(s) for s in args.sizes.split(",") if s]
    for n in sizes:
        argv = ["--worker", str(n), "--repeat", str(args.repeat), "--far", repr(args.far), "--panel", args.panel]
        r = run_worker("benchmarks.bench_joints", argv, env=env, cwd=alma_dir)
        if "error" in r:
            print(f"{n}: worker failed: {r['error']}", flush=True)
            continue
        print(
            f"{r['blocks']:7d} blocks {r['joints']:7d} joints: find_joints median {r['joints_s']:.4f} s "
            f"(min {r['min_s']:.4f}), peak RSS {r['rss_peak_mb']:.0f} MB "
            f"({r['rss_above_scene_mb']:.0f} MB above the scene)  [{r['alma']}]",
            flush=True,
        )
        if r.get("snap_s") is not None:
            print(
                f"{'':15s}snapping's own work: median {r['snap_s']:.4f} s, "
                f"{r['snap_s'] / r['joints_s']:.2f} of find_joints",
                flush=True,
            )


if __name__ == "__main__":
    main()
