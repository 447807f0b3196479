"""Block outlines checked against SPEC §2, vectorised over all edges, and overlapping blocks.

Free blocks must be convex; fixed blocks may be any simple polygon.  Every rule reads the
contact tolerance (:func:`alma.geometry.edges.contact_lengths`): a hanging node bumped by less
than it is still a straight edge, an overlap no deeper than it is snapped to a joint, while an
outline that doubles back on itself (a polyline drawn past its closing point) is refused.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from alma.geometry.contacts import snapped_edges
from alma.geometry.edges import Edges, contact_lengths, local_origin, previous_edge, scene_edges, signed_areas
from alma.geometry.parsing import SceneError

if TYPE_CHECKING:  # pragma: no cover
    from alma.geometry.scene import Scene


def check_polygons(scene: Scene) -> None:
    """Refuse the first block (in scene order) whose outline breaks a rule, naming it and the rule."""
    edges = scene_edges(scene, local_origin(scene))
    snap, _ = contact_lengths(scene, edges)
    fixed = np.array([b.fixed for b in scene.blocks])
    vec = edges.end - edges.start
    length = np.hypot(vec[:, 0], vec[:, 1])
    before = previous_edge(edges)  # the edge ending at each edge's start vertex
    e1, e2 = vec[before], vec
    cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    dot = (e1 * e2).sum(axis=1)
    lo, hi = _extent(edges)
    size = np.maximum(hi - lo, 0.0).max(axis=1)
    floor = np.maximum(snap, 1e-12 * size)[edges.block]
    chord = np.hypot(*(e1 + e2).T)
    area = signed_areas(edges)
    flat = ~(area > np.maximum(snap * size, 1e-9 * size * size))
    rules = [
        (length <= floor, "degenerate polygon — repeated vertices (an edge shorter than the contact tolerance)"),
        (flat[edges.block], "degenerate polygon — zero area"),
        (
            (dot < 0) & (np.abs(cross) <= floor * np.maximum(length, length[before])),
            "the outline doubles back on itself at vertex {k} (drawn past its closing point, or a repeated edge)",
        ),
        (
            (cross < 0) & (-cross > floor * chord) & ~fixed[edges.block],
            "polygon is not convex (a reflex corner at vertex {k}); only a fixed block may be non-convex",
        ),
    ]
    first = np.concatenate([[0], np.flatnonzero(np.diff(edges.block)) + 1])
    for bad, message in rules:
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            block = int(edges.block[row])
            raise SceneError(f"block '{scene.blocks[block].id}': " + message.format(k=row - first[block]))
    _check_simple(scene, edges)


def _check_simple(scene: Scene, edges: Edges) -> None:
    import shapely

    rings = shapely.linearrings(edges.start, indices=edges.block)
    simple = shapely.is_simple(rings)
    if not simple.all():
        raise SceneError(
            f"block '{scene.blocks[int(np.flatnonzero(~simple)[0])].id}': "
            "polygon is self-intersecting (its outline crosses itself): neither convex nor simple"
        )


def find_overlaps(scene: Scene) -> tuple[list[tuple[int, int, float]], float]:
    """Pairs of blocks that interpenetrate deeper than the contact tolerance, each with its depth
    (mm), and that tolerance (mm).

    The depth of an overlap is 2 area / perimeter of the intersection (the width of a thin
    sliver), so an overlap snapped to a joint by :func:`alma.geometry.contacts.find_joints` is
    not an error and a real one is.  The outlines are those after snapping
    (:mod:`alma.geometry.snap`), as joint detection sees them.
    """

    snapped, snap, _ = snapped_edges(scene, local_origin(scene))
    a, b, depth = overlap_depths(snapped.edges.start, snapped.edges.block)
    bad = depth > max(snap, 1e-12)
    return [(int(x), int(y), float(z)) for x, y, z in zip(a[bad], b[bad], depth[bad], strict=True)], snap


def overlap_depths(
    vertices: np.ndarray, block: np.ndarray, among: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pairs of outlines (i < j) whose interiors intersect and the depth of each intersection
    (mm): 2 area / perimeter, the width of a thin sliver.  ``vertices`` (V, 2) are the blocks'
    outlines one after the other, ``block`` (V,) the block of each; ``among`` (bool per block):
    only the pairs with at least one such block (None: all pairs).  Outlines that only touch (a
    joint) are not intersected, their depth being 0."""
    import shapely

    polygons = shapely.polygons(shapely.linearrings(vertices, indices=block))
    tree = shapely.STRtree(polygons)
    if among is None:
        a, b = tree.query(polygons, predicate="intersects")
    else:
        rows = np.flatnonzero(among)
        q, b = tree.query(polygons[rows], predicate="intersects")
        a = rows[q]
        # a pair of two such blocks is found from both ends: keep it once, as (i < j)
        a, b = np.minimum(a, b), np.maximum(a, b)
        a, b = np.unique(np.column_stack([a, b]), axis=0).T if a.size else (a, b)
    keep = a < b
    a, b = a[keep], b[keep]
    inside = ~shapely.touches(polygons[a], polygons[b])
    a, b = a[inside], b[inside]
    common = shapely.intersection(polygons[a], polygons[b])
    area, perimeter = shapely.area(common), shapely.length(common)
    return a, b, np.where(perimeter > 0, 2.0 * area / np.where(perimeter > 0, perimeter, 1.0), 0.0)


def _extent(edges: Edges) -> tuple[np.ndarray, np.ndarray]:
    n = int(edges.block.max()) + 1
    lo = np.full((n, 2), np.inf)
    hi = np.full((n, 2), -np.inf)
    np.minimum.at(lo, edges.block, edges.start)
    np.maximum.at(hi, edges.block, edges.start)
    return lo, hi
