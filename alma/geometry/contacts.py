"""Joints: contacts between collinear, facing, overlapping block edges.

Every edge of every block is reduced to a line (direction of its outward normal
modulo π) and a position along it.  Facing edges of two blocks lie on nearly the
same line and have opposite normals.  Candidate pairs come from a hash of the line
angles, then, in a common frame per angle cell, a hash of the lines' offsets and an
interval join along the line (one sort of all edge extents), so the work grows with
the edges plus the pairs that really overlap — O(E log E) time and O(E) memory,
whatever the drawing's extent.  No Python loop runs over
blocks or joints.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from alma.geometry.corners import corner_contacts
from alma.geometry.edges import CONTACT, Edges, areas_and_centroids, contact_lengths, local_origin, scene_edges
from alma.geometry.snap import SnappedEdges, snap_edges

if TYPE_CHECKING:  # pragma: no cover
    from alma.geometry.scene import Scene

#: The widest angle (rad) between two edges still paired as candidates: caps the pruning slack
#: where a scene has very short edges.
MAX_ANGLE_TOLERANCE = 1e-2


@dataclass(frozen=True)
class Joints:
    """Joints of a scene (one row per joint).

    ``normal`` points from block ``block_a`` into block ``block_b``; ``tangent``
    is ``normal`` turned +90°; ``start`` and ``end`` are the two end points of
    the contact segment (the two contact points of the yield surface, Eq. 5).
    ``warnings`` names the facing edges that miss each other by more than the contact
    tolerance but less than the near-miss band (no joint is made there).
    """

    block_a: np.ndarray  # (m,) int
    block_b: np.ndarray  # (m,) int
    start: np.ndarray  # (m, 2)
    end: np.ndarray  # (m, 2)
    normal: np.ndarray  # (m, 2)
    warnings: tuple[str, ...] = ()

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


def reference_length(scene: Scene) -> float:
    """√(mean block area): the length that makes the model dimensionless."""
    return float(np.sqrt(block_areas_and_centroids(scene)[0].mean()))


def block_areas_and_centroids(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Areas (n,) and centroids (n, 2) of all blocks, vectorised over the flattened edges."""
    return areas_and_centroids(scene_edges(scene))


def find_joints(scene: Scene) -> Joints:
    """All joints of the scene: contacts of positive length between two blocks, and corners
    resting on faces (joints of zero length, :mod:`alma.geometry.corners`).

    The vertices are snapped first (:mod:`alma.geometry.snap`: vertices of different blocks
    within the contact tolerance are one point, a point that close to another block's edge lies
    on it).  Two facing edges then make a joint where both lie within the contact tolerance of
    each other's line (a gap or an overlap that small is closed: the joint lies midway) and
    overlap along it by more than the tolerance.  Joints between two fixed blocks carry nothing
    and are dropped.  Detection runs about a local origin, so that it does not depend on where
    the drawing sits.
    """
    origin = local_origin(scene)
    snapped, snap, band = snapped_edges(scene, origin)
    edges = snapped.edges
    i, j = snapped.pairs
    frames = _frames(edges, snap)
    joints, near = _contact_segments(scene, edges, i, j, *frames, snap, band) if i.size else (_empty_joints(), ())
    fixed = np.array([b.fixed for b in scene.blocks])
    a, b, point, normal = corner_contacts(edges, fixed, joints, snap, frames[3])
    block_a, block_b = np.concatenate([joints.block_a, a]), np.concatenate([joints.block_b, b])
    start, end = np.concatenate([joints.start, point]), np.concatenate([joints.end, point])
    order = np.lexsort((start[:, 1], start[:, 0], block_b, block_a))
    normals = np.concatenate([joints.normal, normal])[order]
    warnings = snapped.warnings + near
    return Joints(block_a[order], block_b[order], start[order] + origin, end[order] + origin, normals, warnings)


def snapped_edges(scene: Scene, origin: np.ndarray) -> tuple[SnappedEdges, float, float]:
    """The scene's edges about ``origin`` after snapping (:mod:`alma.geometry.snap`), with the
    contact tolerance and the near-miss band (mm).

    The snapping looks for T-junctions among the candidate facing pairs of the merged edges,
    searched with tolerances widened by the snapping's reach (a point moves by at most
    ``CONTACT.vertex_merge`` tolerances), so that the pairs are a superset of the snapped
    drawing's joints and :func:`find_joints` reuses them.
    """
    raw = scene_edges(scene, origin)  # flattened once: gathering the vertices is the one pass over blocks
    snap, band = contact_lengths(scene, raw)
    reach = (CONTACT.vertex_merge + 1.0) * snap
    return snap_edges(scene, raw, snap, functools.partial(_pair_indices, snap=reach, band=max(band, reach))), snap, band


def snapped_vertices(scene: Scene) -> tuple[np.ndarray, ...]:
    """Each block's vertices after snapping (mm, in the drawing's frame), in the scene's order:
    the drawing as joint detection and the overlap check see it (an unmoved vertex as drawn)."""
    origin = local_origin(scene)
    snapped, _, _ = snapped_edges(scene, origin)
    drawn = np.concatenate([b.vertices for b in scene.blocks])
    # An unmoved vertex is returned as drawn, not through the local origin and back (round-off).
    points = np.where(snapped.moved[:, None] > 0, snapped.edges.start + origin, drawn)
    counts = np.bincount(snapped.edges.block, minlength=len(scene.blocks))
    return tuple(np.split(points, np.cumsum(counts)[:-1]))


def _pair_indices(edges: Edges, snap: float, band: float) -> tuple[np.ndarray, np.ndarray]:
    """The candidate facing pairs (i, j) of :func:`_candidate_pairs`, empty when there is none."""
    pairs = _candidate_pairs(edges, snap, band)
    if pairs is None:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty
    i, j, _, outward, _, angle_tol = pairs
    # Only the pairs the search guarantees (tilt within its angle tolerance): a wider search (all
    # pairs) then gives the same pairs, hence the same snapping.
    tilt = np.abs(outward[i, 0] * outward[j, 1] - outward[i, 1] * outward[j, 0])
    keep = (tilt <= angle_tol) & ((outward[i] * outward[j]).sum(axis=1) < 0)
    return i[keep], j[keep]


def _frames(edges: Edges, snap: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Each edge's direction, outward normal and length, and the widest angle between two edges
    whose ends lie within ``snap`` of each other's line (2 snap / the shortest edge)."""
    vec = edges.end - edges.start
    length = np.hypot(vec[:, 0], vec[:, 1])
    direction = vec / length[:, None]
    outward = np.column_stack([direction[:, 1], -direction[:, 0]])  # CCW polygon: outward = right of edge
    # Two edges whose ends lie within ``snap`` of each other's line differ in angle by ≤ 2 snap / length.
    angle_tol = min(MAX_ANGLE_TOLERANCE, max(2.0 * snap / float(length.min()), 1e-12))
    return direction, outward, length, angle_tol


def _candidate_pairs(
    edges: Edges, snap: float, band: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, float] | None:
    """Edge pairs (i, j) of two blocks on nearly the same line (offsets within ``band``) with
    opposite outward normals, with each edge's direction, outward normal and length; None when
    there is none."""
    direction, outward, length, angle_tol = _frames(edges, snap)

    # Canonical line: unit normal d with angle in [0, π); its sign s relates to the outward normal.
    angle = np.mod(np.arctan2(outward[:, 1], outward[:, 0]), np.pi)
    angle = np.where(angle >= np.pi, 0.0, angle)  # mod may round up to π
    d = np.column_stack([np.cos(angle), np.sin(angle)])  # ±outward
    midpoint = 0.5 * (edges.start + edges.end)

    facing_sign = np.where((outward * d).sum(axis=1) > 0, 1.0, -1.0)  # outward = ±d
    # Lines near angle 0 ≡ π are duplicated on the other side of the wrap so the search sees them close.
    wrap = angle > np.pi - 4.0 * angle_tol
    ids = np.concatenate([np.arange(len(angle)), np.flatnonzero(wrap)])
    key_angle = np.concatenate([angle, angle[wrap] - np.pi])
    key_sign = np.concatenate([facing_sign, -facing_sign[wrap]])
    # Facing edges have opposite outward normals: pair only across the two orientations.
    plus, minus = np.flatnonzero(key_sign > 0), np.flatnonzero(key_sign < 0)
    p, q = _facing_candidates(key_angle, midpoint[ids], length[ids], band, plus, minus, angle_tol)
    if p.size == 0:
        return None
    i, j = ids[plus[p]], ids[minus[q]]
    keep = edges.block[i] != edges.block[j]
    i, j = i[keep], j[keep]
    # dedupe pairs created by the wrap duplicates
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    _, unique = np.unique(lo * (len(angle) + 1) + hi, return_index=True)
    i, j = lo[unique], hi[unique]
    return i, j, direction, outward, length, angle_tol


def _contact_segments(
    scene: Scene,
    edges: Edges,
    i: np.ndarray,
    j: np.ndarray,
    direction: np.ndarray,
    outward: np.ndarray,
    length: np.ndarray,
    angle_tol: float,
    snap: float,
    band: float,
) -> tuple[Joints, tuple[str, ...]]:
    """The joints of the candidate pairs, numbered with block_a < block_b (pairs of two fixed
    blocks dropped), and the near misses: facing, overlapping edges apart by (snap, band]."""
    # Overlap along edge i's direction.
    t_i = direction[i]
    origin = edges.start[i]
    b0 = ((edges.start[j] - origin) * t_i).sum(axis=1)
    b1 = ((edges.end[j] - origin) * t_i).sum(axis=1)
    s0 = np.maximum(0.0, np.minimum(b0, b1))
    s1 = np.minimum(length[i], np.maximum(b0, b1))
    overlapping = s1 - s0 > snap
    # The gap from edge i's line to edge j's at both ends of the common part (> 0 open, < 0 an
    # overlap), and the tilt between the two lines.
    n_j = outward[j]
    gap = np.column_stack(
        [
            ((origin + s0[:, None] * t_i - edges.start[j]) * n_j).sum(axis=1),
            ((origin + s1[:, None] * t_i - edges.start[j]) * n_j).sum(axis=1),
        ]
    )
    apart = np.abs(gap).max(axis=1)
    tilt = np.abs(outward[i, 0] * n_j[:, 1] - outward[i, 1] * n_j[:, 0])
    # Facing: nearly opposite normals (the same line seen from one side is an overlap, not a joint).
    parallel = (tilt <= angle_tol) & ((outward[i] * n_j).sum(axis=1) < 0)
    fixed = np.array([b.fixed for b in scene.blocks])
    both_fixed = fixed[edges.block[i]] & fixed[edges.block[j]]
    joint = overlapping & parallel & (apart <= snap) & ~both_fixed
    near = overlapping & parallel & (apart > snap) & (apart <= band) & ~both_fixed
    # The message gives the gap the decision compared with the tolerance: the larger end's.
    worst = gap[near][np.arange(int(near.sum())), np.abs(gap[near]).argmax(axis=1)]
    warnings = _near_misses(scene, edges.block[i[near]], edges.block[j[near]], worst, (s1 - s0)[near], snap)

    i, j, s0, s1, t_i, origin = i[joint], j[joint], s0[joint], s1[joint], t_i[joint], origin[joint]
    block_a, block_b = edges.block[i], edges.block[j]
    # Orient joints so block_a < block_b for a stable numbering independent of edge order.
    swap = block_a > block_b
    bisector = outward[i] - outward[j]  # the two outward normals are nearly opposite: their mean line
    bisector /= np.hypot(bisector[:, 0], bisector[:, 1])[:, None]
    normal = np.where(swap[:, None], -bisector, bisector)
    start = _midway(origin + s0[:, None] * t_i, edges.start[j], outward[j])
    end = _midway(origin + s1[:, None] * t_i, edges.start[j], outward[j])
    a = np.where(swap, block_b, block_a)
    b = np.where(swap, block_a, block_b)
    order = np.lexsort((start[:, 1], start[:, 0], b, a))
    joints = Joints(block_a=a[order], block_b=b[order], start=start[order], end=end[order], normal=normal[order])
    return joints, warnings


def _midway(point: np.ndarray, on_line: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Points halfway between ``point`` (on one edge's line) and its projection on the facing
    edge's line (through ``on_line``, unit ``normal``): a snapped gap or overlap is split evenly."""
    return point - 0.5 * ((point - on_line) * normal).sum(axis=1)[:, None] * normal


def _near_misses(
    scene: Scene, a: np.ndarray, b: np.ndarray, gap: np.ndarray, overlap: np.ndarray, snap: float
) -> tuple[str, ...]:
    """One message per pair of blocks whose facing edges miss each other (see _contact_segments)."""
    if a.size == 0:
        return ()
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    _, first = np.unique(lo * len(scene.blocks) + hi, return_index=True)
    ids = [blk.id for blk in scene.blocks]
    return tuple(
        f"blocks '{ids[lo[k]]}' and '{ids[hi[k]]}' nearly touch: facing edges "
        f"{'apart' if gap[k] > 0 else 'overlapping'} by up to {abs(gap[k]):.3g} mm over {overlap[k]:.3g} mm, "
        f"beyond the contact tolerance ({snap:.3g} mm): no joint is made there"
        for k in first.tolist()
    )


def _facing_candidates(
    angle: np.ndarray,
    midpoint: np.ndarray,
    length: np.ndarray,
    band: float,
    plus: np.ndarray,
    minus: np.ndarray,
    angle_tol: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (p, q) of key rows ``plus[p]``, ``minus[q]`` that may face each other.

    A superset of the pairs whose line angles differ by at most ``angle_tol``, whose lines are
    within ``band`` of each other and whose extents along the line intersect.  Angles are hashed
    to cells a little over ``2 angle_tol`` wide; each cell is a frame (its central direction); a
    ``plus`` row enters its own frame, a ``minus`` row its own and the neighbour on its nearer
    side (a partner within ``angle_tol`` in another cell can only be there).  In a frame, every
    row's offset and along coordinate are the projections of its midpoint on the same two axes,
    so two facing edges differ in offset by at most ``band`` plus their lengths times the
    frame's tilt — a bound that holds wherever the edges sit.  Offsets are hashed to cells of
    2.5 times that bound, a ``plus`` row looking into its own and its nearer neighbour, and
    within matched cells an interval join pairs only overlapping extents: time O(E log E +
    pairs) and memory O(E + pairs), independent of the drawing's extent (offsets measured about
    a distant origin on each edge's own axis needed a slack growing with the distance, which
    paired whole courses of a wall with a far block).
    """
    # 2.01: a tilt of angle_tol between two lines is an angle of asin(angle_tol) ≤ 1.0001 angle_tol.
    width_a = 2.01 * angle_tol
    position = angle / width_a
    cell_a = np.floor(position).astype(np.int64)
    nearer = np.where(position - cell_a < 0.5, -1, 1)
    rows = np.concatenate([plus, minus, minus])
    frame = np.concatenate([cell_a[plus], cell_a[minus], cell_a[minus] + nearer[minus]])
    theta = (frame + 0.5) * width_a
    point = midpoint[rows]
    offset = point[:, 0] * np.cos(theta) + point[:, 1] * np.sin(theta)
    along = point[:, 1] * np.cos(theta) - point[:, 0] * np.sin(theta)
    # A row's direction is within 1.5 cells (3.015 angle_tol) of its frame's, and two facing
    # rows' midpoints lie within half their summed lengths of each other along the line: their
    # offsets differ by at most band + reach · 3.015 angle_tol.  1e-12 of the coordinates covers
    # round-off.
    roundoff = 1e-12 * float(np.abs(point).max(initial=0.0))
    slack_o = band + 4.0 * angle_tol * float(length.max(initial=0.0)) + roundoff
    width_o = max(2.5 * slack_o, 2.0**-48 * float(np.abs(offset).max(initial=0.0)))
    position = offset / width_o
    cell_o = np.floor(position).astype(np.int64)
    n_plus = len(plus)
    # Plus rows look into their offset cell and its nearer neighbour; minus rows sit in theirs.
    side = np.where(position[:n_plus] - cell_o[:n_plus] < 0.5, -1, 1)
    x_frame = np.tile(frame[:n_plus], 2)
    x_cell = np.concatenate([cell_o[:n_plus], cell_o[:n_plus] + side])
    group = _group_ids(np.concatenate([x_frame, frame[n_plus:]]), np.concatenate([x_cell, cell_o[n_plus:]]))
    x_at = np.tile(np.arange(n_plus), 2)
    # Half extent + slack: the perpendicular gap (≤ band) seen on an axis tilted by ≤ 3.015
    # angle_tol, and round-off.
    half = 0.5 * length[rows] + 2.0 * band + roundoff
    lo, hi = along - half, along + half
    x, y = _overlapping_intervals(
        group[: 2 * n_plus], lo[x_at], hi[x_at], group[2 * n_plus :], lo[n_plus:], hi[n_plus:]
    )
    x, y = x_at[x], y + n_plus
    close = np.abs(offset[x] - offset[y]) <= slack_o
    # Minus rows entered two frames: back to their index in ``minus``.
    return x[close], (y[close] - n_plus) % max(len(minus), 1)


def _group_ids(major: np.ndarray, minor: np.ndarray) -> np.ndarray:
    """One integer per distinct (major, minor) pair, by one lexicographic sort."""
    order = np.lexsort((minor, major))
    new = np.ones(len(order), dtype=bool)
    new[1:] = (np.diff(major[order]) != 0) | (np.diff(minor[order]) != 0)
    group = np.empty(len(order), dtype=np.int64)
    group[order] = np.cumsum(new) - 1
    return group


def _ranges(start: np.ndarray, stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(owner, k) for every k in range(start[owner], stop[owner]), vectorised."""
    count = np.maximum(stop - start, 0)
    owner = np.repeat(np.arange(len(count)), count)
    k = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count - start, count)
    return owner, k


def _overlapping_intervals(
    gx: np.ndarray, lox: np.ndarray, hix: np.ndarray, gy: np.ndarray, loy: np.ndarray, hiy: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """All (x, y) with ``gx == gy`` whose closed intervals [lo, hi] intersect, each pair once.

    One lexicographic sort of all end points by (group, value, kind) gives both halves of an
    intersection: y starts inside x (lox ≤ loy ≤ hix) or x starts strictly inside y
    (loy < lox ≤ hiy); each half is a contiguous run of the sorted starts, read off by
    counting.  Cost O(N log N + pairs).
    """
    nx, ny = len(gx), len(gy)
    # kind breaks ties: x starts, y starts, x ends, y ends (closed intervals, halves disjoint)
    kind = np.repeat(np.arange(4, dtype=np.int8), [nx, ny, nx, ny])
    order = np.lexsort((kind, np.concatenate([lox, loy, hix, hiy]), np.concatenate([gx, gy, gx, gy])))
    sorted_kind = kind[order]
    position = np.empty_like(order)
    position[order] = np.arange(len(order))
    starts_x = np.cumsum(sorted_kind == 0)  # x starts up to (and including) each position
    starts_y = np.cumsum(sorted_kind == 1)
    by_start_x = order[sorted_kind == 0]  # x indices sorted by (group, start)
    by_start_y = order[sorted_kind == 1] - nx
    # y starts inside x: the y starts between x's start and x's end
    x1, k1 = _ranges(starts_y[position[:nx]], starts_y[position[nx + ny : 2 * nx + ny]])
    # x starts strictly inside y: the x starts after y's start, up to y's end
    y2, k2 = _ranges(starts_x[position[nx : nx + ny]], starts_x[position[2 * nx + ny :]])
    return np.concatenate([x1, by_start_x[k2]]), np.concatenate([by_start_y[k1], y2])


def _empty_joints() -> Joints:
    empty = np.zeros((0, 2))
    return Joints(
        block_a=np.zeros(0, dtype=int),
        block_b=np.zeros(0, dtype=int),
        start=empty,
        end=empty.copy(),
        normal=empty.copy(),
    )
