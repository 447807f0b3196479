"""Joints: contacts between collinear, facing, overlapping block edges.

Every edge of every block is reduced to a line key (direction of its outward
normal modulo π, signed distance of its line from the origin) and a position
along the line.  Facing edges of two blocks share the line key and have
opposite normals.  Candidate pairs come from a hash of the line keys (cells of
twice the tolerances) and, within matching cells, an interval join along the line
(one sort of all edge extents), so the work grows with the edges plus the pairs
that really overlap: O(E log E) time and O(E) memory.  No Python loop runs over
blocks or joints.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from alma.geometry.edges import Edges, areas_and_centroids, contact_lengths, local_origin, scene_edges

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


def reference_length(scene: "Scene") -> float:
    """√(mean block area): the length that makes the model dimensionless."""
    return float(np.sqrt(block_areas_and_centroids(scene)[0].mean()))


def block_areas_and_centroids(scene: "Scene") -> tuple[np.ndarray, np.ndarray]:
    """Areas (n,) and centroids (n, 2) of all blocks, vectorised over the flattened edges."""
    return areas_and_centroids(scene_edges(scene))


def find_joints(scene: "Scene") -> Joints:
    """All joints of the scene (contacts of positive length between two blocks).

    Two facing edges make a joint where both lie within the contact tolerance of each other's
    line (a gap or an overlap that small is snapped: the joint lies midway) and overlap along
    it by more than the tolerance.  Joints between two fixed blocks carry nothing and are
    dropped.  Detection runs about a local origin, so that it does not depend on where the
    drawing sits.
    """
    origin = local_origin(scene)
    edges = scene_edges(scene, origin)  # flattened once: gathering the vertices is the one pass over blocks
    snap, band = contact_lengths(scene, edges)
    pairs = _candidate_pairs(edges, snap, band)
    if pairs is None:
        return _empty_joints()
    joints, near = _contact_segments(scene, edges, *pairs, snap, band)
    return Joints(block_a=joints.block_a, block_b=joints.block_b, start=joints.start + origin,
                  end=joints.end + origin, normal=joints.normal, warnings=near)


def _candidate_pairs(edges: Edges, snap: float, band: float) -> tuple[np.ndarray, ...] | None:
    """Edge pairs (i, j) of two blocks on nearly the same line (offsets within ``band``) with
    opposite outward normals, with each edge's direction, outward normal and length; None when
    there is none."""
    vec = edges.end - edges.start
    length = np.hypot(vec[:, 0], vec[:, 1])
    direction = vec / length[:, None]
    outward = np.column_stack([direction[:, 1], -direction[:, 0]])  # CCW polygon: outward = right of edge
    # Two edges whose ends lie within ``snap`` of each other's line differ in angle by ≤ 2 snap / length.
    angle_tol = min(MAX_ANGLE_TOLERANCE, max(2.0 * snap / float(length.min()), 1e-12))

    # Canonical line: unit normal d with angle in [0, π); its sign s relates to the outward normal.
    angle = np.mod(np.arctan2(outward[:, 1], outward[:, 0]), np.pi)
    angle = np.where(angle >= np.pi, 0.0, angle)  # mod may round up to π
    d = np.column_stack([np.cos(angle), np.sin(angle)])  # ±outward
    midpoint = 0.5 * (edges.start + edges.end)
    offset = (midpoint * d).sum(axis=1)
    along = midpoint[:, 0] * -d[:, 1] + midpoint[:, 1] * d[:, 0]

    facing_sign = np.where((outward * d).sum(axis=1) > 0, 1.0, -1.0)  # outward = ±d
    # Lines near angle 0 ≡ π are duplicated on the other side of the wrap so the search sees them close.
    wrap = angle > np.pi - 4.0 * angle_tol
    ids = np.concatenate([np.arange(len(angle)), np.flatnonzero(wrap)])
    key_angle = np.concatenate([angle, angle[wrap] - np.pi])
    key_offset = np.concatenate([offset, -offset[wrap]])
    key_along = np.concatenate([along, -along[wrap]])
    key_sign = np.concatenate([facing_sign, -facing_sign[wrap]])
    reach = float(length.max())
    points = np.column_stack([key_angle * (reach / angle_tol), key_offset * (reach / band), key_along])
    # Facing edges have opposite outward normals: pair only across the two orientations.
    plus, minus = np.flatnonzero(key_sign > 0), np.flatnonzero(key_sign < 0)
    p, q = _facing_candidates(key_angle, key_offset, key_along, length[ids], np.abs(midpoint[ids]).sum(axis=1),
                              band, plus, minus, angle_tol)
    # Sup-norm distance ≤ reach between the scaled keys: the pruning above only drops pairs
    # that cannot overlap.
    close = np.abs(points[plus[p]] - points[minus[q]]).max(axis=1, initial=0.0) <= reach
    p, q = p[close], q[close]
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


def _contact_segments(scene: "Scene", edges: Edges, i: np.ndarray, j: np.ndarray, direction: np.ndarray,
                      outward: np.ndarray, length: np.ndarray, angle_tol: float, snap: float,
                      band: float) -> tuple[Joints, tuple[str, ...]]:
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
    gap = np.column_stack([((origin + s0[:, None] * t_i - edges.start[j]) * n_j).sum(axis=1),
                           ((origin + s1[:, None] * t_i - edges.start[j]) * n_j).sum(axis=1)])
    apart = np.abs(gap).max(axis=1)
    tilt = np.abs(outward[i, 0] * n_j[:, 1] - outward[i, 1] * n_j[:, 0])
    parallel = tilt <= angle_tol
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


def _near_misses(scene: "Scene", a: np.ndarray, b: np.ndarray, gap: np.ndarray, overlap: np.ndarray,
                 snap: float) -> tuple[str, ...]:
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
        for k in first.tolist())


def _facing_candidates(angle: np.ndarray, offset: np.ndarray, along: np.ndarray, length: np.ndarray,
                       size: np.ndarray, tol_len: float, plus: np.ndarray, minus: np.ndarray,
                       angle_tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (p, q) of key rows ``plus[p]``, ``minus[q]`` that may face each other.

    A superset of the pairs whose line keys differ by at most ``angle_tol`` in angle and
    ``tol_len`` in offset and whose extents along the line intersect.  The extents are widened
    by a slack covering round-off and the tilt allowed between two such lines (their along
    coordinates are measured on slightly different axes), so every pair with a positive
    overlap is kept.  Line keys are hashed to cells twice the tolerances wide: nearly equal
    lines fall in the same or adjacent cells.  Within matched cells an interval join pairs
    only overlapping extents, so the cost grows with the edges plus the overlapping pairs —
    a fixed radius (the longest edge, e.g. a ground as long as the wall) paired every edge
    with all edges of its course and made the candidates grow as n^1.5.
    """
    width_a = 2.0 * angle_tol
    # Cells stay exact integers in floating point (|index| < 2^49) whatever the scene's extent.
    width_o = max(2.0 * tol_len, 2.0 ** -48 * float(np.abs(offset).max(initial=0.0)))
    cell = (np.floor(angle / width_a) + 0.0) + 1j * (np.floor(offset / width_o) + 0.0)  # + 0.0: no -0
    cells, which = np.unique(cell, return_inverse=True)  # complex sort: by angle cell, then offset cell
    has_minus = np.zeros(len(cells), dtype=bool)
    has_minus[which[minus]] = True
    u_all = np.unique(which[plus])
    pair_u, pair_v = [], []
    for shift in (complex(da, do) for da in (-1, 0, 1) for do in (-1, 0, 1)):  # 9 neighbour cells
        target = cells[u_all] + shift
        v = np.minimum(np.searchsorted(cells, target), len(cells) - 1)
        hit = (cells[v] == target) & has_minus[v]
        pair_u.append(u_all[hit])
        pair_v.append(v[hit])
    pair_u, pair_v = np.concatenate(pair_u), np.concatenate(pair_v)
    if pair_u.size == 0:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)

    # Each row joins every cell pair of its cell; the pair index is its group in the join.
    p, group_p = _expand(which[plus], pair_u, len(cells))
    q, group_q = _expand(which[minus], pair_v, len(cells))
    # Half extent + slack: a tilt ≤ angle_tol between two lines moves the along coordinate
    # of a point by ≤ |point| · tilt (size = |midpoint|₁); 4× and 1e-12 are margins for round-off.
    half = 0.5 * length + 10.0 * tol_len + (4.0 * angle_tol + 1e-12) * (size + length)
    rows_p, rows_q = plus[p], minus[q]
    x, y = _overlapping_intervals(group_p, along[rows_p] - half[rows_p], along[rows_p] + half[rows_p],
                                  group_q, along[rows_q] - half[rows_q], along[rows_q] + half[rows_q])
    return p[x], q[y]


def _expand(cell: np.ndarray, pair_cell: np.ndarray, n_cells: int) -> tuple[np.ndarray, np.ndarray]:
    """(row, pair) for every row and every cell pair whose cell on the row's side is the row's cell."""
    order = np.argsort(pair_cell, kind="stable")
    count = np.bincount(pair_cell, minlength=n_cells)
    first = np.cumsum(count) - count
    row, at = _ranges(first[cell], first[cell] + count[cell])
    return row, order[at]


def _ranges(start: np.ndarray, stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(owner, k) for every k in range(start[owner], stop[owner]), vectorised."""
    count = np.maximum(stop - start, 0)
    owner = np.repeat(np.arange(len(count)), count)
    k = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count - start, count)
    return owner, k


def _overlapping_intervals(gx: np.ndarray, lox: np.ndarray, hix: np.ndarray, gy: np.ndarray, loy: np.ndarray,
                           hiy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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
    x1, k1 = _ranges(starts_y[position[:nx]], starts_y[position[nx + ny:2 * nx + ny]])
    # x starts strictly inside y: the x starts after y's start, up to y's end
    y2, k2 = _ranges(starts_x[position[nx:nx + ny]], starts_x[position[2 * nx + ny:]])
    return np.concatenate([x1, by_start_x[k2]]), np.concatenate([by_start_y[k1], y2])


def _empty_joints() -> Joints:
    empty = np.zeros((0, 2))
    return Joints(block_a=np.zeros(0, dtype=int), block_b=np.zeros(0, dtype=int),
                  start=empty, end=empty.copy(), normal=empty.copy())
