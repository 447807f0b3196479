"""alma's interior point (alma.engine) against alma's Clarabel path on Eq. 10 (issue 16).

Cases: the largest paper panel (english 1:2 1:1, f = 0.6, 1,752 blocks) end to end (joints,
build, solve, certificate), the running-bond walls of ``bench_scaling.py`` (``--walls``), and
the 108 paper panels solved one after another (``--panels``).  Each case and engine runs in its
own subprocess so that its peak resident memory is its own; times are medians of ``--repeat``
runs, ratios are taken within one subprocess pair on the same model.  For the interior point
the record splits the time into pattern (symbolic, once per geometry), factorisation and
solves, and counts iterations; the certificate (``alma.associative.certificate``) decides the
status for both engines.

    .venv/bin/python -m benchmarks.bench_engine [--walls 1000,5000,10000,20000] [--repeat 3]
        [--backend auto] [--panels] [--clarabel-walls 1000,5000,10000,20000]
        [--ipx-walls 1000,5000,10000] [--ipx-repeat 1]

HiGHS IPX (``solver="ipm"``, crossover off, its pair passed to the same certificate) is a third
column for reference.  The 100,000-block wall: ``--walls 100000 --clarabel-walls "" --ipx-walls ""
--repeat 1`` (the interior point alone; peak RSS is the worker's).

Writes benchmarks/results/engine.csv (and engine_panels.csv with ``--panels``).
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.harness import run_worker

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"


def _model(case: str):
    import alma
    from benchmarks.bench_scaling import wall_shape

    if case == "panel":
        scene = alma.paper_panel(bond="english", panel_ratio="1:2", block_ratio="1:1", friction=0.6)
    else:
        courses, per_course = wall_shape(int(case))
        scene = alma.wall("running", 240.0 * per_course, 60.0 * courses, 240.0)
    return scene


def _one(scene, engine: str, backend: str) -> dict:
    """One end-to-end certified solve: joints + build + solve + certificate."""
    from alma.associative.lp import solve_lp
    from alma.engine import IPMSettings
    from alma.geometry.contacts import find_joints
    from alma.mechanics.model import build_model

    t0 = time.perf_counter()
    model = build_model(scene, find_joints(scene))
    t1 = time.perf_counter()
    row: dict[str, Any] = dict(blocks=model.n_free, build_s=t1 - t0)
    if engine == "clarabel":
        lp = solve_lp(model, engine="clarabel")
    else:
        lp = solve_lp(model, engine="ipm", ipm_settings=IPMSettings(backend=backend))
        tm = lp.engine
        row.update(
            backend=backend,
            pattern_s=tm.get("pattern_s"),
            factor_s=tm.get("factor_s"),
            solves_s=tm.get("solve_s"),
            factorisations=tm.get("factorisations"),
            solves=tm.get("solves"),
            engine_status="optimal" if tm else "fell back to Clarabel",
        )
    row.update(
        total_s=time.perf_counter() - t0,
        solve_s=lp.solve_time,
        certify_s=lp.certify_time,
        status=lp.status,
        alpha=lp.alpha,
        lower=lp.lower,
        upper=lp.upper,
        iterations=lp.iterations,
        gap=(lp.upper - lp.lower) / max(1.0, abs(lp.upper)),
    )
    return row


def _one_ipx(scene) -> dict:
    """HiGHS IPX (interior point, crossover off) on the same kinematic LP, its pair passed to
    alma's certificate: a reference, not one of alma's engines."""
    from alma.associative.lp import _certified
    from alma.associative.lp_forms import _kinematic_form
    from alma.backends.highs_backend import conic_lp, quiet_highs
    from alma.backends.termination import SolverResult, termination
    from alma.geometry.contacts import find_joints
    from alma.mechanics.model import build_model
    from alma.settings import AssociativeSettings

    t0 = time.perf_counter()
    model = build_model(scene, find_joints(scene))
    s = AssociativeSettings()
    q, A, b = _kinematic_form(model, model.equilibrium, s.normalisation)
    highs_model = conic_lp(q, A, b, 1)
    t1 = time.perf_counter()
    h = quiet_highs(solver="ipm", run_crossover="off")
    h.passModel(highs_model)
    h.run()
    t2 = time.perf_counter()
    raw = str(h.getModelStatus()).rsplit(".", 1)[-1]
    sol = h.getSolution()
    pair = SolverResult(
        termination("highs", raw),
        raw,
        np.asarray(sol.col_value, float),
        -np.asarray(sol.row_dual, float),
        int(h.getInfo().ipm_iteration_count),
        t2 - t1,
        "HiGHS IPX",
    )
    lp_sol = _certified(model, model.equilibrium, s, pair, "HiGHS IPX", "", {})
    return dict(
        blocks=model.n_free,
        build_s=t1 - t0,
        total_s=time.perf_counter() - t0,
        solve_s=t2 - t1,
        certify_s=lp_sol.certify_time,
        status=lp_sol.status,
        alpha=lp_sol.alpha,
        lower=lp_sol.lower,
        upper=lp_sol.upper,
        iterations=pair.iterations,
        engine_status=raw,
        gap=(lp_sol.upper - lp_sol.lower) / max(1.0, abs(lp_sol.upper)),
    )


def worker(case: str, engine: str, backend: str, repeat: int) -> dict:
    from alma.engine import available_backends

    t0 = time.perf_counter()
    available_backends()  # locates and loads the backends' libraries once per process (MKL: ~0.5 s)
    load_s = time.perf_counter() - t0
    scene = _model(case)
    runs = [_one_ipx(scene) if engine == "ipx" else _one(scene, engine, backend) for _ in range(repeat)]
    out = dict(runs[-1])
    for key in ("build_s", "total_s", "solve_s", "certify_s", "pattern_s", "factor_s", "solves_s"):
        if key in out:
            out[key] = statistics.median(r[key] for r in runs)
    out.update(
        case=case,
        engine=engine,
        repeat=repeat,
        library_load_s=load_s,
        peak_rss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    )
    if "factorisations" in out and out["iterations"]:
        out["per_iteration_s"] = (out["factor_s"] + out["solves_s"]) / max(out["factorisations"], 1)
        out["factor_share"] = out["factor_s"] / max(out["solve_s"], 1e-12)
    return out


def panels_worker(engine: str, backend: str) -> dict:
    """The 108 panels one after another (geometry built once, friction varied; the frictions of
    a geometry share the interior point's normal-equations pattern, as in a study)."""
    from alma.associative.lp import solve_lp
    from alma.engine import PatternCache
    from benchmarks.harness import panel_geometry, table5

    total, certified, iterations = 0.0, 0, 0
    patterns = PatternCache()
    for bond, panel_ratio, block_ratio, friction, _ in table5():
        model = panel_geometry(bond, panel_ratio, block_ratio).with_friction(friction)
        t0 = time.perf_counter()
        lp = solve_lp(model, engine=engine, patterns=patterns)
        total += time.perf_counter() - t0
        certified += lp.status == "optimal" and "Clarabel used" not in lp.message
        iterations += lp.iterations
    return dict(engine=engine, panels=len(table5()), certified=certified, solve_certify_s=total, iterations=iterations)


def _spawn(args: list[str]) -> dict:
    return run_worker("benchmarks.bench_engine", args)


def fit(blocks, seconds) -> float:
    x, y = np.asarray(blocks, float), np.asarray(seconds, float)
    ok = (x >= 1000) & np.isfinite(y) & (y > 0)
    return float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0]) if ok.sum() >= 2 else float("nan")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--walls", default="1000,5000,10000,20000")
    parser.add_argument("--clarabel-walls", default=None, help="walls also solved by Clarabel (default: --walls)")
    parser.add_argument(
        "--ipx-walls",
        default="1000,5000,10000",
        help="walls also solved by HiGHS IPX, crossover off (a reference; slow: ~2 min at 10,000)",
    )
    parser.add_argument("--ipx-repeat", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--backend", default="auto")
    parser.add_argument("--panels", action="store_true", help="also the 108 panels, each engine")
    parser.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--panels-worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(worker(args.worker[0], args.worker[1], args.backend, args.repeat)))
        return
    if args.panels_worker:
        print(json.dumps(panels_worker(args.panels_worker, args.backend)))
        return
    import pandas as pd

    RESULTS.mkdir(parents=True, exist_ok=True)
    walls = [w for w in args.walls.split(",") if w]
    clarabel_walls = set(walls if args.clarabel_walls is None else [w for w in args.clarabel_walls.split(",") if w])
    ipx_walls = {w for w in args.ipx_walls.split(",") if w}
    rows = []
    for case in ["panel", *walls]:
        for engine in ("ipm", "clarabel", "ipx"):
            runs = {"ipm": set(walls), "clarabel": clarabel_walls, "ipx": ipx_walls}[engine]
            if case != "panel" and case not in runs:
                continue
            repeat = args.ipx_repeat if engine == "ipx" else args.repeat
            row = _spawn(["--worker", case, engine, "--repeat", str(repeat), "--backend", args.backend])
            row.setdefault("case", case)
            row.setdefault("engine", engine)
            rows.append(row)
            print(json.dumps(row), flush=True)
    df = pd.DataFrame(rows)
    df.to_csv(RESULTS / "engine.csv", index=False)
    _report(df)
    if args.panels:
        panels = pd.DataFrame([_spawn(["--panels-worker", e, "--backend", args.backend]) for e in ("ipm", "clarabel")])
        panels.to_csv(RESULTS / "engine_panels.csv", index=False)
        print("\n== 108 paper panels, one process, serial ==")
        print(panels.to_string(index=False))


def _report(df) -> None:
    import pandas as pd

    pd.set_option("display.width", 250)
    cols = [
        "case",
        "engine",
        "backend",
        "blocks",
        "status",
        "iterations",
        "total_s",
        "solve_s",
        "certify_s",
        "pattern_s",
        "factor_s",
        "solves_s",
        "per_iteration_s",
        "peak_rss_mb",
        "gap",
        "alpha",
    ]
    print("\n== end to end (joints + build + solve + certificate), medians ==")
    print(df[[c for c in cols if c in df]].to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    ok = df[df.get("status", pd.Series(dtype=str)) == "optimal"] if "status" in df else df.iloc[:0]
    for engine in ("ipm", "clarabel", "ipx"):
        sub = ok[(ok.engine == engine) & (ok.case != "panel")]
        print(f"fitted exponent, {engine}: total_s ∝ blocks^{fit(sub.blocks, sub.total_s):.2f} (walls ≥ 1,000 blocks)")
    pivot = ok.pivot_table(index="case", columns="engine", values="total_s")
    for other in ("clarabel", "ipx"):
        if {"ipm", other} <= set(pivot.columns):
            print(f"\n{other} / ipm (end to end):")
            print((pivot[other] / pivot["ipm"]).to_string(float_format=lambda x: f"{x:.2f}"))


if __name__ == "__main__":
    main()
