"""The multi-start search against IPOPT started from the LP solution (issue: non-associative).

The question: on the paper panels, how often does alma's default non-associative search
(``alma.solve(scene, "nonassociative")``: the LP start, Gilbert starts, the projected iteration,
and on small scenes the IPOPT polish and the MILP start) find a lower verified collapse state
than the single path a user would otherwise take, IPOPT on the whole NLNCP of Eq. 9 started from
the associative (LP) mechanism?

For every paper panel up to ``--max-blocks`` blocks (all three frictions):

- ``ipopt from LP``: :func:`alma.nonassociative.nlp.ipopt_polish` from the LP mechanism, no seed
  forces (the Scholtes relaxation driven 1e-2 → 1e-8), each relaxed solve within
  ``--ipopt-iterations`` IPOPT iterations; its mechanism is turned into an exact state and
  verified like every other candidate (:func:`alma.nonassociative.exact_states.exact_state`);
- ``alma default``: ``alma.solve(scene, "nonassociative")`` (its work budgets).

IPOPT on the full problem does not scale (prototype: 16 s at 52 blocks, 195 s at 126), so the
panels are the smallest ones; the 108-panel comparison (``alma compare``) reports the multi-start
against the LP start's own exact state on every panel.

    .venv/bin/python -m studies.bench_ipopt_lp_start [--max-blocks 160] [--ipopt-limit 120]

Writes benchmarks/results/ipopt_lp_start.csv (one row per panel, written as each finishes, and
resumed from on a second run) and ipopt_lp_start.png (α of each against the other).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

import alma
from alma.associative.lp import solve_lp
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import build_model
from alma.nonassociative.nlp import ipopt_polish
from benchmarks.bench_nonassociative import FRICTIONS, paper_geometries

ROOT = Path(__file__).resolve().parents[1]

RESULTS = ROOT / "benchmarks" / "results"
#: A difference in α below this is a tie (the verification tolerances are 1e-7).
TIE = 1e-7


def run_panel(bond: str, panel_ratio: str, block_ratio: str, friction: float, ipopt_iterations: int) -> dict:
    scene = alma.paper_panel(bond, panel_ratio, block_ratio, friction)
    model = build_model(scene)
    lp = solve_lp(model)
    points = ContactPoints.from_model(model)
    t0 = time.perf_counter()
    state = ipopt_polish(model, points, lp.mechanism, None, max_iter=ipopt_iterations)
    ipopt_s = time.perf_counter() - t0
    ipopt_ok = state is not None and state.verified
    t0 = time.perf_counter()
    result = alma.solve(model, "nonassociative")
    alma_s = time.perf_counter() - t0
    alma_ok = result.status in ("feasible", "optimal")
    alpha_ipopt = state.alpha if state is not None and ipopt_ok else np.nan
    alpha_alma = result.alpha if alma_ok else np.nan
    if alma_ok and (not ipopt_ok or alpha_alma < alpha_ipopt - TIE):
        verdict = "alma lower"
    elif ipopt_ok and (not alma_ok or alpha_ipopt < alpha_alma - TIE):
        verdict = "ipopt lower"
    elif alma_ok:
        verdict = "equal"
    else:
        verdict = "neither verified"
    return dict(
        bond=bond,
        panel_ratio=panel_ratio,
        block_ratio=block_ratio,
        friction=friction,
        blocks=model.n_free,
        alpha_lp=lp.alpha,
        alpha_ipopt=alpha_ipopt,
        ipopt_verified=ipopt_ok,
        ipopt_returned=state is not None,
        ipopt_s=ipopt_s,
        alpha_alma=alpha_alma,
        alma_status=result.status,
        alma_start=result.extra.get("start", ""),
        alma_s=alma_s,
        verdict=verdict,
    )


def plot(table: pd.DataFrame, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 5))
    both = table[table.ipopt_verified & (table.alma_status == "optimal")]
    ax.scatter(both.alpha_ipopt, both.alpha_alma, s=18, label="both verified")
    only = table[~table.ipopt_verified & (table.alma_status == "optimal")]
    ax.scatter(only.alpha_lp, only.alpha_alma, s=18, marker="x", label="IPOPT failed (x = α_LP)")
    hi = float(np.nanmax(table[["alpha_lp", "alpha_alma"]].to_numpy())) * 1.05
    ax.plot([0, hi], [0, hi], color="grey", lw=0.8)
    ax.set_xlabel("α from IPOPT started at the LP solution")
    ax.set_ylabel("α of alma's default search")
    ax.set_title("Non-associative α: multi-start vs LP-started IPOPT")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--max-blocks", type=int, default=160)
    parser.add_argument("--ipopt-iterations", type=int, default=3000, help="IPOPT iterations per relaxed solve")
    parser.add_argument("--out", default=str(RESULTS))
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    csv = out / "ipopt_lp_start.csv"
    done = pd.read_csv(csv) if csv.exists() else pd.DataFrame()
    key = ["bond", "panel_ratio", "block_ratio", "friction"]
    seen = set(map(tuple, done[key].astype(str).to_numpy())) if len(done) else set()
    for _blocks, panel_ratio, block_ratio, bond in paper_geometries(args.max_blocks):
        for friction in FRICTIONS:
            if (bond, panel_ratio, block_ratio, str(friction)) in seen:
                continue
            row = run_panel(bond, panel_ratio, block_ratio, friction, args.ipopt_iterations)
            print(
                f"{bond:8s} {panel_ratio} {block_ratio} f={friction:<4} {row['blocks']:4d} blocks  "
                f"LP {row['alpha_lp']:.4f}  IPOPT {row['alpha_ipopt']:.4f} ({row['ipopt_s']:.1f} s)  "
                f"alma {row['alpha_alma']:.4f} ({row['alma_s']:.1f} s)  {row['verdict']}",
                flush=True,
            )
            done = pd.concat([done, pd.DataFrame([row])], ignore_index=True)
            done.to_csv(csv, index=False)  # each panel as it finishes: a rerun resumes
    table = done
    counts = table.verdict.value_counts()
    print()
    print(f"{len(table)} panel-friction cases up to {args.max_blocks} blocks")
    for verdict in ("alma lower", "equal", "ipopt lower", "neither verified"):
        print(f"  {verdict:18s} {int(counts.get(verdict, 0))}")
    lower = table[table.verdict == "alma lower"]
    both = lower[lower.ipopt_verified]
    if len(both):
        drop = both.alpha_ipopt - both.alpha_alma
        print(
            f"  where both verified and alma lower: {len(both)} cases, by median {drop.median():.4f}, "
            f"at most {drop.max():.4f}"
        )
    print(
        f"  IPOPT verified {int(table.ipopt_verified.sum())}/{len(table)}; "
        f"median time {table.ipopt_s.median():.1f} s, alma median {table.alma_s.median():.1f} s"
    )
    plot(table, out / "ipopt_lp_start.png")


if __name__ == "__main__":
    main()
