"""Global certification of the non-associative problem (Eq. 9) by mixed-integer LP.

The complementarity of Eq. 9 is written with binaries (big-M) and solved with
HiGHS (``highspy``).  The slip γ = tangentᵀu is the same at both end points of a
straight joint, so the slip state is one per joint j: slipping +t (s⁺_j = 1),
slipping −t (s⁻_j = 1) or not (s⁺_j + s⁻_j ≤ 1); each contact point p of joint j
is open (o_p = 1) or closed:

- N_p ≤ M_N,p (1 − o_p),            ξ_p = normal_pᵀu ≤ M_ξ,p o_p;
- γ⁺_j ≤ M_γ⁺,j s⁺_j,               γ⁻_j ≤ M_γ⁻,j s⁻_j,   γ_j = γ⁺_j − γ⁻_j;
- f N_p + T_p ≤ 2 f M_N,p (1 − s⁺_j),   f N_p − T_p ≤ 2 f M_N,p (1 − s⁻_j)
  (slipping: T = −f N sign γ; an open point carries nothing and satisfies both);

with equilibrium, yield |T| ≤ f N, no interpenetration ξ ≥ 0 and f_Lᵀu = n_free.
Bounded forces (cohesion, ties; :mod:`alma.nonassociative.bounded`) are columns G τ of the
equilibrium with 0 ≤ τ ≤ cap and rates d = −Gᵀu = d⁺ − d⁻, their flow rule by two binaries
each: d⁺ ≤ M_d⁺ q⁺ with τ ≥ cap q⁺, and d⁻ ≤ M_d⁻ q⁻ with τ ≤ cap (1 − q⁻);
objective min α over α ∈ [0, α_cap], α_cap = min(α_LP, α_best) (Radenkovic:
α_NL ≤ α_LP; α_best is a verified collapse state, also given to HiGHS as the
objective cutoff).

Energy balance.  Every integer-feasible point has Nᵀξ = 0 and Tᵀγ = −Σ f N |γ|, so
the equilibrium dotted with u gives α n_free = −f₀ᵀu + Σ_j f N_j |γ_j| + Σ_i cap_i d⁺_i
(N_j the joint's total normal force).  With ℓ_j = min N_j over the admissible fields (an LP)
this yields the valid row α n_free ≥ −f₀ᵀu + Σ_j f ℓ_j (γ⁺_j + γ⁻_j) + Σ_i cap_i d⁺_i, and
with α ≤ α_cap it bounds every mechanism that lifts weight, slips under load or works a
bounded force.

With ``CertifySettings.backend = "scip"`` the same problem is solved by SCIP with the
complementarity as SOS1 pairs instead of big-M rows (:mod:`alma.certify.sos1`).

The big-M constants come from LPs per scene (:mod:`alma.certify.bigm`).  Points that carry
no force in any admissible field need no binary (they may open); points loaded in every
admissible field never open.  The proven statement is therefore: no collapse state with α
below ``lower`` exists among mechanisms with |u|∞ ≤ U (f_Lᵀu = n_free); the bound on u is
reported, and whether it was active at the optimum.  The work is bounded by a node count
(:class:`~alma.settings.CertifySettings`); a user's wall-clock cap may stop it sooner.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from alma.backends import highs_backend, scip_backend
from alma.certify.bigm import BoundsFailed, derive_big_m
from alma.certify.certificate import Certificate
from alma.certify.rows import MilpData, milp_data
from alma.certify.sos1 import scip_certificate, sos1_data
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.limits import Cap
from alma.settings import CertifySettings

#: Absolute MIP gap: the proven bound is within this of the best state found.
MIP_ABSOLUTE_GAP = 1e-7
#: Integrality tolerance of the binaries: HiGHS's default 1e-6 times a velocity big-M of
#: hundreds releases enough force to settle visibly below the optimum (docs/decisions.md).
MIP_INTEGRALITY_TOLERANCE = 1e-9

#: The MIP solvers of the certificate: HiGHS (big-M binaries) and SCIP (SOS1 pairs, alma[scip]).
BACKENDS = ("highs", "scip")


def _run_milp(
    data: MilpData, alpha_hi: float, alpha_best: float | None, settings: CertifySettings, cap: Cap
) -> highs_backend.MilpOutcome:
    """Solve the MILP with HiGHS within the node budget (and the user's cap, if any)."""
    # The verified state at α_best acts as an incumbent: nodes whose bound reaches it are pruned.
    # The user's cap only bounds the clock: no budget decision rests on it.
    return highs_backend.solve_milp(
        data.cost,
        data.col_lo,
        data.col_hi,
        data.A,
        data.row_lo,
        data.row_hi,
        data.integrality,
        node_limit=settings.node_limit,
        absolute_gap=MIP_ABSOLUTE_GAP,
        relative_gap=1e-9,
        integrality_tolerance=MIP_INTEGRALITY_TOLERANCE,
        time_limit=cap.remaining() if cap.seconds is not None else None,
        objective_bound=alpha_hi if alpha_best is not None else None,
    )


def _certificate(
    out: highs_backend.MilpOutcome, data: MilpData, alpha_cap: float, U: float, t0: float, bounds_s: float
) -> Certificate:
    """Read the proven bound (and the MILP's own optimum) from HiGHS's outcome."""
    dual = out.dual_bound if np.isfinite(out.dual_bound) else 0.0
    best, u, active = np.inf, None, False
    if out.x is not None:
        best, u = float(out.x[data.alpha_column]), out.x[data.velocity_columns]
        active = bool(np.abs(u).max() >= 0.999 * U)
    common: dict[str, Any] = dict(
        velocity_bound=U,
        velocity_bound_active=active,
        mechanism=u,
        binaries=data.binaries,
        nodes=out.nodes,
        bounds_s=bounds_s,
        time_s=time.perf_counter() - t0,
    )
    if out.status == "optimal":
        lower = max(0.0, min(dual, best, alpha_cap))  # α_cap: a verified state exists there
        return Certificate(
            "proven",
            f"optimal within mip gap {best - lower:.1e} (|u|∞ ≤ {U:.3g}{', bound active' if active else ''})",
            float(lower),
            best,
            float(best - lower),
            **common,
        )
    if out.status == "pruned":
        lower = max(0.0, alpha_cap - MIP_ABSOLUTE_GAP)  # pruned against the cap within the MIP gap
        return Certificate(
            "proven",
            f"no collapse state below the cap {alpha_cap:.9g} (best verified state / "
            f"associative bound) within mip gap {MIP_ABSOLUTE_GAP:.0e} (|u|∞ ≤ {U:.3g})",
            float(lower),
            np.inf,
            float(alpha_cap - lower),
            **common,
        )
    if out.status in ("limit_reached", "node_limit"):
        lower = max(0.0, min(dual, alpha_cap))
        why = "time limit reached" if out.status == "limit_reached" else f"node limit {out.nodes} reached"
        return Certificate(
            out.status,
            f"{why}; proven lower bound {lower:.6g} (|u|∞ ≤ {U:.3g})",
            float(lower),
            best,
            float(alpha_cap - lower),
            **common,
        )
    return Certificate("failed", f"MILP failed: HiGHS {out.highs_status}", 0.0, np.inf, np.inf, **common)


def certify(
    model: Model,
    alpha_associative: float,
    mechanisms: list[np.ndarray],
    *,
    settings: CertifySettings = CertifySettings(),
    alpha_best: float | None = None,
    time_limit: float | None = None,
) -> Certificate:
    """Proven lower bound of the non-associative collapse multiplier (see module docstring).

    ``alpha_associative``: α of Eq. 10 (an upper bound, Radenkovic); ``mechanisms``: candidate
    mechanisms whose size sets the velocity bound U; ``alpha_best``: the best verified state's α
    (a cap and cutoff); ``settings``: node and iteration budgets; ``time_limit`` (s): a user's
    cap (status ``limit_reached`` when it stops the work).
    """
    t0, cap = time.perf_counter(), Cap(time_limit)
    points = ContactPoints.from_model(model)

    def fail(message: str, status: str = "failed", U: float = np.nan) -> Certificate:
        return Certificate(
            status, message, 0.0, np.inf, np.inf, time.perf_counter() - t0, U, False, None, backend=settings.backend
        )

    if settings.backend not in BACKENDS:
        return fail(f"unknown certification backend {settings.backend!r} (one of {BACKENDS})")
    if settings.backend == "scip" and not scip_backend.available():
        return fail(scip_backend.INSTALL_HINT)
    if not np.isfinite(alpha_associative) or alpha_associative < 0:
        return fail("the associative bound is not finite and non-negative")
    alpha_cap = alpha_associative if alpha_best is None else min(alpha_associative, alpha_best)
    if alpha_cap < 0:
        return fail("the best verified state has α < 0 (no_equilibrium): nothing to certify")
    alpha_hi = alpha_cap + 1e-9 * max(1.0, alpha_cap)  # the cap itself stays feasible (round-off)
    U = settings.velocity_factor * max([float(np.abs(u).max()) for u in mechanisms if u is not None] + [1.0])
    first = np.flatnonzero(np.r_[True, points.joint[1:] != points.joint[:-1]])
    try:
        big_m = derive_big_m(
            model,
            points,
            alpha_hi,
            U,
            first,
            per_point=points.count <= settings.per_point_bounds,
            max_pivots=settings.bound_lp_iterations,
            cap=cap,
        )
    except BoundsFailed as error:
        if error.by_cap:
            return fail(f"{error}; proven lower bound 0", "limit_reached", U)
        return fail(str(error))
    if settings.backend == "scip":
        written = sos1_data(model, points, big_m, first, alpha_hi, U)
        if isinstance(written, str):
            return fail(written)
        return scip_certificate(
            *written, alpha_cap, alpha_hi, alpha_best, U, settings, cap, t0, time.perf_counter() - t0
        )
    data = milp_data(model, points, big_m, first, alpha_hi, U)
    if isinstance(data, str):
        return fail(data)
    bounds_s = time.perf_counter() - t0
    out = _run_milp(data, alpha_hi, alpha_best, settings, cap)
    return _certificate(out, data, alpha_cap, U, t0, bounds_s)
