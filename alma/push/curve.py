"""The capacity curve α(d): incremental large-displacement limit analysis (SPEC §3 ``alma push``).

From the collapse mechanism at d = 0 (α = α_c), the blocks move rigidly along the current
mechanism (:mod:`alma.push.motion`: finite rotations about the instantaneous centres, the
hinges kept closed; :mod:`alma.push.step`: no contact point closing past its neighbour, a step
shortened to where a block first touches another) in steps of the control point's horizontal
displacement d; on each
displaced geometry the joints are found again and the limit analysis is solved again
(Eq. 10, or Eq. 9 with ``model="nonassociative"``), which gives α(d) and the mechanism for the
next step, until α ≤ 0, or until a configuration carries the dead load at no α (a loss of
equilibrium: the curve then ends with α > 0, its ``end`` says why, :mod:`alma.push.stop`).
Point loads and ties move with their blocks; each state carries its ties' rest lengths, and a
tie shorter than its rest length is slack, left out of that configuration's analysis
(:mod:`alma.push.carried`).

Steps: a probe of ``PushSettings.probe`` × L (L = √(total area of the free blocks)) estimates
d₀ by a secant through α_c; the curve then advances in steps of that estimate / ``steps`` (at most
``max_step`` × L; ``flat_step`` × L when α does not fall over the probe, a sliding part, whose
turn, where α starts to fall, is bisected to ``turn_tolerance`` × L).  The last interval
(α > 0 at its start, α ≤ 0 at its end) is refined by secant steps, each followed by a guard step
``d0_tolerance`` × L / 2 beyond it, until the bracket of d₀ is narrower than ``d0_tolerance`` × L:
d₀ is stated to that accuracy.  A loss of equilibrium is bisected (without guards: α has no value
at its far end) and then proven on the configuration a step from the bracket's low end reaches:
a far end reached by a longer step, along an earlier mechanism, carries other contacts.  Where
the step from the low end finds equilibrium, the curve goes on from that configuration, probing
again (the step budget counts the steps of every walk), unless the contact lost is a support
crushed over its whole length, which sank: the rigid geometry does not follow it, and the end
says so (``end["low_end_step"]``, not ``optimal``).
Every number of the analysis is relative
to L, so a drawing in other units, moved or with its blocks listed in another order takes the
same steps.  The work is counted in LP solves, never in seconds.
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple, cast

import numpy as np

from alma.geometry.contacts import block_areas_and_centroids, find_joints
from alma.geometry.edges import contact_lengths, scene_edges
from alma.geometry.scene import Scene
from alma.geometry.validation import validated
from alma.push.carried import tie_lengths
from alma.push.configuration import solve_at, state_at
from alma.push.control import ControlLeft, control_block, control_end
from alma.push.landing import overlap_depths
from alma.push.motion import MotionError, Pose, advance, block_motions, displaced, joints_after
from alma.push.result import PushResult, _result, _Run, _State
from alma.push.step import held_at, increment, landed
from alma.push.stop import lost_equilibrium, sunk
from alma.settings import PushSettings, Settings
from alma.status import Status

PUSH_MODELS = ("associative", "nonassociative")


def push(
    scene: Scene,
    *,
    model: str = "associative",
    control: str | None = None,
    steps: int | None = None,
    settings: Settings | None = None,
    push_settings: PushSettings | None = None,
) -> PushResult:
    """The capacity curve α(d) of ``scene`` by incremental large-displacement analysis.

    Parameters
    ----------
    scene
        A validated :class:`~alma.geometry.scene.Scene` (mm, kN).
    model
        ``"associative"`` (Eq. 10, the default) or ``"nonassociative"`` (Eq. 9's search at
        every step).
    control
        The block whose centroid's horizontal displacement is d (mm); default: the moving block
        whose centroid moves most horizontally in the collapse mechanism (ties: the smaller id).
    steps
        Steps from α_c to α = 0 (``PushSettings.steps`` when None).

    Returns
    -------
    PushResult
        ``status`` ``optimal`` when every α of the curve is certified (Eq. 10's bounds) and the
        bracket of d₀ is closed to ``PushSettings.d0_tolerance`` × L with α proven > 0 at its start
        and ≤ 0 at its end, or when it stops with α > 0 at a proven loss of equilibrium or where
        the mechanism leaves the control block (``end``; :data:`~alma.push.result.STOPPED_ENDS`);
        ``feasible`` for the non-associative model; ``limit_reached`` when the step budget ran out
        before α reached 0 (a sliding mechanism never does); ``not_converged`` when a step or an LP
        failed.
    """
    if model not in PUSH_MODELS:
        raise ValueError(f"model must be one of {PUSH_MODELS}, got {model!r}")
    p = push_settings or PushSettings()
    if steps is not None:
        if not (isinstance(steps, int) and steps >= 1):
            raise ValueError(f"steps must be a positive integer, got {steps!r}")
        p = dataclasses.replace(p, steps=steps)
    joints = None
    if not scene.validated:
        scene, joints = validated(scene)  # the check's joints serve the first step
    areas, _ = block_areas_and_centroids(scene)
    free = np.array([not b.fixed for b in scene.blocks])
    length = float(np.sqrt(np.abs(areas[free]).sum()))
    pose = Pose.rest(len(scene.blocks))
    start = (scene, find_joints(scene) if joints is None else joints, model, settings, tie_lengths(scene.ties))
    solved = solve_at(*start, p.tie_slack * length)
    first = solved[0]
    if first.status not in (Status.OPTIMAL, Status.FEASIBLE):
        return PushResult(
            first.status,
            f"no capacity curve: {first.message}",
            model,
            None,
            (),
            math.nan,
            (math.nan, math.nan),
            1,
            first,
        )
    index, sense = control_block(scene, first, control)
    if model == "associative" and first.mechanism_class == "sliding":
        # the blend of every part that can slide: the curve starts on the one moving the control
        solved = solve_at(*start, p.tie_slack * length, (index, sense))
    snap = contact_lengths(scene, scene_edges(scene))[0]
    run = _Run(scene, model, settings, p, length, index, sense, snap=snap, overlaps=overlap_depths(scene))
    return _curve(run, state_at(run, 0.0, pose, solved))


class _Walk(NamedTuple):
    """What :func:`_walk` went through: its configurations, the bracket of α = 0 (the last with
    α > 0, the first without; None when it stopped without one), its LP solves, and when it
    stopped without a bracket, the failure, the end's reason and the control's end.  ``taken``:
    its main steps (the step budget's count; a turn's bisection is bounded by its tolerance)."""

    states: list[_State]
    bracket: tuple[_State, _State] | None
    solves: int
    taken: int
    failure: tuple[Status, str] | None = None
    reason: str = ""
    left: ControlLeft | None = None


def _curve(run: _Run, start: _State) -> PushResult:
    states, solves, state, walked = [start], 1, start, 0
    while True:
        walk = _walk(run, state, walked)
        states, solves, walked = states + walk.states, solves + walk.solves, walked + walk.taken
        if walk.bracket is None:
            end = control_end(states[-1], walk.left) if walk.left is not None else {"reason": walk.reason}
            if walk.left is None:
                end["text"] = cast("tuple[Status, str]", walk.failure)[1]
            return _result(run, states, walk.failure, (math.nan, math.nan), math.nan, solves, end)
        lo, hi, extra, stop = _refine(run, *walk.bracket)
        states, solves = states + extra, solves + len(extra)
        if isinstance(stop, ControlLeft):
            kept = [s for s in states if s.d <= lo.d]
            return _result(run, kept, None, (math.nan, math.nan), math.nan, solves, control_end(lo, stop))
        failure = stop
        if math.isfinite(hi.alpha):
            kept, root = [s for s in states if s.d <= hi.d], _secant(lo, hi)
            return _result(run, kept, failure, (lo.d, hi.d), root, solves, {"reason": "alpha_zero", "d": root})
        again = _from_low_end(run, lo, hi) if failure is None else hi
        solves += int(again is not hi)
        kept_up = again is not hi and again.alpha > 0
        if kept_up and not sunk(lo.model, hi.model, lo.result.joints):
            # a step from lo keeps the equilibrium the longer step lost (the contacts a
            # configuration has depend on the mechanism it was reached by): the curve goes on
            states, state = [*(s for s in states if s.d <= lo.d), again], again
            continue
        if again is not hi and not kept_up:  # the loss is proven on the curve's own way
            states, hi = [*states, again], again
        end = lost_equilibrium((lo.d, hi.d), lo.alpha, lo.model, hi.model, lo.result.joints)
        if kept_up:  # a support crushed whole sank: the rigid geometry does not follow it
            end |= {"low_end_step": {"d": again.d, "alpha": again.alpha}}
        kept = [s for s in states if s.d < hi.d]
        return _result(run, kept, failure, (math.nan, math.nan), math.nan, solves, end)


def _walk(run: _Run, start: _State, spent: int = 0) -> _Walk:
    """The configurations past ``start`` until α ≤ 0, a failure, the control's end or the step
    budget (``spent`` of it by the curve before ``start``): the probe first, then the step that
    draws the curve in ``PushSettings.steps`` steps to the probe's secant d₀.  A flat walk (α
    does not fall over the probe: sliding) takes the flat step until α falls, locates where it
    starts to fall (:func:`_turn`), and probes the mechanism it then follows."""
    p = run.push
    budget, walked, solves, taken = p.steps * p.max_steps_factor + 1 - spent, list[_State](), 0, 0
    state, step, probing, flat = start, p.probe * run.length, True, False
    while True:
        if 1 + taken > budget:
            text = f"α is still {state.alpha:.6g} > 0 after {spent + taken} steps (d = {state.d:.6g} mm)"
            return _Walk(
                walked, None, solves, taken, (Status.LIMIT_REACHED, text + ": the step budget ran out"), "step_budget"
            )
        try:
            nxt = _advanced(run, state, step)
        except ControlLeft as exc:
            return _Walk(walked, None, solves, taken, left=exc)
        except MotionError as exc:
            failure = (Status.NOT_CONVERGED, f"at d = {state.d:.6g} mm: {exc}")
            return _Walk(walked, None, solves, taken, failure, "motion")
        solves, taken = solves + 1, taken + 1
        if not _usable(nxt):
            failure = (Status.NOT_CONVERGED, f"at d = {nxt.d:.6g} mm: {nxt.result.message}")
            return _Walk(walked, None, solves, taken, failure, "solver")
        falls = _falls(state, nxt)
        turns = flat and falls
        if turns:  # the sliding has ended: where, then the next mechanism's probe (or α = 0's bracket)
            turned, extra = _turn(run, state, nxt)
            walked, solves = walked + turned[:-1], solves + extra
            state, nxt = (turned[-2] if len(turned) > 1 else state), turned[-1]
            step, probing, flat = p.probe * run.length, True, False
        walked.append(nxt)
        if nxt.alpha <= 0:
            return _Walk(walked, (state, nxt), solves, taken)
        if probing and not turns:  # the step to the secant's d₀ in ``steps`` steps, or the flat step
            drop = state.alpha - nxt.alpha
            step = (state.d + (nxt.d - state.d) * state.alpha / drop) / p.steps if falls else p.flat_step * run.length
            step = min(max(step, p.probe * run.length), p.max_step * run.length)
            probing, flat = False, not falls
        state = nxt


def _falls(state: _State, nxt: _State) -> bool:
    """α at ``nxt`` is below ``state``'s by more than round-off."""
    return state.alpha - nxt.alpha > 1e-9 * max(1.0, abs(state.alpha))


def _turn(run: _Run, lo: _State, hi: _State) -> tuple[list[_State], int]:
    """Where a flat walk's α starts to fall (a sliding part starts to tip), bisected along the flat
    mechanism between ``lo`` (flat) and ``hi`` (fallen) to ``PushSettings.turn_tolerance`` × L, so
    that the mechanism that follows starts there whatever the flat step: the flat configurations
    found, then the first fallen one (the last item), and the LP solves spent."""
    tol, flat, solves = run.push.turn_tolerance * run.length, list[_State](), 0
    while hi.d - lo.d > tol:
        try:
            s = _split(run, lo, 0.5 * (lo.d + hi.d), 0.25 * tol)
        except (ControlLeft, MotionError):
            break  # the bracket stays as wide as the trials left it
        solves += 1
        if not (_usable(s) and lo.d < s.d < hi.d):
            break
        if _falls(lo, s):
            hi = s
        else:
            flat, lo = [*flat, s], s
    return [*flat, hi], solves


def _from_low_end(run: _Run, lo: _State, hi: _State) -> _State:
    """The configuration at ``hi``'s d (``hi`` has no equilibrium) that a step from ``lo`` reaches,
    where the loss is proven on the curve's own way (a longer step, along an earlier mechanism,
    reaches a configuration with other contacts); ``hi`` itself when that step fails or lands no
    further than lo."""
    try:
        again = (run.mover or _move)(run, lo, hi.d)
    except MotionError:
        return hi
    return again if _usable(again) and again.d > lo.d else hi


def _advanced(run: _Run, state: _State, step: float, floor: float | None = None) -> _State:
    """The configuration ``step`` mm past ``state``, the step halved while the corrector finds no
    motion over it (a mechanism that turns from sliding to rocking can lock over a long step),
    down to ``floor`` mm (default the probe step); below that the corrector's
    :class:`MotionError` stands.  The next step is the curve's own again."""
    floor = run.push.probe * run.length if floor is None else floor
    while True:
        try:
            return (run.mover or _move)(run, state, state.d + step)
        except ControlLeft:
            raise  # the state's own mechanism leaves the control block: no step helps
        except MotionError:
            if not step / 2 >= floor:
                raise
            step /= 2


def _refine(
    run: _Run, lo: _State, hi: _State
) -> tuple[_State, _State, list[_State], tuple[Status, str] | ControlLeft | None]:
    """Secant steps with a guard beyond each (bisections without one where α at hi is not a
    number), inside [lo, hi], until hi.d − lo.d ≤ the tolerance.  The last item: None, the
    failure that stopped it, or the :class:`ControlLeft` of a low end whose mechanism does not
    move the control block on (the curve ends there, as the walk's would)."""
    tol = run.push.d0_tolerance * run.length
    extra: list[_State] = []
    while hi.d - lo.d > tol:
        if len(extra) >= run.push.refine_solves:
            return (
                lo,
                hi,
                extra,
                (
                    Status.LIMIT_REACHED,
                    f"d₀ bracketed in [{lo.d:.9g}, {hi.d:.9g}] mm after {len(extra)} refining solves",
                ),
            )
        secant = _secant(lo, hi)
        d = secant if math.isfinite(secant) else 0.5 * (lo.d + hi.d)
        d = min(max(d, lo.d + 0.25 * tol), hi.d - 0.25 * tol)
        # the guard closes the bracket when the secant lands near the root; a bisection's point
        # (no secant: α is not a number at hi, a loss of equilibrium) is no nearer the end than
        # any other, so it goes without one
        for target in (d, None) if math.isfinite(secant) else (d,):
            if target is None:  # the guard: just across the root from the secant's point
                target = d + 0.5 * tol if lo.d == d else d - 0.5 * tol
                if not lo.d < target < hi.d:
                    break
            try:
                s = _split(run, lo, target, 0.25 * tol)
            except ControlLeft as exc:  # lo's mechanism does not move the control on: an end
                return lo, hi, extra, exc
            except MotionError as exc:
                return lo, hi, extra, (Status.NOT_CONVERGED, f"refining d₀ at {target:.9g} mm: {exc}")
            if not _usable(s):
                return lo, hi, extra, (Status.NOT_CONVERGED, f"refining d₀ at {target:.9g} mm: {s.result.message}")
            extra.append(s)
            lo, hi = (s, hi) if s.alpha > 0 else (lo, s)
            if hi.d - lo.d <= tol:
                break
    return lo, hi, extra, None


def _split(run: _Run, lo: _State, target: float, floor: float) -> _State:
    """The configuration at ``target`` mm from ``lo``, or, where the corrector cannot reach it or
    its α is not certified (an LP next to a loss of equilibrium), one nearer ``lo``: the step
    halved down to ``floor`` mm.  Any configuration between a bracket's ends splits it as well.
    The last one tried when none is usable; the corrector's :class:`MotionError` below ``floor``."""
    step = target - lo.d
    while True:
        s = _advanced(run, lo, step, floor)
        step = 0.5 * (s.d - lo.d)
        if _usable(s) or not step >= floor:
            return s


def _secant(lo: _State, hi: _State) -> float:
    """The zero of the line through (lo.d, α) and (hi.d, α); NaN when α at hi is not a number (an
    LP that finds no admissible field for any multiplier: the structure cannot stand there)."""
    if not (math.isfinite(hi.alpha) and hi.alpha < lo.alpha):
        return math.nan
    return lo.d + (hi.d - lo.d) * lo.alpha / (lo.alpha - hi.alpha)


def _move(run: _Run, state: _State, d: float) -> _State:
    """The configuration at control displacement ``d`` along ``state``'s mechanism, solved."""
    bodies = state.bodies
    if bodies.count == 0 or bodies.of_block[run.control] < 0:
        raise ControlLeft("control_still", "its mechanism leaves the control block still")
    scene0 = run.scene
    # the configuration's own blocks (its model leaves out slack ties only)
    where = block_areas_and_centroids(state.model.scene)[1][run.control]
    rate = bodies.velocity_at(np.array([run.control]), where[None, :])[0, 0] * run.sense
    if not rate > 0:
        raise ControlLeft("control_reverses", "its mechanism moves the control block backwards")
    held = held_at(run, state)  # the same for every trial step from this state
    d, z = landed(run, state, d, increment(run, state, d, rate, where, held.tolerance), rate, where, held)
    pose = advance(state.pose, scene0, bodies, z)
    current = displaced(scene0, pose)
    joints = joints_after(current, state.contacts, bodies, z)
    follow = (run.control, run.sense)
    slack = run.push.tie_slack * run.length
    previous = block_motions(state.model.scene, state.result)
    return state_at(
        run, d, pose, solve_at(current, joints, run.model, run.settings, state.rest, slack, follow, previous)
    )


def _usable(state: _State) -> bool:
    """An α the curve can use: a certified (or verified) value, negative ones included."""
    status = state.result.status
    if status == Status.NO_EQUILIBRIUM:
        return not math.isnan(state.alpha)  # −inf: no field carries the dead load at any α
    return status in (Status.OPTIMAL, Status.FEASIBLE) and math.isfinite(state.alpha)
