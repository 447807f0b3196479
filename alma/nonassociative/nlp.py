"""IPOPT polish of the non-associative problem (Eq. 9) with CasADi.

Unknowns: α, contact forces (N, T) at every contact point, the mechanism u and
the slip split γ = γ⁺ − γ⁻ (γ± ≥ 0).  Constraints: equilibrium (Eq. 3), yield
|T| ≤ f N (Eq. 5), no interpenetration ξ = normalᵀu ≥ 0, f_Lᵀu = n_free
(Eq. 8), and the complementarity of Eq. 7 with a Scholtes relaxation driven to
zero: N ξ ≤ ε, (f N + T) γ⁺ ≤ ε, (f N − T) γ⁻ ≤ ε (the CasADi problem and IPOPT's runs are in
:mod:`alma.backends.ipopt_backend`).  Bounded forces (cohesion, ties:
0 ≤ τ ≤ capacity on the columns G) add G τ to the equilibrium and their flow rule on
d = −Gᵀu = d⁺ − d⁻ (d± ≥ 0): (capacity − τ) d⁺ ≤ ε (a column that dissipates is at its
capacity), τ d⁻ ≤ ε (one that moves against itself carries nothing).  A tiny regularisation of
the slips keeps multipliers of unloaded points bounded.  Sparse Jacobians and
exact Hessians come from CasADi.  The result is only a start: its mechanism is
turned into an exact, verified state by :func:`alma.nonassociative.exact_states.exact_state`.
Each relaxed solve is bounded by IPOPT's iteration count, never by its clock.
"""

from __future__ import annotations

import numpy as np

from alma.backends.ipopt_backend import ComplementarityData, solve_relaxations
from alma.floats import dot
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.exact_states import exact_state
from alma.nonassociative.limits import Cap, no_cap
from alma.nonassociative.states import CollapseState, ExactLimits


def ipopt_polish(
    model: Model,
    points: ContactPoints,
    mechanism: np.ndarray,
    seed: CollapseState | None = None,
    relaxations: tuple[float, ...] = (1e-2, 1e-4, 1e-6, 1e-8),
    max_iter: int = 300,
    cap: Cap | None = None,
    limits: ExactLimits | None = None,
) -> CollapseState | None:
    """A candidate collapse state from IPOPT started at ``mechanism`` (and the seed's forces).

    The relaxations ε of the complementarity (Eq. 7) are solved in turn, each warm from the
    last and within ``max_iter`` IPOPT iterations (:func:`alma.backends.ipopt_backend.solve_relaxations`);
    a run that does not converge ends the sequence, and the last relaxation that converged is the
    answer, made exact within ``limits``.  No relaxed solve begins once the user's ``cap`` has passed.
    """
    cap = cap or no_cap()
    P, n = points.count, model.dead.shape[0]
    data = ComplementarityData(
        points.normal,
        points.tangent,
        points.friction,
        model.dead,
        model.live,
        model.n_free,
        model.bounded if model.n_bounded else None,
        model.capacity,
    )
    sol = solve_relaxations(
        data, _initial(model, points, mechanism, seed), _bounds(model, P), relaxations, max_iter, cap.expired
    )
    if not sol.x.size:
        return None
    return exact_state(model, points, sol.x[1 + 2 * P : 1 + 2 * P + n], "ipopt", limits=limits or ExactLimits())


def _bounds(model: Model, P: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Bounds of the constraints g (equalities, yield and opening ≥ 0, complementarities ≤ ε)
    and of x = (α, N, T, u, γ⁺, γ⁻, τ, d⁺, d⁻) for ``P`` contact points."""
    n, q = model.dead.shape[0], model.n_bounded
    n_eq = n + P + 1 + q
    lbg = np.concatenate([np.zeros(n_eq), np.zeros(3 * P), np.full(3 * P + 2 * q, -np.inf)])
    ubg = np.concatenate([np.zeros(n_eq), np.full(3 * P, np.inf), np.zeros(3 * P + 2 * q)])
    lbx = np.concatenate([[-np.inf], np.zeros(P), np.full(P, -np.inf), np.full(n, -np.inf), np.zeros(2 * P + 3 * q)])
    ubx = np.concatenate([np.full(1 + 2 * P + n + 2 * P, np.inf), model.capacity, np.full(2 * q, np.inf)])
    return lbg, ubg, lbx, ubx


def _initial(model: Model, points: ContactPoints, mechanism: np.ndarray, seed: CollapseState | None) -> np.ndarray:
    """IPOPT's start: the mechanism scaled to f_Lᵀu = n_free, its slips and bounded-force
    elongations split by sign, and the seed's forces (zero forces without a seed)."""
    P, q = points.count, model.n_bounded
    work = dot(model.live, mechanism)
    u0 = mechanism * (model.n_free / work) if work > 0 else mechanism
    slip = points.tangent.T @ u0
    d = -(model.bounded.T @ u0) if q else np.zeros(0)  # type: ignore[union-attr]  # q > 0: it has columns
    if seed is not None:
        forces = np.concatenate([[seed.alpha], seed.normal, seed.shear])
        tau = seed.bounded if seed.bounded.size == q else np.where(d > 0, model.capacity, 0.0)
    else:
        forces = np.zeros(1 + 2 * P)
        tau = np.where(d > 0, model.capacity, 0.0)
    return np.concatenate(
        [forces, u0, np.maximum(slip, 0), np.maximum(-slip, 0), tau, np.maximum(d, 0), np.maximum(-d, 0)]
    )
