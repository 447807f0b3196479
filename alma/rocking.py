"""Candidate mechanisms of rigid macro-blocks rocking about a support point (starts for Eq. 9).

A set S of blocks turning as one rigid body about a pivot c, every other block
at rest, is a mechanism of the non-associative model when no contact point
interpenetrates (opening ξ ≥ 0, Eq. 2); its points may open or slip freely.
S is grown from one seed block: turning the seed about one of its support
points pushes into some neighbours, and those join S (they turn with it),
until no point interpenetrates, or the ground would be pushed (no mechanism),
or S passes a size limit.

The virtual work of such a mechanism bounds its collapse multiplier from below,
α ≥ −f_0ᵀu / f_Lᵀu (the lifting work; the friction dissipation Σ f N |γ| is
≥ 0), with equality when the static field can leave the slipping points
unloaded.  The associative LP cannot see these mechanisms where a face slides
without opening (a corner column rocking off its neighbour's face), and the
Gilbert iterates find them only by chance; they are ranked by that bound and
the lowest are made exact and verified like every other candidate.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .contact_points import ContactPoints
from .model import Model


@dataclass(frozen=True)
class RockingCandidate:
    """A rigid rotation of ``blocks`` (free-block indices) about ``pivot`` (dimensionless)."""

    blocks: tuple[int, ...]
    pivot: tuple[float, float]
    rotation: float  # ω, +1 counter-clockwise
    lifting_bound: float  # −f_0ᵀu / f_Lᵀu ≤ α of any collapse state with this mechanism
    mechanism: np.ndarray  # u (3 n_free), f_Lᵀu = n_free


def rocking_candidates(model: Model, points: ContactPoints, *, max_blocks: int = 60,
                       tolerance: float = 1e-9) -> list[RockingCandidate]:
    """All macro-block rotations grown from single blocks (see module docstring), lowest bound first.

    Seeds: every free block, turned clockwise about the support point furthest along
    +x (across gravity) and counter-clockwise about the one furthest back (the points of
    the contacts it rests on).
    Distinct (blocks, pivot) pairs only; candidates whose live load does no
    positive work are dropped.
    """
    joints = model.joints
    n_free = model.n_free
    if n_free == 0 or points.count == 0:
        return []
    xy = np.stack([joints.start, joints.end], axis=1).reshape(-1, 2)
    xy = (xy - model.origin) / model.length_scale  # (P, 2) point coordinates, model units
    normal = np.repeat(joints.normal, 2, axis=0)  # (P, 2), from block a into block b
    side_a = model.free_index[np.repeat(joints.block_a, 2)]  # free index or −1 (fixed)
    side_b = model.free_index[np.repeat(joints.block_b, 2)]
    P = xy.shape[0]

    # Incidences (a point seen from one of its free blocks), grouped by block (CSR order), and
    # for each the sign that turns n·(v_b − v_a) into the opening when only that block moves.
    owner = np.concatenate([side_b, side_a])
    point_of = np.concatenate([np.arange(P), np.arange(P)])
    sign_of = np.concatenate([np.ones(P), -np.ones(P)])
    other_of = np.concatenate([side_a, side_b])
    order = np.flatnonzero(owner >= 0)
    order = order[np.argsort(owner[order], kind="stable")]
    indptr = np.concatenate([[0], np.cumsum(np.bincount(owner[order], minlength=n_free))])
    inc_point, inc_sign, inc_other = point_of[order], sign_of[order], other_of[order]
    # Opening of incidence i under a rotation ω about c: ω (offset_i + normal_x_i c_y − normal_y_i c_x),
    # with n·(ω × (x − c)) = ω (n_y (x_x − c_x) − n_x (x_y − c_y)) seen from the moving block.
    signed_normal = inc_sign[:, None] * normal[inc_point]
    normal_x, normal_y = signed_normal[:, 0], signed_normal[:, 1]
    offset = normal_y * xy[inc_point, 0] - normal_x * xy[inc_point, 1]

    # Support points of each block: where it rests on what is below it (the joint normal points
    # up into it), the two extremes across the direction of gravity.
    gravity = np.asarray(model.scene.gravity, dtype=float)
    up = -gravity / max(float(np.hypot(*gravity)), 1e-300)
    across = np.array([up[1], -up[0]])
    resting = (inc_sign * (normal[inc_point] @ up)) > 0.5

    seen: set[tuple[tuple[int, ...], tuple[float, float]]] = set()
    found: list[RockingCandidate] = []
    for block in range(n_free):
        ids = np.arange(indptr[block], indptr[block + 1])
        ids = ids[resting[ids]]
        if ids.size == 0:
            continue
        along = xy[inc_point[ids]] @ across
        # Tipping over an edge: clockwise about the support point furthest along `across`,
        # counter-clockwise about the one furthest back (the other pairings push the block down).
        for pivot_id, omega in ((int(ids[np.argmax(along)]), -1.0), (int(ids[np.argmin(along)]), 1.0)):
            pivot = xy[inc_point[pivot_id]]
            members = _grow(block, pivot, omega, indptr, offset, normal_x, normal_y, inc_other,
                            n_free, max_blocks, tolerance)
            if members is None:
                continue
            key = (tuple(members), (round(float(pivot[0]), 9), round(float(pivot[1]), 9)))
            if key in seen:
                continue
            seen.add(key)
            u = np.zeros(3 * n_free)
            index = np.asarray(members)
            arm = model.centroid[index] - pivot
            u[3 * index] = -omega * arm[:, 1]
            u[3 * index + 1] = omega * arm[:, 0]
            u[3 * index + 2] = omega
            work = float(model.live @ u)
            if not work > 0:
                continue
            u *= n_free / work
            bound = float(-(model.dead @ u) / n_free)
            found.append(RockingCandidate(tuple(members), (float(pivot[0]), float(pivot[1])), omega, bound, u))
    found.sort(key=lambda c: c.lifting_bound)
    return found


def _grow(seed: int, pivot: np.ndarray, omega: float, indptr: np.ndarray, offset: np.ndarray,
          normal_x: np.ndarray, normal_y: np.ndarray, inc_other: np.ndarray, n_free: int,
          max_blocks: int, tolerance: float) -> list[int] | None:
    """Members of the macro-block grown from ``seed`` (sorted), or None (ground pushed, too large).

    Per incidence i (point p seen from its block), the opening under a rotation ω about c is
    ω (offset_i + normal_x_i c_y − normal_y_i c_x), the normal carrying the incidence's sign.
    The frontier is expanded a whole ring at a time.
    """
    members = np.zeros(n_free, dtype=bool)
    members[seed] = True
    count = 1
    frontier = np.array([seed])
    while frontier.size:
        starts, lengths = indptr[frontier], indptr[frontier + 1] - indptr[frontier]
        total = int(lengths.sum())
        ids = np.repeat(starts - np.concatenate([[0], np.cumsum(lengths)[:-1]]), lengths) + np.arange(total)
        opening = omega * (offset[ids] + normal_x[ids] * pivot[1] - normal_y[ids] * pivot[0])
        pushed = inc_other[ids[opening < -tolerance]]
        if pushed.size and pushed.min() < 0:
            return None  # the rotation pushes into a fixed block
        frontier = np.unique(pushed[~members[pushed]])
        members[frontier] = True
        count += frontier.size
        if count > max_blocks:
            return None
    return np.flatnonzero(members).tolist()
