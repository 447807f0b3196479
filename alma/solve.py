"""The public entry point: ``alma.solve(scene, model=...)``."""
from __future__ import annotations

import time

from .associative import solve_lp
from .contacts import Joints, find_joints
from .model import Model, build_model
from .result import Result, build_result
from .scene import Scene

MODELS = ("associative", "nonassociative", "both")


def solve(scene: Scene | Model, model: str = "associative", *, tolerance: float = 1e-11,
          joints: Joints | None = None) -> Result:
    """Collapse multiplier and mechanism of a scene.

    ``model="associative"`` solves the dilatant LP (Eq. 10) with certified
    bounds.  A prebuilt :class:`~alma.model.Model` may be passed instead of a
    scene to skip joint detection and assembly (e.g. when only friction changes).
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, got {model!r}")
    if model != "associative":
        raise NotImplementedError(
            f"model={model!r}: the non-associative solver (Eq. 9) is not available in this version")
    timings: dict[str, float] = {}
    if isinstance(scene, Model):
        built = scene
        timings["joints_s"] = 0.0
        timings["build_s"] = 0.0
    else:
        t0 = time.perf_counter()
        joints = find_joints(scene) if joints is None else joints
        t1 = time.perf_counter()
        built = build_model(scene, joints)
        t2 = time.perf_counter()
        timings["joints_s"] = t1 - t0
        timings["build_s"] = t2 - t1
    lp = solve_lp(built, tolerance=tolerance)
    timings["solve_s"] = lp.solve_time
    timings["certify_s"] = lp.certify_time
    return build_result(built, lp, timings)
