"""One finite step of the capacity curve: the bodies' motion to a control displacement, with
the contacts unilateral.

:func:`increment` moves the bodies along the last configuration's mechanism (the predictor of
:func:`alma.push.motion.predictor`, then the closure corrector of :mod:`alma.push.corrector`,
which holds the mechanism's hinges and sliding points).  The corrector's equations hold only
those points; a contact point the mechanism opens at first order can still close past its
neighbour over a finite step (a joint opening by rotation while a held sliding point pulls the
block back).  Such a point is held as well (zero normal gap, free slip) and the step solved
again, up to ``PushSettings.unilateral_rounds`` times; a mechanism no closure can follow takes
the unilateral step of :mod:`alma.push.projection`.  :func:`landed` handles the contacts the
configuration does not have yet: where the step drives a corner into a block it does not touch,
the step is shortened to where they first touch (:mod:`alma.push.landing`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from alma.push.corrector import corrected, one_hinge_opened
from alma.push.landing import depths, grown, landing
from alma.push.motion import Bodies, Contacts, MotionError, _moved, _rotate, advance, outlines, predictor
from alma.push.projection import projected_step
from alma.push.result import _Run, _State

#: How far (in contact tolerances) a step may close a point of a pair already as deep as a
#: landing may leave it: round-off only.
ENTERING_AT_CAP = 1e-6


def entering(bodies: Bodies, contacts: Contacts, z: np.ndarray, tolerance: float | np.ndarray) -> np.ndarray:
    """Per contact point: neither a hinge nor sliding nor on a crushing joint, and the increments
    ``z`` carry its two blocks into each other by more than ``tolerance`` mm (per point or one
    for all) along its normal (turned with block a)."""
    pa = _moved(bodies, z, contacts.a, contacts.point)
    pb = _moved(bodies, z, contacts.b, contacts.point)
    g = bodies.of_block[contacts.a]
    angle = np.where(g >= 0, z[np.maximum(g, 0), 0], 0.0) if bodies.count else np.zeros(g.size)
    gap = ((pb - pa) * _rotate(contacts.normal, angle)).sum(axis=1)
    # a crushing joint's points enter the other block by design (the crushed zone)
    return ~(contacts.hinge | contacts.sliding | contacts.crushing) & (gap < -tolerance)


def _held_apart(
    solve: Callable[[Contacts], np.ndarray],
    bodies: Bodies,
    contacts: Contacts,
    tolerance: float | np.ndarray,
    rounds: int,
    unheld: list[np.ndarray],
) -> np.ndarray:
    """``solve(contacts)``'s increments, each contact point they drive into its neighbour held as
    a sliding point and the step solved again (at most ``rounds`` times); the increments before
    any point was held are appended to ``unheld``."""
    held = contacts
    z = solve(held)
    unheld.append(z)
    for _ in range(rounds):
        more = entering(bodies, held, z, tolerance)
        if not more.any():
            break
        held = dataclasses.replace(held, sliding=held.sliding | more)
        z = solve(held)
    return z


def increment(
    run: _Run, state: _State, d: float, rate: float, where: np.ndarray, tolerance: np.ndarray | None = None
) -> np.ndarray:
    """The bodies' increments (g, 3) from ``state`` to control displacement ``d`` (mm) along its
    mechanism (``rate``: the control point's speed per unit of the mechanism; ``where``: its
    position), no contact point closing past a tenth of the contact tolerance (``run.snap``, mm;
    none for a pair already as deep as a landing may leave it: ``tolerance``, per point, by default
    :func:`held_at`).
    When no way of holding them moves the bodies, the first motion found without them stands:
    the landing (:func:`landed`) then shortens the step to where the point touches.  When the
    hinges themselves do not close (they close to first order only, and lock), one of them opens
    (:func:`alma.push.corrector.one_hinge_opened`); when no single one frees them (a first-order
    mechanism), the motion nearest the mechanism with every contact unilateral moves the bodies
    (:func:`alma.push.projection.projected_step`)."""
    bodies, push = state.bodies, run.push
    z0 = predictor(bodies, (d - state.d) / rate)
    args = (z0, (run.control, where), (d - state.d) * run.sense, run.length, push)

    def solve(contacts: Contacts) -> np.ndarray:
        return corrected(bodies, contacts, *args)

    tolerance = held_at(run, state).tolerance if tolerance is None else tolerance
    unheld = list[np.ndarray]()
    try:
        return _held_apart(solve, bodies, state.contacts, tolerance, push.unilateral_rounds, unheld)
    except MotionError:
        pass
    # sliding points kept closed over-constrain a dilatant mechanism of many bodies: let them
    # open as the associative flow rule does, and keep the hinges
    free = dataclasses.replace(state.contacts, sliding=np.zeros_like(state.contacts.sliding))
    try:
        return _held_apart(solve, bodies, free, tolerance, push.unilateral_rounds, unheld)
    except MotionError:
        pass
    if unheld:  # the hinges close (without the held points): no lock, the landing shortens the step
        return unheld[0]
    try:  # hinges that close only to first order lock: one of them opens
        return one_hinge_opened(bodies, free, *args)
    except MotionError:
        pass
    # a first-order mechanism of many bodies: its contacts are unilateral, any of them may open
    return projected_step(bodies, state.contacts, z0, (run.control, where), args[2], run.length, push, 0.1 * run.snap)


class Held(NamedTuple):
    """What every trial step from one state shares: the overlaps (mm) at the state of the pairs
    with a block its mechanism moves, and per contact point the closing (mm) past which a step
    holds it (:func:`entering_tolerance`)."""

    start: dict[tuple[int, int], float]
    tolerance: np.ndarray


def held_at(run: _Run, state: _State) -> Held:
    """:class:`Held` of ``state``, measured once."""
    start = depths(*outlines(run.scene, state.pose), state.bodies.of_block >= 0)
    return Held(start, entering_tolerance(run, state, start))


def entering_tolerance(run: _Run, state: _State, start: dict[tuple[int, int], float]) -> np.ndarray:
    """Per contact point of ``state``, how far (mm) a step may close it before it is held: a tenth
    of the contact tolerance, and none for a pair already as deep as a landing may leave it (half
    the tolerance past the drawing's overlap; ``start``: the overlaps at the state), whose every
    further closing would land the step at once (:func:`landed`)."""
    contacts, n = state.contacts, len(run.scene.blocks)
    pairs = np.array(list(start), dtype=np.int64).reshape(-1, 2)
    depth = np.fromiter(start.values(), dtype=float, count=len(start))
    drawn = np.fromiter((run.overlaps.get(p, 0.0) for p in start), dtype=float, count=len(start))
    deep = pairs[depth >= drawn + 0.5 * run.snap]
    keys = np.minimum(contacts.a, contacts.b).astype(np.int64) * n + np.maximum(contacts.a, contacts.b)
    at_cap = np.isin(keys, deep[:, 0] * n + deep[:, 1])
    return np.where(at_cap, ENTERING_AT_CAP * run.snap, 0.1 * run.snap)


def landed(
    run: _Run, state: _State, d: float, z: np.ndarray, rate: float, where: np.ndarray, held: Held | None = None
) -> tuple[float, np.ndarray]:
    """``(d, z)``, or where the step first drives a block into one it does not touch (an overlap
    of the drawing's outlines, ``run.overlaps``, grown by more than half ``run.snap``) the
    shorter step to where they touch (:func:`alma.push.landing.landing`) and its increments.
    A pair of blocks in contact at the step's start grows from its overlap there, up to
    ``run.snap`` past the drawing's in all: a landing left it up to half ``run.snap`` deep, and
    measured from the drawing any motion along that contact would land again at once (the
    corrector keeps its held points within a tenth of it).  ``held``: :func:`held_at` of ``state``
    when the caller has it."""
    scene0, before, snap = run.scene, run.overlaps, run.snap
    crushing = state.contacts.crushing
    # a crushing joint's blocks overlap by design (the crushed zone)
    a, b = state.contacts.a[crushing], state.contacts.b[crushing]
    ignored = set(zip(np.minimum(a, b).tolist(), np.maximum(a, b).tolist(), strict=True))

    # a pair of blocks the step leaves still keeps the overlap its configuration was accepted with
    moving = state.bodies.of_block >= 0

    def overlaps(z: np.ndarray) -> dict[tuple[int, int], float]:
        after = depths(*outlines(scene0, advance(state.pose, scene0, state.bodies, z)), moving)
        return {pair: depth for pair, depth in after.items() if pair not in ignored}

    reached = overlaps(z)
    if grown(before, reached) <= 0.5 * snap:
        return d, z
    # a pair in contact at the step's start was landed earlier: its overlap is measured from there
    held = held_at(run, state) if held is None else held
    start = held.start
    a, b = state.contacts.a, state.contacts.b
    touching = set(zip(np.minimum(a, b).tolist(), np.maximum(a, b).tolist(), strict=True))
    # ... up to the contact tolerance past the drawing's, beyond which it would be no contact
    before = before | {
        pair: max(before.get(pair, 0.0), min(v, before.get(pair, 0.0) + 0.5 * snap))
        for pair, v in start.items()
        if pair in touching
    }
    at_d = grown(before, reached)
    if at_d <= 0.5 * snap:
        return d, z

    tolerance = held.tolerance

    def growth_at(x: float) -> float | None:
        try:
            return grown(before, overlaps(increment(run, state, x, rate, where, tolerance)))
        except MotionError:
            return None

    width = run.push.d0_tolerance * run.length  # no landing is located more finely than d₀
    touch = landing(growth_at, state.d, d, snap, run.push.landing_iterations, at_d, width)
    if touch is None:
        raise MotionError(f"the step to d = {d:.6g} mm drives a block into another from its start")
    return touch, increment(run, state, touch, rate, where, tolerance)
