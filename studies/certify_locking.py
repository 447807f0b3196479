"""Can joints be proven never to slip below a threshold t?  A lower bound from "locked" joints.

Issue 31's third lever (``docs/decisions.md``, "Proofs for the friction model: locked joints").
A joint j cannot slip along ±t in any collapse state with α ≤ t when the LP

    {statically admissible fields (Eqs. 3, 5) with 0 ≤ α ≤ t and T_p = ∓ f N_p at j's points}

is infeasible (a slipping joint is at its friction limit in its state's own admissible field).
With K the locked joints, every collapse state with α < t has γ_K = 0, and its energy balance
gives α ≥ β_K = min {−f₀ᵀu + Σ_{j∉K} f ℓ_j |γ_j| : ξ ≥ 0, γ_K = 0, f_Lᵀu = n_free} / n_free
(ℓ_j = min N_j over the admissible fields), so α_NL ≥ min(t, β_K).

This study counts the locked joints and computes β_K on the Ferris & Tin-Loi walls 1 and 3 (the
course patterns of ``verification/test_ferris_tin_loi.py``) and on the benchmark's 20-block
scenes, at t = 0.5 α_NL.

    python -m studies.certify_locking [--walls 1,3] [--share 0.5]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.sparse as sp

import alma
from alma.backends import highs_backend
from alma.certify.bigm import joint_normal_minima
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import build_model
from alma.nonassociative.limits import Cap
from benchmarks.bench_friction import FRICTION, WALLS


def ferris_wall(k: int) -> alma.Scene:
    return alma.coursed_wall(
        WALLS[k], 400.0, 175.0, friction=FRICTION, thickness=1000.0, unit_weight=10.0, name=f"Ferris & Tin-Loi wall {k}"
    )


def _feasible(h) -> bool:
    h.run()
    return str(h.getModelStatus()).rsplit(".", 1)[-1] == "kOptimal"


def locked_joints(model, points: ContactPoints, t: float) -> np.ndarray:
    """Joints whose slip in either direction makes the admissible fields at α ≤ t empty."""
    P, first = points.count, np.flatnonzero(np.r_[True, points.joint[1:] != points.joint[:-1]])
    A_eq, b_eq, A_ub = points.static_constraints(model, points.friction)
    if model.n_bounded:
        raise SystemExit("bounded forces: not covered by this study")
    joint_of = np.searchsorted(first, np.arange(P), side="right") - 1
    lo = np.concatenate([b_eq, np.full(2 * P, -np.inf)])
    hi = np.concatenate([b_eq, np.zeros(2 * P)])
    col_lo = np.concatenate([[0.0], np.zeros(P), np.full(P, -np.inf)])
    col_hi = np.concatenate([[t], np.full(2 * P, np.inf)])
    A = sp.vstack([A_eq, A_ub]).tocsr()
    out = np.zeros(first.size, dtype=bool)
    f = points.friction
    for j in range(first.size):  # a study: one LP per joint and direction
        pts = np.flatnonzero(joint_of == j)
        blocked = []
        for sign in (1.0, -1.0):  # slip +t: T = −f N; slip −t: T = +f N
            rows = sp.csr_matrix(
                (
                    np.r_[sign * np.ones(pts.size), f[pts]],
                    (np.r_[np.arange(pts.size), np.arange(pts.size)], np.r_[1 + P + pts, 1 + pts]),
                ),
                shape=(pts.size, 1 + 2 * P),
            )
            h = highs_backend.new_model(
                np.zeros(1 + 2 * P),
                col_lo,
                col_hi,
                sp.vstack([A, rows]),
                np.r_[lo, np.zeros(pts.size)],
                np.r_[hi, np.zeros(pts.size)],
            )
            blocked.append(not _feasible(h))
        out[j] = all(blocked)
    return out


def beta(model, points: ContactPoints, locked: np.ndarray, ell: np.ndarray) -> float:
    """min (−f₀ᵀu + Σ_{j∉K} f ℓ_j |γ_j|) / n_free over ξ ≥ 0, γ_K = 0, f_Lᵀu = n_free."""
    P, n = points.count, model.dead.shape[0]
    first = np.flatnonzero(np.r_[True, points.joint[1:] != points.joint[:-1]])
    m = first.size
    tj = points.tangent[:, first].T
    # x = (u, g⁺, g⁻) with γ = g⁺ − g⁻
    A = sp.vstack(
        [
            sp.hstack([points.normal.T, sp.csr_matrix((P, 2 * m))]),
            sp.hstack([sp.csr_matrix(model.live[None, :]), sp.csr_matrix((1, 2 * m))]),
            sp.hstack([tj, -sp.identity(m), sp.identity(m)]),
        ]
    )
    lo = np.r_[np.zeros(P), model.n_free, np.zeros(m)]
    hi = np.r_[np.full(P, np.inf), model.n_free, np.zeros(m)]
    w = points.friction[first] * ell
    cost = np.r_[-model.dead, w, w]
    col_hi = np.r_[np.full(n, np.inf), np.where(locked, 0.0, np.inf), np.where(locked, 0.0, np.inf)]
    h = highs_backend.new_model(cost, np.r_[np.full(n, -np.inf), np.zeros(2 * m)], col_hi, A, lo, hi)
    h.run()
    status = str(h.getModelStatus()).rsplit(".", 1)[-1]
    if status == "kInfeasible":
        return np.inf
    if status != "kOptimal":
        return -np.inf
    return h.getInfo().objective_function_value / model.n_free


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--walls", default="1,3")
    parser.add_argument("--share", type=float, default=0.5, help="t = share × α_NL")
    args = parser.parse_args(argv)
    for k in (int(w) for w in args.walls.split(",")):
        scene = ferris_wall(k)
        t0 = time.perf_counter()
        result = alma.solve(scene, model="nonassociative")
        model = build_model(scene)
        points = ContactPoints.from_model(model)
        first = np.flatnonzero(np.r_[True, points.joint[1:] != points.joint[:-1]])
        t = args.share * result.alpha
        locked = locked_joints(model, points, t)
        ell = joint_normal_minima(model, points, first, t, max_pivots=200_000, cap=Cap(None))
        b = beta(model, points, locked, np.maximum(ell, 0.0))
        print(
            f"wall {k}: α_NL {result.alpha:.6f}, t = {t:.6f}; joints {first.size}, locked {int(locked.sum())}, "
            f"ℓ_j > 0 on {int((ell > 1e-9).sum())}; β_K = {b:.6g}; bound min(t, β_K) = {min(t, max(b, 0.0)):.6g} "
            f"({time.perf_counter() - t0:.1f} s)",
            flush=True,
        )


if __name__ == "__main__":
    main()
