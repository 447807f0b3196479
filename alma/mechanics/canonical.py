"""The canonical model of the friction search, and motions and fields carried back to the drawing's model.

:func:`alma.geometry.canonical.canonical_scene` fixes the frame, the vertices and the order of
the blocks; the model built from it is then snapped to a binary grid (:func:`snapped`), so that
the round-off of a change of units or unit weight (forces are in mean block weights, lengths in
√ mean block area) leaves no trace in the data the search sees.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp

from alma.floats import rows_dot, times
from alma.geometry.canonical import CanonicalFrame
from alma.mechanics.model import Model

#: Below this (1.5e-11) a datum is round-off of a zero and becomes 0: the model's data are of
#: order one, and a zero's round-off reached 6.9e-13 in panels turned and moved 100 m away.
ZERO = 2.0**-36


def _snap(values: np.ndarray, bits: int) -> np.ndarray:
    """Each value rounded to ``bits`` significant bits; below :data:`ZERO` it becomes 0."""
    x = np.asarray(values, dtype=float)
    mantissa, exponent = np.frexp(x)
    out = np.ldexp(np.round(np.ldexp(mantissa, bits)), exponent - bits)
    out[np.abs(x) < ZERO] = 0.0
    return out


def _snap_matrix(matrix: sp.csc_matrix | None, bits: int) -> sp.csc_matrix | None:
    if matrix is None:
        return None
    out = matrix.copy()
    out.data = _snap(out.data, bits)
    return out


def snapped(model: Model, bits: int) -> Model:
    """``model`` with its dimensionless data rounded to ``bits`` significant bits (:func:`_snap`)."""
    return dataclasses.replace(
        model,
        centroid=_snap(model.centroid, bits),
        normal_part=_snap_matrix(model.normal_part, bits),
        tangent_part=_snap_matrix(model.tangent_part, bits),
        dead=_snap(model.dead, bits),
        live=_snap(model.live, bits),
        bounded=_snap_matrix(model.bounded, bits),
        capacity=_snap(model.capacity, bits),
    )


def mechanism_to_drawing(u: np.ndarray, canonical: Model, frame: CanonicalFrame, model: Model) -> np.ndarray:
    """A mechanism of the canonical model as a mechanism of the drawing's ``model``.

    ``u`` holds (u_x, u_y, ω) per free block in the canonical model's units (the velocity of its
    centroid, translations in its length unit); returned: the same rigid motions in ``model``'s
    frame and units, each block's velocity taken at the drawing's own centroid (the canonical
    centroid sits up to a grid step away).
    """
    moves = np.asarray(u, dtype=float).reshape(-1, 3)
    target = model.free_index[frame.order[canonical.free_blocks]]  # drawing's free index of each canonical one
    to_mm = canonical.length_scale * frame.unit
    centre_mm = times(
        (canonical.centroid * canonical.length_scale + canonical.origin) * frame.unit - frame.offset, frame.matrix
    )
    centre = (centre_mm - model.origin) / model.length_scale  # canonical centroids, drawing model units
    omega = frame.handedness * moves[:, 2]
    velocity = times(moves[:, :2], frame.matrix) * (to_mm / model.length_scale)
    arm = model.centroid[target] - centre
    out = np.zeros((model.n_free, 3))
    out[target, 0] = velocity[:, 0] - omega * arm[:, 1]
    out[target, 1] = velocity[:, 1] + omega * arm[:, 0]
    out[target, 2] = omega
    return out.ravel()


#: Canonical and drawn joints are the same joint when their end points agree to this share of
#: the canonical length unit: the canonical vertices sit on a grid of 2⁻²⁰ of it (≈ 1e-6).
SAME_POINT = 1e-4


def _joint_match(canonical: Model, frame: CanonicalFrame, model: Model) -> tuple[np.ndarray, np.ndarray] | None:
    """For each drawn joint, its canonical joint and whether its end points come in swapped order;
    None when the two models' joints are not the same joints (then no field is carried)."""
    cj, dj = canonical.joints, model.joints
    if cj.count != dj.count:
        return None

    def to_drawing(x: np.ndarray) -> np.ndarray:
        return times(x * frame.unit - frame.offset, frame.matrix)

    c_start, c_end = to_drawing(cj.start), to_drawing(cj.end)
    c_pair = np.sort(np.column_stack([frame.order[cj.block_a], frame.order[cj.block_b]]), axis=1)
    d_pair = np.sort(np.column_stack([dj.block_a, dj.block_b]), axis=1)
    c_mid, d_mid = 0.5 * (c_start + c_end), dj.centre
    c_rank = np.lexsort((c_mid[:, 1], c_mid[:, 0], c_pair[:, 1], c_pair[:, 0]))
    d_rank = np.lexsort((d_mid[:, 1], d_mid[:, 0], d_pair[:, 1], d_pair[:, 0]))
    match = np.empty(dj.count, dtype=int)
    match[d_rank] = c_rank
    same = np.hypot(*(c_start[match] - dj.start).T) + np.hypot(*(c_end[match] - dj.end).T)
    swapped = np.hypot(*(c_end[match] - dj.start).T) + np.hypot(*(c_start[match] - dj.end).T)
    tolerance = SAME_POINT * frame.unit
    if np.any(c_pair[match] != d_pair) or np.any(np.minimum(same, swapped) > 2 * tolerance):
        return None
    return match, swapped < same


def _bounded_to_drawing(
    tau: np.ndarray, canonical: Model, model: Model, match: np.ndarray, flip: np.ndarray
) -> np.ndarray | None:
    """τ of the canonical bounded columns on the drawing's: a joint's cohesive shear pair
    (``j<k>+`` / ``j<k>-``) goes to its drawn joint, the pair exchanged where the drawn tangent
    is the opposite (``flip``); a tie keeps its id.  None when a column has no counterpart."""
    column = {str(label): i for i, label in enumerate(canonical.bounded_labels)}

    def counterpart(label: str) -> str:
        if label.startswith("tie:"):
            return label
        k, sign = int(label[1:-1]), label[-1]
        return f"j{match[k]}{sign if not flip[k] else '+-'[sign == '+']}"

    found = [column.get(counterpart(str(label))) for label in model.bounded_labels]
    if any(i is None for i in found) or len(found) != len(column):
        return None
    return tau[np.array(found, dtype=int)]


def field_to_drawing(
    normal: np.ndarray,
    shear: np.ndarray,
    canonical: Model,
    frame: CanonicalFrame,
    model: Model,
    bounded: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """A static field of the canonical model as one of the drawing's ``model`` (same joints).

    ``normal``, ``shear``: N and T at the canonical contact points (two per joint, its start and
    end; model force units).  Each joint's force on its block b, N n + T t, is turned into the
    drawing's frame and read on the drawn joint's own n and t: N keeps its value, T changes sign
    where the drawn tangent points the other way (blocks a and b swapped, or a mirror image).
    ``bounded``: τ of the canonical cohesion and tie columns (:func:`_bounded_to_drawing`).
    Returns (N, T, τ), or None when the joints or bounded columns do not correspond one to one
    (:data:`SAME_POINT`); then only the mechanism is carried (:func:`mechanism_to_drawing`).
    """
    found = _joint_match(canonical, frame, model)
    if found is None:
        return None
    match, swapped = found
    cj, dj = canonical.joints, model.joints
    # Vectors turn as points do (x_drawing = Mᵀ x_canonical); each joint's n and t read in the drawing.
    n_sign = np.sign(rows_dot(times(cj.normal[match], frame.matrix), dj.normal))
    t_sign = np.sign(rows_dot(times(cj.tangent[match], frame.matrix), dj.tangent))
    # N n + T t on block b: when a and b are swapped the force on the drawn b is the opposite one.
    if np.any(n_sign != np.where(frame.order[cj.block_b[match]] == dj.block_b, 1.0, -1.0)):
        return None
    scale = canonical.force_scale / model.force_scale
    tau = np.zeros(0) if bounded is None else np.asarray(bounded, dtype=float)
    carried = _bounded_to_drawing(tau, canonical, model, match, n_sign * t_sign < 0)
    if carried is None:
        return None
    points = np.column_stack([2 * match, 2 * match + 1])
    points[swapped] = points[swapped][:, ::-1]
    points = points.ravel()
    return normal[points] * scale, shear[points] * np.repeat(n_sign * t_sign, 2) * scale, carried * scale
