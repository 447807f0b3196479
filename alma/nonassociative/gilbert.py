"""The iterative LP of Gilbert, Casapulla & Ahmed (2006), plain and projected.

Coulomb's friction slope is driven to zero while the shear capacity is carried as a fictitious
cohesion f N̄ from the previous normal forces, until N = N̄: then the sliding flow rule has no
dilatancy and the iterate is a collapse state of Eq. 9.  With cohesion and ties the capped LP
carries their forces 0 ≤ τ ≤ capacity beside the points' (:mod:`alma.nonassociative.cap_lp`):
the fictitious cohesion adds to the real one, and at N = N̄ the LP's optimality puts each τ on
its flow rule (:mod:`alma.nonassociative.bounded`).  Both variants spend a :class:`Work`
budget (LP solves and simplex iterations) and stop early only at the user's :class:`Cap`.
"""

from __future__ import annotations

from typing import cast

import numpy as np

from alma.floats import least_squares, times
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.cap_lp import CapLP
from alma.nonassociative.closest_field import ClosestField
from alma.nonassociative.exact_states import exact_state_by
from alma.nonassociative.fixed_set_lps import FixedSetLPs
from alma.nonassociative.limits import Cap, Work, no_cap
from alma.nonassociative.states import CollapseState, Tally, active_set, bounded_active_set, lower, verify
from alma.nonassociative.static_lps import StaticLP, static_lp_clarabel
from alma.settings import StateTolerances


def _settled(lp: StaticLP, n_bar: np.ndarray, tolerance: float) -> bool:
    """N = N̄ to ``tolerance`` of the largest normal force."""
    change = float(np.abs(lp.normal - n_bar).max(initial=0.0))
    return change <= tolerance * max(1.0, float(np.abs(lp.normal).max(initial=0.0)))


def _as_state(
    model: Model,
    points: ContactPoints,
    alpha: float,
    normal: np.ndarray,
    shear: np.ndarray,
    mechanism: np.ndarray,
    start: str,
    bounded: np.ndarray,
    tolerances: StateTolerances,
    checked: tuple[dict[str, float], bool] | None = None,
) -> CollapseState | None:
    """The iterate itself (``bounded``: its τ) as a verified collapse state, or None if it fails
    (``checked``: its :func:`verify` already done)."""
    residuals, ok = checked or verify(model, points, alpha, normal, shear, mechanism, bounded, tolerances)
    if not ok:
        return None
    return CollapseState(
        alpha=alpha,
        normal=normal,
        shear=shear,
        mechanism=mechanism,
        start=start,
        residuals=residuals,
        verified=True,
        bounded=bounded,
    )


def gilbert(
    model: Model,
    points: ContactPoints,
    initial_normal: np.ndarray,
    *,
    start: str = "gilbert",
    relaxation: float = 0.5,
    slope_steps: int = 4,
    tolerance: float = 1e-7,
    ipm_above: int = 6000,
    yield_rows: bool = False,
    work: Work = Work(),
    cap: Cap | None = None,
    tally: Tally | None = None,
    lps: FixedSetLPs | None = None,
) -> tuple[CollapseState | None, int]:
    """Iterative LP of Gilbert, Casapulla & Ahmed (2006) on Eqs. 3 and 5.

    The friction slope is halved for ``slope_steps`` steps, then zero, while the rest of the shear capacity
    is a fictitious cohesion (f − slope) N̄ from the previous normal forces.  An iterate whose
    own forces already satisfy Coulomb's law with its mechanism (:func:`verify`) is an exact
    collapse state; the loop stops when N = N̄, when an active set that came back verifies, or
    when ``work`` is spent.  Scenes up to ``ipm_above`` contact points re-solve :class:`CapLP`'s
    persistent HiGHS models warm (its sloped model with the yield conditions as rows when
    ``yield_rows``); larger ones use Clarabel.  Returns the best verified state (or the exact
    state of the last mechanism) and the LP solves used.  ``lps``: the search's store of
    ``model``'s fixed-set LPs, for the exact states (None: their own).
    """
    cap, tally = cap or no_cap(), tally if tally is not None else Tally()
    f = points.friction
    n_bar = np.maximum(initial_normal, 0.0)
    interior = points.count > ipm_above
    cap_lp = (
        None
        if interior
        else CapLP(model, points, max_pivots=work.lp_pivots, yield_rows=yield_rows, alpha_floor=work.alpha_floor)
    )
    last, best, used = None, None, 0
    returning = _ReturningSets()
    for iteration in range(work.iterations):
        if cap.expired() or work.spent(tally):
            break
        ratio = 0.5 ** (iteration + 1) if iteration < slope_steps else 0.0
        slope = f * ratio
        if interior:
            lp = static_lp_clarabel(
                model, points, slope=slope, cap=(f - slope) * n_bar, max_iter=work.interior_iterations
            )
        else:
            lp = cast(CapLP, cap_lp).solve(
                slope, (f - slope) * n_bar, max_pivots=work.lp_limit(tally), seconds=cap.remaining()
            )
        tally.add(lp.pivots)
        used += 1
        if lp.status != "optimal" or lp.mechanism is None:
            break
        last = lp
        if ratio == 0.0:
            field = (lp.normal, lp.shear, lp.bounded)
            state = _iterate_state(model, points, cap_lp, lp, field, f * n_bar, start, work, tally, cap)
            if state is not None and (best is None or state.alpha < best.alpha):
                best = state
            if _settled(lp, n_bar, tolerance):
                break
        if ratio == 0.0 and not interior:
            state = returning.exact_state(model, points, lp.mechanism, start, work, tally, lps)
            if state is not None:
                return lower(state, best), used
        n_bar = np.maximum(n_bar + relaxation * (lp.normal - n_bar), 0.0)  # N̄ ≥ 0 past HiGHS's round-off
    if last is None:
        return best, used
    final = exact_state_by(
        work.exact_method,
        model,
        points,
        cast(np.ndarray, last.mechanism),
        start,
        limits=work.exact_limits(tally),
        tally=tally,
        lps=lps,
    )
    return lower(final, best), used


class _ReturningSets:
    """The active sets a Gilbert run has met.  Once a set comes back (the iterates settle or
    cycle), its exact state usually verifies: each such set is tried once."""

    def __init__(self) -> None:
        self.seen: set[tuple[bytes, ...]] = set()
        self.tried: set[tuple[bytes, ...]] = set()

    def exact_state(
        self,
        model: Model,
        points: ContactPoints,
        mechanism: np.ndarray,
        start: str,
        work: Work,
        tally: Tally,
        lps: FixedSetLPs | None,
    ) -> CollapseState | None:
        """The verified exact state of ``mechanism``'s active set when that set came back and was
        not tried yet; None otherwise (the set is remembered)."""
        active, linkage = work.tolerances.active, work.tolerances.linkage
        sets = (
            *active_set(model, points, mechanism, tolerance=active, linkage=linkage),
            bounded_active_set(model, points, mechanism, active, linkage),
        )
        current = tuple(part.tobytes() for part in sets)
        state = None
        if current in self.seen and current not in self.tried:
            self.tried.add(current)
            state = exact_state_by(
                work.exact_method,
                model,
                points,
                mechanism,
                start,
                limits=work.exact_limits(tally),
                tally=tally,
                lps=lps,
            )
        self.seen.add(current)
        return state if state is not None and state.verified else None


class _Anderson:
    """Anderson mixing (type II) of the fixed-point map N̄ ↦ N over the last ``memory`` steps."""

    def __init__(self, memory: int) -> None:
        self.memory = memory
        self.x: list[np.ndarray] = []
        self.g: list[np.ndarray] = []

    def reset(self) -> None:
        """Forget the history (after a restart)."""
        self.x, self.g = [], []

    def step(self, n_bar: np.ndarray, step: np.ndarray) -> np.ndarray:
        """The next N̄: the combination of the last steps that best cancels the residual."""
        self.x = [*self.x, n_bar.copy()][-(self.memory + 1) :]
        self.g = [*self.g, step][-(self.memory + 1) :]
        if len(self.x) == 1:
            return n_bar + step
        d_g = np.diff(np.array(self.g), axis=0).T
        d_x = np.diff(np.array(self.x), axis=0).T
        gamma = least_squares(d_g, step)
        return np.maximum(n_bar + step - times(gamma, (d_x + d_g).T), 0.0)


def _iterate_state(
    model: Model,
    points: ContactPoints,
    cap_lp: CapLP | None,
    lp: StaticLP,
    field: tuple[np.ndarray, np.ndarray, np.ndarray],
    caps: np.ndarray,
    start: str,
    work: Work,
    tally: Tally,
    cap: Cap,
) -> CollapseState | None:
    """A slope-zero iterate's ``field`` (N, T, τ) at the LP's α as a verified state: with the LP's
    mechanism, or, where its forces pass and the mechanism alone fails, with the mechanism
    re-optimised at α's cost Σ|f_L| (:meth:`CapLP.clean_mechanism`): the duals of a vertex at
    cost 1 are feasible only to the LP's tolerance times Σ|f_L| (1.25e-7 of their velocities on a
    1,560-block panel, over the verification's 1e-7).  Without ``cap_lp`` (Clarabel's path) the
    iterate is taken as it is."""
    tol = work.tolerances
    normal, shear, tau = field
    mechanism = cast(np.ndarray, lp.mechanism)
    checked = verify(model, points, lp.alpha, normal, shear, mechanism, tau, tol)
    residuals, ok = checked
    if cap_lp is None or ok or residuals["equilibrium"] > tol.equilibrium or residuals["yield"] > tol.yield_violation:
        return _as_state(model, points, lp.alpha, normal, shear, mechanism, start, tau, tol, checked)
    clean, pivots = cap_lp.clean_mechanism(caps, max_pivots=work.lp_limit(tally), seconds=cap.remaining())
    tally.add(pivots)
    if clean is None:
        return None
    return _as_state(model, points, lp.alpha, normal, shear, clean, start, tau, tol)


def _projected(
    closest: ClosestField, lp: StaticLP, caps: np.ndarray, n_bar: np.ndarray, work: Work
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The static field closest to ``n_bar`` on the face of the capped LP's mechanism, at its α
    less a hair (the face at α exactly is only feasible to the LP's tolerance); None when the
    projection QP does not solve."""
    tol = work.tolerances
    mechanism = cast(np.ndarray, lp.mechanism)
    face = active_set(closest.model, closest.points, mechanism, tolerance=tol.active, linkage=tol.linkage)
    return closest.solve(lp.alpha - 1e-9 * max(1.0, abs(lp.alpha)), caps, n_bar, face)


def projected_gilbert(
    model: Model,
    points: ContactPoints,
    initial_normal: np.ndarray,
    *,
    start: str = "gilbert-projected",
    plain_steps: int = 0,
    memory: int = 5,
    tolerance: float = 1e-7,
    restart_after: int = 60,
    restart_plain_steps: int = 20,
    work: Work = Work(iterations=400),
    cap: Cap | None = None,
    tally: Tally | None = None,
    lps: FixedSetLPs | None = None,
) -> tuple[CollapseState | None, int]:
    """Gilbert's iteration at slope zero with the normal forces chosen by projection.

    Each iteration takes α* and the mechanism u from the capped LP (cap f N̄, warm HiGHS),
    then, among the static fields that carry α* on the face complementary to u (N = 0 where u
    opens, T at its cap where u slips), the one closest to N̄ (:class:`ClosestField`).
    On large panels the plain iteration jumps between distant vertices of a large optimal face
    and never settles; the projected one moves N̄ only as far as the face forces it to, and its
    fixed point (N = N̄) is a collapse state: |T| ≤ f N̄ = f N, and u slips only where |T| = f N.
    N̄ ← N is accelerated by Anderson mixing of the last ``memory`` steps.  The first
    ``plain_steps`` iterations are plain (vertex N, relaxation 0.5).  When ``restart_after``
    projected iterations have not settled, the iteration starts again (once) from the initial
    field with ``restart_plain_steps`` plain iterations first, whose vertex jumps get it off a
    face it drifts along.  A verified iterate ends the loop; its mechanism's exact state is also
    taken, whichever is lower.  Returns the state and the LP solves used.  ``lps``: as in
    :func:`gilbert`.
    """
    cap, tally = cap or no_cap(), tally if tally is not None else Tally()
    f = points.friction
    n_bar = np.maximum(initial_normal, 0.0)
    cap_lp = CapLP(model, points, max_pivots=work.lp_pivots, alpha_floor=work.alpha_floor)
    closest, anderson = None, _Anderson(memory)
    best, lp, used = None, None, 0
    plain_left, projected_run, restarted = plain_steps, 0, False
    for _ in range(work.iterations):
        if cap.expired() or work.spent(tally):
            break
        lp = cap_lp.solve(np.zeros(points.count), f * n_bar, max_pivots=work.lp_limit(tally), seconds=cap.remaining())
        tally.add(lp.pivots)
        used += 1
        if lp.status != "optimal" or lp.mechanism is None:
            break
        normal, shear, tau = lp.normal, lp.shear, lp.bounded
        if plain_left == 0:
            closest = closest or ClosestField(model, points, max_iter=work.interior_iterations)
            nearest = _projected(closest, lp, f * n_bar, n_bar, work)
            if nearest is None:
                break
            normal, shear, tau = nearest
        best = _iterate_state(model, points, cap_lp, lp, (normal, shear, tau), f * n_bar, start, work, tally, cap)
        if best is not None:
            break
        step = normal - n_bar
        if plain_left > 0:
            plain_left -= 1
            n_bar = np.maximum(n_bar + 0.5 * step, 0.0)
            continue
        if float(np.abs(step).max(initial=0.0)) <= tolerance * max(1.0, float(np.abs(normal).max(initial=0.0))):
            break
        projected_run += 1
        if projected_run >= restart_after and not restarted and restart_plain_steps > 0:
            plain_left, projected_run, restarted = restart_plain_steps, 0, True
            anderson.reset()
            n_bar = np.maximum(initial_normal, 0.0)  # the first path again: plain steps from the start field
            continue
        n_bar = anderson.step(n_bar, step)
    if lp is None or lp.mechanism is None:
        return best, used
    final = exact_state_by(
        work.exact_method, model, points, lp.mechanism, start, limits=work.exact_limits(tally), tally=tally, lps=lps
    )
    return lower(final, best), used
