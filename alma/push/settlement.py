"""Settlement capacity: the support settlement at which a structure can no longer carry its dead load.

The scene's ``settlement`` (SPEC §2: a rigid motion of a fixed block, translation t and rotation
r about a point c) is scaled by a growing factor s: at s the support has moved by

    x ↦ R(s r)(x − c) + c + s t                                   (exact, finite rotation)

and the free blocks take the compatible crack pattern (:func:`alma.settle`, the kinematic
problem of Iannuzzo et al.: the motion that lets the dead load do the most work) for the next
increment of s.  Each increment is a finite rigid step of push's machinery
(:mod:`alma.push.motion`, :mod:`alma.push.corrector`): the settling supports move exactly by
their prescribed increment, the free blocks turn about their instantaneous centres, and the
corrector keeps every contact the settlement mechanism keeps (hinges, sliding points) closed;
the joints are then found again on the displaced geometry (contacts open and close, new ones
appear).  At each s the associative limit analysis (Eq. 10) of the displaced structure, or with
``model="nonassociative"`` the friction search (Eq. 9's lowest verified state), gives its load
multiplier α(s) under the scene's live load; the structure stands under its dead
load while α(s) > 0 (Eq. 10's static problem is feasible at α = 0).  The settlement capacity
s_u is where α reaches 0, or where no stress field carries the dead load at any α (a loss of
equilibrium): push's adaptive steps and bracket refinement (:func:`alma.push.curve._curve`) find
it, to ``PushSettings.d0_tolerance`` times the abscissa's scale.

The abscissa of the curve is the settlement of the *control support* (the settling support
with the largest translation, ties by id): s |t| in mm; when no support translates, the
rotation s |r| in rad (scale 1 rad).  Steps and accuracy are relative to L = √(free area) for
a translation, so units, origin and block order do not change the steps taken.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np

from alma.geometry.contacts import Joints, block_areas_and_centroids, find_joints
from alma.geometry.scene import Scene
from alma.mechanics.model import build_model
from alma.push.corrector import corrected
from alma.push.curve import PUSH_MODELS, _curve
from alma.push.motion import (
    MotionError,
    Pose,
    advance,
    classify,
    displaced,
    face_first,
    joints_after,
    predictor,
    signature,
)
from alma.push.result import PushPoint, PushResult, _Run, _State
from alma.push.settlement_motion import _bodies, _cracked, _placed, _Supports, _supports, _touching
from alma.results.types import Result, finite
from alma.settings import PushSettings, Settings
from alma.settle import settle
from alma.solve import solve
from alma.status import Status

#: A configuration's analysis that found its α: certified (Eq. 10), or a verified friction state.
_STANDS = (Status.OPTIMAL, Status.FEASIBLE)


@dataclass(frozen=True)
class _Context:
    """What the settlement's steps share: the supports, the geometric length and the crack
    patterns met (abscissa → opened joints; this module's own record, filled as states are made)."""

    supports: _Supports
    length: float  # L, mm
    settings: Settings | None
    model: str  # "associative" (Eq. 10) or "nonassociative" (Eq. 9's search)
    cracks: dict[float, tuple[tuple[str, str], ...]] = field(default_factory=dict)


@dataclass(frozen=True)
class SettlementCapacity:
    """The settlement capacity of a scene: s_u, the curve α(s) and the crack pattern at each step.

    ``s_u`` is in ``unit`` (mm of the control support's translation, or rad of its rotation);
    ``factor_u`` = s_u / that measure (the multiple of the scene's settlement at capacity);
    ``curve`` is push's :class:`~alma.push.result.PushResult` whose abscissa ``d`` is the
    settlement (its ``control`` the control support).
    """

    status: Status
    message: str
    support: str
    unit: str
    s_u: float
    bracket: tuple[float, float]
    factor_u: float
    curve: PushResult
    cracks: tuple[tuple[tuple[str, str], ...], ...]  # per curve point: the joints the settlement moves
    measure: float  # the control support's settlement per unit factor (mm or rad)

    @property
    def cracked_u(self) -> tuple[tuple[str, str], ...]:
        """The crack pattern of the last configuration that still stands (α > 0), before s_u."""
        standing = [c for p, c in zip(self.curve.curve, self.cracks, strict=True) if p.alpha > 0]
        return standing[-1] if standing else ()

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``alma settle --capacity``."""
        points = [
            {
                "s": p.d,
                "factor": p.d / self.measure,
                "alpha": finite(p.alpha),
                "mechanism_changed": p.mechanism_changed,
                "status": str(p.status),
                "cracked": [list(j) for j in c],
            }
            for p, c in zip(self.curve.curve, self.cracks, strict=True)
        ]
        return {
            "status": str(self.status),
            "message": self.message,
            "model": self.curve.model,
            "support": self.support,
            "unit": self.unit,
            "s_u": finite(self.s_u),
            "s_u_bracket": [finite(x) for x in self.bracket],
            "factor_u": finite(self.factor_u),
            "alpha_0": finite(self.curve.alpha_c),
            "cracked_u": [list(j) for j in self.cracked_u],
            "curve": points,
            "solves": self.curve.solves,
            "end": self.curve.end,
        }


def settlement_capacity(
    scene: Scene,
    *,
    steps: int | None = None,
    settings: Settings | None = None,
    push_settings: PushSettings | None = None,
    model: str = "associative",
) -> SettlementCapacity:
    """The settlement at which ``scene`` can no longer carry its dead load (module docstring).

    Parameters
    ----------
    scene
        A scene (mm, kN) with a ``settlement`` on at least one fixed block.
    steps
        Steps from s = 0 to the capacity (``PushSettings.steps`` when None).
    model
        α(s) by the associative limit analysis (Eq. 10, the default) or by the friction search
        (``"nonassociative"``, Eq. 9: the lowest verified collapse state, α_NL ≤ α_LP, so its
        s_u comes no later on the same crack path; a lower state could bring it sooner).  The
        crack path itself is the settlement problem's (:func:`alma.settle`), for both.

    Returns
    -------
    SettlementCapacity
        ``status`` ``optimal`` when every α of the curve is certified and s_u is bracketed to
        the stated accuracy (``feasible`` with the friction search: its α are verified states,
        not proven minima); ``no_equilibrium`` when the structure cannot carry its dead load
        before it settles; ``limit_reached`` when the step budget ran out with α still > 0.

    Raises
    ------
    SettleError
        When no support of the scene has a settlement, or the settlement is zero.
    """
    p = push_settings or PushSettings()
    if model not in PUSH_MODELS:
        raise ValueError(f"model must be one of {PUSH_MODELS}, got {model!r}")
    if steps is not None:
        if not (isinstance(steps, int) and steps >= 1):
            raise ValueError(f"steps must be a positive integer, got {steps!r}")
        p = dataclasses.replace(p, steps=steps)
    if not scene.validated:
        scene.validate()
    supports = _supports(scene)
    areas, _ = block_areas_and_centroids(scene)
    free = np.array([not b.fixed for b in scene.blocks])
    ctx = _Context(supports, float(np.sqrt(np.abs(areas[free]).sum())), settings, model)
    scale = ctx.length if supports.unit == "mm" else 1.0
    run = _Run(scene, model, settings, p, scale, supports.control, 1.0, mover=functools.partial(_move, ctx))
    support = scene.blocks[supports.control].id
    try:
        start = _configuration(ctx, run, 0.0, Pose.rest(len(scene.blocks)), find_joints(scene))
    except MotionError as exc:  # the settlement mechanism of the scene as drawn is not certified
        drawn = cast(Result, solve(build_model(scene), model=model, settings=settings))
        return _failed(drawn, Status.NOT_CONVERGED, supports, support, model, f"before any settlement: {exc}")
    if not (start.result.status in _STANDS and start.alpha > 0):
        status = Status.NO_EQUILIBRIUM if start.result.status in _STANDS else start.result.status
        return _failed(
            start.result,
            status,
            supports,
            support,
            model,
            f"before any settlement: {start.result.message} (α = {start.alpha:.6g})",
        )
    # Any settlement cracks the intact structure (a spreading arch takes its hinges at once): α
    # may drop at s = 0⁺, so push's steps start from the first cracked configuration, whose
    # slope, not the jump, sets their length.
    try:
        first = _move(ctx, run, start, p.probe * scale)
    except MotionError as exc:
        return _failed(
            start.result, Status.NOT_CONVERGED, supports, support, model, f"the first settlement step: {exc}"
        )
    if not (math.isfinite(first.alpha) and first.alpha > 0 and first.result.status in _STANDS):
        curve = _curve(run, start)  # α ≤ 0 already at the probe: push's refinement inside it
    else:
        curve = _curve(run, first)
        head = PushPoint(0.0, start.alpha, False, start.result.status, start.result.mechanism_class, start.pose)
        points = list(curve.curve)
        points[0] = dataclasses.replace(points[0], mechanism_changed=first.signature != start.signature)
        curve = dataclasses.replace(curve, curve=(head, *points), solves=curve.solves + 1, first=start.result)
    return _capacity(ctx, curve, support)


def _failed(
    result: Result, status: Status, supports: _Supports, support: str, model: str, message: str
) -> SettlementCapacity:
    """No curve: the structure does not stand at s = 0, or its first step failed (``result``: the
    analysis of the scene as drawn)."""
    empty = PushResult(result.status, result.message, model, support, (), math.nan, (math.nan, math.nan), 1, result)
    return SettlementCapacity(
        status, message, support, supports.unit, math.nan, (math.nan, math.nan), math.nan, empty, (), supports.measure
    )


def _capacity(ctx: _Context, curve: PushResult, support: str) -> SettlementCapacity:
    """s_u from push's end of the curve: α = 0 (its d₀), or the bracket of a loss of equilibrium."""
    unit = ctx.supports.unit
    if curve.end.get("reason") == "no_equilibrium":
        lo, hi = curve.end["bracket"]
        bracket = (float(lo), float(hi))
    else:
        bracket = curve.d0_bracket
    s_u = curve.d0 if math.isfinite(curve.d0) else 0.5 * (bracket[0] + bracket[1])
    cracks = tuple(ctx.cracks.get(p.d, ()) for p in curve.curve)
    message = (
        curve.message.replace("d0 = ", "s_u = ").replace(" mm", f" {unit}")
        if unit == "rad"
        else curve.message.replace("d0 = ", "s_u = ")
    )
    if curve.status == Status.LIMIT_REACHED or not math.isfinite(s_u):
        message = f"the structure still carries its dead load at the last settlement tried: {message}"
    result = SettlementCapacity(
        curve.status,
        message,
        support,
        unit,
        s_u,
        bracket,
        s_u / ctx.supports.measure,
        curve,
        cracks,
        ctx.supports.measure,
    )
    return result


def _configuration(ctx: _Context, run: _Run, s: float, pose: Pose, joints: Joints) -> _State:
    """The configuration at factor ``s``: α of the displaced structure and its settlement mechanism."""
    sup = ctx.supports
    here = _touching(_placed(run.scene, pose, sup, s), joints)
    built = build_model(here, joints)
    # PUSH_MODELS: one model, never "both", so no Comparison comes back.
    result = cast(Result, solve(built, model=ctx.model, settings=ctx.settings))
    associative = ctx.settings.associative if ctx.settings is not None else None
    crack = settle(here, associative, joints, crisp=run.push.settlement_vertex_slack)
    d = s * sup.measure
    if crack.status == Status.NO_EQUILIBRIUM and result.status in _STANDS and result.alpha > 0:
        # The settlement LP's dual is the dead load's own equilibrium (α = 0): it has none here,
        # although a field carries α_c > 0 of live load (the structure leans on the live load):
        # the dead load is lost, which is the capacity's question.
        result = dataclasses.replace(
            result,
            status=Status.NO_EQUILIBRIUM,
            alpha=-math.inf,
            message=f"the dead load alone has no equilibrium ({crack.message}); "
            f"α_c = {result.alpha:.6g} needs the live load's help",
        )
    if crack.status == Status.OPTIMAL:
        bodies = _bodies(here, crack, sup, s, ctx.length)
    elif not (math.isfinite(result.alpha) and result.alpha > 0):
        bodies = _bodies(here, None, sup, s, ctx.length)  # the curve ends here: no step leaves it
    else:
        raise MotionError(
            f"the settlement mechanism at s = {d:.6g} {sup.unit} is not certified ({crack.status}: {crack.message})"
        )
    contacts = classify(built.joints, bodies, built.friction)
    ctx.cracks[d] = _cracked(here, built.joints, bodies, ctx.length)
    return _State(d, pose, result, bodies, contacts, signature(here, result, contacts), built)


def _move(ctx: _Context, run: _Run, state: _State, d: float) -> _State:
    """The configuration at abscissa ``d``: the supports by their exact increment, the free
    blocks along ``state``'s settlement mechanism with its contacts kept closed."""
    sup, bodies = ctx.supports, state.bodies
    s0, s1 = state.d / sup.measure, d / sup.measure
    ds = s1 - s0
    z0 = predictor(bodies, ds)
    mine = bodies.of_block[sup.index]
    z0[mine] = np.column_stack([ds * sup.rotation, ds * sup.translation])
    prescribed = np.zeros(bodies.count, dtype=bool)
    prescribed[mine] = True
    args = (z0, None, 0.0, ctx.length, run.push, prescribed)
    contacts = face_first(displaced(run.scene, state.pose), state.contacts)
    on_support = np.isin(contacts.a, sup.index) | np.isin(contacts.b, sup.index)
    tries = (
        contacts,
        # as push does: sliding points kept closed may over-constrain a dilatant mechanism
        dataclasses.replace(contacts, sliding=np.zeros_like(contacts.sliding)),
        # a block hinged to a fixed support and resting on a settling one by a corner (a lintel
        # over a sinking pier) slides on it at second order: its corner stays on the face only
        dataclasses.replace(
            contacts, hinge=contacts.hinge & ~on_support, sliding=contacts.sliding | (contacts.hinge & on_support)
        ),
    )
    for k, kept in enumerate(tries):
        try:
            z = corrected(bodies, kept, *args)
            break
        except MotionError:
            if k == len(tries) - 1:
                raise
    pose = advance(state.pose, run.scene, bodies, z)
    joints = joints_after(_placed(run.scene, pose, sup, s1), state.contacts, bodies, z)
    return _configuration(ctx, run, s1, pose, joints)
