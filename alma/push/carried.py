"""What the blocks carry along a capacity curve: point loads and tie ends, and a tie's slack.

A point load's point and a tie's end points are drawn on their blocks; when the blocks move
rigidly (x = R(angle)(X − G₀) + G₀ + shift, :class:`alma.push.motion.Pose`) they move with them,
so the forces act where they act on the displaced blocks and a tie's line runs between its
displaced ends (an end on a fixed block stays).  A load keeps its direction (gravity, the
horizontal action); a tie's direction is its current line.

A tie is rigid-plastic and tension-only (:mod:`alma.mechanics.forces`: 0 ≤ F ≤ strength): it does
not stretch below its strength, and an elongation is its plastic yield, which stays.  Its *rest
length* is therefore the longest it has been along the curve (the drawn length at first); a tie
shorter than its rest length is slack and carries nothing until it is stretched back to it
(docs/decisions.md, "Ties in the capacity curve").  Lengths in mm, angles in rad.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from alma.geometry.loads import PointLoad, Tie
from alma.geometry.scene import Scene


def carry(points: np.ndarray, rows: np.ndarray, angle: np.ndarray, shift: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """``points`` (k, 2) drawn on the blocks ``rows`` (k,), moved by those blocks' rigid motions
    (``angle`` (n,) rad, ``shift`` (n, 2) mm of the centroids ``origin`` (n, 2) mm)."""
    c, s = np.cos(angle[rows]), np.sin(angle[rows])
    r = points - origin[rows]
    moved = np.column_stack([c * r[:, 0] - s * r[:, 1], s * r[:, 0] + c * r[:, 1]]) + origin[rows] + shift[rows]
    # a block at rest (a support, an anchor) keeps its points bit for bit
    still = (angle[rows] == 0) & (shift[rows] == 0).all(axis=1)
    return np.where(still[:, None], points, moved)


def moved_loads(scene: Scene, angle: np.ndarray, shift: np.ndarray, origin: np.ndarray) -> tuple[PointLoad, ...]:
    """The scene's point loads with their points moved by their blocks (None: the centroid)."""
    if not any(load.point is not None for load in scene.loads):
        return scene.loads
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    at = [k for k, load in enumerate(scene.loads) if load.point is not None]
    rows = np.array([index[scene.loads[k].block] for k in at])
    points = np.array([scene.loads[k].point for k in at], dtype=float)
    moved = carry(points, rows, angle, shift, origin)
    loads = list(scene.loads)
    for k, point in zip(at, moved.tolist(), strict=True):
        loads[k] = dataclasses.replace(loads[k], point=(point[0], point[1]))
    return tuple(loads)


def moved_ties(scene: Scene, angle: np.ndarray, shift: np.ndarray, origin: np.ndarray) -> tuple[Tie, ...]:
    """The scene's ties with both end points moved by their blocks (a fixed block's end stays:
    its pose is the rest pose)."""
    if not scene.ties:
        return scene.ties
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    ends = []
    for side in ("from", "to"):
        rows = np.array([index[getattr(t, f"{side}_block")] for t in scene.ties])
        points = np.array([getattr(t, f"{side}_point") for t in scene.ties], dtype=float)
        ends.append(carry(points, rows, angle, shift, origin).tolist())
    return tuple(
        dataclasses.replace(t, from_point=(a[0], a[1]), to_point=(b[0], b[1]))
        for t, a, b in zip(scene.ties, *ends, strict=True)
    )


def tie_lengths(ties: tuple[Tie, ...]) -> np.ndarray:
    """Each tie's length between its end points (mm), shape (k,)."""
    if not ties:
        return np.zeros(0)
    a = np.array([t.from_point for t in ties], dtype=float)
    b = np.array([t.to_point for t in ties], dtype=float)
    return np.hypot(b[:, 0] - a[:, 0], b[:, 1] - a[:, 1])


def without_slack(scene: Scene, rest: np.ndarray, tolerance: float) -> tuple[Scene, np.ndarray]:
    """``scene`` (a displaced configuration) without its slack ties, and the rest lengths after it.

    A tie is slack when its length is shorter than its rest length ``rest`` (mm, the longest it
    has been) by more than ``tolerance`` (mm, the round-off of rigid motions); a taut tie's rest
    length becomes its length (a longer one has yielded).  The scene keeps its validation: only
    forces are left out.
    """
    if not scene.ties:
        return scene, rest
    length = tie_lengths(scene.ties)
    taut = length >= rest - tolerance
    after = np.maximum(rest, length)
    if taut.all():
        return scene, after
    kept = dataclasses.replace(
        scene, ties=tuple(t for t, k in zip(scene.ties, taut.tolist(), strict=True) if k), validated=scene.validated
    )
    return kept, after
