"""Forces beyond the contact cones, as dimensionless block vectors and columns.

- :func:`point_load_vectors`: the point loads of a scene (SPEC §2 ``loads``) into f₀ and f_L;
- :func:`bounded_columns`: columns G with capacities for the forces that are bounded on both
  sides instead of lying in a cone: the cohesive shear of a joint (|τ| ≤ c l t, two columns ±t
  of capacity c l t each) and the tension of a tie (0 ≤ F ≤ strength, one column).

Equilibrium (Eq. 3) then reads H μ + G τ + f₀ + α f_L = 0 with μ ≥ 0 and 0 ≤ τ ≤ capacity, and
for any mechanism u the work of the bounded forces is at most Σ capacity · max(0, −Gᵀu): the
dissipation c l t |γ| of cohesion and strength · max(0, elongation rate) of a tie.

Units as in :mod:`alma.mechanics.model`: lengths per ``length_scale``, forces per
``force_scale`` (kN), points relative to ``origin`` (mm).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from alma.geometry.contacts import Joints
from alma.geometry.scene import Scene, SceneError

#: kN per (kPa · mm²): cohesion c (kN/m²) times joint length and thickness (mm).
_KPA_MM2_TO_KN = 1e-6
#: kN per (MPa · mm²): a compressive strength σ_c (N/mm²) times joint length and thickness (mm).
_MPA_MM2_TO_KN = 1e-3


@dataclass(frozen=True)
class Frame:
    """Where the model's dimensionless coordinates come from."""

    free_index: np.ndarray  # (n_blocks,) position among the free blocks, -1 if fixed
    centroid: np.ndarray  # (n_free, 2) dimensionless
    origin: np.ndarray  # (2,) mm
    length_scale: float  # mm
    force_scale: float  # kN

    def assemble(
        self,
        column: np.ndarray,
        blocks: np.ndarray,
        points_mm: np.ndarray,
        forces: np.ndarray,
        n_columns: int,
        *,
        in_kn: bool = True,
    ) -> sp.csc_matrix:
        """Sparse (3 n_free, n_columns): entry rows for force ``forces[i]`` acting at
        ``points_mm[i]`` on scene block ``blocks[i]``, in column ``column[i]``; forces on fixed
        blocks are dropped (a support takes them).  ``in_kn``: the forces are in kN (else they
        are already dimensionless, e.g. unit directions that a multiplier scales)."""
        free = self.free_index[blocks]
        keep = free >= 0
        free, column = free[keep], column[keep]
        r = (points_mm[keep] - self.origin) / self.length_scale - self.centroid[free]
        f = forces[keep] / (self.force_scale if in_kn else 1.0)
        moment = r[:, 0] * f[:, 1] - r[:, 1] * f[:, 0]
        rows = np.concatenate([3 * free, 3 * free + 1, 3 * free + 2])
        vals = np.concatenate([f[:, 0], f[:, 1], moment])
        n = 3 * int(self.centroid.shape[0])
        return sp.csc_matrix((vals, (rows, np.tile(column, 3))), shape=(n, n_columns))


def point_load_vectors(scene: Scene, frame: Frame, centroid_mm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The scene's point loads as dimensionless (dead, live) block vectors (3 n_free each).

    A load without ``point`` acts at its block's centroid (``centroid_mm``, of every block).
    """
    n = 3 * int(frame.centroid.shape[0])
    if not scene.loads:
        return np.zeros(n), np.zeros(n)
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    blocks = np.array([index[load.block] for load in scene.loads])
    points = np.array(
        [load.point if load.point is not None else centroid_mm[index[load.block]] for load in scene.loads], dtype=float
    )
    column = np.zeros(len(scene.loads), dtype=int)
    out = []
    for forces in (
        np.array([load.dead for load in scene.loads], dtype=float),
        np.array([load.live for load in scene.loads], dtype=float),
    ):
        out.append(np.asarray(frame.assemble(column, blocks, points, forces, 1).todense()).ravel())
    return out[0], out[1]


def joint_values(scene: Scene, joints: Joints, name: str, default: float) -> np.ndarray:
    """A joint property (``"friction"``, ``"cohesion"``, ``"compressive_strength"``) of every joint: ``default``, or a
    joint override's value; an override between blocks that do not touch is an error."""
    values = np.full(joints.count, float(default))
    if scene.joint_overrides:
        index = {b.id: i for i, b in enumerate(scene.blocks)}
        lo, hi = np.minimum(joints.block_a, joints.block_b), np.maximum(joints.block_a, joints.block_b)
        for override in scene.joint_overrides:  # a handful of user overrides, not a hot path
            i, j = sorted(index[k] for k in override.blocks)
            hit = (lo == i) & (hi == j)
            if not hit.any():
                raise SceneError(f"joint {list(override.blocks)}: these blocks do not touch")
            if getattr(override, name) is not None:
                values[hit] = getattr(override, name)
    return values


def crushing_capacity(scene: Scene, joints: Joints, force_scale: float) -> np.ndarray:
    """Each joint's crushing capacity σ_c l t (SPEC §2 ``compressive_strength``, MPa) in units of
    ``force_scale`` (kN): the largest normal force, carried by a stress block over the whole
    length.  ∞ for a joint without a strength; an empty array when no joint has one, so that a
    scene without the key builds the model it always did."""
    default = np.inf if scene.compressive_strength is None else float(scene.compressive_strength)
    strength = joint_values(scene, joints, "compressive_strength", default)
    if not np.isfinite(strength).any():
        return np.zeros(0)
    return strength * joints.length * scene.thickness * (_MPA_MM2_TO_KN / force_scale)


def bounded_columns(scene: Scene, joints: Joints, frame: Frame) -> tuple[sp.csc_matrix, np.ndarray, np.ndarray]:
    """G, capacities (dimensionless) and labels of the bounded forces (module docstring).

    Labels: ``j<k>+`` / ``j<k>-`` for joint k's cohesive shear along ±t (on block b, the
    opposite on block a, at the joint's centre: a shear along the joint line has the same moment
    wherever it acts on it), ``tie:<id>`` for a tie.
    """
    cohesion = joint_values(scene, joints, "cohesion", scene.cohesion)
    cohesive = np.flatnonzero(cohesion > 0)
    q_c = 2 * cohesive.size
    n_cols = q_c + len(scene.ties)
    capacity = np.zeros(n_cols)
    capacity[:q_c] = np.repeat(cohesion[cohesive] * joints.length[cohesive] * scene.thickness * _KPA_MM2_TO_KN, 2)
    labels = [f"j{k}{s}" for k in cohesive.tolist() for s in "+-"] + [f"tie:{t.id}" for t in scene.ties]
    pieces_col, pieces_block, pieces_point, pieces_force = [], [], [], []
    if q_c:
        col = np.arange(q_c)
        joint = np.repeat(cohesive, 2)
        sign = np.tile([1.0, -1.0], cohesive.size)
        shear = joints.tangent[joint] * sign[:, None]
        centre = joints.centre[joint]
        pieces_col += [col, col]
        pieces_block += [joints.block_b[joint], joints.block_a[joint]]
        pieces_point += [centre, centre]
        pieces_force += [shear, -shear]
    if scene.ties:
        index = {b.id: i for i, b in enumerate(scene.blocks)}
        a = np.array([t.from_point for t in scene.ties], dtype=float)
        b = np.array([t.to_point for t in scene.ties], dtype=float)
        d = (b - a) / np.hypot(*(b - a).T)[:, None]  # tension pulls the "from" end towards "to"
        col = q_c + np.arange(len(scene.ties))
        pieces_col += [col, col]
        pieces_block += [
            np.array([index[t.from_block] for t in scene.ties]),
            np.array([index[t.to_block] for t in scene.ties]),
        ]
        pieces_point += [a, b]
        pieces_force += [d, -d]
        capacity[q_c:] = [t.strength for t in scene.ties]
    if not n_cols:
        return sp.csc_matrix((3 * frame.centroid.shape[0], 0)), capacity, np.array(labels, dtype=object)
    G = frame.assemble(
        np.concatenate(pieces_col),
        np.concatenate(pieces_block),
        np.concatenate(pieces_point),
        np.concatenate(pieces_force),
        n_cols,
        in_kn=False,
    )
    return G, capacity / frame.force_scale, np.array(labels, dtype=object)
