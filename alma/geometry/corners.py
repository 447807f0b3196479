"""Point contacts: a block's corner resting on another block's face.

A flat joint (:mod:`alma.geometry.contacts`) needs two facing edges on one line.  A block that
has turned about an edge, a leaning stone, a voussoir drawn out of true touch their neighbour
with a corner only: a vertex of one block lies on an edge of another (within the contact
tolerance), away from that edge's ends, the corner is convex and neither of the block's two
edges at that vertex enters the face.  Such a contact is a joint of zero length (both contact
points at the corner; Eq. 5 with l = 0) whose normal is the face's.  The candidates come from a
k-d tree over the vertices and pieces of the edges no longer than a typical edge, so the work
grows with the edges and their near neighbours, not with the square of the blocks.  No Python
loop runs over blocks or edges.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from alma.geometry.edges import Edges, previous_edge

if TYPE_CHECKING:  # pragma: no cover
    from alma.geometry.contacts import Joints
    from alma.geometry.scene import Scene


def corner_contacts(
    edges: Edges, fixed: np.ndarray, flat: Joints, snap: float, angle_tol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The corner-on-face contacts of ``edges`` (a scene's snapped outlines, counter-clockwise).

    Parameters
    ----------
    edges : Edges
        All block edges, one row per edge; edge k runs from vertex k to the next vertex of its block.
    fixed : ndarray of bool, (n,)
        Whether each block is a support: a contact between two supports is dropped.
    flat : Joints
        The flat joints already found, in the frame of ``edges``: a corner lying on one of them
        between the same two blocks is part of it, not a contact of its own.
    snap : float
        The contact tolerance (mm): the largest gap or overlap between the corner and the face.
    angle_tol : float
        The tilt (sine of the angle) below which an edge at the corner is parallel to the face:
        an edge entering the face by more is an overlap, not a contact; one along it makes a
        flat joint where the two overlap by more than ``snap`` (then the corner is part of it).

    Returns
    -------
    block_a, block_b, point, normal
        One row per contact, ``block_a < block_b``; ``point`` (mm) halfway between the corner and
        the face; ``normal`` the face's outward unit normal turned to point from ``block_a`` into
        ``block_b``.
    """
    vertex, face = _near_pairs(edges, snap)
    vec = edges.end - edges.start
    length = np.hypot(vec[:, 0], vec[:, 1])
    direction = vec / np.maximum(length, 1e-300)[:, None]
    outward = np.column_stack([direction[:, 1], -direction[:, 0]])
    rel = edges.start[vertex] - edges.start[face]
    along = (rel * direction[face]).sum(axis=1)
    gap = (rel * outward[face]).sum(axis=1)  # > 0: the corner stands off the face
    inside = (np.abs(gap) <= snap) & (along > snap) & (along < length[face] - snap)
    previous = previous_edge(edges)
    leaving_next = (direction[vertex] * outward[face]).sum(axis=1)
    leaving_prev = -(direction[previous[vertex]] * outward[face]).sum(axis=1)
    incoming, outgoing = direction[previous[vertex]], direction[vertex]
    convex = incoming[:, 0] * outgoing[:, 1] - incoming[:, 1] * outgoing[:, 0] > 0
    resting = inside & convex & (np.minimum(leaving_next, leaving_prev) >= -angle_tol)
    corner_block, face_block = edges.block[vertex], edges.block[face]
    resting &= ~(fixed[corner_block] & fixed[face_block])
    vertex, face, gap = vertex[resting], face[resting], gap[resting]
    corner_block, face_block = corner_block[resting], face_block[resting]
    point = edges.start[vertex] - 0.5 * gap[:, None] * outward[face]
    keep = ~covered(flat, corner_block, face_block, point, snap)
    swap = face_block > corner_block  # the normal points from the face's block into the corner's
    a = np.where(swap, corner_block, face_block)[keep]
    b = np.where(swap, face_block, corner_block)[keep]
    normal = (np.where(swap[:, None], -1.0, 1.0) * outward[face])[keep]
    return a, b, point[keep], normal


def _near_pairs(edges: Edges, snap: float) -> tuple[np.ndarray, np.ndarray]:
    """(vertex, edge) pairs of different blocks that may lie within ``snap`` of each other: a
    superset, found by a k-d tree between the vertices and pieces of the edges (each no longer
    than the median edge), every pair once."""
    vec = edges.end - edges.start
    length = np.hypot(vec[:, 0], vec[:, 1])
    piece = max(float(np.median(length)), snap)
    count = np.maximum(np.ceil(length / piece), 1).astype(np.int64)
    owner = np.repeat(np.arange(length.size), count)
    k = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    middle = edges.start[owner] + ((k + 0.5) / count[owner])[:, None] * vec[owner]
    # A point within snap of an edge lies within half a piece plus snap of a piece's middle.
    pairs = cKDTree(edges.start).sparse_distance_matrix(
        cKDTree(middle), max_distance=0.5 * piece + snap, output_type="ndarray"
    )
    vertex, edge = pairs["i"].astype(np.int64), owner[pairs["j"]]
    other = edges.block[vertex] != edges.block[edge]
    key = np.unique(vertex[other] * length.size + edge[other])
    return key // length.size, key % length.size


def covered(found: Joints, a: np.ndarray, b: np.ndarray, points: np.ndarray, snap: float) -> np.ndarray:
    """Per point: it lies within ``snap`` of a joint of ``found`` between the same two blocks."""
    if found.count == 0 or a.size == 0:
        return np.zeros(a.size, dtype=bool)
    n = int(max(found.block_a.max(), found.block_b.max(), a.max(), b.max())) + 1
    key = found.block_a.astype(np.int64) * n + found.block_b
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    mine = np.minimum(a, b).astype(np.int64) * n + np.maximum(a, b)
    lo = np.searchsorted(sorted_key, mine, "left")
    hi = np.searchsorted(sorted_key, mine, "right")
    count = hi - lo
    owner = np.repeat(np.arange(a.size), count)
    k = order[np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count - lo, count)]
    p = points[owner]
    s0, s1 = found.start[k], found.end[k]
    seg = s1 - s0
    t = np.clip(((p - s0) * seg).sum(axis=1) / np.maximum((seg * seg).sum(axis=1), 1e-300), 0.0, 1.0)
    near = np.hypot(*(p - s0 - t[:, None] * seg).T) <= snap
    out = np.zeros(a.size, dtype=bool)
    np.logical_or.at(out, owner, near)
    return out


def padded_outlines(scene: Scene) -> np.ndarray:
    """The blocks' outlines as one array (n, width, 2) mm, each padded with its first vertex up
    to the widest outline (the padding's edges have no length)."""
    counts = np.array([len(blk.vertices) for blk in scene.blocks])
    row = np.repeat(np.arange(len(counts)), counts)
    col = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    first = np.array([blk.vertices[0] for blk in scene.blocks], dtype=float)
    padded = np.repeat(first[:, None, :], int(counts.max()), axis=1)
    padded[row, col] = np.concatenate([blk.vertices for blk in scene.blocks])
    return padded


def outline_distances(outlines: np.ndarray, blocks: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per point of ``points`` (k, 2) mm: its distance (mm) to the outline of its block ``blocks``
    (k,) in ``outlines`` (:func:`padded_outlines`), and to that outline's nearest vertex."""
    start = outlines[blocks]
    seg = np.roll(start, -1, axis=1) - start
    rel = points[:, None, :] - start
    t = np.clip((rel * seg).sum(axis=2) / np.maximum((seg * seg).sum(axis=2), 1e-300), 0.0, 1.0)
    to_edge = np.hypot(*(rel - t[:, :, None] * seg).transpose(2, 0, 1)).min(axis=1)
    to_vertex = np.hypot(*rel.transpose(2, 0, 1)).min(axis=1)
    return to_edge, to_vertex
