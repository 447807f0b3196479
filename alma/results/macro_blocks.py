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

from alma.geometry.edges import scene_edges
from alma.mechanics.model import Model

#: A macro-block translates when its rotation moves its farthest point by less than this
#: fraction of its speed.
TRANSLATION_TOLERANCE = 1e-3
#: A centre of rotation within this fraction of the median block size of a contact point is a hinge.
HINGE_TOLERANCE = 1e-2


def macro_blocks(model: Model, mechanism: np.ndarray, rel: np.ndarray, tol: float
                 ) -> tuple[list[dict], str]:
    """The moving macro-blocks of a mechanism and its class.

    ``mechanism``: u (dimensionless, 3 per free block about its centroid); ``rel``: the joints'
    relative velocities (m, 2, 2); ``tol``: the motion threshold (same units as ``rel``).
    Returns ([{"members": free-block indices, "motion", "centre" (mm) or None, "direction" or
    None}], class).
    """
    u = mechanism.reshape(-1, 3)
    speed = _vertex_speed(model, u)
    moving = speed > tol
    if not moving.any():
        return [], "none"
    label = _components(model, rel, moving, tol)
    groups = [np.flatnonzero(label == g) for g in np.unique(label[moving])]
    bodies = [_motion(model, u, members) for members in groups]
    hinged = [_hinged(model, u, label, g, body) for g, body in zip(np.unique(label[moving]), bodies)]
    kinds = {b["motion"] for b in bodies}
    if kinds == {"translation"}:
        klass = "sliding"
    elif kinds == {"rotation"} and all(hinged):
        klass = "rocking"
    else:
        klass = "mixed"
    return bodies, klass


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
    still = np.abs(rel).max(axis=(1, 2)) <= tol
    link = (a >= 0) & (b >= 0) & still
    link &= moving[np.where(a >= 0, a, 0)] & moving[np.where(b >= 0, b, 0)]
    n = model.n_free
    graph = sp.coo_matrix((np.ones(int(link.sum())), (a[link], b[link])), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def _motion(model: Model, u: np.ndarray, members: np.ndarray) -> dict:
    """Rigid motion of a macro-block: rotation about a centre (mm) or translation (a direction)."""
    centre = model.centroid[members].mean(axis=0)
    theta = float(u[members, 2].mean())
    d = centre - model.centroid[members]
    v = np.column_stack([u[members, 0] - u[members, 2] * d[:, 1], u[members, 1] + u[members, 2] * d[:, 0]]).mean(axis=0)
    reach = float(np.hypot(*(model.centroid[members] - centre).T).max(initial=0.0)) + 1.0
    body = {"members": members, "theta": theta, "velocity": v, "reference": centre}
    if abs(theta) * reach <= TRANSLATION_TOLERANCE * (float(np.hypot(*v)) + abs(theta) * reach):
        return {**body, "motion": "translation", "centre": None, "direction": tuple((v / np.hypot(*v)).tolist())}
    pivot = centre + np.array([-v[1], v[0]]) / theta
    return {**body, "motion": "rotation", "centre": tuple((model.origin + pivot * model.length_scale).tolist()),
            "direction": None}


def _hinged(model: Model, u: np.ndarray, label: np.ndarray, group: int, body: dict) -> bool:
    """The macro-block rotates about a contact point it shares with a neighbour (a support, a
    block at rest, or another macro-block, relative to that one's motion)."""
    if body["motion"] != "rotation":
        return False
    joints = model.joints
    a, b = model.free_index[joints.block_a], model.free_index[joints.block_b]
    mine_a, mine_b = (a >= 0) & (label[np.maximum(a, 0)] == group), (b >= 0) & (label[np.maximum(b, 0)] == group)
    border = np.flatnonzero(mine_a ^ mine_b)
    if border.size == 0:
        return False
    size = float(np.median(np.sqrt(np.abs([blk.area for blk in model.scene.blocks]))))
    other = np.where(mine_a[border], b[border], a[border])
    theta = np.full(border.size, body["theta"])
    v = np.tile(body["velocity"], (border.size, 1))
    moving = other >= 0  # relative to the neighbouring block's motion, at the reference point
    o = other[moving]
    d = body["reference"] - model.centroid[o]
    theta[moving] -= u[o, 2]
    v[moving] -= np.column_stack([u[o, 0] - u[o, 2] * d[:, 1], u[o, 1] + u[o, 2] * d[:, 0]])
    turning = np.abs(theta) > 1e-300
    if not turning.any():
        return False
    rel = body["reference"] + np.column_stack([-v[turning, 1], v[turning, 0]]) / theta[turning, None]
    pivot = model.origin + rel * model.length_scale
    j = border[turning]
    gap = np.minimum(np.hypot(*(joints.start[j] - pivot).T), np.hypot(*(joints.end[j] - pivot).T))
    return bool(gap.min() <= HINGE_TOLERANCE * size)
