"""The settlement capacity's motion: the settling supports, the scene they displace, and the crack pattern.

A settling support moves by x ↦ R(s r)(x − c) + c + s t (mm, rad) at the factor s;
:func:`_bodies` gives the bodies of one step (the settlement mechanism's moving free blocks and
the supports), :func:`_cracked` the joints whose sides move apart in it.  The steps are
:mod:`alma.push.settlement`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import cast

import numpy as np

from alma.geometry.contacts import Joints, block_areas_and_centroids
from alma.geometry.loads import Settlement
from alma.geometry.scene import Scene
from alma.push.motion import Bodies, Pose, displaced
from alma.results.joints import MOTION_TOLERANCE
from alma.settle import SettleError, SettlementResult


@dataclass(frozen=True)
class _Supports:
    """The settling supports: scene index, translation t (mm), rotation r (rad), point c (mm)."""

    index: np.ndarray  # (k,)
    translation: np.ndarray  # (k, 2)
    rotation: np.ndarray  # (k,)
    about: np.ndarray  # (k, 2)
    control: int  # scene index of the control support
    measure: float  # |t| (mm) or |r| (rad) of the control support: abscissa per unit s
    unit: str  # "mm" or "rad"


def _supports(scene: Scene) -> _Supports:
    """The settling supports and the control one (largest translation, then rotation; ties by id)."""
    rows = [(i, b.id, b.settlement) for i, b in enumerate(scene.blocks) if b.settlement is not None]
    if not rows:
        raise SettleError(
            "no support of the scene has a 'settlement' (a fixed block's prescribed motion, "
            "SPEC §2): there is no settlement to grow"
        )
    index = np.array([i for i, _, _ in rows])
    t = np.array([m.translation for _, _, m in rows], dtype=np.float64).reshape(-1, 2)
    r = np.array([m.rotation for _, _, m in rows], dtype=np.float64)
    c = np.array([m.about for _, _, m in rows], dtype=np.float64).reshape(-1, 2)
    size = np.hypot(t[:, 0], t[:, 1])
    ids = [k for _, k, _ in rows]
    unit, magnitude = ("mm", size) if size.max() > 0 else ("rad", np.abs(r))
    if not magnitude.max() > 0:
        raise SettleError("every 'settlement' of the scene is zero: there is no settlement to grow")
    best = min(range(len(rows)), key=lambda k: (-magnitude[k], ids[k]))
    return _Supports(index, t, r, c, int(index[best]), float(magnitude[best]), unit)


def _placed(scene0: Scene, pose: Pose, supports: _Supports, s: float) -> Scene:
    """The scene displaced by ``pose``, each settling support's ``about`` carried to c + s t (its
    settlement there is the rate of the motion at s)."""
    here = displaced(scene0, pose)
    blocks = list(here.blocks)
    for k, i in enumerate(supports.index):  # the few settling supports, not the blocks' loop
        about = supports.about[k] + s * supports.translation[k]
        moved = dataclasses.replace(cast(Settlement, blocks[i].settlement), about=(float(about[0]), float(about[1])))
        blocks[i] = dataclasses.replace(blocks[i], settlement=moved)
    return dataclasses.replace(here, blocks=tuple(blocks), validated=True)  # a rigid motion of a validated geometry


def _touching(scene: Scene, joints: Joints) -> Scene:
    """``scene`` keeping the joint overrides of the pairs that still touch: a block that moved
    off its neighbour has no joint there for the override to name (not a mistake of the scene)."""
    if not scene.joint_overrides:
        return scene
    ids = scene.block_ids
    pairs = {frozenset((ids[a], ids[b])) for a, b in zip(joints.block_a.tolist(), joints.block_b.tolist(), strict=True)}
    kept = tuple(o for o in scene.joint_overrides if frozenset(o.blocks) in pairs)
    if len(kept) == len(scene.joint_overrides):
        return scene
    return dataclasses.replace(scene, joint_overrides=kept, validated=True)  # fewer overrides of a validated scene


def _bodies(scene: Scene, crack: SettlementResult | None, sup: _Supports, s: float, length: float) -> Bodies:
    """The moving free blocks of the settlement mechanism (each its own body, velocity at its
    centroid per unit s) and the settling supports (velocity t at c + s t, rotation rate r)."""
    n = len(scene.blocks)
    u = np.zeros((n, 3))
    if crack is not None and crack.blocks:
        index = {b.id: i for i, b in enumerate(scene.blocks)}
        u[[index[b.id] for b in crack.blocks]] = np.array([b.u for b in crack.blocks], dtype=float)
    own = float((np.hypot(*sup.translation.T) + np.abs(sup.rotation) * length).max())
    # a free block moves as the joints' states read motion: above this fraction of the largest
    moving = np.hypot(u[:, 0], u[:, 1]) + np.abs(u[:, 2]) * length > MOTION_TOLERANCE * own
    moving[sup.index] = False
    free = np.flatnonzero(moving)
    of_block = np.full(n, -1)
    of_block[free] = np.arange(free.size)
    of_block[sup.index] = free.size + np.arange(sup.index.size)
    centroid = block_areas_and_centroids(scene)[1]
    centre = np.vstack([centroid[free], sup.about + s * sup.translation])
    omega = np.concatenate([u[free, 2], sup.rotation])
    velocity = np.vstack([u[free, :2], sup.translation])
    return Bodies(of_block, centre, omega, velocity)


def _cracked(scene: Scene, joints: Joints, bodies: Bodies, length: float) -> tuple[tuple[str, str], ...]:
    """The crack pattern: the joints whose two sides move apart in the settlement mechanism (a
    relative velocity at either end: hinging, opening or sliding), as sorted id pairs."""
    if bodies.count == 0 or joints.count == 0:
        return ()
    ends = np.concatenate([joints.start, joints.end])
    a, b = np.tile(joints.block_a, 2), np.tile(joints.block_b, 2)
    rel = np.hypot(*(bodies.velocity_at(b, ends) - bodies.velocity_at(a, ends)).T)
    scale = max(float(np.abs(bodies.velocity).max(initial=0.0)), 1e-300)
    moving = (rel > MOTION_TOLERANCE * scale).reshape(2, -1).any(axis=0)
    # a hinge's two sides meet at the point and turn at different rates
    omega = np.where(bodies.of_block >= 0, bodies.omega[np.maximum(bodies.of_block, 0)], 0.0)
    moving |= np.abs(omega[joints.block_b] - omega[joints.block_a]) * length > MOTION_TOLERANCE * scale
    ids = scene.block_ids
    return tuple(
        sorted(
            {
                tuple(sorted((ids[i], ids[j])))
                for i, j in zip(joints.block_a[moving].tolist(), joints.block_b[moving].tolist(), strict=True)
            }
        )
    )
