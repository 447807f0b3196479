"""Macro-blocks: the sets of blocks that move as one rigid body, their motion, and the
mechanism's class in the paper's words (SPEC §3 ``mechanism_class``, ``macro_blocks``).

Two moving blocks belong to one macro-block when a joint between them has no relative motion
at either end (to ``MOTION_TOLERANCE`` of the largest velocity).  Each macro-block either
translates (a direction) or rotates about an instantaneous centre.  The class is ``sliding``
when every moving macro-block translates, ``rocking`` (the paper's "rotational") when every one
rotates about a centre on a contact point it shares with a support, a block at rest or another
macro-block (relative to that one), ``mixed`` otherwise, ``none`` when nothing moves.
Lengths in mm; velocities per unit mechanism.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from alma.geometry.edges import scene_edges, signed_areas
from alma.mechanics.model import Model

#: A macro-block translates when its rotation moves its farthest point by less than this
#: fraction of its speed.
TRANSLATION_TOLERANCE = 1e-3
#: A centre of rotation within this fraction of the median block size of a contact point is a hinge.
HINGE_TOLERANCE = 1e-2


def macro_blocks(model: Model, mechanism: np.ndarray, rel: np.ndarray, tol: float) -> tuple[list[dict], str]:
    """The moving macro-blocks of a mechanism and its class.

    ``mechanism``: u (dimensionless, 3 per free block about its centroid); ``rel``: the joints'
    relative velocities (m, 2, 2); ``tol``: the motion threshold (same units as ``rel``).
    Returns ([{"members": free-block indices, "motion", "centre" (mm) or None, "direction" or
    None}], class).  Vectorised over blocks, joints and macro-blocks.
    """
    u = mechanism.reshape(-1, 3)
    moving = _vertex_speed(model, u) > tol
    if not moving.any():
        return [], "none"
    label = _components(model, rel, moving, tol)
    groups, group = np.unique(label[moving], return_inverse=True)
    of_block = np.full(model.n_free, -1)
    of_block[np.flatnonzero(moving)] = group
    centre, theta, velocity, reach = _rigid_motions(model, u, of_block, groups.size)
    speed = np.hypot(velocity[:, 0], velocity[:, 1])
    translating = np.abs(theta) * reach <= TRANSLATION_TOLERANCE * (speed + np.abs(theta) * reach)
    hinged = _hinged(model, u, of_block, centre, theta, velocity) & ~translating
    bodies = []
    members = np.argsort(of_block, kind="stable")[np.sort(of_block) >= 0]
    split = np.split(members, np.cumsum(np.bincount(of_block[of_block >= 0]))[:-1])
    for g, block_ids in enumerate(split):
        if translating[g]:
            bodies.append(
                {
                    "members": block_ids,
                    "motion": "translation",
                    "centre": None,
                    "direction": tuple((velocity[g] / speed[g]).tolist()),
                }
            )
        else:
            pivot = centre[g] + np.array([-velocity[g, 1], velocity[g, 0]]) / theta[g]
            bodies.append(
                {
                    "members": block_ids,
                    "motion": "rotation",
                    "direction": None,
                    "centre": tuple((model.origin + pivot * model.length_scale).tolist()),
                }
            )
    if translating.all():
        return bodies, "sliding"
    return bodies, "rocking" if hinged.all() else "mixed"


def _vertex_speed(model: Model, u: np.ndarray) -> np.ndarray:
    """Largest speed over each free block's vertices (dimensionless)."""
    edges = scene_edges(model.scene)
    k = model.free_index[edges.block]
    keep = k >= 0
    k = k[keep]
    r = (edges.start[keep] - model.origin) / model.length_scale - model.centroid[k]
    vx = u[k, 0] - u[k, 2] * r[:, 1]
    vy = u[k, 1] + u[k, 2] * r[:, 0]
    out = np.zeros(model.n_free)
    np.maximum.at(out, k, np.hypot(vx, vy))
    return out


def _components(model: Model, rel: np.ndarray, moving: np.ndarray, tol: float) -> np.ndarray:
    """Component label of every free block: moving blocks joined by joints without relative motion."""
    a = model.free_index[model.joints.block_a]
    b = model.free_index[model.joints.block_b]
    # a point contact (length 0: a hinge kept over a large displacement, alma.push) at rest
    # pins two blocks together but lets them turn: it does not join them into one body
    still = (np.abs(rel).max(axis=(1, 2)) <= tol) & (model.joints.length > 0)
    link = (a >= 0) & (b >= 0) & still
    link &= moving[np.where(a >= 0, a, 0)] & moving[np.where(b >= 0, b, 0)]
    n = model.n_free
    graph = sp.coo_matrix((np.ones(int(link.sum())), (a[link], b[link])), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def _velocity_at(model: Model, u: np.ndarray, blocks: np.ndarray, point: np.ndarray) -> np.ndarray:
    """Velocity (rows) of ``blocks`` at ``point`` (rows, dimensionless)."""
    d = point - model.centroid[blocks]
    return np.column_stack([u[blocks, 0] - u[blocks, 2] * d[:, 1], u[blocks, 1] + u[blocks, 2] * d[:, 0]])


def _rigid_motions(
    model: Model, u: np.ndarray, of_block: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per macro-block: centre (mean centroid), rotation, velocity at the centre (means over the
    members) and reach (farthest member centroid + one reference length), dimensionless."""
    blocks = np.flatnonzero(of_block >= 0)
    g = of_block[blocks]
    size = np.bincount(g, minlength=count).astype(float)
    centre = np.column_stack([np.bincount(g, model.centroid[blocks, i], count) for i in (0, 1)]) / size[:, None]
    theta = np.bincount(g, u[blocks, 2], count) / size
    v = _velocity_at(model, u, blocks, centre[g])
    velocity = np.column_stack([np.bincount(g, v[:, i], count) for i in (0, 1)]) / size[:, None]
    reach = np.zeros(count)
    np.maximum.at(reach, g, np.hypot(*(model.centroid[blocks] - centre[g]).T))
    return centre, theta, velocity, reach + 1.0


def _hinged(
    model: Model, u: np.ndarray, of_block: np.ndarray, centre: np.ndarray, theta: np.ndarray, velocity: np.ndarray
) -> np.ndarray:
    """Per macro-block: it turns about a contact point it shares with a neighbour (a support, a
    block at rest, or another macro-block, relative to that one's motion)."""
    joints = model.joints
    sides = []
    for mine, other in ((joints.block_a, joints.block_b), (joints.block_b, joints.block_a)):
        fm, fo = model.free_index[mine], model.free_index[other]
        g = np.where(fm >= 0, of_block[np.maximum(fm, 0)], -1)
        h = np.where(fo >= 0, of_block[np.maximum(fo, 0)], -1)
        border = np.flatnonzero((g >= 0) & (g != h))
        sides.append((border, g[border], fo[border]))
    j = np.concatenate([s[0] for s in sides])
    g = np.concatenate([s[1] for s in sides])
    other = np.concatenate([s[2] for s in sides])
    rel_theta = theta[g].copy()
    rel_v = velocity[g].copy()
    free = other >= 0
    rel_theta[free] -= u[other[free], 2]
    rel_v[free] -= _velocity_at(model, u, other[free], centre[g[free]])
    turning = np.abs(rel_theta) > 1e-300
    j, g, rel_theta, rel_v = j[turning], g[turning], rel_theta[turning], rel_v[turning]
    pivot = (
        model.origin
        + (centre[g] + np.column_stack([-rel_v[:, 1], rel_v[:, 0]]) / rel_theta[:, None]) * model.length_scale
    )
    gap = np.minimum(np.hypot(*(joints.start[j] - pivot).T), np.hypot(*(joints.end[j] - pivot).T))
    areas = np.abs(signed_areas(scene_edges(model.scene)))
    near = gap <= HINGE_TOLERANCE * float(np.median(np.sqrt(areas)))
    hinged = np.zeros(theta.size, dtype=bool)
    np.logical_or.at(hinged, g, near)
    return hinged
