"""Why a vertex of the optimal face cannot be had for 20 % of the solve (issue 19).

On one paper panel (default: the largest, english 1:2 1:1, f = 0.6), after the certified solve
(``solve_lp``), four ways of reading a single mechanism off the interior point's pair are
measured:

1. **The partition.**  How many generators are ambiguous (relative power s and relative
   multiplier μ both below 1e-4): the certified pair cannot tell whether they are held.
2. **The null vector of the held rows.**  Holding the generators whose multiplier exceeds
   ``t`` × the largest, the rows H_Bᵀ leave one null direction from some ``t`` on (the two smallest
   eigenvalues of H_B H_Bᵀ, shift-invert Lanczos); its α and flow-rule violation against the
   certified bounds show whether that vertex is the optimal one.
3. **A uniqueness bound.**  Every mechanism u with f_Lᵀu = 1, Hᵀu ≥ 0 and α(u) ≤ the certified
   upper bound has μᵀHᵀu ≤ gap + |rᵀu| (r the certified field's residual), so
   ‖H_Bᵀu‖ ≤ (gap + ‖r‖₁‖u‖∞) / min_B μ, and two such mechanisms differ by at most
   2 S / √λ₂ (1 + ‖f_L‖ / |f_Lᵀv₁|): the optimal face's diameter, printed relative to ‖u‖∞.
4. **CLP's values-pass crossover** (``cylp``, EPL-2.0, not a dependency: run with it installed):
   the primal simplex started from the interior point's mechanism, all columns superbasic.

    python -m studies.bench_crisp_floor [--case english 1:2 1:1 0.6]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh

import alma
from alma.associative.lp import solve_lp


def _relative(v: np.ndarray) -> np.ndarray:
    return np.maximum(v, 0.0) / max(float(v.max(initial=0.0)), 1e-300)


def held_null_vector(model, lp, t: float) -> dict:
    """The two smallest eigenvalues of H_B H_Bᵀ (B: μ ≥ t max μ) and the null vector's α."""
    H, mu = model.equilibrium, lp.multipliers
    held = np.flatnonzero(mu >= t * mu.max())
    t0 = time.perf_counter()
    HB = H[:, held]
    KB = (HB @ HB.T).tocsc()
    w, V = eigsh(KB, k=2, sigma=-1e-12 * KB.diagonal().max(), which="LM")
    seconds = time.perf_counter() - t0
    x = V[:, 0] / (model.live @ V[:, 0])
    power = H.T @ x
    return dict(
        held=len(held),
        eig=w,
        seconds=seconds,
        v1=V[:, 0],
        alpha=float(-model.dead @ x),
        violation=float(-power.min() / np.abs(power).max()),
        mu_min=float(mu[held].min()),
    )


def uniqueness_bound(model, lp, null: dict) -> float:
    """The optimal face's diameter bound (item 3 of the module docstring), relative to ‖u‖∞."""
    mu, u, fL = lp.multipliers, lp.mechanism, np.asarray(model.live).ravel()
    residual = model.equilibrium @ mu + np.asarray(model.dead).ravel() + lp.lower * fL
    S = (lp.upper - lp.lower + np.abs(residual).sum() * 2 * np.abs(u).max()) / null["mu_min"]
    lam2 = float(null["eig"][1])
    if lam2 <= 0:
        return float("inf")
    diameter = 2 * S / np.sqrt(lam2) * (1 + np.linalg.norm(fL) / abs(fL @ null["v1"]))
    return float(diameter / np.abs(u).max())


def clp_values_pass(model, lp) -> str:
    try:
        from cylp.cy import CyClpSimplex
        from cylp.cy.CyCoinPackedMatrix import CyCoinPackedMatrix
    except ImportError:
        return "cylp not installed (pip install cylp), not measured"
    H = model.equilibrium
    n, m = H.shape
    scale = 10.0 * model.n_free
    A = sp.vstack([sp.csr_matrix(model.live), H.T.tocsr()]).tocoo()
    clp = CyClpSimplex()
    inf = clp.getCoinInfinity()
    clp.loadProblem(
        CyCoinPackedMatrix(True, A.row.astype(np.int32), A.col.astype(np.int32), A.data.astype(float)),
        np.full(n, -inf),
        np.full(n, inf),
        -np.asarray(model.dead, float).ravel(),
        np.r_[scale, np.zeros(m)],
        np.r_[scale, np.full(m, inf)],
    )
    clp.logLevel = 0
    clp.primalVariableSolution[:] = lp.mechanism * scale  # a view of CLP's column values
    status = clp.getStatusArray()  # a view of CLP's status bytes; the low 3 bits: 4 = superbasic
    status[:n] = (status[:n] & ~np.uint8(7)) | np.uint8(4)
    t0 = time.perf_counter()
    outcome = clp.primal(ifValuesPass=1)
    seconds = time.perf_counter() - t0
    u = np.array(clp.primalVariableSolution) / scale
    power = H.T @ u
    return (
        f"{outcome} after {clp.iteration} pivots, {seconds:.2f} s; α {-(model.dead @ u) / (model.live @ u):.12f}, "
        f"flow-rule violation {-power.min() / np.abs(power).max():.1e}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--case", nargs=4, default=["english", "1:2", "1:1", "0.6"], metavar=("BOND", "PANEL", "BLOCKS", "F")
    )
    parser.add_argument("--thresholds", default="1e-7,3e-7,1e-6,1e-5")
    args = parser.parse_args()
    bond, panel, blocks, friction = args.case
    model = alma.build_model(alma.paper_panel(bond, panel, blocks, float(friction)))
    t0 = time.perf_counter()
    lp = solve_lp(model)
    solve = time.perf_counter() - t0
    print(
        f"{' '.join(args.case)}: {model.n_free} free blocks, {model.equilibrium.shape[1]} generators; "
        f"solve {solve:.3f} s (20 %: {0.2 * solve:.3f} s); certified α ∈ [{lp.lower:.12f}, {lp.upper:.12f}]"
    )
    s, mu = _relative(model.equilibrium.T @ lp.mechanism), _relative(lp.multipliers)
    print(f"1. ambiguous generators (s and μ both < 1e-4 of their largest): {int(((s < 1e-4) & (mu < 1e-4)).sum())}")
    for t in map(float, args.thresholds.split(",")):
        null = held_null_vector(model, lp, t)
        print(
            f"2. μ ≥ {t:.0e} max: {null['held']} held, eigenvalues {null['eig'][0]:.1e} {null['eig'][1]:.1e} "
            f"({null['seconds']:.3f} s); null vector α {null['alpha']:.12f}, flow-rule violation "
            f"{null['violation']:.1e}\n"
            f"3.   diameter bound of the optimal face / ‖u‖∞: {uniqueness_bound(model, lp, null):.1e}"
        )
    print(f"4. CLP values pass: {clp_values_pass(model, lp)}")


if __name__ == "__main__":
    main()
