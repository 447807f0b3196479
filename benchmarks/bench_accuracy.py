"""Run time against error for the associative LP (SPEC §6: benchmarks).

Every method solves the same LP, built once per case by ``alma.build_model`` (joint detection
and assembly are not timed here; see ``bench_scaling.py``):

- ``alma tol=…``  ``alma.solve(model, tolerance=tol)``: Clarabel on the kinematic LP, then the
  certification of both bounds (time = solve + certify). tol = 1e-11 is alma's default;
- ``clarabel plain``  the kinematic LP straight into Clarabel with default settings, no
  certification;
- ``highs-ipm``, ``highs-ipm no crossover``, ``highs-ds``  ``scipy.optimize.linprog`` on the
  static LP (max α s.t. Hμ + f_0 + α f_L = 0, μ ≥ 0) with default HiGHS tolerances; crossover is
  switched off with the HiGHS option ``run_crossover="off"``, which SciPy passes through
  verbatim (with an OptimizeWarning);
- ``cvxpy CLARABEL``, ``cvxpy HIGHS``  the kinematic LP written in cvxpy (what a user would
  otherwise write), time includes cvxpy's canonicalisation.

Reference value of each case: the midpoint of alma's certified interval at tol = 1e-11. The
benchmark re-checks that certificate from the raw fields (μ ≥ 0 and the equilibrium residual of
the static field; the flow-rule residual of the mechanism; both bounds recomputed from H), and
compares it with an independent solve: HiGHS dual simplex on the kinematic LP with feasibility
tolerances tightened to 1e-10 (untimed).  Their agreement is printed and written to the CSV.

Error = |α − α_ref| / |α_ref| (all α_ref here are between 0.02 and 1).

Each timing is the median of ``--repeat`` runs in the same process, except that a solve whose
first run takes longer than ``--single-above`` seconds is run once (the budget of one command
is ~15 minutes on 2 shared cores); a solve that hits ``--time-limit`` counts as not solved.

    .venv/bin/python -m benchmarks.bench_accuracy [--cases default|full|quick] [--repeat 3]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
import warnings
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import OptimizeWarning, linprog

import alma
from alma.associative.lp import solve_lp
from alma.geometry.panels import BLOCK_LENGTHS, BONDS, PANEL_HEIGHTS
from benchmarks.accuracy_methods import DEFAULT_NAME, DEFAULT_TOLERANCE, method_table

ROOT = Path(__file__).resolve().parents[1]


# ----------------------------------------------------------------------------- reference
def reference(model, time_limit: float) -> dict:
    """alma's certified interval at the default tolerance, re-checked from the raw fields and
    compared with HiGHS dual simplex (kinematic LP, feasibility tolerances 1e-10)."""
    lp = solve_lp(model, tolerance=DEFAULT_TOLERANCE)
    H = model.equilibrium
    mu, u = lp.multipliers, lp.mechanism
    static_res = float(np.abs(H @ mu + model.dead + lp.lower * model.live).max())
    power = H.T @ u
    flow_res = max(0.0, -float(power.min())) / float((abs(H.T) @ np.abs(u)).max())
    upper = float(-model.dead @ u / (model.live @ u))
    mid = 0.5 * (lp.lower + lp.upper)
    tight = dict(primal_feasibility_tolerance=1e-10, dual_feasibility_tolerance=1e-10, time_limit=float(time_limit))
    k = H.shape[1]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", OptimizeWarning)
        res = linprog(
            -model.dead,
            A_ub=-H.T,
            b_ub=np.zeros(k),
            A_eq=model.live.reshape(1, -1),
            b_eq=[1.0],
            bounds=(None, None),
            method="highs-ds",
            options=tight,
        )
    check = float(res.fun) if res.status == 0 else math.nan
    return dict(
        alpha_ref=mid,
        ref_lower=lp.lower,
        ref_upper=lp.upper,
        ref_status=lp.status,
        ref_gap=(lp.upper - lp.lower) / abs(mid),
        ref_mu_min=float(mu.min(initial=0.0)),
        ref_static_residual=static_res,
        ref_flow_residual=flow_res,
        ref_upper_recomputed_diff=abs(upper - lp.upper) / abs(mid),
        check_highs_ds_tight=check,
        check_agreement=abs(check - mid) / abs(mid),
    )


# ----------------------------------------------------------------------------- cases
def cases(which: str):
    """(name, blocks-hint, scene factory) of the benchmark cases."""
    out = []
    largest = [(b, "1:2", "1:1") for b in BONDS]
    if which == "quick":
        for bond in BONDS:
            out.append((bond, "2:1", "4:1", 0.6))
        panels = out
        walls = [(10, 20)]
    else:
        panels = []
        frictions_all = (0.27, 0.6, 1.0)
        for bond in BONDS:
            for pr in PANEL_HEIGHTS:
                for br in BLOCK_LENGTHS:
                    fs: tuple[float, ...]
                    if which == "full":
                        fs = frictions_all
                    elif which == "default":
                        fs = (0.6,)
                    else:  # "largest": the default set plus the 4 largest panels at every friction
                        fs = frictions_all if (bond, pr, br) in largest else (0.6,)
                    for f in fs:
                        panels.append((bond, pr, br, f))
        walls = [(40, 50), (50, 100)] if which == "full" else [(40, 50)]
    result = []
    for bond, pr, br, f in panels:
        result.append((f"{bond} {pr} {br} f={f:g}", "panel", partial(alma.paper_panel, bond, pr, br, f)))
    for courses, per_course in walls:
        result.append(
            (
                f"running wall {courses}x{per_course}",
                "wall",
                partial(alma.wall, "running", 240.0 * per_course, 60.0 * courses, 240.0),
            )
        )
    return result


# ----------------------------------------------------------------------------- timing
def timed(fn, model, repeat: int, single_above: float, time_limit: float):
    times, value = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        value = fn(model, time_limit)
        dt = time.perf_counter() - t0
        times.append(dt)
        if dt > single_above or dt > time_limit:
            break
    return statistics.median(times), len(times), value


def run(which: str, repeat: int, single_above: float, time_limit: float, out: Path) -> pd.DataFrame:
    methods = method_table()
    rows = []
    geometry_cache: dict[str, alma.Model] = {}
    t_start = time.perf_counter()
    for name, kind, factory in cases(which):
        scene = factory()
        key = scene.name.split(", f =")[0]
        if key in geometry_cache:
            model = geometry_cache[key].with_friction(scene.friction)
        else:
            model = alma.build_model(scene)
            geometry_cache[key] = model
        ref = reference(model, time_limit)
        for method, fn in methods.items():
            t, n_runs, (alpha, status) = timed(fn, model, repeat, single_above, time_limit)
            err = abs(alpha - ref["alpha_ref"]) / abs(ref["alpha_ref"]) if math.isfinite(alpha) else math.inf
            rows.append(
                dict(
                    case=name,
                    kind=kind,
                    blocks=model.n_free,
                    joints=model.n_joints,
                    method=method,
                    time_s=t,
                    runs=n_runs,
                    alpha=alpha,
                    status=status,
                    rel_error=err,
                    **ref,
                )
            )
        done = pd.DataFrame([r for r in rows if r["case"] == name])
        print(
            f"[{time.perf_counter() - t_start:6.0f} s] {name:32s} {model.n_free:5d} blocks  "
            f"ref {ref['alpha_ref']:.10f}  gap {ref['ref_gap']:.1e}  ds-check {ref['check_agreement']:.1e}  "
            + " ".join(f"{e:.0e}" for e in done.rel_error),
            flush=True,
        )
        pd.DataFrame(rows).to_csv(out / "accuracy_cases.csv", index=False)
    return pd.DataFrame(rows)


def summarise(df: pd.DataFrame) -> pd.DataFrame:
    g = df.groupby("method", sort=False)
    summary = pd.DataFrame(
        {
            "cases": g.size(),
            "not_solved": g.apply(lambda d: int((~np.isfinite(d.rel_error)).sum())),
            "non_optimal_status": g.apply(lambda d: int((d.status != "optimal").sum())),
            "total_time_s": g.time_s.sum(),
            "median_time_s": g.time_s.median(),
            "time_vs_default": g.time_s.sum() / df[df.method == DEFAULT_NAME].time_s.sum(),
            "max_rel_error": g.apply(
                lambda d: (
                    float(d.rel_error[np.isfinite(d.rel_error)].max()) if np.isfinite(d.rel_error).any() else math.inf
                )
            ),
            "median_rel_error": g.rel_error.median(),
            "worst_case": g.apply(
                lambda d: d.case.iloc[int(np.argmax(np.nan_to_num(d.rel_error.values, posinf=1e300)))]
            ),
        }
    )
    return summary.reset_index()


def pareto(summary: pd.DataFrame) -> tuple[bool, list[str]]:
    """Is the default on the front? Dominating = faster in total, smaller max error, no more failures."""
    d = summary.set_index("method").loc[DEFAULT_NAME]
    dominating = []
    for _, row in summary.iterrows():
        if row.method == DEFAULT_NAME:
            continue
        if row.total_time_s < d.total_time_s and row.max_rel_error < d.max_rel_error and row.not_solved <= d.not_solved:
            dominating.append(row.method)
    return not dominating, dominating


def plot(summary: pd.DataFrame, df: pd.DataFrame, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.5))
    floor = max(1e-13, float(df.ref_gap.max()) / 2)
    for i, (_, row) in enumerate(summary.iterrows()):
        err = max(row.max_rel_error, floor) if math.isfinite(row.max_rel_error) else np.nan
        is_default = row.method == DEFAULT_NAME
        marker = "*" if is_default else ("o" if row.method.startswith("alma") else "s")
        color = "C3" if is_default else f"C{i % 10}"
        ax.scatter(
            row.total_time_s,
            err,
            s=220 if is_default else 60,
            marker=marker,
            facecolors="none" if row.not_solved else color,
            edgecolors="k" if is_default else color,
            linewidths=1.5,
            zorder=3,
        )
        label = row.method + (f" ({row.not_solved} hit the time limit; max over the rest)" if row.not_solved else "")
        ax.annotate(label, (row.total_time_s, err), textcoords="offset points", xytext=(6, 4), fontsize=8)
    ax.axhline(floor, color="0.6", ls=":", lw=1)
    ax.text(ax.get_xlim()[0], floor, " resolution of the reference (max gap/2)", fontsize=7, va="bottom", color="0.4")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("total run time over all cases [s] (sum of per-case medians)")
    ax.set_ylabel("max relative error of α over all cases")
    ax.set_title(f"Associative LP: run time against error ({df.case.nunique()} cases)")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=130)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "--cases",
        choices=("quick", "default", "largest", "full"),
        default="default",
        help="default: the 36 panel geometries at f=0.6 + a 2,020-block running-bond wall; "
        "largest: default + the 4 largest panels at f=0.27 and 1.0; "
        "full: all 108 panels + 2,020- and 5,025-block walls (about an hour)",
    )
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument(
        "--single-above",
        type=float,
        default=4.0,
        help="a solve whose first run takes longer than this (s) is not repeated",
    )
    parser.add_argument("--time-limit", type=float, default=30.0, help="per solve (s)")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results"))
    parser.add_argument("--replot", action="store_true", help="redraw the plot from accuracy*.csv only")
    args = parser.parse_args()
    if args.replot:
        out = Path(args.out)
        plot(pd.read_csv(out / "accuracy.csv"), pd.read_csv(out / "accuracy_cases.csv"), out / "accuracy.png")
        return
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    pd.set_option("display.width", 250)
    pd.set_option("display.max_columns", 30)

    df = run(args.cases, args.repeat, args.single_above, args.time_limit, out)
    df.to_csv(out / "accuracy_cases.csv", index=False)
    summary = summarise(df)
    summary.to_csv(out / "accuracy.csv", index=False)
    plot(summary, df, out / "accuracy.png")

    fmt = lambda x: f"{x:.3g}"  # noqa: E731
    print(
        f"\n== run time against error, {df.case.nunique()} cases ({args.cases}); times: median of "
        f"{args.repeat} runs (1 run above {args.single_above:g} s), limit {args.time_limit:g} s =="
    )
    print(summary.to_string(index=False, float_format=fmt))
    ref = df.drop_duplicates("case")
    print(
        f"\nreference: alma tol=1e-11 certified interval; max relative gap {ref.ref_gap.max():.2e}; "
        f"statuses {sorted(set(ref.ref_status))}; re-checked: min μ {ref.ref_mu_min.min():.1e}, "
        f"max static residual {ref.ref_static_residual.max():.1e}, max flow-rule residual "
        f"{ref.ref_flow_residual.max():.1e}"
    )
    agree = ref.check_agreement
    bad = ref[~(agree <= 1e-9)]
    print(
        f"independent check (HiGHS dual simplex, kinematic LP, feasibility tol 1e-10): max |Δα|/α "
        f"{agree.max():.2e}, median {agree.median():.2e}; {len(bad)} of {len(ref)} cases disagree by more "
        f"than 1e-9"
        + (
            ": " + ", ".join(f"{c} ({a:.1e})" for c, a in zip(bad.case, bad.check_agreement, strict=True))
            if len(bad)
            else ""
        )
    )
    on_front, dominating = pareto(summary)
    print(
        f"\ndefault ({DEFAULT_NAME}) on the Pareto front: {'YES' if on_front else 'NO'}"
        + ("" if on_front else f" — dominated by {', '.join(dominating)}")
    )
    print(f"written: {out / 'accuracy.csv'}, {out / 'accuracy_cases.csv'}, {out / 'accuracy.png'}")


if __name__ == "__main__":
    main()
