"""Collapse states of Eq. 9: active sets and verification (a mechanism's exact state: :mod:`.exact_states`).

A *collapse state* is a load multiplier α, contact forces (N, T) at every contact point and a
mechanism u (f_Lᵀu > 0) such that equilibrium holds (Eq. 3), forces are admissible (Eq. 5:
N ≥ 0, |T| ≤ f N), the mechanism is compatible (Eq. 2) with no interpenetration, an open point
carries no force (N ξ = 0) and a slipping point has its friction fully mobilised against the
slip (T = −f N sign γ; Eqs. 6–7 without dilatancy).  Then α f_Lᵀu = −f_0ᵀu + Σ f N |γ|.

With cohesion and ties the equilibrium gains their forces, points.normal N + points.tangent T +
G τ + f_0 + α f_L = 0 with 0 ≤ τ ≤ capacity; a cohesive joint's yield |T_joint| ≤ f N_joint +
c l t is the point generators plus its two bounded shear columns.  A slipping joint has its
cohesive shear at the bound against the slip and its point shears at −s f N; a joint that opens
or hinges without slip leaves the cohesive shear free within its bounds; a tie that elongates
pulls with its strength, one that shortens is slack (:mod:`alma.nonassociative.bounded`).  The
energy balance becomes α f_Lᵀu = −f_0ᵀu + Σ f N |γ| + Σ c l t |γ_joint| + Σ strength ·
max(0, elongation rate).  The active set of a state then has a third part, the bounded columns'
signs, fixed in the static LP (τ at capacity, at 0, or free) and in the kinematic LP alike.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from alma.floats import dot
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative import bounded as bf
from alma.settings import StateTolerances

#: The default tolerances (:class:`alma.settings.StateTolerances`; a search passes its settings').
TOLERANCES = StateTolerances()


@dataclass(frozen=True)
class CollapseState:
    """A candidate collapse state and its verification residuals (all dimensionless)."""

    alpha: float
    normal: np.ndarray  # N at each contact point
    shear: np.ndarray  # T at each contact point
    mechanism: np.ndarray  # u (3 n_free), f_Lᵀu = n_free
    start: str
    residuals: dict[str, float] = field(default_factory=dict)
    verified: bool = False
    #: τ of the bounded forces (cohesion, ties), 0 ≤ τ ≤ capacity; empty without them.
    bounded: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass
class Tally:
    """Work one start has spent so far: LP solves and simplex (or interior-point) iterations."""

    solves: int = 0
    pivots: int = 0

    def add(self, pivots: int) -> None:
        """Count one more LP solve of ``pivots`` iterations."""
        self.solves += 1
        self.pivots += int(pivots)


@dataclass(frozen=True)
class ExactLimits:
    """Iteration caps of the LPs that make a mechanism an exact state."""

    #: Simplex iterations of each HiGHS static or kinematic LP.
    lp_pivots: int = 200_000
    #: HiGHS iterations (interior point, crossover) of the vertex asked for after Clarabel's field.
    vertex_pivots: int = 200_000
    #: Clarabel iterations of the fixed-active-set LP.
    interior_iterations: int = 200
    #: When the state is verified, and how its active sets are read.
    tolerances: StateTolerances = field(default_factory=StateTolerances)


def velocity_scale(mechanism: np.ndarray, *relative: np.ndarray, linkage: float = TOLERANCES.linkage) -> float:
    """The scale of a mechanism's velocities: its largest relative velocity (openings, slips,
    bounded rates) or, when that is below ``linkage`` times the largest velocity of a block's
    centroid, that centroid velocity (same units).  The second case is a linkage: the four-hinge
    arch displaced onto its point hinges turns every block and moves no contact (each hinge turns
    about its point), so its relative velocities are round-off, by which no share can be read."""
    contacts = max((float(np.abs(v).max(initial=0.0)) for v in relative), default=0.0)
    centroids = float(np.abs(mechanism.reshape(-1, 3)[:, :2]).max(initial=0.0))
    return max(contacts if contacts > linkage * centroids else centroids, 1e-300)


def active_set(
    model: Model,
    points: ContactPoints,
    mechanism: np.ndarray,
    *,
    dilatant: bool = False,
    tolerance: float = TOLERANCES.active,
    linkage: float = TOLERANCES.linkage,
) -> tuple[np.ndarray, np.ndarray]:
    """Open points and slip signs of a mechanism (relative velocities below a threshold are zero).

    ``dilatant``: the mechanism obeys the associative flow rule (Eq. 6), where a
    sliding point opens by f |γ|; such a point is read as closed and slipping, and
    only an opening beyond f |γ| as a separation.  ``tolerance``: the share of the largest
    relative velocity below which one counts as zero (:attr:`alma.settings.StateTolerances.active`),
    or the centroids' largest velocity for a linkage (``linkage``, :func:`velocity_scale`).
    """
    opening = points.normal.T @ mechanism
    slip = points.tangent.T @ mechanism
    tol = tolerance * velocity_scale(mechanism, opening, slip, linkage=linkage)
    if dilatant:
        opening = opening - points.friction * np.abs(slip)
    open_points = opening > tol
    slip_sign = np.where(slip > tol, 1.0, np.where(slip < -tol, -1.0, 0.0))
    return open_points, slip_sign


def bounded_active_set(
    model: Model,
    points: ContactPoints,
    mechanism: np.ndarray,
    tolerance: float = TOLERANCES.active,
    linkage: float = TOLERANCES.linkage,
) -> np.ndarray:
    """Signs of the bounded columns' rates d = −Gᵀu (:mod:`alma.nonassociative.bounded`), read
    to the threshold of :func:`active_set` (relative to the largest opening, slip or rate)."""
    if not model.n_bounded:
        return np.zeros(0)
    d = bf.rates(model, mechanism)
    scale = velocity_scale(mechanism, points.normal.T @ mechanism, points.tangent.T @ mechanism, d, linkage=linkage)
    return bf.rate_signs(d, tolerance * scale)


def _allowed(signs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rates a bounded active set allows (+1: d ≥ 0, −1: d ≤ 0, 0: d = 0)."""
    return signs > 0, signs < 0


def force_active_set(
    points: ContactPoints, normal: np.ndarray, shear: np.ndarray, tolerance: float = TOLERANCES.force
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The most permissive mechanism set a force field allows (complementarity of Eq. 7).

    Returns (may_open, may_slip_sign, free_slip): a point with N = 0 may open and slip either way;
    a point at the friction limit T = −s f N (N > 0) may slip in direction s; any other point
    must stay closed and stick.  "= 0" and "at the limit" are read to ``tolerance`` times the
    largest normal force.
    """
    scale = max(1.0, float(np.abs(normal).max(initial=0.0)))
    unloaded = normal <= tolerance * scale
    limit = points.friction * normal
    at_plus = (~unloaded) & (shear <= -limit + tolerance * scale)  # T = −f N: slip in +t
    at_minus = (~unloaded) & (shear >= limit - tolerance * scale)  # T = +f N: slip in −t
    sign = np.where(at_plus, 1.0, np.where(at_minus, -1.0, 0.0))
    return unloaded, sign, unloaded


def verify(
    model: Model,
    points: ContactPoints,
    alpha: float,
    normal: np.ndarray,
    shear: np.ndarray,
    mechanism: np.ndarray,
    bounded: np.ndarray | None = None,
    tolerances: StateTolerances = TOLERANCES,
) -> tuple[dict[str, float], bool]:
    """Residuals of a collapse state (Eqs. 2, 3, 5, 7 and the energy balance) and whether all pass.

    ``bounded``: τ of the model's bounded forces (required when it has them); their equilibrium,
    bounds, flow rule and dissipation are checked with the rest (module docstring), and the
    residuals gain ``bounded_not_mobilised``.  ``tolerances``: what passes
    (:class:`alma.settings.StateTolerances`).  The kinematic residuals are relative to the largest
    relative velocity, or for a linkage of point hinges, which moves no contact, to the largest
    centroid velocity (:func:`velocity_scale`).
    """
    q = model.n_bounded
    tau = np.zeros(0) if bounded is None else np.asarray(bounded, dtype=float)
    if tau.shape != (q,):
        raise ValueError(f"verify: {q} bounded forces expected (cohesion, ties), got {tau.shape[0]}")
    force_scale = max(1.0, float(np.abs(normal).max(initial=0.0)), float(tau.max(initial=0.0)))
    balance = points.normal @ normal + points.tangent @ shear + model.dead + alpha * model.live
    if q:
        balance = balance + model.bounded @ tau  # type: ignore[operator]  # q > 0: the model has its columns
    equilibrium = float(np.abs(balance).max(initial=0.0))
    yield_violation = float(
        max(
            np.maximum(-normal, 0).max(initial=0.0),
            np.maximum(np.abs(shear) - points.friction * normal, 0).max(initial=0.0),
        )
    )
    work = dot(model.live, mechanism)
    u = mechanism * (model.n_free / work) if work > 0 else mechanism
    opening = points.normal.T @ u
    slip = points.tangent.T @ u
    rates = bf.rates(model, u)
    vel_scale = velocity_scale(u, opening, slip, rates, linkage=tolerances.linkage)
    penetration = float(np.maximum(-opening, 0).max(initial=0.0)) / vel_scale
    open_force = float((np.maximum(normal, 0) * np.maximum(opening, 0)).max(initial=0.0)) / (force_scale * vel_scale)
    # friction fully mobilised against the slip: f N |γ| + T γ = 0
    slip_gap = float(np.abs(points.friction * np.maximum(normal, 0) * np.abs(slip) + shear * slip).max(initial=0.0)) / (
        force_scale * vel_scale
    )
    dissipation = float(np.sum(points.friction * np.maximum(normal, 0) * np.abs(slip)))
    bounded_gap = 0.0
    if q:
        bounded_yield, bounded_gap, bounded_work = bf.residuals(model, tau, rates, force_scale, vel_scale)
        yield_violation, dissipation = max(yield_violation, bounded_yield), dissipation + bounded_work
    energy = abs(alpha * dot(model.live, u) + dot(model.dead, u) - dissipation) / max(
        1.0, abs(dot(model.dead, u)), dissipation
    )
    residuals = {
        "equilibrium": equilibrium / force_scale,
        "yield": yield_violation / force_scale,
        "interpenetration": penetration,
        "open_with_force": open_force,
        "slip_not_mobilised": slip_gap,
        "energy_balance": float(energy),
        "live_load_work": work,
    }
    if q:
        residuals["bounded_not_mobilised"] = bounded_gap
    t = tolerances
    ok = (
        work > 0
        and residuals["equilibrium"] <= t.equilibrium
        and residuals["yield"] <= t.yield_violation
        and penetration <= t.kinematic
        and open_force <= t.kinematic
        and slip_gap <= t.kinematic
        and bounded_gap <= t.kinematic
        and energy <= t.energy
    )
    return residuals, bool(ok)


def lowest(states: list[CollapseState], same: float) -> CollapseState | None:
    """The first of ``states`` whose α is within ``same`` (relative) of the lowest α, if any."""
    if not states:
        return None
    floor = min(c.alpha for c in states)
    return next(c for c in states if c.alpha <= floor + same * max(1.0, abs(floor)))


def lower(state: CollapseState | None, other: CollapseState | None) -> CollapseState | None:
    """The verified state with the smaller α (an unverified one only if neither is verified)."""
    if state is None or (other is not None and other.verified and (not state.verified or other.alpha < state.alpha)):
        return other
    return state
