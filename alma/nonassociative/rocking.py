"""Candidate mechanisms of rigid macro-blocks rocking about a support point (starts for Eq. 9).

A set S of blocks turning as one rigid body about a pivot c, every other block
at rest, is a mechanism of the non-associative model when no contact point
interpenetrates (opening ξ ≥ 0, Eq. 2); its points may open or slip freely.
S is grown from one seed block: turning the seed about one of its support
points pushes into some neighbours, and those join S (they turn with it),
until no point interpenetrates, or the ground would be pushed (no mechanism),
or S passes an optional size limit.

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

from alma.floats import rows_dot
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.limits import Cap, no_cap


@dataclass(frozen=True)
class RockingCandidate:
    """A rigid rotation of ``blocks`` (free-block indices) about ``pivot`` (dimensionless)."""

    blocks: tuple[int, ...]
    pivot: tuple[float, float]
    rotation: float  # ω, +1 counter-clockwise
    lifting_bound: float  # −f_0ᵀu / f_Lᵀu ≤ α of any collapse state with this mechanism
    mechanism: np.ndarray  # u (3 n_free), f_Lᵀu = n_free


def rocking_candidates(
    model: Model,
    points: ContactPoints,
    *,
    max_blocks: int | None = None,
    keep: int | None = None,
    max_seeds: int | None = None,
    cap: Cap | None = None,
    tolerance: float = 1e-9,
) -> list[RockingCandidate]:
    """All macro-block rotations grown from single blocks (see module docstring), lowest bound first.

    Seeds: every free block, turned clockwise about the support point furthest along
    +x (across gravity) and counter-clockwise about the one furthest back (the points of
    the contacts it rests on).
    Distinct (blocks, pivot) pairs only; candidates whose live load does no
    positive work are dropped.  ``max_blocks`` (default: no limit) drops larger macro-blocks:
    on the paper panels the lowest candidates include wedges of 450-850 blocks (a stepped
    diagonal crack), which gave the only verified states of four 600-1,176-block panels.
    ``keep``: only the lowest ``keep`` candidates (each carries a mechanism of 3 n_free numbers).
    ``max_seeds``: only the first seeds (in block order) are grown (on large walls the macro-blocks
    of tens of thousands of seeds can each reach thousands of blocks).  Seeds not grown when the
    user's ``cap`` passes give no candidate.
    """
    n_free = model.n_free
    if n_free == 0 or points.count == 0:
        return []
    table = _incidences(model)
    seed_block, seed_pivot, seed_omega = _seeds(model, table)
    if max_seeds is not None:
        seed_block, seed_pivot, seed_omega = seed_block[:max_seeds], seed_pivot[:max_seeds], seed_omega[:max_seeds]
    if not seed_block:
        return []
    grown = _grow(
        np.asarray(seed_block),
        np.asarray(seed_pivot),
        np.asarray(seed_omega),
        table.indptr,
        table.offset,
        table.normal_x,
        table.normal_y,
        table.other,
        n_free,
        n_free if max_blocks is None else max_blocks,
        tolerance,
        cap or no_cap(),
    )
    return _ranked(model, grown, seed_pivot, seed_omega, keep)


@dataclass(frozen=True)
class _Incidences:
    """Each contact point seen from one of its free blocks, grouped by block (CSR order)."""

    xy: np.ndarray  # (P, 2) point coordinates, model units
    normal: np.ndarray  # (P, 2) joint normal, from block a into block b
    indptr: np.ndarray  # incidences of free block k: indptr[k]:indptr[k + 1]
    point: np.ndarray  # contact point of each incidence
    sign: np.ndarray  # turns n·(v_b − v_a) into the opening when only that block moves
    other: np.ndarray  # free index of the block on the other side (−1: fixed)
    offset: np.ndarray  # opening under a unit rotation about the origin
    normal_x: np.ndarray  # signed normal, x
    normal_y: np.ndarray  # signed normal, y


def _incidences(model: Model) -> _Incidences:
    """The incidence tables of :func:`_grow` (vectorised over all contact points).

    Opening of incidence i under a rotation ω about c: ω (offset_i + normal_x_i c_y − normal_y_i c_x),
    with n·(ω × (x − c)) = ω (n_y (x_x − c_x) − n_x (x_y − c_y)) seen from the moving block.
    """
    joints = model.joints
    xy = np.stack([joints.start, joints.end], axis=1).reshape(-1, 2)
    xy = (xy - model.origin) / model.length_scale
    normal = np.repeat(joints.normal, 2, axis=0)
    side_a = model.free_index[np.repeat(joints.block_a, 2)]  # free index or −1 (fixed)
    side_b = model.free_index[np.repeat(joints.block_b, 2)]
    P = xy.shape[0]
    owner = np.concatenate([side_b, side_a])
    point_of = np.concatenate([np.arange(P), np.arange(P)])
    sign_of = np.concatenate([np.ones(P), -np.ones(P)])
    other_of = np.concatenate([side_a, side_b])
    order = np.flatnonzero(owner >= 0)
    order = order[np.argsort(owner[order], kind="stable")]
    indptr = np.concatenate([[0], np.cumsum(np.bincount(owner[order], minlength=model.n_free))])
    inc_point, inc_sign = point_of[order], sign_of[order]
    signed_normal = inc_sign[:, None] * normal[inc_point]
    normal_x, normal_y = signed_normal[:, 0], signed_normal[:, 1]
    offset = normal_y * xy[inc_point, 0] - normal_x * xy[inc_point, 1]
    return _Incidences(xy, normal, indptr, inc_point, inc_sign, other_of[order], offset, normal_x, normal_y)


def _seeds(model: Model, table: _Incidences) -> tuple[list[int], list[np.ndarray], list[float]]:
    """Seed (block, pivot, ω) pairs: each free block tipping over the extreme points it rests on.

    The support points of a block are where it rests on what is below it (the joint normal points
    up into it); it tips clockwise about the one furthest along the direction across gravity and
    counter-clockwise about the one furthest back (the other pairings push the block down).
    """
    gravity = np.asarray(model.scene.gravity, dtype=float)
    up = -gravity / max(float(np.hypot(*gravity)), 1e-300)
    across = np.array([up[1], -up[0]])
    resting = (table.sign * rows_dot(table.normal[table.point], up)) > 0.5
    seed_block, seed_pivot, seed_omega = [], [], []
    for block in range(model.n_free):
        ids = np.arange(table.indptr[block], table.indptr[block + 1])
        ids = ids[resting[ids]]
        if ids.size == 0:
            continue
        along = rows_dot(table.xy[table.point[ids]], across)
        for pivot_id, omega in ((int(ids[np.argmax(along)]), -1.0), (int(ids[np.argmin(along)]), 1.0)):
            seed_block.append(block)
            seed_pivot.append(table.xy[table.point[pivot_id]])
            seed_omega.append(omega)
    return seed_block, seed_pivot, seed_omega


def _ranked(
    model: Model,
    grown: list[np.ndarray | None],
    seed_pivot: list[np.ndarray],
    seed_omega: list[float],
    keep: int | None,
) -> list[RockingCandidate]:
    """Distinct macro-blocks whose live load does positive work, lowest lifting bound first."""
    n_free = model.n_free
    seen: set[tuple[bytes, tuple[float, float]]] = set()
    ranked: list[tuple[float, int, np.ndarray, np.ndarray, float, float]] = []
    live, dead = model.live.reshape(-1, 3), model.dead.reshape(-1, 3)
    for index, pivot, omega in zip(grown, seed_pivot, seed_omega, strict=True):
        if index is None:
            continue
        key = (index.tobytes(), (round(float(pivot[0]), 9), round(float(pivot[1]), 9)))
        if key in seen:
            continue
        seen.add(key)
        motion = _rotation(model.centroid[index], pivot, omega)
        work = float(np.sum(live[index] * motion))
        if not work > 0:
            continue
        scale = n_free / work
        bound = float(-np.sum(dead[index] * motion) * scale / n_free)
        ranked.append((bound, len(ranked), index, pivot, float(omega), scale))
    ranked.sort(key=lambda item: (item[0], item[1]))
    found: list[RockingCandidate] = []
    for bound, _, index, pivot, omega, scale in ranked[:keep]:
        u = np.zeros((n_free, 3))
        u[index] = scale * _rotation(model.centroid[index], pivot, omega)
        found.append(
            RockingCandidate(tuple(index.tolist()), (float(pivot[0]), float(pivot[1])), omega, bound, u.ravel())
        )
    return found


def _rotation(centroids: np.ndarray, pivot: np.ndarray, omega: float) -> np.ndarray:
    """(u, v, θ) of blocks with these centroids turning at rate ω about the pivot."""
    arm = centroids - pivot
    return np.column_stack([-omega * arm[:, 1], omega * arm[:, 0], np.full(arm.shape[0], omega)])


#: Seeds grown together in one batch use dense (seeds × blocks) tables of at most this many
#: entries (a membership bool and an int32 scratch: 5 bytes each).
_BATCH_ENTRIES = 8_000_000


def _grow(
    seeds: np.ndarray,
    pivots: np.ndarray,
    omegas: np.ndarray,
    indptr: np.ndarray,
    offset: np.ndarray,
    normal_x: np.ndarray,
    normal_y: np.ndarray,
    inc_other: np.ndarray,
    n_free: int,
    max_blocks: int,
    tolerance: float,
    cap: Cap,
) -> list[np.ndarray | None]:
    """Members of the macro-block grown from each seed (sorted), or None (ground pushed, too large,
    or not grown before the user's ``cap`` passed).

    Per incidence i (point p seen from its block), the opening under a rotation ω about c is
    ω (offset_i + normal_x_i c_y − normal_y_i c_x), the normal carrying the incidence's sign.
    All seeds of a batch grow together, a whole ring of each per step: the number of steps is
    the depth of the largest macro-block, not the number of seeds times it (on the 1,752-block
    panel, 3,504 seeds and wedges of up to 850 blocks: ~86,000 small steps one seed at a time).
    """
    out: list[np.ndarray | None] = []
    batch = max(1, _BATCH_ENTRIES // max(n_free, 1))
    for first in range(0, seeds.size, batch):
        out.extend(
            _grow_batch(
                seeds[first : first + batch],
                pivots[first : first + batch],
                omegas[first : first + batch],
                indptr,
                offset,
                normal_x,
                normal_y,
                inc_other,
                n_free,
                max_blocks,
                tolerance,
                cap,
            )
        )
    return out


def _grow_batch(
    seeds: np.ndarray,
    pivots: np.ndarray,
    omegas: np.ndarray,
    indptr: np.ndarray,
    offset: np.ndarray,
    normal_x: np.ndarray,
    normal_y: np.ndarray,
    inc_other: np.ndarray,
    n_free: int,
    max_blocks: int,
    tolerance: float,
    cap: Cap,
) -> list[np.ndarray | None]:
    """:func:`_grow` for one batch of seeds."""
    count = seeds.size
    if cap.expired():
        return [None] * count
    members = np.zeros((count, n_free), dtype=bool)
    members[np.arange(count), seeds] = True
    stamp = np.empty((count, n_free), dtype=np.int32)  # scratch: written before it is read
    alive = np.ones(count, dtype=bool)
    size = np.ones(count, dtype=np.int64)
    frontier_seed, frontier_block = np.arange(count), seeds.copy()
    while frontier_seed.size:
        if cap.expired():
            return [None] * count
        starts, lengths = indptr[frontier_block], indptr[frontier_block + 1] - indptr[frontier_block]
        total = int(lengths.sum())
        ids = np.repeat(starts - np.concatenate([[0], np.cumsum(lengths)[:-1]]), lengths) + np.arange(total)
        owner = np.repeat(frontier_seed, lengths)
        opening = omegas[owner] * (offset[ids] + normal_x[ids] * pivots[owner, 1] - normal_y[ids] * pivots[owner, 0])
        pushing = opening < -tolerance
        owner, pushed = owner[pushing], inc_other[ids[pushing]]
        alive[owner[pushed < 0]] = False  # the rotation pushes into a fixed block
        keep = alive[owner]
        owner, pushed = owner[keep], pushed[keep]
        fresh = ~members[owner, pushed]
        owner, pushed = owner[fresh], pushed[fresh]
        # Each new (seed, block) pair once: the stamps written are distinct, so of repeated pairs
        # exactly one (whichever is written last) reads its own stamp back.
        stamp[owner, pushed] = np.arange(owner.size, dtype=np.int32)
        once = stamp[owner, pushed] == np.arange(owner.size, dtype=np.int32)
        frontier_seed, frontier_block = owner[once], pushed[once]
        members[frontier_seed, frontier_block] = True
        size += np.bincount(frontier_seed, minlength=count)
        alive &= size <= max_blocks
        keep = alive[frontier_seed]
        frontier_seed, frontier_block = frontier_seed[keep], frontier_block[keep]
    return [np.flatnonzero(members[k]) if alive[k] else None for k in range(count)]
