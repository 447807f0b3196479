"""The canonical model of the friction search, and motions carried back to the drawing's model.

:func:`alma.geometry.canonical.canonical_scene` fixes the frame, the vertices and the order of
the blocks; the model built from it is then snapped to a binary grid (:func:`snapped`), so that
the round-off of a change of units or unit weight (forces are in mean block weights, lengths in
√ mean block area) leaves no trace in the data the search sees.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp

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
    centre_mm = (
        (canonical.centroid * canonical.length_scale + canonical.origin) * frame.unit - frame.offset
    ) @ frame.matrix
    centre = (centre_mm - model.origin) / model.length_scale  # canonical centroids, drawing model units
    omega = frame.handedness * moves[:, 2]
    velocity = (moves[:, :2] @ frame.matrix) * (to_mm / model.length_scale)
    arm = model.centroid[target] - centre
    out = np.zeros((model.n_free, 3))
    out[target, 0] = velocity[:, 0] - omega * arm[:, 1]
    out[target, 1] = velocity[:, 1] + omega * arm[:, 0]
    out[target, 2] = omega
    return out.ravel()
