"""Flattened block edges, areas, centroids and the contact tolerance of a scene.

Every block's outline becomes rows of one edge array, so that joint detection and polygon
checks run vectorised over all edges.  The contact tolerance (SPEC §2 ``contact_tolerance``)
is relative to the blocks' size, never to the coordinates: a drawing moved 1 km gets the same
joints.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from alma.geometry.scene import Scene


@dataclass(frozen=True)
class ContactSettings:
    """Default contact tolerances, relative to the median √area of the free blocks."""

    #: Gaps and overlaps up to this are snapped to a joint: CAD coordinates rounded to 1e-3 mm
    #: on 100 mm blocks stay joints, while the paper's exact panels are unaffected.
    tolerance: float = 1e-4
    #: Facing edges apart by up to this (and beyond ``tolerance``) are reported as near misses:
    #: a gap a drawing most likely meant to close.
    warning_band: float = 1e-2
    #: Vertices of different blocks within this multiple of the tolerance are one point, and a
    #: vertex that close to another block's edge lies on it (alma.geometry.snap): two copies of a
    #: corner, each drawn within the tolerance of it, lie within twice the tolerance of each other.
    vertex_merge: float = 2.0


CONTACT = ContactSettings()


@dataclass(frozen=True)
class Edges:
    """All block edges of a scene, flattened (one row per edge)."""

    block: np.ndarray  # (E,) block index
    start: np.ndarray  # (E, 2)
    end: np.ndarray  # (E, 2)


def scene_edges(scene: Scene, origin: np.ndarray | None = None) -> Edges:
    """The edges of all blocks, in mm, optionally about a local ``origin``."""
    counts = np.array([len(b.vertices) for b in scene.blocks])
    start = np.concatenate([b.vertices for b in scene.blocks])
    if origin is not None:
        start = start - origin
    # next vertex of each polygon: roll within each block, vectorised via offsets
    index = np.arange(start.shape[0])
    first = np.repeat(np.cumsum(counts) - counts, counts)
    nxt = np.where(index + 1 - first < np.repeat(counts, counts), index + 1, first)
    return Edges(block=np.repeat(np.arange(len(counts)), counts), start=start, end=start[nxt])


def previous_edge(edges: Edges) -> np.ndarray:
    """Index of the edge before each edge in its own polygon (the one ending at its start vertex)."""
    index = np.arange(len(edges.block))
    counts = np.bincount(edges.block)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    return np.where(index == first, first + np.repeat(counts, counts) - 1, index - 1)


def local_origin(scene: Scene) -> np.ndarray:
    """Centre of the scene's bounding box: coordinates about it keep the detection translation invariant."""
    lo = np.min([b.vertices.min(axis=0) for b in scene.blocks], axis=0)
    hi = np.max([b.vertices.max(axis=0) for b in scene.blocks], axis=0)
    return 0.5 * (lo + hi)


def areas_and_centroids(edges: Edges) -> tuple[np.ndarray, np.ndarray]:
    """Signed areas (n,) in mm² and centroids (n, 2) in mm of the blocks of ``edges``."""
    first = np.concatenate([[0], np.flatnonzero(np.diff(edges.block)) + 1])
    origin = edges.start[first][edges.block]  # each polygon about its first vertex, for accuracy
    p, q = edges.start - origin, edges.end - origin
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    area = 0.5 * np.add.reduceat(cross, first)
    cx = np.add.reduceat((p[:, 0] + q[:, 0]) * cross, first) / (6 * area)
    cy = np.add.reduceat((p[:, 1] + q[:, 1]) * cross, first) / (6 * area)
    return area, origin[first] + np.column_stack([cx, cy])


def signed_areas(edges: Edges) -> np.ndarray:
    """Signed areas (n,) in mm² of the blocks of ``edges`` (positive when counter-clockwise)."""
    first = np.concatenate([[0], np.flatnonzero(np.diff(edges.block)) + 1])
    origin = edges.start[first][edges.block]
    p, q = edges.start - origin, edges.end - origin
    return 0.5 * np.add.reduceat(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1], first)


def contact_lengths(scene: Scene, edges: Edges) -> tuple[float, float]:
    """(snap, warn): the contact tolerance and the near-miss band of ``scene``, in mm.

    Both are relative to the median √area of the free blocks (all blocks if none is free), so
    that a large ground or a distant origin does not change them.
    """
    area = np.abs(signed_areas(edges))
    free = np.array([not b.fixed for b in scene.blocks])
    size = float(np.median(np.sqrt(area[free] if free.any() else area)))
    relative = scene.contact_tolerance if scene.contact_tolerance is not None else CONTACT.tolerance
    return relative * size, max(CONTACT.warning_band, relative) * size
