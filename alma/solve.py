"""The public entry point: ``alma.solve(scene, model=...)``."""
from __future__ import annotations

import time

from dataclasses import replace

import numpy as np

from alma.associative.lp import solve_lp
from alma.certify.milp import certify as certify_milp
from alma.nonassociative.search import solve_nonassociative
from alma.geometry.contacts import Joints, find_joints
from alma.mechanics.model import Model, build_model
from alma.results.result import Result, build_nonassociative_result, build_result
from alma.geometry.scene import Scene

MODELS = ("associative", "nonassociative", "both")


def solve(scene: Scene | Model, model: str = "associative", *, tolerance: float = 1e-11,
          joints: Joints | None = None, effort: str = "auto", certify: bool = False,
          time_limit: float | None = None) -> Result:
    """Collapse multiplier and mechanism of a scene.

    ``model="associative"`` solves the dilatant LP (Eq. 10) with certified
    bounds; ``"nonassociative"`` searches the collapse states of Eq. 9 (see
    :mod:`alma.nonassociative`) from the LP solution, ``effort`` "fast",
    "thorough" or "auto" (thorough up to 200 blocks), within ``time_limit``
    seconds, and with ``certify`` proves a lower bound by MILP under another
    ``time_limit`` seconds; ``"both"`` reports both
    multipliers and their ratio.  A prebuilt :class:`~alma.model.Model` may be
    passed instead of a scene to skip joint detection and assembly.
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, got {model!r}")
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
    if model == "associative":
        return build_result(built, lp, timings)

    if effort == "auto":
        effort = "thorough" if built.n_free <= 200 else "fast"
    t0 = time.perf_counter()
    lp_ok = lp.status in ("optimal", "not_converged")
    solution = solve_nonassociative(built, lp.mechanism if lp_ok else None,
                                    lp.multipliers if lp_ok else None, effort=effort, time_limit=time_limit,
                                    associative_alpha=lp.alpha if lp_ok else None)
    timings["nonassociative_s"] = time.perf_counter() - t0
    timings.update({k: v for k, v in solution.timings.items()})
    certificate = None
    if certify:
        mechanisms = [c.mechanism for c in solution.candidates] + ([lp.mechanism] if lp_ok else [])
        best = solution.best.alpha if solution.best is not None else None
        certificate = certify_milp(built, lp.alpha, mechanisms, time_limit=time_limit, alpha_best=best)
        timings["certification_s"] = certificate.time_s
    result = build_nonassociative_result(built, lp, solution, timings, certificate,
                                         name="both" if model == "both" else "nonassociative")
    if model == "both":
        extra = dict(result.extra, alpha_nonassociative=result.alpha,
                     ratio=result.alpha / lp.alpha if lp.alpha not in (0.0,) and np.isfinite(lp.alpha) else None)
        result = replace(result, extra=extra)
    return result
