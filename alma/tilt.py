"""The tilting table: the critical tilt angle of a structure (SPEC §3 ``alma tilt``).

The table, and with it the structure, turns by θ so that gravity turns towards +x:
g(θ) = R(θ) g₀, g₀ the scene's gravity.  Weights and dead point loads turn with it; the
structure stands at θ when the associative LP (Eq. 10) with that dead load and the live load
dg/dθ (the weights along R(θ + 90°) g₀) has α ≥ 0.

For a scene whose only loads are the self-weights, with no cohesion and no ties, the problem is
homogeneous: W g(θ) / cos θ = W g₀ + tan θ · W R(90°) g₀, so θ_c = atan(α_c) of the live load
R(90°) g₀ (horizontal for the default gravity), certified by the LP's own bounds.  Otherwise
θ is bisected on [0°, 90°] with one certified LP per step: a step counts as standing when the
LP proves α ≥ 0 and as collapsing when it proves α < 0.  The number of steps is a work budget,
not a time.  Angles in degrees.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from alma.associative.lp import solve_lp
from alma.geometry.scene import Scene
from alma.mechanics.model import build_model
from alma.settings import AssociativeSettings
from alma.status import Status


@dataclass(frozen=True)
class TiltSettings:
    """The bisection of the general case."""

    #: Width of the certified bracket (degrees) that ends the bisection: a thousandth of a table's
    #: reading (0.1°), and wide enough that the LP's certified gap (1e-7) still decides each side.
    tolerance_deg: float = 1e-4
    #: LP solves the bisection may spend: 90° / 2^20 ≈ 9e-5°, so the tolerance ends it first.
    max_steps: int = 24


@dataclass(frozen=True)
class TiltResult:
    """Critical tilt angle θ_c (degrees): the structure stands up to ``bounds_deg[0]`` (proven)
    and collapses from ``bounds_deg[1]`` on (proven) when ``status`` is ``optimal``."""

    status: Status
    message: str
    angle_deg: float
    bounds_deg: tuple[float, float]
    method: str  # "exact" (atan of α_c) or "bisection"
    steps: int  # LP solves

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of SPEC §3 for ``alma tilt``."""

        def num(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        return {
            "status": str(self.status),
            "message": self.message,
            "angle_deg": num(self.angle_deg),
            "bounds_deg": [num(self.bounds_deg[0]), num(self.bounds_deg[1])],
            "method": self.method,
            "steps": self.steps,
        }


def tilt(
    scene: Scene,
    *,
    settings: TiltSettings | None = None,
    associative: AssociativeSettings | None = None,
    method: str = "auto",
) -> TiltResult:
    """The critical tilt angle of ``scene`` on a tilting table (degrees).

    ``method``: "auto" (exact where the problem is homogeneous, see the module docstring),
    "exact" or "bisection".
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be an alma.Scene, got {type(scene).__name__}")
    if not scene.validated:
        scene = scene.validate()
    if method not in ("auto", "exact", "bisection"):
        raise ValueError(f"method must be 'auto', 'exact' or 'bisection', got {method!r}")
    homogeneous = _homogeneous(scene)
    if method == "exact" and not homogeneous:
        raise ValueError(
            "the exact tilt angle needs self-weight as the only load, no cohesion, no ties and no compressive strength"
        )
    s = settings or TiltSettings()
    if _stands(scene, 0.0, associative, backwards=True) is False:
        # α of Eq. 10 is the largest multiplier carried: the level table must also carry the
        # reversed load, or the structure already falls the other way.
        return TiltResult(
            Status.NO_EQUILIBRIUM,
            "the structure cannot stand on the level table (it falls towards −x)",
            math.nan,
            (-math.inf, 0.0),
            method,
            1,
        )
    if method == "bisection" or not homogeneous:
        return _bisection(scene, s, associative)
    return _exact(scene, associative)


def tilted(scene: Scene, degrees: float, *, backwards: bool = False) -> Scene:
    """``scene`` on the table turned by ``degrees``: gravity and dead loads turned, the live load
    the weights along dg/dθ (the table turning further; against it when ``backwards``)."""
    theta = math.radians(degrees)
    g0 = np.asarray(scene.gravity, dtype=float)
    gravity = _rotate(g0, theta)
    live = _rotate(g0, theta + (-1 if backwards else 1) * math.pi / 2)
    loads = tuple(
        dataclasses.replace(load, dead=tuple(_rotate(np.asarray(load.dead), theta)), live=(0.0, 0.0))
        for load in scene.loads
    )
    return dataclasses.replace(
        scene, gravity=tuple(gravity), live_load_direction=tuple(live), live_self_weight=True, loads=loads
    )


def _homogeneous(scene: Scene) -> bool:
    """Self-weight is the only load, and no joint has a strength of its own (cohesion, ties, a
    compressive strength: its capacity does not scale with the loads)."""
    g0 = np.asarray(scene.gravity, dtype=float)
    live = np.asarray(scene.live_load_direction, dtype=float)
    return (
        not scene.loads
        and not scene.ties
        and scene.cohesion == 0
        and scene.compressive_strength is None
        and all(not o.cohesion and o.compressive_strength is None for o in scene.joint_overrides)
        and scene.live_self_weight
        and np.allclose(live, _rotate(g0, math.pi / 2), atol=1e-12)
    )


def _exact(scene: Scene, associative: AssociativeSettings | None) -> TiltResult:
    lp = solve_lp(build_model(scene), associative)
    if lp.status == Status.NO_COLLAPSE:
        return TiltResult(
            Status.NO_COLLAPSE,
            "no mechanism: the structure stands at any tilt up to 90°",
            90.0,
            (90.0, math.inf),
            "exact",
            2,
        )
    if lp.status == Status.NO_EQUILIBRIUM or (lp.status == Status.OPTIMAL and lp.upper < 0):
        return TiltResult(
            Status.NO_EQUILIBRIUM,
            "the structure cannot stand on the level table",
            math.nan,
            (-math.inf, 0.0),
            "exact",
            2,
        )
    to_deg = lambda a: math.degrees(math.atan(a)) if math.isfinite(a) else (90.0 if a > 0 else -90.0)  # noqa: E731
    bounds = (to_deg(lp.lower), to_deg(lp.upper))
    message = f"θ_c = atan(α_c) of the horizontal self-weight load; {lp.message}"
    return TiltResult(lp.status, message, to_deg(lp.alpha), bounds, "exact", 2)


def _stands(
    scene: Scene, degrees: float, associative: AssociativeSettings | None, *, backwards: bool = False
) -> bool | None:
    """True when the LP proves the structure stands at ``degrees``, False when it proves collapse,
    None when it proves neither (``backwards``: against the live load turned back)."""
    lp = solve_lp(build_model(tilted(scene, degrees, backwards=backwards)), associative)
    if lp.status == Status.NO_COLLAPSE:
        return True
    if lp.status == Status.NO_EQUILIBRIUM:
        return False
    if lp.status == Status.OPTIMAL:
        return bool(lp.lower >= 0) if (lp.lower >= 0 or lp.upper < 0) else None
    return None


def _bisection(scene: Scene, s: TiltSettings, associative: AssociativeSettings | None) -> TiltResult:
    first = _stands(scene, 0.0, associative)
    if first is False:
        return TiltResult(
            Status.NO_EQUILIBRIUM,
            "the structure cannot stand on the level table",
            math.nan,
            (-math.inf, 0.0),
            "bisection",
            2,
        )
    last = _stands(scene, 90.0, associative)
    if last is True:
        return TiltResult(Status.NO_COLLAPSE, "the structure stands at 90°", 90.0, (90.0, math.inf), "bisection", 3)
    lo, hi, steps, unproven = 0.0, 90.0, 3, first is None or last is None
    while hi - lo > s.tolerance_deg and steps < s.max_steps:
        mid = 0.5 * (lo + hi)
        verdict = _stands(scene, mid, associative)
        steps += 1
        if verdict is None:
            unproven = True
            break
        lo, hi = (mid, hi) if verdict else (lo, mid)
    closed = hi - lo <= s.tolerance_deg and not unproven
    status = Status.OPTIMAL if closed else Status.NOT_CONVERGED
    message = (
        f"certified bracket of {hi - lo:.1e}° after {steps} LP solves"
        if closed
        else f"bracket [{lo:.9f}°, {hi:.9f}°] after {steps} LP solves; an LP proved neither side"
    )
    return TiltResult(status, message, 0.5 * (lo + hi), (lo, hi), "bisection", steps)


def _rotate(v: np.ndarray, theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])
