"""The power of the supports' settlements on each force of the settlement LP (h and g of :mod:`alma.settle`).

A settling support moves rigidly, v_s(p) = d + r × (p − c); the power of a generator or a bounded
force is its unit force times the relative velocity this motion gives its points.  Dimensionless
(velocities per ``length_scale``; settlements in mm and rad).
"""

from __future__ import annotations

import numpy as np

from alma.geometry.scene import Scene
from alma.mechanics.forces import joint_values
from alma.mechanics.model import Model


def support_power(model: Model) -> np.ndarray:
    """h: for each generator column of H, the power of its force under the supports' settlements.

    A generator of joint k at point p is the force n ± f t on block b (and its opposite on
    block a); with supports moving rigidly, its power is (n ± f t) · (v_b(p) − v_a(p)) over the
    supports among a and b (:func:`support_relative`).  Dimensionless.
    """
    rel = support_relative(model)
    f = model.friction[:, None]
    h = np.stack([rel[..., 0] + f * rel[..., 1], rel[..., 0] - f * rel[..., 1]], axis=2)  # (m, point, ±)
    return h.ravel()


def bounded_support_power(model: Model) -> np.ndarray:
    """g: for each bounded-force column of G (:func:`alma.mechanics.forces.bounded_columns`: the
    cohesive shears ±t of each cohesive joint, then the ties), the power of its unit force under
    the supports' settlements, per ``length_scale``.  Dimensionless."""
    scene, joints = model.scene, model.joints
    if not model.n_bounded:
        return np.zeros(0)
    cohesive = np.flatnonzero(joint_values(scene, joints, "cohesion", scene.cohesion) > 0)
    centre = joints.centre[cohesive]
    slip = np.einsum(
        "kx,kx->k",
        _support_velocity(model, joints.block_b[cohesive], centre)
        - _support_velocity(model, joints.block_a[cohesive], centre),
        joints.tangent[cohesive],
    )
    shear = np.stack([slip, -slip], axis=1).ravel()  # columns +t, −t of each cohesive joint
    if not scene.ties:
        return shear / model.length_scale
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    a = np.array([t.from_point for t in scene.ties], dtype=float)
    b = np.array([t.to_point for t in scene.ties], dtype=float)
    d = (b - a) / np.hypot(*(b - a).T)[:, None]  # the tie's pull on its "from" end
    v_from = _support_velocity(model, np.array([index[t.from_block] for t in scene.ties]), a)
    v_to = _support_velocity(model, np.array([index[t.to_block] for t in scene.ties]), b)
    tie = np.einsum("kx,kx->k", v_from - v_to, d)
    return np.concatenate([shear, tie]) / model.length_scale


def _support_velocity(model: Model, block: np.ndarray, point: np.ndarray) -> np.ndarray:
    """(k, 2) mm: the settlement velocity d + r × (p − c) of scene block ``block[i]`` at
    ``point[i]`` (zero for a block without settlement)."""
    moves, centre = _settlement_table(model.scene)
    d, r, c = moves[block, :2], moves[block, 2:3], centre[block]
    arm = point - c
    return d + r * np.stack([-arm[:, 1], arm[:, 0]], axis=-1)


def _settlement_table(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """(n_blocks, 3) settlements (d_x, d_y, r) and (n_blocks, 2) their ``about`` points."""
    moves = np.zeros((len(scene.blocks), 3))
    centre = np.zeros((len(scene.blocks), 2))
    for i, block in enumerate(scene.blocks):  # the few settling supports, not the blocks' loop
        if block.settlement is not None:
            moves[i] = (*block.settlement.translation, block.settlement.rotation)
            centre[i] = block.settlement.about
    return moves, centre


def support_relative(model: Model) -> np.ndarray:
    """(m, point, (normal, tangent)): relative velocity v_b − v_a of each joint's contact points
    due to the supports' settlements (v_s(p) = d + r × (p − c)), per ``length_scale``."""
    joints = model.joints
    moves, centre = _settlement_table(model.scene)  # d_x, d_y, r; about
    points = np.stack([joints.start, joints.end], axis=1)  # (m, 2, 2) mm

    def velocity(block: np.ndarray) -> np.ndarray:  # (m, 2, 2): support velocity at each point
        d, r, c = moves[block, None, :2], moves[block, None, 2:3], centre[block, None, :]
        arm = points - c
        return d + r * np.stack([-arm[..., 1], arm[..., 0]], axis=-1)

    relative = (velocity(joints.block_b) - velocity(joints.block_a)) / model.length_scale
    return np.stack(
        [np.einsum("mpx,mx->mp", relative, joints.normal), np.einsum("mpx,mx->mp", relative, joints.tangent)], axis=2
    )
