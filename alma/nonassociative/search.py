"""Non-associative friction: the collapse states of Eq. 9 and the search for the lowest one.

A *collapse state* is a load multiplier α, contact forces (N, T) at every
contact point and a mechanism u (f_Lᵀu > 0) such that

- equilibrium holds (Eq. 3) and forces are admissible (Eq. 4/5: N ≥ 0, |T| ≤ f N);
- the mechanism is compatible (Eq. 2) with no interpenetration (opening ξ ≥ 0);
- the non-associative flow rule and complementarity (Eqs. 6–7 with a slip that
  does not dilate): an open point carries no force (N ξ = 0), and a point that
  slips has its friction fully mobilised against the slip (T = −f N sign γ).

Then α f_Lᵀu = −f_0ᵀu + Σ f N |γ| (virtual work: lifting plus friction
dissipation).  Eq. 9 asks for the smallest such α; the problem is non-convex,
so the answer here is the lowest *verified* state found from several starts:

- ``lp``: the active set of the associative mechanism (Eq. 10), its dilatant
  openings read as slips;
- ``rocking``: macro-blocks turning about a support point (a corner column or
  wedge tipping off its neighbours' faces, :mod:`alma.rocking`), lowest lifting
  bound first (:func:`rocking_start`);
- ``gilbert``: the iterative LP of Gilbert, Casapulla & Ahmed (2006): Coulomb's
  friction slope is driven to zero while the shear capacity is carried as a
  fictitious cohesion f N̄ from the previous normal forces, until N = N̄;
  started from several initial shear caps, relaxations and slope schedules
  (:data:`GILBERT_STARTS`);
- ``gilbert-projected``: the same iteration at slope zero, but with the normal
  forces taken as the static field closest to N̄ among those that carry the LP's α
  (a QP), Anderson-accelerated; it settles on large panels where the vertex
  iterates keep jumping (last, with all the time the fixed starts leave: with
  ``effort="fast"`` when no start verified a state, with ``"thorough"`` when no start
  other than ``rocking`` did; with ``"fast"`` each fixed start is capped at
  :data:`FAST_FIXED_SHARE` of the limit, or at :data:`FAST_FIXED_VERIFIED_SHARE` once a
  state is verified);
- ``ipopt``: a CasADi/IPOPT polish of Eq. 9 with a Scholtes relaxation of the
  complementarity (see ``alma.nlp``), on small scenes;
- ``milp``: on the smallest scenes, the mixed-integer program of ``alma.certify``
  capped at the best state found, which finds a lower state when one exists.

Every candidate is turned into an exact point — its active set fixed, the
smallest α of a static LP with that active set and a mechanism from a
kinematic LP with the same set — and verified before it can be reported.  ``alma.certify`` proves lower bounds by mixed-integer programming.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from alma.nonassociative.cap_lp import CapLP, ClosestField, StaticLP
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.rocking import rocking_candidates

#: Verification tolerances (forces in mean block weights, velocities with f_Lᵀu = n_free).
EQUILIBRIUM_TOLERANCE = 1e-7
YIELD_TOLERANCE = 1e-7
KINEMATIC_TOLERANCE = 1e-7
ENERGY_TOLERANCE = 1e-6
#: Relative velocity below this fraction of the largest counts as zero when reading an active set.
ACTIVE_TOLERANCE = 1e-6
#: HiGHS method for the static LPs (vertex solutions: simplex, or IPM with crossover).
LP_METHOD = "highs"
#: Seconds allowed to one static LP; a stalled LP counts as a failed start, not a hang.
LP_TIME_LIMIT = 60.0


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


def static_lp(model: Model, points: ContactPoints, *, slope: np.ndarray, cap: np.ndarray,
              maximise: bool = True, open_points: np.ndarray | None = None,
              slip_sign: np.ndarray | None = None, time_limit: float = LP_TIME_LIMIT,
              method: str = LP_METHOD) -> StaticLP:
    """The static problem on contact points, solved with HiGHS.

    Yield: |T_p| ≤ slope_p N_p + cap_p (Coulomb: slope = f, cap = 0; Gilbert: slope
    → 0, cap = (f − slope) N̄).  With an active set: N_p = 0 at ``open_points`` and
    T_p = −slip_sign_p f_p N_p where ``slip_sign`` ≠ 0.
    Variables (α, N, T); the mechanism is read from the equality duals.  ``method``: the
    ``scipy.optimize.linprog`` HiGHS method.
    """
    P = points.count
    n = model.dead.shape[0]
    A_eq, b_eq, A_ub = points.static_constraints(model, slope)
    b_ub = np.concatenate([cap, cap])
    bounds = np.zeros((1 + 2 * P, 2))
    bounds[0] = (-np.inf, np.inf)
    bounds[1:1 + P] = (0, np.inf)
    bounds[1 + P:] = (-np.inf, np.inf)
    if open_points is not None and open_points.any():
        bounds[1 + np.flatnonzero(open_points), 1] = 0.0
    if slip_sign is not None and np.any(slip_sign != 0):
        sliding = np.flatnonzero(slip_sign != 0)
        extra = sp.csr_matrix((np.concatenate([slip_sign[sliding] * points.friction[sliding], np.ones(sliding.size)]),
                               (np.tile(np.arange(sliding.size), 2), np.concatenate([1 + sliding, 1 + P + sliding]))),
                              shape=(sliding.size, 1 + 2 * P))
        A_eq = sp.vstack([A_eq, extra]).tocsr()
        b_eq = np.concatenate([b_eq, np.zeros(sliding.size)])
    c = np.zeros(1 + 2 * P)
    c[0] = -1.0 if maximise else 1.0
    # A time limit: HiGHS simplex was seen to stall for minutes on degenerate cap LPs of large walls.
    res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=bounds, method=method,
                  options={"time_limit": time_limit})
    if res.status == 3:
        return StaticLP("unbounded", np.inf if maximise else -np.inf, np.zeros(P), np.zeros(P), None)
    if res.status == 2:
        return StaticLP("infeasible", np.nan, np.zeros(P), np.zeros(P), None)
    if res.status != 0:
        return StaticLP("error", np.nan, np.zeros(P), np.zeros(P), None)
    x = res.x
    mechanism = None
    if maximise and res.eqlin is not None:
        y = -np.asarray(res.eqlin.marginals)[:n]  # ∂(−α)/∂b: f_Lᵀu = 1 at the optimum
        work = model.live @ y
        if work > 0:
            mechanism = y * (model.n_free / work)
    return StaticLP("optimal", float(x[0]), x[1:1 + P], x[1 + P:], mechanism)


def fixed_set_static_interior(model: Model, points: ContactPoints, open_points: np.ndarray,
                              slip_sign: np.ndarray, *, time_limit: float = LP_TIME_LIMIT,
                              tolerance: float = 1e-12) -> StaticLP:
    """The smallest α with a fixed active set (as :func:`static_lp` there), by Clarabel.

    Written on the cone generators n ± f t of each point (Eq. 5): an open point keeps neither,
    a point slipping in +t (T = −f N) keeps only n − f t, one slipping in −t only n + f t.  Then

        min α  s.t.  H_S μ + f_0 + α f_L = 0,  μ ≥ 0

    is solved through its kinematic dual, min f_0ᵀv s.t. f_Lᵀv = c, H_Sᵀv ≤ 0 (the shape and
    size of Eq. 10), and (α, μ) are read from its duals.  An interior point of the optimal face
    rather than a vertex, which is enough: with the set fixed, any optimal field complements a
    mechanism with that set.  Measured on an idle machine (first rocking candidate): 0.09 s on
    flemish 1:1 1:1 (780 blocks) against 6.6 s for HiGHS's interior point and 6.9 s for its
    simplex on (N, T); 0.28 s on english 1:2 1:1 (1,752 blocks) against 42 s and > 60 s.
    """
    import clarabel

    from alma.associative.lp import NORMALISATION

    P = points.count
    plus_kept = ~open_points & (slip_sign <= 0)  # n + f t (T = +f N) only where not slipping in +t
    minus_kept = ~open_points & (slip_sign >= 0)
    kept = np.empty(2 * P, dtype=bool)
    kept[0::2], kept[1::2] = plus_kept, minus_kept
    columns = np.flatnonzero(kept)
    H = model.equilibrium[:, columns]
    n = H.shape[0]
    A = sp.vstack([sp.csr_matrix(model.live[None, :]), H.T]).tocsc()
    b = np.zeros(1 + columns.size)
    b[0] = NORMALISATION * float(model.n_free)
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tolerance
    settings.direct_solve_method = "qdldl"
    settings.iterative_refinement_enable = False
    settings.time_limit = float(time_limit)
    sol = clarabel.DefaultSolver(sp.csc_matrix((n, n)), model.dead.copy(), A, b,
                                 [clarabel.ZeroConeT(1), clarabel.NonnegativeConeT(columns.size)],
                                 settings).solve()
    status = str(sol.status)
    if status == "DualInfeasible":  # the kinematic side unbounded: no static field has this set
        return StaticLP("infeasible", np.nan, np.zeros(P), np.zeros(P), None)
    if status == "PrimalInfeasible":  # no mechanism: α unbounded below
        return StaticLP("unbounded", -np.inf, np.zeros(P), np.zeros(P), None)
    if status not in ("Solved", "AlmostSolved"):
        return StaticLP("error", np.nan, np.zeros(P), np.zeros(P), None)
    z = np.asarray(sol.z)
    mu = np.zeros(2 * P)
    mu[columns] = np.maximum(z[1:], 0.0)
    plus, minus = mu[0::2], mu[1::2]
    return StaticLP("optimal", float(z[0]), plus + minus, points.friction * (plus - minus), None)


def static_lp_clarabel(model: Model, points: ContactPoints, *, slope: np.ndarray, cap: np.ndarray,
                       tolerance: float = 1e-9) -> StaticLP:
    """``static_lp`` (maximise α, no fixed active set) with Clarabel's interior point.

    Much faster than simplex on large scenes; its mechanism is the interior-point
    one (a blend on degenerate faces), so states built from it are always passed
    through :func:`exact_state` before they count.
    """
    import clarabel

    P = points.count
    n = model.dead.shape[0]
    A_eq, b_eq, A_ub = points.static_constraints(model, slope)
    non_negative = sp.hstack([sp.csr_matrix((P, 1)), -sp.identity(P), sp.csr_matrix((P, P))])  # −N ≤ 0
    A = sp.vstack([A_eq, A_ub, non_negative]).tocsc()
    b = np.concatenate([b_eq, cap, cap, np.zeros(P)])
    q = np.zeros(1 + 2 * P)
    q[0] = -1.0
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tolerance
    sol = clarabel.DefaultSolver(sp.csc_matrix((1 + 2 * P, 1 + 2 * P)), q, A, b,
                                 [clarabel.ZeroConeT(n), clarabel.NonnegativeConeT(3 * P)], settings).solve()
    status = str(sol.status)
    if status == "DualInfeasible":
        return StaticLP("unbounded", np.inf, np.zeros(P), np.zeros(P), None)
    if status == "PrimalInfeasible":
        return StaticLP("infeasible", np.nan, np.zeros(P), np.zeros(P), None)
    if status not in ("Solved", "AlmostSolved"):
        return StaticLP("error", np.nan, np.zeros(P), np.zeros(P), None)
    x = np.asarray(sol.x)
    y = np.asarray(sol.z)[:n]  # equality duals: the mechanism, up to sign and scale
    work = model.live @ y
    mechanism = y * (model.n_free / work) if work > 0 else None
    return StaticLP("optimal", float(x[0]), np.maximum(x[1:1 + P], 0.0), x[1 + P:], mechanism)


def active_set(model: Model, points: ContactPoints, mechanism: np.ndarray, *,
               dilatant: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Open points and slip signs of a mechanism (relative velocities below a threshold are zero).

    ``dilatant``: the mechanism obeys the associative flow rule (Eq. 6), where a
    sliding point opens by f |γ|; such a point is read as closed and slipping, and
    only an opening beyond f |γ| as a separation.
    """
    opening = points.normal.T @ mechanism
    slip = points.tangent.T @ mechanism
    scale = max(float(np.abs(opening).max(initial=0.0)), float(np.abs(slip).max(initial=0.0)), 1e-300)
    tol = ACTIVE_TOLERANCE * scale
    if dilatant:
        opening = opening - points.friction * np.abs(slip)
    open_points = opening > tol
    slip_sign = np.where(slip > tol, 1.0, np.where(slip < -tol, -1.0, 0.0))
    return open_points, slip_sign


def force_active_set(points: ContactPoints, normal: np.ndarray, shear: np.ndarray,
                     tolerance: float = 1e-9) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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


def kinematic_lp(model: Model, points: ContactPoints, open_points: np.ndarray, slip_sign: np.ndarray,
                 *, time_limit: float = LP_TIME_LIMIT, free_slip: np.ndarray | None = None) -> np.ndarray | None:
    """A mechanism with a prescribed active set (Eq. 2), or None if there is none.

    Closed points do not open (ξ = 0), open points do not interpenetrate (ξ ≥ 0),
    sticking points do not slip (γ = 0), slipping points slip only in their sign's
    direction (s γ ≥ 0); f_Lᵀu = n_free.  Any such u complements every force field of
    the same active set, so it removes the round-off of the candidate's small velocities.
    """
    closed = ~open_points
    free = np.zeros(points.count, dtype=bool) if free_slip is None else free_slip
    sticking = closed & (slip_sign == 0) & ~free
    slipping = closed & (slip_sign != 0) & ~free
    normal_t = points.normal.T.tocsr()
    tangent_t = points.tangent.T.tocsr()
    A_eq = sp.vstack([sp.csr_matrix(model.live[None, :]), normal_t[np.flatnonzero(closed)],
                      tangent_t[np.flatnonzero(sticking)]]).tocsr()
    b_eq = np.zeros(A_eq.shape[0])
    b_eq[0] = float(model.n_free)
    A_ub = sp.vstack([-normal_t[np.flatnonzero(open_points)],
                      -sp.diags(slip_sign[slipping]) @ tangent_t[np.flatnonzero(slipping)]]).tocsr()
    n = model.dead.shape[0]
    res = linprog(np.zeros(n), A_ub=A_ub if A_ub.shape[0] else None, b_ub=np.zeros(A_ub.shape[0]) if A_ub.shape[0] else None,
                  A_eq=A_eq, b_eq=b_eq, bounds=(None, None), method=LP_METHOD, options={"time_limit": time_limit})
    if res.status != 0:
        return None
    return np.asarray(res.x)


def verify(model: Model, points: ContactPoints, alpha: float, normal: np.ndarray, shear: np.ndarray,
           mechanism: np.ndarray) -> tuple[dict[str, float], bool]:
    """Residuals of a collapse state (equilibrium, yield, kinematics, complementarity, energy)."""
    force_scale = max(1.0, float(np.abs(normal).max(initial=0.0)))
    equilibrium = float(np.abs(points.normal @ normal + points.tangent @ shear + model.dead
                               + alpha * model.live).max(initial=0.0))
    yield_violation = float(max(np.maximum(-normal, 0).max(initial=0.0),
                                np.maximum(np.abs(shear) - points.friction * normal, 0).max(initial=0.0)))
    work = float(model.live @ mechanism)
    u = mechanism * (model.n_free / work) if work > 0 else mechanism
    opening = points.normal.T @ u
    slip = points.tangent.T @ u
    vel_scale = max(float(np.abs(opening).max(initial=0.0)), float(np.abs(slip).max(initial=0.0)), 1e-300)
    penetration = float(np.maximum(-opening, 0).max(initial=0.0)) / vel_scale
    open_force = float((np.maximum(normal, 0) * np.maximum(opening, 0)).max(initial=0.0)) / (force_scale * vel_scale)
    # friction fully mobilised against the slip: f N |γ| + T γ = 0
    slip_gap = float(np.abs(points.friction * np.maximum(normal, 0) * np.abs(slip) + shear * slip).max(initial=0.0)) \
        / (force_scale * vel_scale)
    dissipation = float(np.sum(points.friction * np.maximum(normal, 0) * np.abs(slip)))
    energy = abs(alpha * (model.live @ u) + model.dead @ u - dissipation) / max(1.0, abs(model.dead @ u), dissipation)
    residuals = {"equilibrium": equilibrium / force_scale, "yield": yield_violation / force_scale,
                 "interpenetration": penetration, "open_with_force": open_force, "slip_not_mobilised": slip_gap,
                 "energy_balance": float(energy), "live_load_work": work}
    ok = (work > 0 and residuals["equilibrium"] <= EQUILIBRIUM_TOLERANCE
          and residuals["yield"] <= YIELD_TOLERANCE
          and penetration <= KINEMATIC_TOLERANCE and open_force <= KINEMATIC_TOLERANCE
          and slip_gap <= KINEMATIC_TOLERANCE and energy <= ENERGY_TOLERANCE)
    return residuals, bool(ok)


def exact_state(model: Model, points: ContactPoints, mechanism: np.ndarray, start: str, *,
                dilatant: bool = False, time_limit: float = LP_TIME_LIMIT,
                method: str = LP_METHOD, vertex_time_limit: float = LP_TIME_LIMIT) -> CollapseState | None:
    """Turn a candidate mechanism into an exact collapse state and verify it.

    Its active set is fixed (:func:`active_set`); one static LP takes the smallest
    α with that set (N = 0 where open, T = −f N sign γ where slipping, |T| ≤ f N
    elsewhere) and one kinematic LP (:func:`kinematic_lp`) a mechanism with the same
    set.  The pair satisfies Eq. 9 by construction; :func:`verify` checks it.  When no
    mechanism has exactly that set, the kinematic LP is asked for one within the widest set
    the static field allows (:func:`force_active_set`); failing that, the candidate's own
    mechanism is verified.  ``method``: a HiGHS method of ``scipy.optimize.linprog`` for the
    static LP (a vertex), or ``"clarabel"`` (:func:`fixed_set_static_interior`; then, when no
    mechanism has exactly the set, a HiGHS simplex vertex for at most ``vertex_time_limit`` s
    gives the widest set).
    """
    work = float(model.live @ mechanism)
    if not work > 0:
        return None
    mechanism = mechanism * (model.n_free / work)
    open_points, slip_sign = active_set(model, points, mechanism, dilatant=dilatant)
    if method == "clarabel":
        lp = fixed_set_static_interior(model, points, open_points, slip_sign, time_limit=time_limit)
        if lp.status == "error":  # Clarabel did not converge: HiGHS decides, within the vertex's time
            lp = static_lp(model, points, slope=points.friction, cap=np.zeros(points.count), maximise=False,
                           open_points=open_points, slip_sign=slip_sign,
                           time_limit=min(time_limit, vertex_time_limit), method="highs-ipm")
    else:
        lp = static_lp(model, points, slope=points.friction, cap=np.zeros(points.count), maximise=False,
                       open_points=open_points, slip_sign=slip_sign, time_limit=time_limit, method=method)
    if lp.status != "optimal":
        return None
    clean = kinematic_lp(model, points, open_points, slip_sign, time_limit=time_limit)
    if clean is None and method == "clarabel":
        # Clarabel's field lies inside the optimal face, where fewest points are unloaded or at
        # the friction limit; the widest set below is read from a vertex (HiGHS's simplex).
        # Seen on english 2:1 1:1, f = 0.6 and 1, and 1:1 2:1, f = 1: no mechanism in the set of
        # the interior field, one in that of the simplex vertex (not in that of the vertex after
        # HiGHS's interior point and crossover).
        vertex = static_lp(model, points, slope=points.friction, cap=np.zeros(points.count), maximise=False,
                           open_points=open_points, slip_sign=slip_sign,
                           time_limit=min(time_limit, vertex_time_limit), method="highs")
        if vertex.status == "optimal":
            lp = vertex
    if clean is None:
        # No mechanism has exactly the candidate's set: take the widest set the static field
        # allows (open and free slip where N = 0, slip where friction is at its limit).
        may_open, may_slip, free = force_active_set(points, lp.normal, lp.shear)
        clean = kinematic_lp(model, points, may_open, may_slip, free_slip=free, time_limit=time_limit)
    best = None
    for u in ((clean, mechanism) if clean is not None else (mechanism,)):
        if dilatant and u is mechanism:
            continue  # an associative mechanism opens where it slips: never a non-associative state
        residuals, ok = verify(model, points, lp.alpha, lp.normal, lp.shear, u)
        state = CollapseState(alpha=lp.alpha, normal=lp.normal, shear=lp.shear, mechanism=u, start=start,
                              residuals=residuals, verified=ok)
        if best is None or (ok and not best.verified):
            best = state
        if ok:
            break
    return best


def fast_exact_state(model: Model, points: ContactPoints, mechanism: np.ndarray, start: str, *,
                     dilatant: bool = False, deadline: float | None = None,
                     vertex_time_limit: float = LP_TIME_LIMIT) -> CollapseState | None:
    """:func:`exact_state` with Clarabel's static LP; HiGHS's vertex for at most ``vertex_time_limit`` s.

    When a mechanism has exactly the candidate's set, it complements every optimal field, so the
    interior point of :func:`fixed_set_static_interior` serves as well as a vertex and is far
    faster on large panels (1,752 blocks: 0.28 s, where HiGHS's interior point took 42 s and its
    simplex more than 60 s).  A vertex is needed when the widest set of the field has to be read
    (see :func:`exact_state`) or when the interior field's round-off fails the verification;
    HiGHS gets ``vertex_time_limit`` seconds for it.
    """
    state = exact_state(model, points, mechanism, start, dilatant=dilatant, time_limit=_remaining(deadline),
                        method="clarabel", vertex_time_limit=vertex_time_limit)
    if state is not None and not state.verified and (deadline is None or time.perf_counter() < deadline):
        state = exact_state(model, points, mechanism, start, dilatant=dilatant,
                            time_limit=min(_remaining(deadline), vertex_time_limit), method="highs-ipm")
    return state


def gilbert(model: Model, points: ContactPoints, initial_normal: np.ndarray, *, start: str = "gilbert",
            relaxation: float = 0.5, slope_steps: int = 4, max_iter: int = 40,
            tolerance: float = 1e-7, ipm_above: int = 6000,
            deadline: float | None = None) -> tuple[CollapseState | None, int]:
    """Iterative LP of Gilbert, Casapulla & Ahmed (2006).

    The friction slope is halved each step down to zero while the rest of the
    shear capacity is a fictitious cohesion (f − slope) N̄ from the previous
    normal forces; at slope zero the sliding flow rule has no dilatancy.  An
    iterate whose own forces already satisfy Coulomb's law with its mechanism
    (|T| ≤ f N, slipping points at T = −f N sign γ: checked by :func:`verify`)
    is an exact collapse state and ends the loop; otherwise the loop stops
    when N = N̄.  Scenes up to ``ipm_above`` contact points re-solve one
    persistent HiGHS model from the previous basis (:class:`~alma.cap_lp.CapLP`);
    larger ones use Clarabel's interior point.  ``deadline`` (perf_counter
    seconds) bounds the time.  Returns the best verified state (or the exact
    state of the last mechanism), and the iterations used.
    """
    f = points.friction
    n_bar = np.maximum(initial_normal, 0.0)
    used = 0
    interior = points.count > ipm_above
    cap_lp = None if interior else CapLP(model, points, time_limit=LP_TIME_LIMIT)
    last = None
    best: CollapseState | None = None
    seen: set[tuple[bytes, bytes]] = set()
    tried: set[tuple[bytes, bytes]] = set()
    for iteration in range(max_iter):
        if deadline is not None and time.perf_counter() > deadline:
            break
        ratio = 0.5 ** (iteration + 1) if iteration < slope_steps else 0.0
        slope = f * ratio
        if interior:
            lp = static_lp_clarabel(model, points, slope=slope, cap=(f - slope) * n_bar)
        else:
            lp = cap_lp.solve(slope, (f - slope) * n_bar, time_limit=_remaining(deadline))
        used += 1
        if lp.status != "optimal" or lp.mechanism is None:
            break
        last = lp
        if ratio == 0.0:
            residuals, ok = verify(model, points, lp.alpha, lp.normal, lp.shear, lp.mechanism)
            if ok and (best is None or lp.alpha < best.alpha):  # the iterate is itself a Coulomb collapse state
                best = CollapseState(alpha=lp.alpha, normal=lp.normal, shear=lp.shear, mechanism=lp.mechanism,
                                     start=start, residuals=residuals, verified=True)
        change = float(np.abs(lp.normal - n_bar).max(initial=0.0))
        if ratio == 0.0 and change <= tolerance * max(1.0, float(np.abs(lp.normal).max(initial=0.0))):
            break
        if ratio == 0.0 and not interior:
            # Once an active set comes back (the iterates settle or cycle), its exact state usually
            # verifies: try each such set once, and stop at the first verified state.
            open_points, slip_sign = active_set(model, points, lp.mechanism)
            current = (open_points.tobytes(), slip_sign.tobytes())
            if current in seen and current not in tried:
                tried.add(current)
                state = exact_state(model, points, lp.mechanism, start, time_limit=_remaining(deadline))
                if state is not None and state.verified:
                    return _lower(state, best), used
            seen.add(current)
        n_bar = n_bar + relaxation * (lp.normal - n_bar)
    if last is None:
        return best, used
    limit = _remaining(deadline, floor=LATE_LP_TIME)
    return _lower(exact_state(model, points, last.mechanism, start, time_limit=limit), best), used


def projected_gilbert(model: Model, points: ContactPoints, initial_normal: np.ndarray, *,
                      start: str = "gilbert-projected", plain_steps: int = 0, memory: int = 5,
                      max_iter: int = 400, tolerance: float = 1e-7, restart_after: int = 60,
                      restart_plain_steps: int = 20,
                      deadline: float | None = None) -> tuple[CollapseState | None, int]:
    """Gilbert's iteration at slope zero with the normal forces chosen by projection.

    Each iteration takes α* and the mechanism u from the capped LP (cap f N̄, warm HiGHS),
    then, among the static fields that carry α*, the one closest to N̄
    (:class:`~alma.cap_lp.ClosestField`).  On large panels the plain iteration jumps between
    distant vertices of a large optimal face and never settles; the projected one moves N̄
    only as far as the face forces it to, and its fixed point (N = N̄) is a collapse state:
    |T| ≤ f N̄ = f N, and u slips only where |T| = f N.  N̄ ← N is accelerated by Anderson
    mixing of the last ``memory`` steps (the face drifts for tens of iterations in one
    direction).  The first ``plain_steps`` iterations are plain (vertex N, relaxation 0.5).
    When ``restart_after`` projected iterations have not settled, the iteration starts again
    (once) from the initial field with ``restart_plain_steps`` plain iterations first:
    projecting from the associative field at once settles in tens of iterations on most large
    panels, where 20 plain steps first cost 15 s of warm re-solves after large cap jumps (588
    blocks), but on some (english 1:1, blocks 4:1, f = 1) it drifts along the face and only the
    plain steps' vertex jumps get it out.  A verified iterate ends the loop; its mechanism's exact state
    (:func:`exact_state`) is also taken, whichever is lower.
    """
    f = points.friction
    n_bar = np.maximum(initial_normal, 0.0)
    cap_lp = CapLP(model, points, time_limit=LP_TIME_LIMIT)
    closest = None
    history_x: list[np.ndarray] = []
    history_g: list[np.ndarray] = []
    best: CollapseState | None = None
    lp = None
    used = 0
    plain_left, projected_run, restarted = plain_steps, 0, False
    for _ in range(max_iter):
        if deadline is not None and time.perf_counter() > deadline:
            break
        lp = cap_lp.solve(np.zeros(points.count), f * n_bar, time_limit=_remaining(deadline))
        used += 1
        if lp.status != "optimal" or lp.mechanism is None:
            break
        normal, shear = lp.normal, lp.shear
        plain = plain_left > 0
        if not plain:
            closest = closest or ClosestField(model, points)
            # α* less a hair: the face at α* exactly is only feasible to the LP's tolerance.
            nearest = closest.solve(lp.alpha - 1e-9 * max(1.0, abs(lp.alpha)), f * n_bar, n_bar)
            if nearest is None:
                break
            normal, shear = nearest
        residuals, ok = verify(model, points, lp.alpha, normal, shear, lp.mechanism)
        if ok:
            best = CollapseState(alpha=lp.alpha, normal=normal, shear=shear, mechanism=lp.mechanism,
                                 start=start, residuals=residuals, verified=True)
            break
        step = normal - n_bar
        if plain:
            plain_left -= 1
            n_bar = n_bar + 0.5 * step
            continue
        if float(np.abs(step).max(initial=0.0)) <= tolerance * max(1.0, float(np.abs(normal).max(initial=0.0))):
            break
        projected_run += 1
        if projected_run >= restart_after and not restarted and restart_plain_steps > 0:
            plain_left, projected_run, restarted = restart_plain_steps, 0, True
            history_x, history_g = [], []
            n_bar = np.maximum(initial_normal, 0.0)  # the earlier path: plain steps from the start field
            continue
        history_x = (history_x + [n_bar.copy()])[-(memory + 1):]
        history_g = (history_g + [step])[-(memory + 1):]
        if len(history_x) > 1:
            # Anderson (type II): the combination of the last steps that best cancels the residual.
            d_g = np.diff(np.array(history_g), axis=0).T
            d_x = np.diff(np.array(history_x), axis=0).T
            gamma = np.linalg.lstsq(d_g, step, rcond=None)[0]
            n_bar = np.maximum(n_bar + step - (d_x + d_g) @ gamma, 0.0)
        else:
            n_bar = n_bar + step
    if lp is None or lp.mechanism is None:
        return best, used
    return _lower(exact_state(model, points, lp.mechanism, start, time_limit=_remaining(deadline)), best), used


def _remaining(deadline: float | None, floor: float = 1.0) -> float:
    """Seconds left for one LP: the per-LP limit, or less when the search's deadline is nearer
    (but at least ``floor``)."""
    if deadline is None:
        return LP_TIME_LIMIT
    return float(min(LP_TIME_LIMIT, max(floor, deadline - time.perf_counter())))


#: A Gilbert start past its deadline still turns its last iterate into an exact state, with at
#: most this many seconds per LP.  With the 1 s of the other LPs, every start that ran out of its
#: share overran it by ~1 s on large panels (54 s in a 108-panel run of 2026-11-23, 68 runs),
#: where that LP then stopped at its limit without a state.
LATE_LP_TIME = 0.1


def _lower(state: CollapseState | None, other: CollapseState | None) -> CollapseState | None:
    """The verified state with the smaller α (an unverified one only if neither is verified)."""
    if state is None or (other is not None and other.verified and (not state.verified or other.alpha < state.alpha)):
        return other
    return state


#: Gilbert starts (initial N̄ as a multiple of the associative normal forces, relaxation of the
#: N̄ update, slope-halving steps).  Measured on the paper panels up to 300 blocks: no single
#: start is always lowest; (0, 1, 1) and (1, 0.5, 0) are cheap and together found the lowest state
#: on most panels; the thorough set adds the slower variants.
GILBERT_STARTS: dict[str, tuple[tuple[float, float, int], ...]] = {
    "fast": ((0.0, 1.0, 1), (1.0, 0.5, 0)),
    "thorough": ((0.0, 1.0, 1), (1.0, 0.5, 0), (0.0, 1.0, 4), (1.0, 0.5, 4), (0.5, 0.5, 1), (2.0, 1.0, 1),
                 (1.0, 1.0, 0)),
}


#: The rocking start tries the exact states of at most this many macro-block rotations, lowest
#: lifting bound first, for at most ``ROCKING_SHARE`` of the time limit.
ROCKING_TRIES = 4
ROCKING_SHARE = 0.25


def rocking_start(model: Model, points: ContactPoints, verified: list[CollapseState], *,
                  tries: int = ROCKING_TRIES, upper: float | None = None,
                  deadline: float | None = None,
                  vertex_time_limit: float = LP_TIME_LIMIT) -> tuple[CollapseState | None, int]:
    """The lowest verified exact state among macro-block rotations (:mod:`alma.rocking`).

    Candidates are taken in the order of their lifting bound (a lower bound on the α of any
    state with that mechanism) while the bound is below the best verified α so far and below
    ``upper`` (the associative α: Radenkovic's theorem puts the minimum below it, so a
    candidate bounded above it cannot be the answer; on the paper panels such candidates' static
    LPs took 20-30 s each to fail).  Returns the state (None if none verified) and the number of
    candidates tried.
    """
    best_alpha = min([c.alpha for c in verified] + ([upper] if upper is not None and np.isfinite(upper) else []),
                     default=np.inf)
    best: CollapseState | None = None
    tried = 0
    for candidate in rocking_candidates(model, points, keep=tries, deadline=deadline):
        if tried >= tries or candidate.lifting_bound >= best_alpha - 1e-12:
            break
        if deadline is not None and time.perf_counter() > deadline:
            break
        tried += 1
        state = fast_exact_state(model, points, candidate.mechanism, "rocking", deadline=deadline,
                                 vertex_time_limit=vertex_time_limit)
        if state is not None and state.verified and state.alpha < best_alpha:
            best, best_alpha = state, state.alpha
    return best, tried


#: The ``lp`` and ``rocking`` starts give a HiGHS vertex (:func:`fast_exact_state`) at most this
#: fraction of the time limit: on the paper panels of 780 blocks and more its simplex took 5-60 s,
#: and there its widest set had no mechanism either (2026-11-23).  At 0.1 (6 s of 60), no `lp`
#: start that took over 3 s verified a state in three 108-panel runs (18-19 such runs each, 99 s).
VERTEX_SHARE = 0.05
#: Scenes up to this many contact points take the ``lp`` start's static LP from HiGHS's simplex.
LP_VERTEX_POINTS = 1000

#: With ``effort="fast"`` and a time limit, a fixed Gilbert start runs for at most this fraction of it,
FAST_FIXED_SHARE = 0.2
#: and for at most this fraction once an earlier start has verified a state.  In the 108-panel run
#: of 2026-11-23 (60 s, fast-stop) 60 fixed-start runs used up their 12 s without verifying; of
#: the runs that began after a verified state, those that verified after 6 s were the lowest on
#: one panel (english 1:2 4:1 f = 1, 0.42492 at 7.99 s, against 0.43643).
FAST_FIXED_VERIFIED_SHARE = 0.1

#: With ``effort="thorough"``, scenes up to this many free blocks also get the MILP of
#: :mod:`alma.certify` as a start, for at most ``MILP_START_TIME`` seconds (it proves 7–12-block
#: scenes within a minute, the smallest ones in well under a second).
MILP_START_BLOCKS = 12
MILP_START_TIME = 10.0


@dataclass(frozen=True)
class StartRecord:
    """What one start of the search cost and gave: α of its state (NaN if none), verified or not."""

    start: str
    time_s: float
    iterations: int
    alpha: float
    verified: bool


@dataclass(frozen=True)
class NonAssociativeSolution:
    status: str  # optimal (a verified state) | not_converged | no_collapse | no_equilibrium
    message: str
    best: CollapseState | None
    candidates: tuple[CollapseState, ...]
    timings: dict[str, float]
    starts: tuple[StartRecord, ...] = ()  # in the order they ran


def solve_nonassociative(model: Model, associative_mechanism: np.ndarray | None,
                         associative_multipliers: np.ndarray | None, *, effort: str = "fast",
                         polish: bool | None = None, time_limit: float | None = None,
                         associative_alpha: float | None = None) -> NonAssociativeSolution:
    """Lowest verified collapse state of Eq. 9 over several starts (see module docstring).

    ``time_limit`` (s): no start begins, and no Gilbert iteration, after it has passed;
    the states found by then are the answer (the timings say how far the search got).
    """
    deadline = None if time_limit is None else time.perf_counter() + time_limit
    if effort not in ("fast", "thorough"):
        raise ValueError(f"effort must be 'fast' or 'thorough', got {effort!r}")
    points = ContactPoints.from_model(model)
    timings: dict[str, float] = {}
    candidates: list[CollapseState] = []
    records: list[StartRecord] = []

    def add(state: CollapseState | None, name: str, since: float, iterations: int = 0) -> None:
        if state is not None:
            candidates.append(state)
        records.append(StartRecord(name, time.perf_counter() - since, int(iterations),
                                   state.alpha if state is not None else float("nan"),
                                   state is not None and state.verified))

    vertex_time_limit = LP_TIME_LIMIT if time_limit is None else VERTEX_SHARE * time_limit
    t0 = time.perf_counter()
    if associative_mechanism is not None:
        # Clarabel's static LP: on panels of 780 blocks and more HiGHS's simplex, on a highly
        # degenerate face, took 10-60 s.  On the 108 panels (2026-11-23) this start took 148 s in
        # all against 482 s and gave the same state on 105; on the other 3 (876-1,752 blocks) the
        # vertex needed more than its 6 s, and the search's answer there is 0.25, far below.
        # Up to LP_VERTEX_POINTS contact points HiGHS's simplex vertex is cheap and exact to the last
        # digit: Clarabel's interior field put the lp state of three blocks side by side (f = 0.45)
        # at α = 0.45 − 2e-14, and with that cap HiGHS's MILP in alma.certify settled at 0.4499977
        # (verification/test_certify.py, hypothesis, 2026-11-23).  That MILP's own fix, its
        # integrality tolerance (alma.certify.MIP_INTEGRALITY_TOLERANCE), passes the same test
        # with Clarabel's state too (checked with LP_VERTEX_POINTS = 0); the vertex stays here
        # because it is exact and cheap on small scenes.
        if points.count <= LP_VERTEX_POINTS:
            state = exact_state(model, points, associative_mechanism, "lp", dilatant=True,
                                time_limit=_remaining(deadline))
        else:
            state = fast_exact_state(model, points, associative_mechanism, "lp", dilatant=True, deadline=deadline,
                                     vertex_time_limit=vertex_time_limit)
        add(state, "lp", t0)
    timings["lp_start_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    state, tried = rocking_start(model, points, [c for c in candidates if c.verified], upper=associative_alpha,
                                 deadline=None if deadline is None else t0 + ROCKING_SHARE * time_limit,
                                 vertex_time_limit=vertex_time_limit)
    add(state, "rocking", t0, tried)
    timings["rocking_s"] = time.perf_counter() - t0

    # Normal forces of the associative static field (the two generators of each point).
    if associative_multipliers is not None and associative_multipliers.size:
        n_lp = associative_multipliers.reshape(-1, 2).sum(axis=1)
    else:
        n_lp = np.zeros(points.count)
    starts = GILBERT_STARTS[effort]
    t0 = time.perf_counter()
    iterations = 0

    fixed = [(f"gilbert(N̄={scale:g}·N_LP, r={relaxation:g}, steps={slope_steps})", scale, relaxation, slope_steps)
             for scale, relaxation, slope_steps in starts]
    # "thorough" (small scenes): the fixed starts, then the projected iteration if none verified.
    # "fast" (large scenes): the fixed starts, each for at most FAST_FIXED_SHARE of the time limit
    # (FAST_FIXED_VERIFIED_SHARE once a state is verified; an equal share of what is left when
    # that is less), then, if no start verified, the projected iteration with all the time that
    # is left.  In the 108-panel run of 2026-11-23 (time limit 60 s, equal shares) the fixed
    # starts, when they verified at all, did so in a median of 2.5-4.5 s (5 of 98 after 12 s);
    # their vertex iterates otherwise never settle and use up their share, while the
    # projected iteration settles on large panels but needed 18-32 s where it was timed alone.
    plan: list = fixed + ["projected"]
    for k, item in enumerate(plan):
        now = time.perf_counter()
        if deadline is not None and now > deadline:
            timings["stopped_by_time_limit"] = 1.0
            break
        if item == "projected" and any(c.verified and (effort == "fast" or c.start != "rocking")
                                       for c in candidates):
            # "thorough": a rocking state does not count, since the projected iteration can go
            # below it (flemish 2:1 2:1 f = 1: 0.5514 against the corner column's 0.5909).
            # "fast": any verified state ends the search here.  In the 108-panel run of
            # 2026-11-23 (60 s) the projected iteration took 1,086 of the 2,625 s of search on the
            # 74 panels where another start had verified, and went lower on 2 of them (by 0.0011
            # and 0.0017); where nothing else verifies it still runs, with all the time left.
            continue
        share = None
        if deadline is not None:
            cap = FAST_FIXED_VERIFIED_SHARE if any(c.verified for c in candidates) else FAST_FIXED_SHARE
            share = deadline if effort == "thorough" or item == "projected" else \
                now + min((deadline - now) / (len(plan) - k), cap * time_limit)
        if item == "projected":
            name = "gilbert-projected"
            state, used = projected_gilbert(model, points, n_lp, start=name, deadline=share)
        else:
            name, scale, relaxation, slope_steps = item
            state, used = gilbert(model, points, scale * n_lp, relaxation=relaxation, slope_steps=slope_steps,
                                  start=name, deadline=share)
        iterations += used
        add(state, name, now, used)
    timings["gilbert_s"] = time.perf_counter() - t0
    timings["gilbert_iterations"] = float(iterations)

    if polish is None:
        polish = effort == "thorough" and model.n_free <= 60
    if polish and (deadline is None or time.perf_counter() < deadline):
        from alma.nonassociative.nlp import ipopt_polish

        t0 = time.perf_counter()
        verified = [c for c in candidates if c.verified]
        seed = min(verified, key=lambda c: c.alpha) if verified else None
        mech = seed.mechanism if seed is not None else associative_mechanism
        if mech is not None:
            left = None if deadline is None else max(0.0, deadline - time.perf_counter())
            add(ipopt_polish(model, points, mech, seed, time_limit=left), "ipopt", t0)
        timings["ipopt_s"] = time.perf_counter() - t0

    if (effort == "thorough" and model.n_free <= MILP_START_BLOCKS and associative_alpha is not None
            and np.isfinite(associative_alpha) and associative_alpha >= 0
            and (deadline is None or time.perf_counter() < deadline)):
        # Small scenes: the mixed-integer program of alma.certify as one more start. Capped at the
        # best verified α, it returns a lower state if one exists (within its time), and that
        # state goes through the same exact-state verification as every other candidate.
        from alma.certify.milp import certify

        t0 = time.perf_counter()
        verified = [c for c in candidates if c.verified]
        best_alpha = min(c.alpha for c in verified) if verified else None
        limit = MILP_START_TIME if deadline is None else min(MILP_START_TIME, max(0.0, deadline - t0))
        mechanisms = [c.mechanism for c in candidates] + ([associative_mechanism]
                                                          if associative_mechanism is not None else [])
        certificate = certify(model, associative_alpha, mechanisms, time_limit=limit, alpha_best=best_alpha)
        add(exact_state(model, points, certificate.mechanism, "milp") if certificate.mechanism is not None else None,
            "milp", t0)
        timings["milp_start_s"] = time.perf_counter() - t0

    verified = [c for c in candidates if c.verified]
    if not verified:
        return NonAssociativeSolution("not_converged", "no verified collapse state was found",
                                      None, tuple(candidates), timings, tuple(records))
    best = min(verified, key=lambda c: c.alpha)
    status = "optimal" if best.alpha >= 0 else "no_equilibrium"
    return NonAssociativeSolution(status, f"lowest verified collapse state from start '{best.start}'",
                                  best, tuple(candidates), timings, tuple(records))
