"""The capacity curve's result (SPEC §3 ``alma push``): its points, the run and state the steps share, and its status.

:class:`PushResult` holds α(d) at every solved configuration (d in mm, α the live load's
multiplier), d₀ and its bracket; :func:`_result` orders the states of a run into it and says
what the curve's end proves (:func:`_status`, :func:`_status_lost`).  The stepping is
:mod:`alma.push.curve`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from alma.geometry.scene import Scene
from alma.mechanics.model import Model
from alma.push.motion import Bodies, Contacts, Pose
from alma.results.types import NonAssociativeResult, Result, finite
from alma.settings import PushSettings, Settings
from alma.status import Status

#: The ends of a curve that stops with α > 0 on a mechanical finding, not a failure: a loss of
#: equilibrium beyond the last point, or a mechanism at the last point that the control block
#: does not follow (still or backwards).  d₀ is not defined; the seismic check reads the stop as
#: the ultimate displacement's bound.
STOPPED_ENDS = ("no_equilibrium", "control_still", "control_reverses")


@dataclass(frozen=True)
class PushPoint:
    """One configuration of the curve: the control displacement ``d`` (mm), α there, whether the
    mechanism differs from the previous point's, and the blocks' pose (not serialised)."""

    d: float
    alpha: float
    mechanism_changed: bool
    status: Status
    mechanism_class: str
    pose: Pose = field(repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        return {
            "d": self.d,
            "alpha": finite(self.alpha),
            "mechanism_changed": self.mechanism_changed,
            "status": str(self.status),
            "mechanism_class": self.mechanism_class,
        }


@dataclass(frozen=True)
class PushResult:
    """The capacity curve of SPEC §3 ``alma push``: α(d) from α_c to α = 0 at d₀ (mm)."""

    status: Status
    message: str
    model: str
    control: str | None
    curve: tuple[PushPoint, ...]
    d0: float
    d0_bracket: tuple[float, float]
    solves: int
    #: The analysis at d = 0 (the collapse mechanism the seismic check reads its virtual
    #: displacements from).
    first: Result = field(repr=False, compare=False)
    #: +1 when d grows with the control block's x, −1 when the mechanism moves it towards −x.
    sense: float = 1.0
    #: Why the curve ends: ``reason`` ("alpha_zero": α reached 0 at d₀; "no_equilibrium": a
    #: configuration beyond the last point carries the dead load at no α, with the ``bracket`` of
    #: that loss, α there and the blocks of the falling mode; "control_still" or "control_reverses":
    #: the mechanism at the last point, ``d``, leaves the control block still or moves it backwards;
    #: "step_budget", "motion", "solver").
    end: dict[str, Any] = field(default_factory=dict)

    @property
    def alpha_c(self) -> float:
        return self.curve[0].alpha if self.curve else math.nan

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of SPEC §3 for ``alma push``."""
        return {
            "status": str(self.status),
            "message": self.message,
            "model": self.model,
            "control": self.control,
            "alpha_c": finite(self.alpha_c),
            "curve": [p.to_dict() for p in self.curve],
            "d0": finite(self.d0),
            "d0_bracket": [finite(x) for x in self.d0_bracket],
            "solves": self.solves,
            "end": self.end,
        }


@dataclass(frozen=True)
class _State:
    """A solved configuration and what the next step needs of it."""

    d: float
    pose: Pose
    result: Result
    bodies: Bodies
    contacts: Contacts
    signature: tuple
    model: Model = field(repr=False, compare=False)
    #: Each tie's rest length (mm): the longest it has been up to here (:mod:`alma.push.carried`).
    rest: np.ndarray = field(repr=False, compare=False, default_factory=lambda: np.zeros(0))

    @property
    def alpha(self) -> float:
        """α here; for a friction search that proved no equilibrium by Radenkovic's bound
        (α_nonassociative ≤ α_associative < 0, no state to show), the associative α, its upper bound."""
        result = self.result
        if (
            isinstance(result, NonAssociativeResult)
            and result.status == Status.NO_EQUILIBRIUM
            and math.isnan(result.alpha)
            and result.associative is not None
        ):
            return float(result.associative.alpha)
        return float(result.alpha)


@dataclass(frozen=True)
class _Run:
    """What does not change over the analysis."""

    scene: Scene
    model: str
    settings: Settings | None
    push: PushSettings
    length: float  # L, mm
    control: int
    sense: float
    #: The step to a configuration (default :func:`alma.push.curve._move`; the settlement capacity's its own).
    mover: Callable[[_Run, _State, float], _State] | None = None
    #: The drawing's contact tolerance (mm) and its own overlaps (block pair → depth, mm), against
    #: which a step's overlaps are measured (:mod:`alma.push.landing`).
    snap: float = math.nan
    overlaps: dict[tuple[int, int], float] = field(default_factory=dict)


def _result(
    run: _Run,
    states: list[_State],
    failure: tuple | None,
    bracket: tuple[float, float],
    d0: float,
    solves: int,
    end: dict[str, Any],
) -> PushResult:
    ordered = sorted(states, key=lambda s: s.d)
    points = tuple(
        PushPoint(
            s.d,
            s.alpha,
            k > 0 and s.signature != ordered[k - 1].signature,
            s.result.status,
            s.result.mechanism_class,
            s.pose,
        )
        for k, s in enumerate(ordered)
    )
    changes = sum(pt.mechanism_changed for pt in points)
    control = run.scene.blocks[run.control].id
    if end["reason"] in STOPPED_ENDS:
        status, message = _status_stopped(run, ordered, failure, end, changes)
    elif failure is not None:
        status, message = failure
    else:
        status, message = _status(run, ordered, bracket, d0, changes)
    if failure is not None and math.isfinite(d0):
        message = f"{message}; d0 = {d0:.6g} mm is known only to its bracket [{bracket[0]:.9g}, {bracket[1]:.9g}] mm"
    return PushResult(
        status, message, run.model, control, points, d0, bracket, solves, ordered[0].result, run.sense, end
    )


def _status_stopped(
    run: _Run, states: list[_State], failure: tuple | None, end: dict[str, Any], changes: int
) -> tuple[Status, str]:
    """A curve that stops with α > 0 (:data:`STOPPED_ENDS`): d₀ is not defined, the stop is stated."""
    text = f"{end['text']}; {len(states)} configurations, the mechanism changed {changes} time(s)"
    if "low_end_step" in end:
        step = end["low_end_step"]
        return Status.NOT_CONVERGED, (
            f"{text}; not proven on the curve's way: a step from the bracket's low end to "
            f"{step['d']:.9g} mm finds equilibrium there (α = {step['alpha']:.6g}), but the curve does not "
            "go on past a joint crushed over its whole length"
        )
    if failure is not None:
        return failure[0], f"{text}; the bracket of the loss is not closed ({failure[1]})"
    if run.model == "nonassociative":
        return Status.FEASIBLE, f"{text}; each α is a verified non-associative state"
    every = all(s.result.status == Status.OPTIMAL for s in states)
    return (Status.OPTIMAL, f"{text}; every α certified") if every else (Status.NOT_CONVERGED, text)


def _status(
    run: _Run, states: list[_State], bracket: tuple[float, float], d0: float, changes: int
) -> tuple[Status, str]:
    lo = next(s for s in states if s.d == bracket[0])
    hi = next(s for s in states if s.d == bracket[1])
    proven = lo.result.bounds.lower > 0 and hi.result.bounds.upper <= 0
    every = all(s.result.status in (Status.OPTIMAL, Status.NO_EQUILIBRIUM) for s in states)
    text = (
        f"d0 = {d0:.6g} mm (bracket width {bracket[1] - bracket[0]:.2g} mm) after {len(states)} "
        f"configurations; the mechanism changed {changes} time(s)"
    )
    if run.model == "nonassociative":
        return Status.FEASIBLE, f"{text}; each α is a verified non-associative state"
    if proven and every:
        return Status.OPTIMAL, f"{text}; every α certified"
    return Status.NOT_CONVERGED, f"{text}; the sign of α at the bracket of d0 is not proven"
