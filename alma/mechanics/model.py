"""The mechanical model of Eqs. 1–8, dimensionless and sparse.

Each joint k is represented by its two end points (the contact points of the
yield surface of Eq. 5).  At every contact point the admissible contact forces
on block ``b`` form the Coulomb cone spanned by the two generators
``n ± f t``; with non-negative multipliers ``μ`` this is exactly the yield
domain ``Nᵀσ ≤ 0`` of Eq. 5 (no tension, |M| ≤ N l/2, |T| ≤ f N).

Equilibrium (Eq. 3) reads ``H μ + f_0 + α f_L = 0`` with ``H = -Bᵀ N``-type
matrix of shape (3 n_free, 4 m); its transpose maps block velocities to the
generators' power, so the associative flow rule (Eq. 6) is ``Hᵀ u ≥ 0``.

Units: lengths are divided by ``reference_length`` (√ mean block area) and
forces by the mean weight of a free block plus the mean point load per free
block, so every number the solver sees is
of order one (with the total weight as unit, one block's equilibrium in a wall
of 1000 blocks would be resolved 1000 times less accurately).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from alma.geometry.contacts import Joints, block_areas_and_centroids, find_joints
from alma.geometry.scene import Scene, SceneError
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.forces import Frame, bounded_columns, crushing_capacity, joint_values, point_load_vectors

#: kN per (mm³ · kN/m³)
_MM3_TO_M3 = 1e-9


@dataclass(frozen=True)
class Model:
    """Dimensionless limit-analysis model of a scene (Eqs. 1–8).

    Attributes carry the paper's notation: ``equilibrium`` is the matrix of
    Eq. 3 written on cone generators, ``dead``/``live`` are f_0 and f_L.
    """

    scene: Scene
    joints: Joints
    free_index: np.ndarray  # (n_blocks,) position of each block among the free ones, -1 if fixed
    free_blocks: np.ndarray  # (n_free,) scene index of each free block
    length_scale: float  # mm per model length unit
    force_scale: float  # kN per model force unit (mean weight + mean point load of a free block)
    origin: np.ndarray  # (2,) mm, subtracted before scaling
    centroid: np.ndarray  # (n_free, 2) dimensionless
    weight: np.ndarray  # (n_free,) kN
    friction: np.ndarray  # (m,) tan φ per joint
    normal_part: sp.csc_matrix  # generator columns with f = 0 (the n part)
    tangent_part: sp.csc_matrix  # the ±t part, multiplied by the joint friction
    dead: np.ndarray  # (3 n_free,) f_0, dimensionless
    live: np.ndarray  # (3 n_free,) f_L, dimensionless
    #: Bounded forces (cohesion, ties; :mod:`alma.mechanics.forces`): columns G, 0 ≤ τ ≤ capacity.
    bounded: sp.csc_matrix | None = None
    capacity: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    bounded_labels: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0, dtype=object))
    #: (m,) crushing capacity σ_c l t of each joint (dimensionless; ∞: infinitely strong blocks,
    #: :func:`alma.mechanics.forces.crushing_capacity`); empty when no joint has one.
    crushing: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))

    @property
    def n_bounded(self) -> int:
        """Number of bounded-force columns (0 without cohesion and ties)."""
        return int(self.capacity.shape[0])

    @property
    def crushes(self) -> bool:
        """True when some joint has a finite compressive strength (the conic model applies)."""
        return bool(np.isfinite(self.crushing).any())

    @property
    def n_free(self) -> int:
        return int(self.free_blocks.shape[0])

    @property
    def n_joints(self) -> int:
        return self.joints.count

    @functools.cached_property
    def equilibrium(self) -> sp.csc_matrix:
        """H of ``H μ + f_0 + α f_L = 0`` (columns: joint k, point p, sign ±), built once per model.

        In canonical form (sorted indices): scipy sorts an unsorted matrix in place on first use
        (``abs``, sums), even through a transposed view, so an unsorted H would change under a
        solver's hands and a second solve of the same model would sum in another order.
        """
        scale = np.repeat(self.friction, 4)
        H = (self.normal_part + self.tangent_part @ sp.diags(scale)).tocsc()
        H.sort_indices()  # a fresh matrix of this model's own: sorted before anyone reads it
        return H

    @functools.cached_property
    def contact_points(self) -> ContactPoints:
        """The contact-point form of this model (normal and tangential columns per point, Eq. 2),
        built once per model: this model's own lazy attribute, not a cache a solver writes in."""
        return ContactPoints.build(self)

    def with_friction(self, friction: float) -> Model:
        """The same geometry and joints with a uniform friction coefficient."""
        if not (np.isfinite(friction) and friction >= 0):
            raise SceneError(f"friction must be a finite number >= 0, got {friction}")
        return dataclasses.replace(
            self, scene=self.scene.with_friction(friction), friction=np.full(self.n_joints, float(friction))
        )


def build_model(scene: Scene, joints: Joints | None = None) -> Model:
    """Assemble the sparse model of a validated scene (vectorised, no loop over joints)."""
    joints = find_joints(scene) if joints is None else joints
    blocks = scene.blocks
    fixed = np.array([b.fixed for b in blocks])
    free_blocks = np.flatnonzero(~fixed)
    free_index = np.full(len(blocks), -1)
    free_index[free_blocks] = np.arange(free_blocks.size)

    areas, centroids = block_areas_and_centroids(scene)
    length_scale = float(np.sqrt(areas.mean()))
    all_vertices = np.concatenate([b.vertices for b in blocks])
    origin = 0.5 * (all_vertices.min(axis=0) + all_vertices.max(axis=0))
    centroid_mm = centroids[free_blocks]
    weight = areas[free_blocks] * (scene.thickness * scene.unit_weight * _MM3_TO_M3)
    overrides = [(k, blocks[i].weight) for k, i in enumerate(free_blocks) if blocks[i].weight is not None]
    for k, value in overrides:
        weight[k] = value
    # Forces in units of the mean block weight plus the mean point load per free block: every
    # block's load is of order one, so the solver's absolute tolerances act on each block's
    # equilibrium, not on the whole wall's; and blocks of almost no weight under kN point loads
    # (unit weight 1e-9) are not scaled to loads of 1e12.
    force_scale = float(weight.mean()) + _mean_point_load(scene, free_blocks.size)
    if not force_scale > 0:
        raise SceneError("scene: the free blocks weigh nothing and carry no load; the load multiplier is undefined")
    centroid = (centroid_mm - origin) / length_scale

    friction = joint_values(scene, joints, "friction", scene.friction)
    normal_part, tangent_part = _generator_matrices(joints, free_index, centroid, origin, length_scale)

    frame = Frame(free_index, centroid, origin, length_scale, force_scale)
    dead, live = point_load_vectors(scene, frame, centroids)
    share = weight / force_scale
    dead[0::3] += share * scene.gravity[0]
    dead[1::3] += share * scene.gravity[1]
    if scene.live_self_weight:
        live[0::3] += share * scene.live_load_direction[0]
        live[1::3] += share * scene.live_load_direction[1]
    bounded, capacity, labels = bounded_columns(scene, joints, frame)
    return Model(
        scene=scene,
        joints=joints,
        free_index=free_index,
        free_blocks=free_blocks,
        length_scale=length_scale,
        force_scale=force_scale,
        origin=origin,
        centroid=centroid,
        weight=weight,
        friction=friction,
        normal_part=normal_part,
        tangent_part=tangent_part,
        dead=dead,
        live=live,
        bounded=bounded,
        capacity=capacity,
        bounded_labels=labels,
        crushing=crushing_capacity(scene, joints, force_scale),
    )


def _mean_point_load(scene: Scene, n_free: int) -> float:
    """Σ (|dead| + |live|) of the scene's point loads per free block (kN)."""
    if not scene.loads:
        return 0.0
    forces = np.array([(*load.dead, *load.live) for load in scene.loads], dtype=float).reshape(-1, 2, 2)
    return float(np.hypot(forces[..., 0], forces[..., 1]).sum()) / max(n_free, 1)


def _generator_matrices(
    joints: Joints, free_index: np.ndarray, centroid: np.ndarray, origin: np.ndarray, length_scale: float
) -> tuple[sp.csc_matrix, sp.csc_matrix]:
    """Columns of the normal part n and tangential part ±t of the generators n ± f t.

    Column 4k + 2p + s is joint k, end point p (0 start, 1 end), sign s (0: +t, 1: -t).
    Each column holds the force on block b and its opposite on block a, with moments
    about the block centroids (Eq. 3 written on contact points).
    """
    m = joints.count
    n_free = centroid.shape[0]
    points = np.stack([joints.start, joints.end], axis=1)  # (m, 2, 2)
    points = (points - origin) / length_scale
    col_point = np.repeat(points.reshape(-1, 2), 2, axis=0)  # (4m, 2)
    col_joint = np.repeat(np.arange(m), 4)
    sign = np.tile([1.0, -1.0], 2 * m)
    normal = joints.normal[col_joint]
    tangent = joints.tangent[col_joint] * sign[:, None]

    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    vals_n: list[np.ndarray] = []
    vals_t: list[np.ndarray] = []
    columns = np.arange(4 * m)
    for side, block in ((1.0, joints.block_b), (-1.0, joints.block_a)):
        free = free_index[block[col_joint]]
        mask = free >= 0
        c = columns[mask]
        r = col_point[mask] - centroid[free[mask]]
        for vec, vals in ((normal[mask], vals_n), (tangent[mask], vals_t)):
            moment = r[:, 0] * vec[:, 1] - r[:, 1] * vec[:, 0]
            vals.append(side * np.concatenate([vec[:, 0], vec[:, 1], moment]))
        rows.append(np.concatenate([3 * free[mask], 3 * free[mask] + 1, 3 * free[mask] + 2]))
        cols.append(np.tile(c, 3))
    rows_a, cols_a = np.concatenate(rows), np.concatenate(cols)
    shape = (3 * n_free, 4 * m)
    normal_part = sp.csc_matrix((np.concatenate(vals_n), (rows_a, cols_a)), shape=shape)
    tangent_part = sp.csc_matrix((np.concatenate(vals_t), (rows_a, cols_a)), shape=shape)
    return normal_part, tangent_part
