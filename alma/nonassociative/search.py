"""Non-associative friction: the search for the lowest collapse state of Eq. 9.

A *collapse state* (:mod:`alma.nonassociative.states`) is a load multiplier α, contact forces
and a mechanism that satisfy equilibrium, Coulomb's yield condition, compatibility without
interpenetration and the complementarity of a slip that does not dilate; Eq. 9 asks for the
smallest such α.  The problem is non-convex, so the answer is the lowest *verified* state found
from several starts (:mod:`alma.nonassociative.starts`; which run is the
:mod:`~alma.nonassociative.policy`):

- ``lp``: the active set of the associative mechanism (Eq. 10), its dilatant openings read as
  slips;
- ``rocking``: macro-blocks turning about a support point, lowest lifting bound first;
- ``gilbert(...)``: the iterative LP of Gilbert, Casapulla & Ahmed (2006) from several initial
  shear caps, relaxations and slope schedules, and on small scenes its restarts from a start
  field spread point by point (``…·(1±δ)#k``);
- ``tilt(θ°)``: the same iteration on the table turned by θ, its states carried back to the
  level table (:mod:`alma.nonassociative.tilted`);
- ``gilbert-projected``: the same iteration at slope zero with the normal forces projected onto
  the static fields that carry the LP's α, Anderson-accelerated;
- ``ipopt``: a CasADi/IPOPT polish with a Scholtes relaxation, on small scenes;
- ``milp``: on the smallest scenes, the MILP of :mod:`alma.certify` capped at the best state.

With cohesion and ties every start takes their bounded forces (the collapse states of
:mod:`alma.nonassociative.states`).

Every candidate is made exact (its active set fixed, the smallest α of a static LP with that
set and a mechanism of a kinematic LP with the same set) and verified before it can count.
Every start spends work budgets (:class:`~alma.settings.SearchSettings`), never seconds: the
same scene and settings give the same answer on any machine.  The user's ``time_limit`` is a
hard cap; when it cuts the work the solution says so and lists what was skipped.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from alma.geometry.canonical import CanonicalFrame
from alma.mechanics.canonical import field_to_drawing, mechanism_to_drawing
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.exact_states import fast_exact_state
from alma.nonassociative.limits import Cap
from alma.nonassociative.policy import make_start, parse_kind, plan, resolve_effort, start_name, wanted
from alma.nonassociative.starts import Context
from alma.nonassociative.states import CollapseState, ExactLimits, Tally, lowest, verify
from alma.settings import CertifySettings, SearchSettings
from alma.status import Status

#: Timing keys of the starts' kinds (seconds), summed over starts of a kind.
_TIMING_KEYS = {
    "lp": "lp_start_s",
    "rocking": "rocking_s",
    "gilbert": "gilbert_s",
    "projected": "gilbert_s",
    "ipopt": "ipopt_s",
    "milp": "milp_start_s",
    "tilt": "tilt_s",
    "restart": "gilbert_s",
}


@dataclass(frozen=True)
class StartRecord:
    """What one start cost and gave: α of its state (NaN if none), verified or not.

    ``iterations`` counts the start's own loop (LP solves, candidates tried, MILP nodes);
    ``pivots`` the simplex and interior-point iterations of all its LPs.
    """

    start: str
    time_s: float
    iterations: int
    alpha: float
    verified: bool
    pivots: int = 0
    lp_solves: int = 0


@dataclass(frozen=True)
class NonAssociativeSolution:
    """The search's answer: the best verified state, every candidate, and what each start did."""

    status: Status  # feasible (a verified state) | not_converged | no_equilibrium
    message: str
    best: CollapseState | None
    candidates: tuple[CollapseState, ...]
    timings: dict[str, float]
    starts: tuple[StartRecord, ...] = ()  # in the order they ran
    #: True when the user's time limit cut the work (the answer may then depend on the machine).
    stopped_by_limit: bool = False
    #: Starts not run, or cut short ("… (cut short)"), because of the time limit.
    skipped: tuple[str, ...] = ()


def _associative_normal(multipliers: np.ndarray | None, count: int) -> np.ndarray:
    """N of the associative static field at each contact point (the sum of its two generators)."""
    if multipliers is not None and multipliers.size:
        return multipliers.reshape(-1, 2).sum(axis=1)
    return np.zeros(count)


def _run_starts(ctx: Context, polish: bool | None) -> tuple[list[StartRecord], list[str], dict[str, float]]:
    """Run the plan in order; returns the records, the skipped starts and the timings."""
    records: list[StartRecord] = []
    skipped: list[str] = []
    timings: dict[str, float] = {}
    for kind in plan(ctx.settings, ctx.effort):
        if ctx.cap.expired():
            if wanted(kind, ctx, polish):
                skipped.append(start_name(kind, ctx.settings, ctx.effort))
            continue
        if not wanted(kind, ctx, polish):
            continue
        start = make_start(kind, ctx)
        tally, t0 = Tally(), time.perf_counter()
        state, iterations = start.run(ctx, tally)
        elapsed = time.perf_counter() - t0
        if state is not None:
            ctx.candidates.append(state)
        records.append(
            StartRecord(
                start.name,
                elapsed,
                int(iterations),
                state.alpha if state is not None else float("nan"),
                state is not None and state.verified,
                tally.pivots,
                tally.solves,
            )
        )
        if ctx.cap.hit:
            skipped.append(f"{start.name} (cut short)")
        key = _TIMING_KEYS[parse_kind(kind)[0]]
        timings[key] = timings.get(key, 0.0) + elapsed
        if parse_kind(kind)[0] in ("gilbert", "projected", "restart"):
            timings["gilbert_iterations"] = timings.get("gilbert_iterations", 0.0) + iterations
    return records, skipped, timings


def solve_nonassociative(
    model: Model,
    associative_mechanism: np.ndarray | None,
    associative_multipliers: np.ndarray | None,
    *,
    effort: str = "fast",
    settings: SearchSettings = SearchSettings(),
    polish: bool | None = None,
    time_limit: float | None = None,
    associative_alpha: float | None = None,
    certify: CertifySettings | None = None,
) -> NonAssociativeSolution:
    """Lowest verified collapse state of Eq. 9 over several starts (see module docstring).

    ``associative_mechanism`` / ``associative_multipliers`` / ``associative_alpha``: the
    solution of Eq. 10 (None when it failed).  ``effort``: "fast", "thorough" or "auto".
    ``polish``: force the IPOPT start on or off (None: the policy decides).  ``time_limit`` (s):
    the user's hard cap, checked between units of work; when it cuts the work,
    ``stopped_by_limit`` is set and ``skipped`` says what did not run.  ``certify``: the user's
    certification settings, for the ``milp`` start (default: the defaults).
    """
    points = ContactPoints.from_model(model)
    ctx = Context(
        model,
        points,
        settings,
        resolve_effort(effort, settings, model.n_free),
        Cap(time_limit),
        associative_mechanism,
        _associative_normal(associative_multipliers, points.count),
        associative_alpha,
        certify=certify if certify is not None else CertifySettings(),
    )
    records, skipped, timings = _run_starts(ctx, polish)
    common: dict[str, Any] = dict(
        candidates=tuple(ctx.candidates),
        timings=timings,
        starts=tuple(records),
        stopped_by_limit=ctx.cap.hit,
        skipped=tuple(skipped),
    )
    best = ctx.best()
    if best is None:
        return NonAssociativeSolution(Status.NOT_CONVERGED, "no verified collapse state was found", None, **common)
    status = Status.FEASIBLE if best.alpha >= 0 else Status.NO_EQUILIBRIUM
    return NonAssociativeSolution(status, f"lowest verified collapse state from start '{best.start}'", best, **common)


def _at_its_floor(state: CollapseState, canonical: Model, limits: ExactLimits) -> CollapseState:
    """``state`` or, when lower, the exact state of its mechanism on the canonical model (its active
    set fixed, the smallest α with that set): a start's verified iterate need not be that floor."""
    own = fast_exact_state(canonical, ContactPoints.from_model(canonical), state.mechanism, state.start, limits=limits)
    if own is None or not own.verified or not own.alpha < state.alpha:
        return state
    return own


def carried_state(
    state: CollapseState,
    canonical: Model,
    frame: CanonicalFrame,
    model: Model,
    settings: SearchSettings = SearchSettings(),
) -> CollapseState | None:
    """A canonical state carried whole to the drawing's ``model``: the same α, its forces on the
    drawn joints and bounded columns (:func:`~alma.mechanics.canonical.field_to_drawing`) and its
    mechanism (:func:`~alma.mechanics.canonical.mechanism_to_drawing`), verified on ``model``;
    None when the joints or bounded columns do not correspond."""
    field = field_to_drawing(state.normal, state.shear, canonical, frame, model, state.bounded)
    if field is None:
        return None
    normal, shear, bounded = field
    mechanism = mechanism_to_drawing(state.mechanism, canonical, frame, model)
    points = ContactPoints.from_model(model)
    residuals, ok = verify(model, points, state.alpha, normal, shear, mechanism, bounded, settings.states)
    return dataclasses.replace(
        state, normal=normal, shear=shear, mechanism=mechanism, bounded=bounded, residuals=residuals, verified=ok
    )


def carried_back(
    solution: NonAssociativeSolution,
    canonical: Model,
    frame: CanonicalFrame,
    model: Model,
    settings: SearchSettings = SearchSettings(),
) -> NonAssociativeSolution:
    """The canonical search's answer as an answer for the drawing's ``model``.

    The verified canonical states are tried lowest α first (at most ``carry_back_tries`` of
    them), until one verifies on ``model`` itself; that state is the answer and takes its
    candidate's place.  Each one's mechanism is carried to ``model``'s frame and blocks
    (:func:`~alma.mechanics.canonical.mechanism_to_drawing`) and made exact there, its active set fixed
    (:func:`~alma.nonassociative.exact_states.fast_exact_state`), so that α is exact on the
    drawing's own data (the bounds and proofs are computed there).  When that does not verify, the
    state is taken to its own fixed-set floor on the canonical model (:func:`_at_its_floor`) and
    carried whole (:func:`carried_state`: its α is the canonical model's, within the data's
    rounding of the drawing's).  The other candidates keep their canonical α and forces, their
    mechanisms carried back (what the MILP's start reads).
    """
    t0 = time.perf_counter()
    moved = tuple(
        dataclasses.replace(c, mechanism=mechanism_to_drawing(c.mechanism, canonical, frame, model))
        for c in solution.candidates
    )
    points = ContactPoints.from_model(model)
    limits = ExactLimits(settings.lp_pivots, settings.vertex_pivots, settings.interior_iterations, settings.states)
    best = None
    verified = [k for k, c in enumerate(moved) if c.verified]
    first = lowest([moved[k] for k in verified], settings.same_alpha)
    order = sorted(verified, key=lambda k: (moved[k] is not first, moved[k].alpha))
    for k in order[: settings.carry_back_tries]:
        exact = fast_exact_state(model, points, moved[k].mechanism, moved[k].start, limits=limits)
        if exact is None or not exact.verified:
            floor = _at_its_floor(solution.candidates[k], canonical, limits)
            exact = carried_state(floor, canonical, frame, model, settings)
        if exact is not None and exact.verified:
            best = exact
            moved = (*moved[:k], exact, *moved[k + 1 :])
            break
    timings = dict(solution.timings, carry_back_s=time.perf_counter() - t0)
    common: dict[str, Any] = dict(
        candidates=moved,
        timings=timings,
        starts=solution.starts,
        stopped_by_limit=solution.stopped_by_limit,
        skipped=solution.skipped,
    )
    if best is None:
        message = (
            solution.message
            if solution.best is None
            else "no state of the canonical search verified on the drawing's model"
        )
        return NonAssociativeSolution(Status.NOT_CONVERGED, message, None, **common)
    status = Status.FEASIBLE if best.alpha >= 0 else Status.NO_EQUILIBRIUM
    return NonAssociativeSolution(status, f"lowest verified collapse state from start '{best.start}'", best, **common)
