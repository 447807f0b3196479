"""A first-order LP method on Eq. 10 (issue 16, "another algorithm"): HiGHS's PDLP.

The kinematic LP of Eq. 10 as alma poses it for HiGHS, solved by PDLP (primal-dual hybrid
gradient with restarts: one matrix-vector product pair per iteration, no factorisation), its
pair passed to alma's certificate.  Prints the status, iterations, time and the certified bounds.

    python -m studies.bench_first_order [--case panel|BLOCKS] [--tolerance 1e-8] [--iterations 200000]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from alma.associative.lp import _certified
from alma.associative.lp_forms import _kinematic_form
from alma.backends.highs_backend import conic_lp, quiet_highs
from alma.backends.termination import SolverResult, termination
from alma.geometry.contacts import find_joints
from alma.mechanics.model import build_model
from alma.settings import AssociativeSettings
from benchmarks.bench_engine import _model


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", default="panel", help="'panel' (english 1:2 1:1 f = 0.6) or a wall's block count")
    parser.add_argument("--tolerance", type=float, default=1e-8, help="PDLP's gap and feasibility tolerances")
    parser.add_argument("--iterations", type=int, default=200_000)
    args = parser.parse_args()
    scene = _model(args.case)
    model = build_model(scene, find_joints(scene))
    s = AssociativeSettings()
    q, A, b = _kinematic_form(model, model.equilibrium, s.normalisation)
    h = quiet_highs(
        solver="pdlp",
        pdlp_d_gap_tol=args.tolerance,
        primal_feasibility_tolerance=args.tolerance,
        dual_feasibility_tolerance=args.tolerance,
        pdlp_iteration_limit=args.iterations,
    )
    h.passModel(conic_lp(q, A, b, 1))
    t0 = time.perf_counter()
    h.run()
    seconds = time.perf_counter() - t0
    raw = str(h.getModelStatus()).rsplit(".", 1)[-1]
    sol, iterations = h.getSolution(), int(h.getInfo().pdlp_iteration_count)
    pair = SolverResult(
        termination("highs", raw),
        raw,
        np.asarray(sol.col_value, float),
        -np.asarray(sol.row_dual, float),
        iterations,
        seconds,
        "HiGHS PDLP",
    )
    lp = _certified(model, model.equilibrium, s, pair, "HiGHS PDLP", "", {})
    print(
        f"{args.case}: {model.n_free} free blocks; PDLP {raw} after {iterations} iterations, {seconds:.1f} s; "
        f"certificate: {lp.status}, α ∈ [{lp.lower:.10g}, {lp.upper:.10g}]"
    )


if __name__ == "__main__":
    main()
