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
2. *vertex to edge*: a point that ends an edge and lies within ``r`` of the interior of a facing
   edge of a block that does not meet there (the T-junction of a running bond's head joint, the
   ends of two edges overlapping in part) is put on that edge, the nearest such edge.  Facing
   pairs come from joint detection's candidate search (:mod:`alma.geometry.contacts`), which
   joint detection then reuses, so the pass costs little more than pass 1.  All such points are
   placed at once (one sparse linear system), so that each ends exactly on its edge as that
   edge ends.

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

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import splu
from scipy.spatial import cKDTree

from alma.geometry.edges import CONTACT, Edges, signed_areas
from alma.geometry.parsing import SceneError

if TYPE_CHECKING:  # pragma: no cover
    from alma.geometry.scene import Scene


@dataclass(frozen=True)
class SnappedEdges:
    """The edges of a scene after snapping, with the warnings the snapping raised.

    ``edges.start[k]`` is the snapped vertex ``k`` (flattened over the blocks, as
    :func:`alma.geometry.edges.scene_edges` orders them); ``moved`` the distance (mm) each
    vertex was moved; ``pairs`` the candidate facing edge pairs (i, j) in which T-junctions were
    looked for (a superset of the joints' pairs, for joint detection to reuse).
    """

    edges: Edges
    moved: np.ndarray
    pairs: tuple[np.ndarray, np.ndarray]
    warnings: tuple[str, ...] = ()


def snap_edges(
    scene: Scene, edges: Edges, snap: float, facing: Callable[[Edges], tuple[np.ndarray, np.ndarray]]
) -> SnappedEdges:
    """Merge near-coincident vertices of different blocks, then move T-junction points onto the
    edges they lie on (module docstring); lengths in mm, ``snap`` the contact tolerance, the
    radius of both passes ``CONTACT.vertex_merge × snap``.  ``facing(edges)`` gives a superset
    of the pairs of edges (i, j) of two blocks that may face each other once snapped
    (:func:`alma.geometry.contacts.snapped_edges` passes the joints' candidate search): a
    T-junction is an end of one of them inside the other.

    Raises
    ------
    SceneError
        Two vertices of one block would become one point (a chain of merges across a block about
        as thin as the tolerance), naming the block and the two vertices; or a block's snapped
        outline is flat (:func:`_refuse_flattened`).
    """
    nxt = _next_vertex(edges)
    radius = CONTACT.vertex_merge * snap
    unique, inverse = _unique_rows(edges.start)
    cluster, centre, warnings = _merge_vertices(scene, edges, unique, inverse, radius, snap)
    i, j = facing(Edges(block=edges.block, start=centre[cluster], end=centre[cluster[nxt]]))
    points = _onto_edges(edges, centre, cluster, nxt, radius, i, j)[cluster]
    snapped = Edges(block=edges.block, start=points, end=points[nxt])
    _refuse_flattened(scene, edges, snapped, snap)
    return SnappedEdges(snapped, np.hypot(*(points - edges.start).T), (i, j), warnings)


def _next_vertex(edges: Edges) -> np.ndarray:
    """Index of the next vertex of each vertex's own polygon (the end of its edge)."""
    index = np.arange(len(edges.block))
    counts = np.bincount(edges.block)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    return np.where(index + 1 - first < np.repeat(counts, counts), index + 1, first)


def _unique_rows(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct points, lowest-left first (by x, then y), and each row's index among them."""
    order = np.lexsort((points[:, 1], points[:, 0]))
    ordered = points[order]
    new = np.ones(len(points), dtype=bool)
    new[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    inverse = np.empty(len(points), dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    return ordered[new], inverse


def _merge_vertices(
    scene: Scene, edges: Edges, unique: np.ndarray, inverse: np.ndarray, radius: float, snap: float
) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Pass 1: the clusters (distinct points joined by chains of distances ≤ ``radius`` between
    vertices of different blocks), each vertex's cluster, each cluster's mean of its vertices,
    and the warning for clusters spread wider than ``radius``."""
    n = len(unique)
    count = np.bincount(inverse, minlength=n)  # the vertices drawn at each distinct point
    alone = count[inverse] == 1
    block_alone = np.full(n, -1)
    block_alone[inverse[alone]] = edges.block[alone]  # the block of a point drawn once, else -1
    pairs = cKDTree(unique).query_pairs(radius, output_type="ndarray")
    if pairs.size:  # two points each drawn once, by one block, are that block's own outline
        pairs = pairs[(block_alone[pairs[:, 0]] < 0) | (block_alone[pairs[:, 0]] != block_alone[pairs[:, 1]])]
    if pairs.size == 0:
        return inverse, unique, ()
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    order = np.argsort(label, kind="stable")  # by cluster, then lowest-left first (``unique`` is)
    first = np.concatenate([[0], np.flatnonzero(np.diff(label[order])) + 1])
    anchor = unique[order[first]]  # each cluster's lowest-left point
    weight = count[order]
    offset = (unique[order] - anchor[label[order]]) * weight[:, None]
    centre = anchor + np.add.reduceat(offset, first, axis=0) / np.add.reduceat(weight, first)[:, None]
    cluster = label[inverse]
    _refuse_one_block_twice(scene, edges, cluster, np.bincount(label)[cluster] > 1)
    spread = np.hypot(*(unique - centre[label]).T)
    return cluster, centre, _wide_clusters(scene, edges, cluster, spread[inverse], radius, snap)


def _refuse_one_block_twice(scene: Scene, edges: Edges, cluster: np.ndarray, merged: np.ndarray) -> None:
    """Refuse a merged cluster holding two vertices of one block (they would become one point)."""
    rows = np.flatnonzero(merged)
    key = cluster[rows] * len(scene.blocks) + edges.block[rows]
    order = np.argsort(key, kind="stable")
    twice = np.flatnonzero(np.diff(key[order]) == 0)
    if twice.size == 0:
        return
    u, v = int(rows[order[twice[0]]]), int(rows[order[twice[0] + 1]])
    block = int(edges.block[u])
    start = int(np.flatnonzero(edges.block == block)[0])
    others = sorted({scene.blocks[b].id for b in np.unique(edges.block[cluster == cluster[u]]).tolist() if b != block})
    through = f" through block(s) {others}" if others else ""
    raise SceneError(
        f"block '{scene.blocks[block].id}': vertices {u - start} and {v - start} would be merged into one "
        f"point{through} (vertices of different blocks within twice the contact tolerance are one point): "
        "the block is about as thin as the tolerance, or the drawing is noisier than it (lower "
        "contact_tolerance, or redraw the block)"
    )


def _refuse_flattened(scene: Scene, raw: Edges, snapped: Edges, snap: float) -> None:
    """Refuse the first block whose snapped outline is flat by the outline check's rule (area at
    most ``snap`` × its extent, :func:`alma.geometry.polygons.check_polygons`): a block less than
    twice the tolerance thick whose far side was put on a neighbour's edge."""
    first = np.concatenate([[0], np.flatnonzero(np.diff(raw.block)) + 1])
    extent = (np.maximum.reduceat(raw.start, first, axis=0) - np.minimum.reduceat(raw.start, first, axis=0)).max(axis=1)
    flat = ~(signed_areas(snapped) > np.maximum(snap * extent, 1e-9 * extent**2))
    if flat.any():
        block = scene.blocks[int(raw.block[first[np.flatnonzero(flat)[0]]])]
        raise SceneError(
            f"block '{block.id}': flat once its vertices are snapped (vertices within twice the contact "
            "tolerance of another block's vertex or edge lie on it): the block is about as thin as the "
            "tolerance (lower contact_tolerance, or redraw the block)"
        )


def _wide_clusters(
    scene: Scene, edges: Edges, cluster: np.ndarray, spread: np.ndarray, radius: float, snap: float
) -> tuple[str, ...]:
    """One warning for the merged points with a vertex farther than ``radius`` from them (a chain
    of merges: the drawing is noisier than the guarantee), naming the blocks of the widest."""
    wide = spread > radius
    if not wide.any():
        return ()
    worst = int(np.argmax(spread))
    blocks = sorted({scene.blocks[b].id for b in np.unique(edges.block[cluster == cluster[worst]]).tolist()})
    count = int(np.unique(cluster[wide]).size)
    return (
        f"{count} merged point(s) gather vertices lying more than twice the contact tolerance "
        f"({radius:.3g} mm) from them, up to {spread[worst]:.3g} mm (blocks {blocks}): the drawing is noisier "
        f"than the tolerance ({snap:.3g} mm per vertex); check that these corners are meant to meet",
    )


def _onto_edges(
    edges: Edges, centre: np.ndarray, cluster: np.ndarray, nxt: np.ndarray, radius: float, i: np.ndarray, j: np.ndarray
) -> np.ndarray:
    """Pass 2: each point (a cluster of pass 1) that ends an edge of a facing pair (i, j) and lies
    within ``radius`` of the interior of the other edge, whose block has no vertex at that point,
    put on that edge (the nearest such edge).

    The point keeps its place along the edge, ``p = (1 − t) a + t b``; as an edge's ends may be
    such points too (two edges overlapping in part: each has an end inside the other), all these
    equations are solved together, one sparse linear system, so that the points end exactly on
    the edges as they end (:func:`_on_their_edges`).  A point within ``radius`` of an edge's end
    is left alone (it is a near miss of that end, not a T-junction), which keeps every weight t
    in the system at least ``radius / length`` away from 0 and 1.
    """
    a, b = cluster, cluster[nxt]  # each edge's ends, as points of ``centre``
    direction = centre[b] - centre[a]
    length = np.hypot(direction[:, 0], direction[:, 1])
    p = np.concatenate([a[i], b[i], a[j], b[j]])
    e = np.concatenate([j, j, i, i])
    # Along and across the edge, in columns (a gather of rows of pairs is several times slower).
    x, y, ux, uy = centre[:, 0], centre[:, 1], direction[:, 0] / length, direction[:, 1] / length
    rx, ry = x[p] - x[a[e]], y[p] - y[a[e]]
    along = rx * ux[e] + ry * uy[e]
    across = np.abs(rx * uy[e] - ry * ux[e])
    # A point off the line by round-off only (of its coordinates about the local origin) stays
    # where it is, so that a drawing's exact T-junctions are kept bit for bit wherever it sits.
    roundoff = 1e-12 * float(np.abs(centre).max(initial=0.0))
    inside = (along > radius) & (length[e] - along > radius) & (across > roundoff) & (across <= radius)
    p, e = p[inside], e[inside]
    if p.size == 0:
        return centre
    key = _distinct(p * len(length) + e)  # a pair may come from two facing pairs
    p, e = key // len(length), key % len(length)
    # A block with a vertex at the point meets there: its edges are not a T-junction's.
    n_blocks = int(edges.block.max()) + 1
    met = _distinct(cluster * n_blocks + edges.block)
    probe = p * n_blocks + edges.block[e]
    own = met[np.minimum(np.searchsorted(met, probe), len(met) - 1)] == probe
    p, e = p[~own], e[~own]
    if p.size == 0:
        return centre
    t = ((centre[p] - centre[a[e]]) * direction[e]).sum(axis=1) / length[e] ** 2
    foot = centre[a[e]] + t[:, None] * direction[e]
    distance = np.hypot(*(centre[p] - foot).T)
    # The nearest edge per point; ties broken by the foot's position, never by the input order.
    pick = np.lexsort((foot[:, 1], foot[:, 0], distance, p))
    keep = pick[np.concatenate([[True], np.diff(p[pick]) != 0])]
    moved = centre.copy()
    moved[p[keep]] = _on_their_edges(centre, p[keep], a[e[keep]], b[e[keep]], t[keep], radius)
    return moved


def _distinct(keys: np.ndarray) -> np.ndarray:
    """The distinct integers of ``keys``, sorted (by one sort: numpy's hashed unique is slower here)."""
    ordered = np.sort(keys)
    return ordered[np.concatenate([[True], ordered[1:] != ordered[:-1]])] if ordered.size else ordered


def _on_their_edges(
    centre: np.ndarray, p: np.ndarray, a: np.ndarray, b: np.ndarray, t: np.ndarray, radius: float
) -> np.ndarray:
    """Solve x_p = (1 − t) x_a + t x_b for the points ``p`` (rows of ``centre``; an end that is no
    such point keeps its place): the points on their edges, all at once.

    Each row has weights 1 and −(1 − t), −t: the matrix is singular only if a set of points all
    lie on edges ending at points of the same set (a ring of T-junctions with no fixed corner,
    which a finite drawing near a consistent one does not have); there, or wherever the solution
    would move a point farther than ``radius`` from its foot, each point is put on its edge as
    that edge lies now (the feet), and joint detection's tolerance closes what is left.
    """
    n = len(p)
    feet = (1.0 - t)[:, None] * centre[a] + t[:, None] * centre[b]
    var = np.full(len(centre), -1)
    var[p] = np.arange(n)
    rows, cols, vals = [np.arange(n)], [np.arange(n)], [np.ones(n)]
    rhs = np.zeros((n, 2))
    for end, weight in ((a, 1.0 - t), (b, t)):
        unknown = var[end] >= 0
        rows.append(np.flatnonzero(unknown))
        cols.append(var[end[unknown]])
        vals.append(-weight[unknown])
        rhs += np.where(unknown[:, None], 0.0, weight[:, None] * centre[end])
    matrix = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    if matrix.nnz == n:  # no point lies on an edge that ends at another: the feet themselves
        return rhs
    try:
        solved = splu(matrix).solve(rhs)
    except RuntimeError:  # exactly singular (see above)
        return feet
    if not np.isfinite(solved).all() or np.hypot(*(solved - feet).T).max() > radius:
        return feet
    return solved
