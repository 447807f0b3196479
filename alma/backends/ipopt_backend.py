"""IPOPT adapter (through CasADi): the Scholtes relaxations of the non-associative problem (Eq. 9).

Plain data in (the contact points' normal and tangent columns, friction, f₀, f_L, the bounded
forces' columns G and capacities), as :mod:`alma.engine` takes Eq. 10.  Unknowns
x = (α, N, T, u, γ⁺, γ⁻, τ, d⁺, d⁻); constraints: equilibrium (Eq. 3), slip split
tangentᵀu = γ⁺ − γ⁻, f_Lᵀu = n_free, the bounded rates −Gᵀu = d⁺ − d⁻, yield (Eq. 5), no
interpenetration, and the complementarity of Eq. 7 relaxed to ε: N ξ ≤ ε, (f N + T) γ⁺ ≤ ε,
(f N − T) γ⁻ ≤ ε, (capacity − τ) d⁺ ≤ ε, τ d⁻ ≤ ε.  A tiny regularisation of the slips keeps the
multipliers of unloaded points bounded.  Each relaxed solve is bounded by IPOPT's iteration
count, never by its clock; the status is read through :data:`alma.backends.termination.IPOPT`.

CasADi is imported on first use: it takes a third of a second to import, and the polish runs
only when asked for (``SearchSettings.ipopt_blocks``).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from alma.backends.termination import SolverResult, Termination, termination

#: Weight of the slips' and rates' squares in the objective (keeps unloaded points' multipliers bounded).
SLIP_REGULARISATION = 1e-8


@dataclass(frozen=True)
class ComplementarityData:
    """Eq. 9 on contact points, dimensionless (forces in mean block weights)."""

    normal: sp.spmatrix  # (n, P) normal columns
    tangent: sp.spmatrix  # (n, P) tangent columns
    friction: np.ndarray  # (P,)
    dead: np.ndarray  # f₀ (n,)
    live: np.ndarray  # f_L (n,)
    n_free: int
    bounded: sp.spmatrix | None  # G (n, q), None without bounded forces
    capacity: np.ndarray  # (q,)


def _dm(ca, matrix: sp.spmatrix):
    m = sp.csc_matrix(matrix)
    m.sort_indices()
    return ca.DM(ca.Sparsity(m.shape[0], m.shape[1], m.indptr.tolist(), m.indices.tolist()), m.data.tolist())


def _problem(ca, d: ComplementarityData) -> dict:
    """CasADi's NLP of the relaxed Eq. 9, the relaxation ε its parameter."""
    P, n, q = d.friction.shape[0], d.dead.shape[0], d.capacity.shape[0]
    alpha, N, T, u = ca.SX.sym("alpha"), ca.SX.sym("N", P), ca.SX.sym("T", P), ca.SX.sym("u", n)
    gp, gm, eps = ca.SX.sym("gp", P), ca.SX.sym("gm", P), ca.SX.sym("eps")
    tau, dp, dm = ca.SX.sym("tau", q), ca.SX.sym("dp", q), ca.SX.sym("dm", q)
    An, At = _dm(ca, d.normal), _dm(ca, d.tangent)
    f = ca.DM(d.friction)
    opening = ca.mtimes(An.T, u)
    equilibrium = ca.mtimes(An, N) + ca.mtimes(At, T) + ca.DM(d.dead) + alpha * ca.DM(d.live)
    capacity = ca.DM(d.capacity) if q else ca.DM.zeros(0)
    if q:
        G = _dm(ca, d.bounded)
        equilibrium = equilibrium + ca.mtimes(G, tau)
    g = ca.vertcat(
        equilibrium,  # = 0
        ca.mtimes(At.T, u) - gp + gm,  # = 0
        ca.dot(ca.DM(d.live), u) - d.n_free,  # = 0
        *([-ca.mtimes(G.T, u) - dp + dm] if q else []),  # = 0
        f * N - T,  # ≥ 0
        f * N + T,  # ≥ 0
        opening,  # ≥ 0
        N * opening - eps,  # ≤ 0
        (f * N + T) * gp - eps,  # ≤ 0
        (f * N - T) * gm - eps,  # ≤ 0
        (capacity - tau) * dp - eps,  # ≤ 0
        tau * dm - eps,  # ≤ 0
    )
    x = ca.vertcat(alpha, N, T, u, gp, gm, tau, dp, dm)
    objective = alpha + SLIP_REGULARISATION * (ca.sumsqr(gp) + ca.sumsqr(gm) + ca.sumsqr(dp) + ca.sumsqr(dm))
    return {"x": x, "p": eps, "f": objective, "g": g}


def solve_relaxations(
    data: ComplementarityData,
    x0: np.ndarray,
    bounds: tuple[np.ndarray, ...],
    relaxations: Sequence[float],
    max_iter: int,
    expired: Callable[[], bool],
) -> SolverResult:
    """Solve the relaxations ε of :func:`_problem` in turn, each warm from the last and within
    ``max_iter`` IPOPT iterations; a solve that does not converge ends the sequence.

    ``bounds``: (lbg, ubg, lbx, ubx); ``expired``: the user's cap, checked before each solve.
    The result's ``x`` is the last converged solution (empty when none converged), its
    termination the last solve's; ``iterations`` counts IPOPT's iterations of all solves.
    """
    import casadi as ca

    start = time.perf_counter()
    lbg, ubg, lbx, ubx = bounds
    options: dict[str, Any] = {
        "ipopt.print_level": 0,
        "print_time": False,
        "ipopt.max_iter": max_iter,
        "ipopt.sb": "yes",
    }
    solver = ca.nlpsol("alma_nlncp", "ipopt", _problem(ca, data), options)
    best, raw, term, iterations = np.zeros(0), "not run", Termination.INTERRUPTED, 0
    for epsilon in relaxations:
        if expired():
            raw, term = "cap expired", Termination.TIME_LIMIT
            break
        sol = solver(x0=x0, p=epsilon, lbg=lbg, ubg=ubg, lbx=lbx, ubx=ubx)
        stats = solver.stats()
        raw = str(stats.get("return_status", ""))
        iterations += int(stats.get("iter_count", 0) or 0)
        term = termination("ipopt", raw)
        if not stats.get("success", False):
            break
        x0 = best = np.asarray(sol["x"]).ravel()
    return SolverResult(term, raw, best, np.zeros(0), iterations, time.perf_counter() - start, "IPOPT", "static")
