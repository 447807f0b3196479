"""Joints: contacts between collinear, facing, overlapping block edges.

Every edge of every block is reduced to a line key (direction of its outward
normal modulo π, signed distance of its line from the origin) and a position
along the line.  Facing edges of two blocks share the line key and have
opposite normals; a k-d tree on the scaled keys finds the candidate pairs in
one vectorised query, so no Python loop runs over blocks or joints.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

if TYPE_CHECKING:  # pragma: no cover
    from .scene import Scene

#: Relative tolerances (of the scene's reference length / radians) for contact detection.
DISTANCE_TOLERANCE = 1e-9
ANGLE_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Edges:
    """All block edges of a scene, flattened (one row per edge)."""

    block: np.ndarray  # (E,) block index
    start: np.ndarray  # (E, 2)
    end: np.ndarray  # (E, 2)


@dataclass(frozen=True)
class Joints:
    """Joints of a scene (one row per joint).

    ``normal`` points from block ``block_a`` into block ``block_b``; ``tangent``
    is ``normal`` turned +90°; ``start`` and ``end`` are the two end points of
    the contact segment (the two contact points of the yield surface, Eq. 5).
    """

    block_a: np.ndarray  # (m,) int
    block_b: np.ndarray  # (m,) int
    start: np.ndarray  # (m, 2)
    end: np.ndarray  # (m, 2)
    normal: np.ndarray  # (m, 2)

    @property
    def count(self) -> int:
        return int(self.block_a.shape[0])

    @property
    def tangent(self) -> np.ndarray:
        return np.column_stack([-self.normal[:, 1], self.normal[:, 0]])

    @property
    def length(self) -> np.ndarray:
        """Joint length l^k of Eq. 5 (mm)."""
        return np.hypot(*(self.end - self.start).T)

    @property
    def centre(self) -> np.ndarray:
        return 0.5 * (self.start + self.end)


def reference_length(scene: "Scene") -> float:
    """√(mean block area): the length that makes the model dimensionless."""
    return float(np.sqrt(block_areas_and_centroids(scene)[0].mean()))


def block_areas_and_centroids(scene: "Scene") -> tuple[np.ndarray, np.ndarray]:
    """Areas (n,) and centroids (n, 2) of all blocks, vectorised over the flattened edges."""
    edges = scene_edges(scene)
    first = np.concatenate([[0], np.flatnonzero(np.diff(edges.block)) + 1])
    origin = edges.start[first][edges.block]  # each polygon about its first vertex, for accuracy
    p, q = edges.start - origin, edges.end - origin
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    area = 0.5 * np.add.reduceat(cross, first)
    cx = np.add.reduceat((p[:, 0] + q[:, 0]) * cross, first) / (6 * area)
    cy = np.add.reduceat((p[:, 1] + q[:, 1]) * cross, first) / (6 * area)
    return area, origin[first] + np.column_stack([cx, cy])


def scene_edges(scene: "Scene") -> Edges:
    counts = np.array([len(b.vertices) for b in scene.blocks])
    start = np.concatenate([b.vertices for b in scene.blocks])
    # next vertex of each polygon: roll within each block, vectorised via offsets
    index = np.arange(start.shape[0])
    first = np.repeat(np.cumsum(counts) - counts, counts)
    nxt = np.where(index + 1 - first < np.repeat(counts, counts), index + 1, first)
    return Edges(block=np.repeat(np.arange(len(counts)), counts), start=start, end=start[nxt])


def find_joints(scene: "Scene") -> Joints:
    """All joints of the scene (contacts of positive length between two blocks).

    Joints between two fixed blocks carry nothing and are dropped.
    """
    edges = scene_edges(scene)
    lref = reference_length(scene)
    vec = edges.end - edges.start
    length = np.hypot(vec[:, 0], vec[:, 1])
    direction = vec / length[:, None]
    outward = np.column_stack([direction[:, 1], -direction[:, 0]])  # CCW polygon: outward = right of edge

    # Canonical line: unit normal d with angle in [0, π); its sign s relates to the outward normal.
    angle = np.mod(np.arctan2(outward[:, 1], outward[:, 0]), np.pi)
    angle = np.where(angle >= np.pi, 0.0, angle)  # mod may round up to π
    d = np.column_stack([np.cos(angle), np.sin(angle)])  # ±outward
    midpoint = 0.5 * (edges.start + edges.end)
    offset = (midpoint * d).sum(axis=1)
    along = midpoint[:, 0] * -d[:, 1] + midpoint[:, 1] * d[:, 0]

    tol_len = DISTANCE_TOLERANCE * lref
    facing_sign = np.where((outward * d).sum(axis=1) > 0, 1.0, -1.0)  # outward = ±d
    # Lines near angle 0 ≡ π are duplicated on the other side of the wrap so the tree sees them close.
    wrap = angle > np.pi - 1e3 * ANGLE_TOLERANCE
    ids = np.concatenate([np.arange(len(angle)), np.flatnonzero(wrap)])
    key_angle = np.concatenate([angle, angle[wrap] - np.pi])
    key_offset = np.concatenate([offset, -offset[wrap]])
    key_along = np.concatenate([along, -along[wrap]])
    key_sign = np.concatenate([facing_sign, -facing_sign[wrap]])
    reach = float(length.max())
    points = np.column_stack([
        key_angle * (reach / ANGLE_TOLERANCE),
        key_offset * (reach / tol_len),
        key_along,
    ])
    # Facing edges have opposite outward normals: query only across the two orientations.
    plus, minus = np.flatnonzero(key_sign > 0), np.flatnonzero(key_sign < 0)
    found = cKDTree(points[plus]).sparse_distance_matrix(cKDTree(points[minus]), reach, p=np.inf,
                                                           output_type="ndarray")
    if found.size == 0:
        return _empty_joints()
    i, j = ids[plus[found["i"]]], ids[minus[found["j"]]]
    keep = edges.block[i] != edges.block[j]
    i, j = i[keep], j[keep]
    # dedupe pairs created by the wrap duplicates
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    _, unique = np.unique(lo * (len(angle) + 1) + hi, return_index=True)
    i, j = lo[unique], hi[unique]

    # Exact collinearity: both ends of edge j lie on the line of edge i.
    n_i = outward[i]
    dist_start = ((edges.start[j] - edges.start[i]) * n_i).sum(axis=1)
    dist_end = ((edges.end[j] - edges.start[i]) * n_i).sum(axis=1)
    collinear = (np.abs(dist_start) <= 10 * tol_len) & (np.abs(dist_end) <= 10 * tol_len)
    i, j = i[collinear], j[collinear]

    # Overlap along edge i's direction.
    t_i = direction[i]
    origin = edges.start[i]
    a0 = np.zeros(len(i))
    a1 = length[i]
    b0 = ((edges.start[j] - origin) * t_i).sum(axis=1)
    b1 = ((edges.end[j] - origin) * t_i).sum(axis=1)
    lo_b, hi_b = np.minimum(b0, b1), np.maximum(b0, b1)
    s0, s1 = np.maximum(a0, lo_b), np.minimum(a1, hi_b)
    positive = s1 - s0 > 10 * tol_len
    i, j, s0, s1, t_i, origin = i[positive], j[positive], s0[positive], s1[positive], t_i[positive], origin[positive]
    block_a, block_b = edges.block[i], edges.block[j]
    fixed = np.array([b.fixed for b in scene.blocks])
    both_fixed = fixed[block_a] & fixed[block_b]
    keep = ~both_fixed
    # Orient joints so block_a < block_b for a stable numbering independent of edge order.
    swap = block_a > block_b
    normal = np.where(swap[:, None], -outward[i], outward[i])
    start = origin + s0[:, None] * t_i
    end = origin + s1[:, None] * t_i
    a = np.where(swap, block_b, block_a)
    b = np.where(swap, block_a, block_b)
    order = np.lexsort((start[keep, 1], start[keep, 0], b[keep], a[keep]))
    sel = np.flatnonzero(keep)[order]
    return Joints(block_a=a[sel], block_b=b[sel], start=start[sel], end=end[sel], normal=normal[sel])


def find_overlaps(scene: "Scene") -> list[tuple[int, int]]:
    """Pairs of blocks whose interiors intersect (area above a relative tolerance)."""
    import shapely

    polygons = shapely.polygons([b.vertices for b in scene.blocks]) if _same_size(scene) else \
        np.array([shapely.Polygon(b.vertices) for b in scene.blocks])
    tree = shapely.STRtree(polygons)
    pairs = tree.query(polygons, predicate="intersects")
    a, b = pairs[0], pairs[1]
    keep = a < b
    a, b = a[keep], b[keep]
    if a.size == 0:
        return []
    areas = shapely.area(shapely.intersection(polygons[a], polygons[b]))
    smaller = np.minimum(shapely.area(polygons[a]), shapely.area(polygons[b]))
    bad = areas > 1e-7 * smaller
    return [(int(x), int(y)) for x, y in zip(a[bad], b[bad])]


def _same_size(scene: "Scene") -> bool:
    return len({len(b.vertices) for b in scene.blocks}) == 1


def _empty_joints() -> Joints:
    empty = np.zeros((0, 2))
    return Joints(block_a=np.zeros(0, dtype=int), block_b=np.zeros(0, dtype=int),
                  start=empty, end=empty.copy(), normal=empty.copy())
