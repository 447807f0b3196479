"""Why a capacity curve stops where no equilibrium is left: the falling mode, in words.

A displaced structure whose opened joints are point contacts is a linkage: it stands at one α
only (the static interval [α_min, α_max] of Eq. 10's dual has shrunk to a point), and a small
further motion can leave it no α at all.  The associative LP then has no statically admissible
field (``no_equilibrium``), and the curve ends with α > 0: not a zero of α but a loss of
equilibrium (a snap-through of a linkage whose thrust leaves a joint, a block left without the
contacts that held it).  This module finds the *falling mode* that proves it, a ray of Eq. 10::

    max  f_0ᵀu      s.t.  f_Lᵀu = 0,   Hᵀu ≥ 0,   −1 ≤ u ≤ 1

(the weights do positive work, the live load none, every contact point opens or slides on its
cone, Eq. 6; :mod:`alma.associative.falling`, a vertex by HiGHS's interior point with
crossover), and names the blocks it moves most and the joints the
last step lost between them and their neighbours.  When the falling mode moves into a joint
the last step dropped (a relative normal velocity < 0 at one of its former contact points), the
text says so: the end may then depend on the contact tolerance
(on the paper's panels, putting those contacts back leaves another falling mode: docs/seismic.md).
Dimensionless as :mod:`alma.mechanics.model`; the blocks are named by their scene ids.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from alma.associative.falling import falling_ray
from alma.mechanics.model import Model
from alma.results.types import JointResult

#: Blocks named in the message: the ones the falling mode moves most.
NAMED = 6
#: A block moves in the falling mode when its largest velocity component exceeds this share of
#: the largest one (the vertex moves the rest by round-off).
MOVING = 1e-3


@dataclass(frozen=True)
class FallingMode:
    """The proof that a configuration has no equilibrium: the blocks that fall (most first) and
    the work of their weights (dimensionless, |u| ≤ 1)."""

    blocks: tuple[str, ...]
    dead_work: float
    #: (3 n_free,) the mode's velocities (u, v, θ per free block, dimensionless).
    u: np.ndarray = field(repr=False, compare=False, default_factory=lambda: np.zeros(0))

    def to_dict(self) -> dict[str, Any]:
        return {"blocks": list(self.blocks), "dead_work": self.dead_work}


def falling_mode(model: Model) -> FallingMode | None:
    """The falling mode of ``model`` (a configuration the LP found without equilibrium), or None
    when HiGHS finds none (the LP's verdict then stands unexplained)."""
    ray = falling_ray(model)
    if ray is None:
        return None
    u = np.abs(ray.u.reshape(-1, 3)).max(axis=1)
    top = float(u.max(initial=0.0))
    ids = np.asarray(model.scene.block_ids, dtype=object)[model.free_blocks]
    moving = np.flatnonzero(u > MOVING * top)
    order = moving[np.lexsort((ids[moving].astype(str), -u[moving]))]
    return FallingMode(tuple(str(i) for i in ids[order]), ray.dead_work, ray.u)


def lost_joints(before: Model, after: Model, blocks: tuple[str, ...]) -> list[tuple[str, str]]:
    """Block pairs in contact in ``before`` and not in ``after`` with one of ``blocks`` among them."""

    def pairs(m: Model) -> set[tuple[str, str]]:
        ids = m.scene.block_ids
        return {tuple(sorted((ids[a], ids[b]))) for a, b in zip(m.joints.block_a, m.joints.block_b, strict=True)}

    named = set(blocks)
    return sorted(p for p in pairs(before) - pairs(after) if named & set(p))


def closing(before: Model, after: Model, mode: FallingMode, lost: list[tuple[str, str]]) -> list[tuple[str, str]]:
    """The ``lost`` joints (block pairs of ``before``) that ``mode`` (a falling mode of ``after``)
    closes: b moves towards a along the joint's normal at one of its former contact points."""
    ids = before.scene.block_ids
    pairs = [tuple(sorted((ids[a], ids[b]))) for a, b in zip(before.joints.block_a, before.joints.block_b, strict=True)]
    rows = np.array([k for k, p in enumerate(pairs) if p in set(lost)], dtype=int)
    if rows.size == 0:
        return []
    J = before.joints
    a, b = J.block_a[rows], J.block_b[rows]
    points = np.concatenate([J.start[rows], J.end[rows]])
    normal = np.concatenate([J.normal[rows], J.normal[rows]])
    rel = _velocity(after, mode.u, np.tile(b, 2), points) - _velocity(after, mode.u, np.tile(a, 2), points)
    closes = ((rel * normal).sum(axis=1) < 0).reshape(2, -1).any(axis=0)
    return sorted({pairs[k] for k in rows[closes]})


def _velocity(model: Model, u: np.ndarray, blocks: np.ndarray, points_mm: np.ndarray) -> np.ndarray:
    """The mode's velocity of ``blocks`` (scene indices) at ``points_mm`` (fixed blocks: 0)."""
    free = model.free_index[blocks]
    rows = np.maximum(free, 0)
    v = u.reshape(-1, 3)[rows]
    r = (points_mm - model.origin) / model.length_scale - model.centroid[rows]
    out = v[:, :2] + v[:, 2:3] * np.column_stack([-r[:, 1], r[:, 0]])
    return np.where((free >= 0)[:, None], out, 0.0)


def crushed_lost(joints: Iterable[JointResult], lost: list[tuple[str, str]]) -> list[tuple[str, str]]:
    """The ``lost`` block pairs whose joint was ``crushing`` in the last configuration's result
    (``joints``): crushed over its whole length, it sinks into its support, a motion the rigid
    geometry of the push does not follow (docs/seismic.md)."""
    crushing = {tuple(sorted(j.blocks)) for j in joints if j.state == "crushing"}
    return [p for p in lost if p in crushing]


def sunk(before: Model, after: Model, joints: Iterable[JointResult]) -> list[tuple[str, str]]:
    """The block pairs in contact in ``before`` and not in ``after`` whose joint crushed over its
    whole length in ``before``'s result (``joints``): a support sinking, not a contact left behind."""
    return crushed_lost(joints, lost_joints(before, after, tuple(before.scene.block_ids)))


def describe(
    d: tuple[float, float],
    alpha: float,
    mode: FallingMode | None,
    lost: list[tuple[str, str]],
    closed: list[tuple[str, str]] | None = None,
    crushed: list[tuple[str, str]] | None = None,
) -> str:
    """The stop in words."""
    text = (
        f"the curve ends at d in [{d[0]:.6g}, {d[1]:.6g}] mm with α = {alpha:.4g} > 0: beyond it the "
        "displaced structure carries its dead load at no multiplier (a loss of equilibrium, not a zero of α)"
    )
    if mode is None:
        return text
    more = len(mode.blocks) - NAMED
    names = ", ".join(mode.blocks[:NAMED]) + (f" and {more} more" if more > 0 else "")
    text += f"; falling mode: {names} can move with their weight doing work and the live load none"
    if lost:
        text += "; the last step opened the joints " + ", ".join(f"{a}–{b}" for a, b in lost[:NAMED])
    if closed:
        text += (
            " and the falling mode moves back into "
            + ", ".join(f"{a}–{b}" for a, b in closed[:NAMED])
            + " (contacts dropped at the contact tolerance: the end may depend on it)"
        )
    if crushed:
        text += (
            "; " + ", ".join(f"{a}–{b}" for a, b in crushed[:NAMED]) + " crushed over its whole length "
            "(N = σ_c l t) and sank into its support, which the rigid geometry does not follow"
        )
    return text


def lost_equilibrium(
    bracket: tuple[float, float], alpha: float, before: Model, after: Model, joints: Iterable[JointResult]
) -> dict[str, Any]:
    """The ``end`` of a curve whose configuration at ``bracket[1]`` (mm) has no equilibrium:
    the falling mode of ``after``, the joints of ``before`` (whose results are ``joints``, α =
    ``alpha`` at ``bracket[0]``) it lost, those the mode closes, and the text."""
    mode = falling_mode(after)
    lost = lost_joints(before, after, mode.blocks) if mode is not None else []
    closed = closing(before, after, mode, lost) if mode is not None else []
    crushed = crushed_lost(joints, lost)
    return {
        "reason": "no_equilibrium",
        "bracket": list(bracket),
        "alpha": alpha,
        "falling_blocks": list(mode.blocks) if mode is not None else None,
        "lost_joints": [list(p) for p in lost],
        "closes_lost_joints": [list(p) for p in closed],
        "crushed_lost_joints": [list(p) for p in crushed],
        "text": describe(bracket, alpha, mode, lost, closed, crushed),
    }
