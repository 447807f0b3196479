"""Snapping a drawing's near-coincident vertices: what the contact tolerance promises.

A drawing exported from CAD or digitised from a survey moves every vertex a little, and the
copies of one corner (one per block that meets there) move independently.  The contact
tolerance ``tol`` (:func:`alma.geometry.edges.contact_lengths`) is the drawing's accuracy: every
vertex is taken to lie within ``tol`` of where it is meant to be, so two copies of one corner
lie within ``r = 2 tol`` (:attr:`alma.geometry.edges.ContactSettings.vertex_merge`) of each
other.  Before joints are found, the outlines are cleaned in two vectorised passes:

1. *vertex to vertex*: vertices of different blocks within ``r`` of each other are one point.
   The pairs come from a KD-tree (``scipy.spatial.cKDTree.query_pairs``), the points from the
   connected components of those pairs (a union-find), and each component is replaced by its
   mean, summed in lexicographic order about its lowest-left member, so that the point depends
   neither on the order of blocks or vertices nor, for a clean drawing, on the sum's round-off
   (identical copies stay bit for bit what they were).  A block's own vertices are never paired
   (its outline is checked by :mod:`alma.geometry.polygons`);
2. *vertex to edge*: a point within ``r`` of the interior of an edge of a block that does not
   meet there (the T-junction of a running bond's head joint) is moved onto that edge's line, the
   nearest such edge first.  The edges are those after pass 1; one pass, so a point moved onto
   an edge whose own end moves in the same pass keeps a gap of at most that end's move.

The guarantee that follows (docs/scenes.md, "Imperfect drawings"): if every vertex of a clean
drawing (whose distinct points lie more than ``r + 2 tol`` apart) is moved by at most ``tol``
(Euclidean), two copies of one corner end at most ``r`` apart and are merged, into a point
within ``tol`` of the clean corner; a T-junction's point ends at most ``r`` from the noisy edge's
line (which moves by at most ``tol`` anywhere along the edge, a convex combination of its ends'
moves) and is moved onto it, to within ``2 tol`` of the clean point.  So the same joints are
found as in the clean drawing, each end within ``2 tol`` of the clean one.  Beyond that noise
alma says so: a merged point with a member farther than ``r`` from it (a chain of merges) is a
warning naming the blocks; a gap left open is a near miss (:mod:`alma.geometry.contacts`); an
overlap left is refused (:func:`alma.geometry.polygons.find_overlaps`).  Two vertices of one
block are never merged: a chain that would do it is refused naming the block, and a block
thinner than the tolerance is refused by the outline check, as before.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
import shapely
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import splu
from scipy.spatial import cKDTree

from alma.geometry.edges import CONTACT, Edges, contact_lengths, local_origin, scene_edges, signed_areas
from alma.geometry.parsing import SceneError

if TYPE_CHECKING:  # pragma: no cover
    from alma.geometry.scene import Scene


@dataclass(frozen=True)
class SnappedEdges:
    """The edges of a scene after snapping, with the warnings the snapping raised.

    ``edges.start[k]`` is the snapped vertex ``k`` (flattened over the blocks, as
    :func:`alma.geometry.edges.scene_edges` orders them); ``moved`` the distance (mm) each
    vertex was moved.
    """

    edges: Edges
    moved: np.ndarray
    warnings: tuple[str, ...] = ()


def snap_edges(scene: "Scene", edges: Edges, snap: float) -> SnappedEdges:
    """Merge near-coincident vertices of different blocks, then move T-junction points onto the
    edges they lie on (module docstring); lengths in mm, ``snap`` the contact tolerance, the
    radius of both passes ``CONTACT.vertex_merge × snap``.

    Raises
    ------
    SceneError
        Two vertices of one block would become one point (a chain of merges across a block about
        as thin as the tolerance), naming the block and the two vertices; or a block's snapped
        outline is flat (:func:`_refuse_flattened`).
    """
    nxt = _next_vertex(edges)
    radius = CONTACT.vertex_merge * snap
    merged, warnings = _merge_vertices(scene, edges, radius, snap)
    points = _onto_edges(edges, merged, nxt, radius)
    snapped = Edges(block=edges.block, start=points, end=points[nxt])
    _refuse_flattened(scene, edges, snapped, snap)
    return SnappedEdges(snapped, np.hypot(*(points - edges.start).T), warnings)


def snapped_vertices(scene: "Scene", snap: float | None = None) -> tuple[np.ndarray, ...]:
    """Each block's vertices after snapping (mm, in the drawing's frame), in the scene's order.

    ``snap`` defaults to the scene's contact tolerance.  Intended for checks and exports; joint
    detection and the overlap check snap their own edges.
    """
    origin = local_origin(scene)
    edges = scene_edges(scene, origin)
    tol = contact_lengths(scene, edges)[0] if snap is None else snap
    snapped = snap_edges(scene, edges, tol)
    drawn = np.concatenate([b.vertices for b in scene.blocks])
    # An unmoved vertex is returned as drawn, not through the local origin and back (round-off).
    points = np.where(snapped.moved[:, None] > 0, snapped.edges.start + origin, drawn)
    counts = np.bincount(edges.block, minlength=len(scene.blocks))
    return tuple(np.split(points, np.cumsum(counts)[:-1]))


def _next_vertex(edges: Edges) -> np.ndarray:
    """Index of the next vertex of each vertex's own polygon (the end of its edge)."""
    index = np.arange(len(edges.block))
    counts = np.bincount(edges.block)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    return np.where(index + 1 - first < np.repeat(counts, counts), index + 1, first)


def _merge_vertices(scene: "Scene", edges: Edges, radius: float, snap: float) -> tuple[np.ndarray, tuple[str, ...]]:
    """Pass 1: every vertex replaced by the mean of its cluster (vertices of different blocks
    joined by chains of distances ≤ ``radius``), and the warning for clusters spread wider."""
    points = edges.start
    n = len(points)
    pairs = cKDTree(points).query_pairs(radius, output_type="ndarray")
    pairs = pairs[edges.block[pairs[:, 0]] != edges.block[pairs[:, 1]]] if pairs.size else pairs
    if pairs.size == 0:
        return points, ()
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    order = np.lexsort((points[:, 1], points[:, 0], label))  # by cluster, then lowest-left first
    sorted_label = label[order]
    first = np.concatenate([[0], np.flatnonzero(np.diff(sorted_label)) + 1])
    count = np.diff(np.append(first, n))
    anchor = points[order][first]  # each cluster's lowest-left member
    offset = points[order] - np.repeat(anchor, count, axis=0)
    centre = anchor + np.add.reduceat(offset, first, axis=0) / count[:, None]
    merged = np.empty_like(points)
    merged[order] = np.repeat(centre, count, axis=0)
    _refuse_one_block_twice(scene, edges, order, sorted_label, first)
    spread = np.hypot(*(points - merged).T)
    return merged, _wide_clusters(scene, edges, label, spread, radius, snap)


def _refuse_one_block_twice(scene: "Scene", edges: Edges, order: np.ndarray, sorted_label: np.ndarray,
                            first: np.ndarray) -> None:
    """Refuse a cluster holding two vertices of one block (they would become one point)."""
    by_block = np.lexsort((order, edges.block[order], sorted_label))
    key = np.column_stack([sorted_label[by_block], edges.block[order][by_block]])
    twice = np.flatnonzero(np.all(key[1:] == key[:-1], axis=1))
    if twice.size == 0:
        return
    k = int(twice[0])
    u, v = int(order[by_block[k]]), int(order[by_block[k + 1]])
    block = int(edges.block[u])
    start = int(np.flatnonzero(edges.block == block)[0])
    others = sorted({scene.blocks[b].id for b in edges.block[order][sorted_label == sorted_label[by_block[k]]]
                     if b != block})
    through = f" through block(s) {others}" if others else ""
    raise SceneError(
        f"block '{scene.blocks[block].id}': vertices {u - start} and {v - start} would be merged into one "
        f"point{through} (vertices of different blocks within twice the contact tolerance are one point): "
        "the block is about as thin as the tolerance, or the drawing is noisier than it (lower "
        "contact_tolerance, or redraw the block)")


def _refuse_flattened(scene: "Scene", raw: Edges, snapped: Edges, snap: float) -> None:
    """Refuse the first block whose snapped outline is flat by the outline check's rule (area at
    most ``snap`` × its extent, :func:`alma.geometry.polygons.check_polygons`): a block less than
    twice the tolerance thick whose far side was put on a neighbour's edge."""
    area = signed_areas(snapped)
    n = len(scene.blocks)
    lo = np.full((n, 2), np.inf)
    hi = np.full((n, 2), -np.inf)
    np.minimum.at(lo, raw.block, raw.start)
    np.maximum.at(hi, raw.block, raw.start)
    extent = (hi - lo).max(axis=1)
    flat = ~(area > np.maximum(snap * extent, 1e-9 * extent ** 2))
    if flat.any():
        block = scene.blocks[int(np.flatnonzero(flat)[0])]
        raise SceneError(
            f"block '{block.id}': flat once its vertices are snapped (vertices within twice the contact "
            "tolerance of another block's vertex or edge lie on it): the block is about as thin as the "
            "tolerance (lower contact_tolerance, or redraw the block)")


def _wide_clusters(scene: "Scene", edges: Edges, label: np.ndarray, spread: np.ndarray, radius: float,
                   snap: float) -> tuple[str, ...]:
    """One warning for the merged points with a member farther than ``radius`` from them (a chain
    of merges: the drawing is noisier than the guarantee), naming the blocks of the widest."""
    wide = spread > radius
    if not wide.any():
        return ()
    worst = int(np.argmax(spread))
    members = label == label[worst]
    blocks = sorted({scene.blocks[b].id for b in np.unique(edges.block[members]).tolist()})
    count = int(np.unique(label[wide]).size)
    return (f"{count} merged point(s) gather vertices lying more than twice the contact tolerance "
            f"({radius:.3g} mm) from them, up to {spread[worst]:.3g} mm (blocks {blocks}): the drawing is noisier "
            f"than the tolerance ({snap:.3g} mm per vertex); check that these corners are meant to meet",)


def _onto_edges(edges: Edges, points: np.ndarray, nxt: np.ndarray, radius: float) -> np.ndarray:
    """Pass 2: each distinct point within ``radius`` of the interior of an edge of a block that has
    no vertex at that point, put on that edge (the nearest such edge).

    The point keeps its place along the edge, ``p = (1 − t) a + t b``; as an edge's ends may be
    such points too (two edges overlapping in part: each has an end inside the other), all these
    equations are solved together, one sparse linear system, so that the points end exactly on
    the edges as they end.  A point within ``radius`` of an edge's end is left alone (it is a
    near miss of that end, not a T-junction), which keeps every weight t in the system at least
    ``radius / length`` away from 0 and 1: its matrix is then diagonally dominant.
    """
    unique, inverse = np.unique(points, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    a, b = inverse, inverse[nxt]  # each edge's ends, as rows of ``unique``
    lines = shapely.linestrings(np.stack([unique[a], unique[b]], axis=1))
    p, e = shapely.STRtree(lines).query(shapely.points(unique), predicate="dwithin", distance=radius)
    if p.size == 0:
        return points
    # A block with a vertex at the point meets there: its edges are not a T-junction's.
    n_blocks = int(edges.block.max()) + 1
    own = np.isin(p * n_blocks + edges.block[e], np.unique(inverse * n_blocks + edges.block))
    p, e = p[~own], e[~own]
    direction = unique[b[e]] - unique[a[e]]
    length = np.hypot(direction[:, 0], direction[:, 1])
    t = ((unique[p] - unique[a[e]]) * direction).sum(axis=1) / length ** 2
    foot = unique[a[e]] + t[:, None] * direction
    distance = np.hypot(*(unique[p] - foot).T)
    # A point off the line by round-off only (of its coordinates about the local origin) stays
    # where it is, so that a drawing's exact T-junctions are kept bit for bit wherever it sits.
    roundoff = 1e-12 * float(np.abs(unique).max())
    inside = (t * length > radius) & ((1.0 - t) * length > radius) & (distance > roundoff) & (distance <= radius)
    p, e, t, foot, distance = p[inside], e[inside], t[inside], foot[inside], distance[inside]
    if p.size == 0:
        return points
    # The nearest edge per point; ties broken by the foot's position, never by the input order.
    pick = np.lexsort((foot[:, 1], foot[:, 0], distance, p))
    keep = pick[np.concatenate([[True], np.diff(p[pick]) != 0])]
    moved = unique.copy()
    moved[p[keep]] = _on_their_edges(unique, p[keep], a[e[keep]], b[e[keep]], t[keep])
    return moved[inverse]


def _on_their_edges(unique: np.ndarray, p: np.ndarray, a: np.ndarray, b: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Solve x_p = (1 − t) x_a + t x_b for the points ``p`` (rows of ``unique``; an end that is no
    such point keeps its place): the points on their edges, all at once."""
    n = len(p)
    var = np.full(len(unique), -1)
    var[p] = np.arange(n)
    rows, cols, vals = [np.arange(n)], [np.arange(n)], [np.ones(n)]
    rhs = np.zeros((n, 2))
    for end, weight in ((a, 1.0 - t), (b, t)):
        unknown = var[end] >= 0
        rows.append(np.flatnonzero(unknown))
        cols.append(var[end[unknown]])
        vals.append(-weight[unknown])
        rhs += np.where(unknown[:, None], 0.0, weight[:, None] * unique[end])
    matrix = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    if matrix.nnz == n:  # no point lies on an edge that ends at another: the feet themselves
        return rhs
    return splu(matrix).solve(rhs)
