"""Course-segment energy cuts of the certification MILP: "this segment slides on its support".

A *course* is a row of free blocks standing on one straight support line of fixed blocks (the
ground) and joined to each other by head joints perpendicular to that line.  A *segment* S is a
run of consecutive blocks of a course.  In a collapse state (Eq. 9) where every point of S's
internal head joints is closed and every other joint of S's blocks with a free block outside S
is either open or presses on S from above:

- the internal heads have zero normal velocity at two points each, so the blocks of S share
  their rotation and their velocity along the support line: every bed point of S slips by the
  same γ_S (the tangential velocity of a rigid motion is constant along a straight line);
- the open joints carry nothing, the joints from above push S onto its bed and the live load
  has no component along the bed normal n, so equilibrium along n gives Σ_bed N = W_S + Σ_top N
  ≥ W_S (W_S = the dead load of S pressing on its bed);

hence the dissipation on S's bed is Σ f N |γ_S| ≥ f_S W_S |γ_S| (f_S the least friction there)
and the energy balance of the state (:mod:`alma.certify.milp`) gives

    α n_free ≥ −f₀ᵀu + f_S W_S |γ_S| + Σ_{j ∉ bed(S)} f ℓ_j |γ_j|,

where the per-joint cut (ℓ_j = min N_j, often 0) gives only Σ_{j ∈ bed(S)} f ℓ_j |γ_j|.  The
condition is written with the MILP's open/closed binaries o_p and a big-M constant
M_E = f_S W_S max_j (M_γ⁺,j + M_γ⁻,j) that releases the cut whenever one internal point is open
or one outside point is closed (the existing cut still holds there, and the released row's
right-hand side exceeds it by at most M_E).  |γ_S| is the mean of γ⁺_j + γ⁻_j over S's bed joints
(equal to |γ_S| at every integer point, where one of γ⁺_j, γ⁻_j is 0).

Scenes with bounded forces (cohesion, ties) get no segment cut: an open cohesive joint or a tie
could carry part of S's weight.  Forces in mean block weights.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from alma.mechanics.model import Model

#: Cosine below which two directions count as perpendicular, and above which (1 − it) parallel.
_ALIGNED = 1e-9


@dataclass(frozen=True)
class Segment:
    """One run S of consecutive blocks of a course (joint and point indices of the model)."""

    bed_joints: np.ndarray  # S's joints with the support (all on one line)
    closed_points: np.ndarray  # points of S's internal head joints (closed in the cut's condition)
    open_points: np.ndarray  # points of S's other joints with free blocks outside S, except from above
    weight: float  # W_S, the dead load of S along −n (mean block weights)
    friction: float  # the least friction on S's bed


def _bed_lines(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For every free block, the inward normal and offset of its support joints (NaN when it has
    none, or support joints on more than one line), and the mask of support joints."""
    J, fi = model.joints, model.free_index
    free_a, free_b = fi[J.block_a] >= 0, fi[J.block_b] >= 0
    support = free_a ^ free_b
    block = np.where(free_b, fi[J.block_b], fi[J.block_a])[support]
    inward = (J.normal * np.where(free_b, 1.0, -1.0)[:, None])[support]  # into the free block
    offset = np.einsum("ij,ij->i", inward, J.start[support]) / model.length_scale
    n_free = model.n_free
    normal = np.full((n_free, 2), np.nan)
    line = np.full(n_free, np.nan)
    normal[block], line[block] = inward, offset
    # A block whose support joints disagree (two lines or two directions) gets no bed.
    spread = np.zeros(n_free)
    np.maximum.at(spread, block, np.abs(inward - normal[block]).max(axis=1) + np.abs(offset - line[block]))
    normal[spread > 1e-9], line[spread > 1e-9] = np.nan, np.nan
    return normal, line, support


def course_segments(model: Model, binary_points: np.ndarray) -> list[Segment]:
    """Every segment of every course of the scene (see the module docstring); none with bounded forces.

    ``binary_points``: the points that have an open/closed binary in the MILP (the others carry
    no force in any admissible field).  A segment whose internal heads have a point without a
    binary is left out (its closedness cannot be written).
    """
    if model.n_bounded or model.n_free == 0:
        return []
    J, fi = model.joints, model.free_index
    normal, line, support = _bed_lines(model)
    a, b = fi[J.block_a], fi[J.block_b]
    both = (a >= 0) & (b >= 0)
    has_bed = ~np.isnan(line)
    same_bed = np.zeros(J.count, dtype=bool)
    ok = both & has_bed[np.maximum(a, 0)] & has_bed[np.maximum(b, 0)]
    same_bed[ok] = ((np.abs(normal[a[ok]] - normal[b[ok]]).max(axis=1) < 1e-9)
                    & (np.abs(line[a[ok]] - line[b[ok]]) < 1e-9))
    # Head joints: between two blocks on one bed line, perpendicular to it.
    head = same_bed.copy()
    head[same_bed] = np.abs(np.einsum("ij,ij->i", J.normal[same_bed], normal[a[same_bed]])) < _ALIGNED
    live_n = np.einsum("ij,ij->i", model.live.reshape(-1, 3)[:, :2], np.nan_to_num(normal))
    dead_n = -np.einsum("ij,ij->i", model.dead.reshape(-1, 3)[:, :2], np.nan_to_num(normal))
    eligible = has_bed & (np.abs(live_n) < 1e-12) & (dead_n > 0)
    head &= eligible[np.maximum(a, 0)] & eligible[np.maximum(b, 0)]
    graph = sp.csr_matrix((np.ones(int(head.sum())), (a[head], b[head])), shape=(model.n_free,) * 2)
    _, label = connected_components(graph, directed=False)
    segments: list[Segment] = []
    tangent = np.column_stack([-normal[:, 1], normal[:, 0]])
    for course in np.unique(label[eligible]):
        members = np.flatnonzero((label == course) & eligible)
        order = members[np.argsort(np.einsum("ij,ij->i", model.centroid[members], tangent[members]))]
        segments += _course(model, order, head, support, dead_n, normal, binary_points, a, b)
    return segments


def _course(model: Model, order: np.ndarray, head: np.ndarray, support: np.ndarray, dead_n: np.ndarray,
            normal: np.ndarray, binary_points: np.ndarray, a: np.ndarray, b: np.ndarray) -> list[Segment]:
    """The segments of one course (blocks ``order`` along the bed), one per run of consecutive
    blocks (k (k + 1) / 2 of them); a course that is not a simple row gives none."""
    J = model.joints
    k = order.size
    pos = np.full(model.n_free, -1)
    pos[order] = np.arange(k)
    in_course_head = head & (pos[np.maximum(a, 0)] >= 0) & (pos[np.maximum(b, 0)] >= 0)
    gaps = np.abs(pos[a[in_course_head]] - pos[b[in_course_head]])
    if np.any(gaps != 1):  # not a simple row (a block touching a non-neighbour): no cut
        return []
    has_binary = np.zeros(2 * J.count, dtype=bool)
    has_binary[binary_points] = True
    free_other = (a >= 0) & (b >= 0)
    out = []
    for i in range(k):
        for j in range(i, k):
            member = np.zeros(model.n_free, dtype=bool)
            member[order[i:j + 1]] = True
            in_a, in_b = member[np.maximum(a, 0)] & (a >= 0), member[np.maximum(b, 0)] & (b >= 0)
            internal = in_course_head & in_a & in_b
            closed = np.flatnonzero(np.repeat(internal, 2))
            if not has_binary[closed].all():
                continue
            crossing = free_other & (in_a ^ in_b)
            inside = np.where(in_a, a, b)
            n_in = normal[np.maximum(inside, 0)]
            into_s = J.normal * np.where(in_b, 1.0, -1.0)[:, None]  # the joint's normal pointing into S
            from_above = crossing & (np.einsum("ij,ij->i", into_s, np.nan_to_num(n_in)) < -1 + _ALIGNED)
            opened = np.flatnonzero(np.repeat(crossing & ~from_above, 2))
            bed = np.flatnonzero(support & (in_a | in_b))
            f_s = float(model.friction[bed].min())
            out.append(Segment(bed, closed, opened[has_binary[opened]], float(dead_n[order[i:j + 1]].sum()), f_s))
    return out
