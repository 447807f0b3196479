"""The public entry point: ``alma.solve(scene, model=...)``."""

from __future__ import annotations

import dataclasses
import time
from typing import Literal, cast, overload

import numpy as np

from alma.associative.crisp import crisp_mechanism, on_face
from alma.associative.lp import solve_lp
from alma.associative.radenkovic import radenkovic_lower_bound
from alma.certify.milp import certify as certify_milp
from alma.engine.pattern_cache import PatternCache
from alma.geometry.canonical import CanonicalFrame, canonical_joints, canonical_scene
from alma.geometry.contacts import Joints, find_joints
from alma.geometry.scene import Scene, SceneError
from alma.geometry.validation import validated
from alma.mechanics.canonical import snapped
from alma.mechanics.model import Model, build_model
from alma.nonassociative.search import NonAssociativeSolution, carried_back, solve_nonassociative
from alma.results.build import associative_result, comparison, nonassociative_result
from alma.results.joints import model_mechanism
from alma.results.types import AssociativeResult, Comparison, NonAssociativeResult
from alma.settings import Effort, Settings
from alma.status import Status

MODELS = ("associative", "nonassociative", "both")


# One signature per model, so that a call names its result's type (the body is the last one).
@overload
def solve(
    scene: Scene | Model,
    model: Literal["associative"] = ...,
    *,
    settings: Settings | None = ...,
    tolerance: float | None = ...,
    joints: Joints | None = ...,
    effort: str | None = ...,
    certify: bool = ...,
    time_limit: float | None = ...,
    patterns: PatternCache | None = ...,
) -> AssociativeResult: ...
@overload
def solve(
    scene: Scene | Model,
    model: Literal["nonassociative"],
    *,
    settings: Settings | None = ...,
    tolerance: float | None = ...,
    joints: Joints | None = ...,
    effort: str | None = ...,
    certify: bool = ...,
    time_limit: float | None = ...,
    patterns: PatternCache | None = ...,
) -> NonAssociativeResult: ...
@overload
def solve(
    scene: Scene | Model,
    model: Literal["both"],
    *,
    settings: Settings | None = ...,
    tolerance: float | None = ...,
    joints: Joints | None = ...,
    effort: str | None = ...,
    certify: bool = ...,
    time_limit: float | None = ...,
    patterns: PatternCache | None = ...,
) -> Comparison: ...
@overload
def solve(
    scene: Scene | Model,
    model: str = ...,
    *,
    settings: Settings | None = ...,
    tolerance: float | None = ...,
    joints: Joints | None = ...,
    effort: str | None = ...,
    certify: bool = ...,
    time_limit: float | None = ...,
    patterns: PatternCache | None = ...,
) -> AssociativeResult | NonAssociativeResult | Comparison: ...
def solve(
    scene: Scene | Model,
    model: str = "associative",
    *,
    settings: Settings | None = None,
    tolerance: float | None = None,
    joints: Joints | None = None,
    effort: str | None = None,
    certify: bool = False,
    time_limit: float | None = None,
    patterns: PatternCache | None = None,
) -> AssociativeResult | NonAssociativeResult | Comparison:
    """Collapse multiplier and mechanism of a scene.

    Parameters
    ----------
    scene
        A :class:`~alma.geometry.scene.Scene` (validated here, at every call, if it was built by
        hand: ``scene = scene.validate()`` once to solve it many times; the scene passed is never
        changed) or a prebuilt :class:`~alma.mechanics.model.Model` (skips joint detection and
        assembly).
    model
        ``"associative"``: the dilatant LP of Eq. 10, certified from both sides;
        ``"nonassociative"``: the lowest verified collapse state of Eq. 9 found by the search
        (``alma.nonassociative``); ``"both"``: both results whole and their ratio.
    settings
        Every tuned number (:class:`alma.settings.Settings`); ``tolerance`` (the LP's),
        ``effort`` ("auto", "fast", "thorough") and ``time_limit`` (s) override its fields.
    certify
        Non-associative models only: prove a lower bound by mixed-integer programming
        (:mod:`alma.certify`; cohesion and ties included).  ``settings.certify.backend`` picks
        HiGHS (big-M binaries, the default) or SCIP (SOS1 pairs, the extra ``alma[scip]``); its
        ``node_limit`` is the work budget, and a proof stopped by it (or by ``time_limit``)
        still gives the bound it reached as ``bounds.lower``.  A scene with a finite
        ``compressive_strength`` is solved by the associative model only (a second-order cone
        program, :mod:`alma.associative.crushing`); the others refuse it with a SceneError.
    time_limit
        A user's wall-clock cap in seconds; when it cuts the work the status is
        ``limit_reached``.  Without it the answer depends on the input and settings only.
    patterns
        A :class:`~alma.engine.PatternCache` the caller keeps across calls: the interior point
        reuses the normal-equations pattern of a structure it solved before (the frictions of
        one geometry in a study).  It changes the cost, never the answer; without it each LP
        builds its own.
    """
    settings = _settings(settings, tolerance, effort, time_limit)
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, got {model!r}")
    if certify and model == "associative":
        raise ValueError(
            "certify applies to the non-associative model (the associative result is "
            "certified by its static and kinematic bounds): use model='nonassociative' or 'both'"
        )
    built, timings = _build(scene, joints)
    if built.crushes and model != "associative":
        raise SceneError(
            "compressive_strength: the non-associative model (Eq. 9) takes no finite compressive "
            "strength (its verifier and certificate check the Coulomb cones only); solve with "
            "model='associative', or remove compressive_strength"
        )
    lp = solve_lp(built, settings.associative, time_limit=settings.time_limit, patterns=patterns)
    timings.update(solve_s=lp.solve_time, certify_s=lp.certify_time)
    warned = built.joints.warnings
    assoc = dataclasses.replace(
        associative_result(built, _crisp(built, lp, settings, timings), timings), warnings=warned
    )
    if model == "associative":
        return assoc
    nl = dataclasses.replace(_nonassociative(built, lp, assoc, settings, certify, patterns), warnings=warned)
    return comparison(assoc, nl) if model == "both" else nl


def _settings(
    settings: Settings | None, tolerance: float | None, effort: str | None, time_limit: float | None
) -> Settings:
    """``settings`` with the keyword overrides applied, checked before any work is done."""
    s = settings if settings is not None else Settings()
    if not isinstance(s, Settings):
        raise TypeError(f"settings must be an alma.settings.Settings, got {type(s).__name__}")
    if tolerance is not None:
        s = dataclasses.replace(s, associative=dataclasses.replace(s.associative, tolerance=float(tolerance)))
    if effort is not None:  # any string: SearchSettings checks it against alma.settings.EFFORTS
        s = dataclasses.replace(s, search=dataclasses.replace(s.search, effort=cast(Effort, effort)))
    if time_limit is not None:
        if not time_limit > 0:
            raise ValueError(f"time_limit must be a positive number of seconds, got {time_limit!r}")
        s = dataclasses.replace(s, time_limit=float(time_limit))
    return s


def _crisp(
    built: Model,
    lp,
    settings: Settings,
    timings: dict[str, float],
    keep: tuple[np.ndarray, float] | None = None,
    previous: np.ndarray | None = None,
):
    """``lp`` with the crisp mechanism of its optimal face (:mod:`alma.associative.crisp`, with the
    row ``keep`` when given) in place of the interior point's blend; α, bounds and the stress
    field stay.  A ``previous`` mechanism (block motions, as :func:`model_mechanism` takes them)
    still on that face with ``keep`` is kept instead, with no LP.  The non-associative search
    keeps starting from the interior point's mechanism."""
    s = settings.associative
    wanted = s.crisp_mechanism or keep is not None
    if not (wanted and lp.status == "optimal" and not built.n_bounded and not built.crushes):
        return lp
    slack = s.gap_tolerance * 5e-3
    t0 = time.perf_counter()
    kept = None if previous is None else on_face(built, lp.upper, slack, model_mechanism(built, previous), keep)
    if kept is not None:
        timings["crisp_s"] = time.perf_counter() - t0
        why = "the previous configuration's mechanism, still on the optimal face"
        return dataclasses.replace(lp, mechanism=kept, message=f"{lp.message}; {why}")
    u, why = crisp_mechanism(
        built,
        lp.upper,
        slack,
        lp.multipliers,
        lp.mechanism,
        max_blocks_capped=s.crisp_capped_blocks,
        time_limit=settings.time_limit,
        keep=keep,
    )
    timings["crisp_s"] = time.perf_counter() - t0
    if u is None:
        return dataclasses.replace(lp, message=f"{lp.message}; {why}, the interior point's mechanism is shown")
    return dataclasses.replace(lp, mechanism=u, message=f"{lp.message}; {why}")


#: A followed mechanism moves its block at least this fraction of the interior point's speed
#: below it: the interior point's own mechanism lies on the face only to its tolerance.
FOLLOW_SLACK = 1e-6


def solve_following(
    built: Model, settings: Settings | None, block: int, sense: float, previous: np.ndarray | None = None
) -> AssociativeResult:
    """Eq. 10 of the prebuilt ``built`` (as :func:`solve`), its mechanism one that keeps moving
    the scene's block ``block`` along x with sign ``sense`` (a capacity curve's control block).

    Where the interior point's mechanism only translates (``sliding``), the optimal face holds
    every part of the wall that can slide at that α, and the interior point returns their blend,
    its blocks moving at different rates.  The mechanism is then the sparsest vertex of the face
    (:mod:`alma.associative.crisp`) that moves ``block`` at least as fast as the blend does; α,
    its bounds and the stress field stay, and ``previous`` (block motions (n_blocks, 3) in the
    scene's order, mm and rad: the mechanism followed so far) is kept instead where it is still
    such a mechanism of the face.  Any other mechanism is the interior point's.
    """
    s = _settings(settings, None, None, None)
    timings = _build(built, None)[1]
    lp = solve_lp(built, s.associative, time_limit=s.time_limit)
    timings.update(solve_s=lp.solve_time, certify_s=lp.certify_time)
    lp = _crisp(built, lp, s, timings)
    row = int(built.free_index[block])
    result = associative_result(built, lp, timings)
    if result.mechanism_class != "sliding" or row < 0:
        return dataclasses.replace(result, warnings=built.joints.warnings)
    toward = np.zeros(built.equilibrium.shape[0])
    toward[3 * row] = sense
    speed = float(toward @ lp.mechanism) / float(built.live @ lp.mechanism)  # f_Lᵀu > 0 on a mechanism
    if speed > 0:
        keep = (toward, (1 - FOLLOW_SLACK) * speed)
        result = associative_result(built, _crisp(built, lp, s, timings, keep, previous), timings)
    return dataclasses.replace(result, warnings=built.joints.warnings)


def _build(scene: Scene | Model, joints: Joints | None) -> tuple[Model, dict[str, float]]:
    """The model of ``scene`` and the seconds of its joints and build; a scene not validated yet
    is validated here, and its ``joints_s`` is the validation's, whose joints the model uses."""
    if isinstance(scene, Model):
        return scene, {"joints_s": 0.0, "build_s": 0.0}
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be an alma.Scene or alma.Model, got {type(scene).__name__}")
    t0 = time.perf_counter()
    if not scene.validated:  # a hand-built scene meets the same rules as a loaded one
        scene, found = validated(scene)
        joints = found if joints is None else joints  # the check's joints, not found again
    elif joints is None:
        joints = find_joints(scene)
    t1 = time.perf_counter()
    built = build_model(scene, joints)
    return built, {"joints_s": t1 - t0, "build_s": time.perf_counter() - t1}


def _search(built: Model, settings: Settings, patterns: PatternCache | None) -> NonAssociativeSolution:
    """Eq. 9 searched on the canonical drawing (one structure, one answer), answered on ``built``.

    The canonical model's joints are found on the canonical drawing when ``built``'s are the ones
    its drawing gives; otherwise ``built``'s own are carried into the canonical frame
    (:func:`~alma.geometry.canonical.canonical_joints`) and the canonical drawing is not validated
    again: a model built with given joints, such as a displaced configuration of ``alma.push``
    with its point contacts, keeps them.
    The canonical model gets its own associative solution (Eq. 10) to start from; the lowest
    canonical states are then carried to ``built`` whole or made exact there (:func:`carried_back`),
    and verified on it.  When none
    of them verifies there, the search runs again with the canonical data rounded to
    ``fallback_bits`` (:class:`~alma.settings.SearchSettings`).
    """
    found = _same_joints(built.joints, find_joints(built.scene))
    scene, frame = canonical_scene(built.scene, check=found)
    unrounded = build_model(scene, None if found else canonical_joints(built.joints, frame))
    answer, solution = _search_at(unrounded, frame, built, settings, settings.search.canonical_bits, patterns)
    fallback = settings.search.fallback_bits
    # Again at the fallback's precision only when canonical states verified there and none here.
    if (
        fallback is not None
        and answer.status == Status.NOT_CONVERGED
        and solution.best is not None
        and not solution.stopped_by_limit
    ):
        answer, _ = _search_at(unrounded, frame, built, settings, fallback, patterns)
    return answer


def _same_joints(one: Joints, other: Joints) -> bool:
    """Whether two joint tables are the same, row for row and bit for bit."""
    fields = ("block_a", "block_b", "start", "end", "normal")
    return one.count == other.count and all(np.array_equal(getattr(one, f), getattr(other, f)) for f in fields)


def _search_at(
    unrounded: Model, frame: CanonicalFrame, built: Model, settings: Settings, bits: int, patterns: PatternCache | None
) -> tuple[NonAssociativeSolution, NonAssociativeSolution]:
    """The search on the canonical model rounded to ``bits`` bits: (the answer on ``built``, the
    canonical search's own solution)."""
    canonical = snapped(unrounded, bits)
    lp = solve_lp(canonical, settings.associative, time_limit=settings.time_limit, patterns=patterns)
    solution = solve_nonassociative(
        canonical,
        lp.mechanism if lp.solved else None,
        lp.multipliers if lp.solved else None,
        effort=settings.search.effort,
        settings=settings.search,
        time_limit=settings.time_limit,
        associative_alpha=lp.alpha if lp.solved else None,
        certify=settings.certify,
    )
    return carried_back(solution, canonical, frame, built, settings.search), solution


def _nonassociative(
    built: Model, lp, assoc: AssociativeResult, settings: Settings, certify: bool, patterns: PatternCache | None
) -> NonAssociativeResult:
    """Eq. 9: the search from the LP's mechanism and field, and the MILP proof if asked."""
    t0 = started = time.perf_counter()
    timings = dict(assoc.timings)
    solution = _search(built, settings, patterns)
    timings["nonassociative_s"] = time.perf_counter() - t0
    timings.update({k: float(v) for k, v in solution.timings.items() if k.endswith("_s")})
    t0 = time.perf_counter()
    radenkovic = radenkovic_lower_bound(built, settings.associative, patterns)
    timings["radenkovic_s"] = time.perf_counter() - t0
    certificate = None
    if certify:
        mechanisms = [c.mechanism for c in solution.candidates] + ([lp.mechanism] if lp.solved else [])
        best = solution.best.alpha if solution.best is not None else None
        # The user's cap covers the search and the proof together: the proof gets what is left.
        left = None if settings.time_limit is None else max(0.0, settings.time_limit - (time.perf_counter() - started))
        certificate = certify_milp(
            built, lp.alpha, mechanisms, settings=settings.certify, time_limit=left, alpha_best=best
        )
        timings["certification_s"] = certificate.time_s
    return nonassociative_result(built, assoc, solution, timings, certificate, radenkovic)


__all__ = ["MODELS", "SceneError", "solve"]
