"""One configuration of a capacity curve solved (:mod:`alma.push.curve`): the limit analysis of
the displaced scene on the joints the step carried, and what the next step needs of it.
"""

from __future__ import annotations

from typing import cast

import numpy as np

from alma.geometry.contacts import Joints
from alma.geometry.scene import Scene
from alma.mechanics.model import Model, build_model
from alma.push.carried import without_slack
from alma.push.motion import Pose, bodies_of, classify, signature
from alma.push.result import _Run, _State
from alma.results.types import Result
from alma.settings import Settings
from alma.solve import solve, solve_following


def solve_at(
    current: Scene,
    joints: Joints,
    model: str,
    settings: Settings | None,
    rest: np.ndarray,
    slack: float,
    follow: tuple[int, float] | None = None,
    previous: np.ndarray | None = None,
) -> tuple[Result, Model, np.ndarray]:
    """The limit analysis of ``current`` (a configuration, :func:`alma.push.motion.displaced`)
    without the ties that are slack there (shorter than their ``rest`` lengths by more than
    ``slack`` mm), and the rest lengths after it.  ``follow`` = (control block, sense): an
    associative sliding mechanism is the one that keeps moving it, ``previous`` (the block motions
    followed so far) where that still is one (:func:`alma.solve.solve_following`)."""
    current, after = without_slack(current, rest, slack)
    built = build_model(current, joints)
    if follow is not None and model == "associative":
        return solve_following(built, settings, *follow, previous), built, after
    # PUSH_MODELS: one model, never "both", so no Comparison comes back.
    return cast(Result, solve(built, model=model, settings=settings)), built, after


def state_at(run: _Run, d: float, pose: Pose, solved: tuple[Result, Model, np.ndarray]) -> _State:
    """The configuration at control displacement ``d`` (mm) and ``pose``, from :func:`solve_at`'s
    ``solved``: its mechanism's bodies, its contacts classified (hinges, sliding, crushing) and
    the signature that tells a change of mechanism."""
    result, built, rest = solved
    current = built.scene
    bodies = bodies_of(current, result)
    contacts = classify(
        built.joints, bodies, built.friction, np.isfinite(built.crushing) if built.crushing.size else None
    )
    return _State(d, pose, result, bodies, contacts, signature(current, result, contacts), built, rest)
