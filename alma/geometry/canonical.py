"""The canonical drawing of a scene: one structure, one scene, however it was written.

The friction search of Eq. 9 is non-convex: which local minimum it ends in can turn on the order
of the LP's columns and on the last bits of its data.  It therefore runs on the scene's
canonical form, which depends on the structure only:

- the frame: gravity points along −y and the live load has a non-negative x component (a mirror
  image otherwise); the origin is the lower-left corner of the bounding box;
- the vertices: in units of the blocks' size (√ mean free-block area), repeated and collinear
  ones dropped, counter-clockwise, starting at the lowest (then leftmost) one;
- the blocks: ordered by their centroid (y, then x).

Positions are compared on a binary grid of :attr:`CanonicalSettings.grid_bits` below the blocks'
size, so that the round-off of a translation, rotation or change of units does not decide an
order; the positions themselves are kept as computed (the model built from them is rounded to
fewer bits: :mod:`alma.mechanics.canonical`), so that a mechanism carried back to the drawing
keeps its hinges where they are.

Point loads, ties and settlements move with their blocks; block ids, materials and joint
overrides are kept.  :class:`CanonicalFrame` maps motions back to the drawing's frame.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from alma.floats import times
from alma.geometry.contacts import Joints
from alma.geometry.loads import PointLoad, Settlement, Tie
from alma.geometry.scene import Scene, cyclic, polygon_area, polygon_centroid


@dataclass(frozen=True)
class CanonicalSettings:
    """Tuned numbers of the canonical drawing."""

    #: Orders compare positions on a grid 2^-grid_bits × the blocks' size (1e-6): far below any
    #: real difference of place, and a round-off of 1e-16 relative lands on another grid point
    #: once in ~1e8.
    grid_bits: int = 20
    #: A vertex is collinear with its neighbours when the triangle they span is below this
    #: fraction of the squared longer edge (a drawing's "same line", not a real corner).
    collinear: float = 1e-12
    #: The live load counts as vertical (no mirror is chosen) below this x component.
    vertical: float = 1e-9


@dataclass(frozen=True)
class CanonicalFrame:
    """x_canonical = (matrix @ x + offset) / unit, x in the drawing's mm; ``order[j]``: the drawing's
    index of canonical block j."""

    matrix: np.ndarray
    offset: np.ndarray
    unit: float  # mm per canonical length unit (√ mean free-block area)
    order: np.ndarray

    @property
    def handedness(self) -> float:
        """+1 for a rotation, −1 for a mirror image (the sign of rotations and moments)."""
        return float(np.sign(np.linalg.det(self.matrix)))


def canonical_scene(
    scene: Scene, settings: CanonicalSettings = CanonicalSettings(), *, check: bool = True
) -> tuple[Scene, CanonicalFrame]:
    """The canonical form of ``scene`` (module docstring) and the frame that maps back to it.

    Lengths are in units of √(mean free-block area), forces stay in kN: the unit weight is
    multiplied by the unit², the cohesion by the unit, so every weight and capacity is kept.
    ``check``: validate the canonical drawing (SPEC §2); False where the joints are given with the
    model, not found on the drawing (a displaced configuration of ``alma.push`` whose blocks touch
    at points only, which the drawing's joint search does not see); it is then marked validated.
    """
    matrix = _frame_matrix(scene, settings)
    turned = [times(b.vertices, matrix.T) for b in scene.blocks]
    corner = np.concatenate(turned).min(axis=0)
    # Areas about each polygon's own first vertex: far from the origin the shoelace sum cancels.
    free = [polygon_area(v - v[0]) for v, b in zip(turned, scene.blocks, strict=True) if not b.fixed] or [
        polygon_area(turned[0] - turned[0][0])
    ]
    unit = float(np.sqrt(np.mean(np.abs(free))))
    step = 2.0**-settings.grid_bits
    frame = CanonicalFrame(matrix, -corner, unit, np.zeros(0, dtype=int))
    blocks = [
        dataclasses.replace(
            b, vertices=_clean((v - corner) / unit, step, settings), settlement=_settlement(b.settlement, frame)
        )
        for b, v in zip(scene.blocks, turned, strict=True)
    ]
    frame = dataclasses.replace(frame, order=_block_order(blocks, step))
    canonical = dataclasses.replace(
        scene,
        blocks=tuple(blocks[i] for i in frame.order),
        gravity=(0.0, -1.0),
        live_load_direction=_unit(times(np.asarray(scene.live_load_direction, dtype=float), matrix.T)),
        unit_weight=scene.unit_weight * unit**2,
        cohesion=scene.cohesion * unit,
        joint_overrides=tuple(
            dataclasses.replace(o, cohesion=None if o.cohesion is None else o.cohesion * unit)
            for o in scene.joint_overrides
        ),
        loads=tuple(_load(load, frame) for load in scene.loads),
        ties=tuple(_tie(tie, frame) for tie in scene.ties),
        validated=not check,
    )
    return (canonical.validate() if check else canonical), frame


def _unit(vector: np.ndarray) -> tuple[float, float]:
    norm = float(np.hypot(*vector))
    return (float(vector[0] / norm), float(vector[1] / norm)) if norm > 0 else (0.0, 0.0)


def _frame_matrix(scene: Scene, settings: CanonicalSettings) -> np.ndarray:
    """The rotation taking gravity to −y, followed by the mirror that makes the live load's x ≥ 0."""
    up = -np.asarray(_unit(np.asarray(scene.gravity, dtype=float)))
    rotation = np.array([[up[1], -up[0]], [up[0], up[1]]])
    live = np.asarray(scene.live_load_direction, dtype=float) if scene.live_self_weight else np.zeros(2)
    live = live + sum((np.asarray(load.live, dtype=float) for load in scene.loads), np.zeros(2))
    turned = times(live, rotation.T)
    if turned[0] < -settings.vertical * max(float(np.hypot(*turned)), 1e-300):
        rotation = np.diag([-1.0, 1.0]) @ rotation
    return rotation


def _clean(vertices: np.ndarray, step: float, settings: CanonicalSettings) -> np.ndarray:
    """Counter-clockwise, without repeated or collinear vertices, from the lowest-leftmost one
    (compared on the grid ``step``)."""
    if polygon_area(vertices) < 0:
        vertices = vertices[::-1]
    distinct = ~np.all(vertices == cyclic(vertices, 1), axis=1)
    keep = vertices[distinct] if distinct.sum() >= 3 else vertices
    a, b = keep - cyclic(keep, 1), cyclic(keep, -1) - keep
    cross = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    corner = cross > settings.collinear * np.maximum((a**2).sum(axis=1), (b**2).sum(axis=1))
    if corner.sum() >= 3:
        keep = keep[corner]
    grid = np.round(keep / step)
    first = np.lexsort((grid[:, 0], grid[:, 1]))[0]
    return cyclic(keep, -int(first))


def _block_order(blocks: list, step: float) -> np.ndarray:
    """Blocks by centroid y, then x, then area, then the first vertex (compared on the grid ``step``)."""
    keys = np.array(
        [[*polygon_centroid(b.vertices)[::-1], polygon_area(b.vertices), *b.vertices[0][::-1]] for b in blocks]
    )
    return np.lexsort(np.round(keys / step).T[::-1])


def _point(point: tuple[float, float], frame: CanonicalFrame) -> tuple[float, float]:
    x = (times(np.asarray(point, dtype=float), frame.matrix.T) + frame.offset) / frame.unit
    return float(x[0]), float(x[1])


def _vector(vector: tuple[float, float], frame: CanonicalFrame) -> tuple[float, float]:
    x = times(np.asarray(vector, dtype=float), frame.matrix.T)
    return float(x[0]), float(x[1])


def _load(load: PointLoad, frame: CanonicalFrame) -> PointLoad:
    point = None if load.point is None else _point(load.point, frame)  # None: the block's centroid
    return dataclasses.replace(load, point=point, dead=_vector(load.dead, frame), live=_vector(load.live, frame))


def _tie(tie: Tie, frame: CanonicalFrame) -> Tie:
    return dataclasses.replace(tie, from_point=_point(tie.from_point, frame), to_point=_point(tie.to_point, frame))


def _settlement(settlement: Settlement | None, frame: CanonicalFrame) -> Settlement | None:
    if settlement is None:
        return None
    about = _point(settlement.about, frame)
    translation = np.asarray(_vector(settlement.translation, frame)) / frame.unit
    return Settlement(
        translation=(float(translation[0]), float(translation[1])),
        rotation=frame.handedness * settlement.rotation,
        about=about,
    )


def canonical_joints(
    joints: Joints, frame: CanonicalFrame, settings: CanonicalSettings = CanonicalSettings()
) -> Joints:
    """A model's own joints (a displaced configuration's, with its point contacts) in the
    canonical drawing of ``frame``: blocks renumbered, points and normals moved with the frame.

    Each joint is written with block_a < block_b (its normal from a to b) and its start before
    its end along the tangent; the joints are ordered by (block_a, block_b, start), positions
    compared on the grid of :attr:`CanonicalSettings.grid_bits`, so that neither the drawing's
    block order nor its joint order decides the canonical one.
    """
    rank = np.empty_like(frame.order)
    rank[frame.order] = np.arange(frame.order.size)
    a, b = rank[joints.block_a], rank[joints.block_b]
    start = (times(joints.start, frame.matrix.T) + frame.offset) / frame.unit
    end = (times(joints.end, frame.matrix.T) + frame.offset) / frame.unit
    flip = a > b
    normal = np.where(flip[:, None], -1.0, 1.0) * times(joints.normal, frame.matrix.T)
    a, b = np.where(flip, b, a), np.where(flip, a, b)
    tangent = np.column_stack([-normal[:, 1], normal[:, 0]])
    back = ((end - start) * tangent).sum(axis=1) < 0
    start, end = np.where(back[:, None], end, start), np.where(back[:, None], start, end)
    grid = np.round(start / 2.0**-settings.grid_bits)
    order = np.lexsort((grid[:, 1], grid[:, 0], b, a))
    return Joints(a[order], b[order], start[order], end[order], normal[order], joints.warnings)
