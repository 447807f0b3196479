"""Bounded forces (cohesion, ties) in the collapse states of Eq. 9.

The columns G of :func:`alma.mechanics.forces.bounded_columns` carry forces 0 ≤ τ ≤ capacity:
a cohesive joint's shear as two columns ±t of capacity c l t, a tie's tension as one column of
capacity ``strength``.  With d = −Gᵀu, the rate at which a column's force is worked against
(the slip γ of a cohesive joint read against ±t, the elongation rate of a tie), a collapse state
of Eq. 9 has every bounded force on its flow rule:

- d > 0 ⇒ τ = capacity (a slipping joint's cohesive shear at its bound against the slip, an
  elongating tie at its strength);
- d < 0 ⇒ τ = 0 (the other column of a slipping joint, a shortening tie);
- d = 0 ⇒ 0 ≤ τ ≤ capacity (a joint that opens or hinges without slip, a tie of constant
  length: power zero).

Then τ d = capacity · max(0, d) for every column, and the energy balance of Eq. 9 reads
α f_Lᵀu = −f₀ᵀu + Σ f N |γ| + Σ capacity · max(0, d): the cohesion dissipates c l t |γ| per
joint and a tie strength · max(0, elongation rate).  Cohesion and ties do not dilate, so the
sliding rule of the point forces (T = −s f N) is unchanged.

An active set of the bounded columns is one sign per column (+1: τ = capacity and d ≥ 0;
−1: τ = 0 and d ≤ 0; 0: τ free within its bounds and d = 0); any field and any mechanism of the
same set complement each other.  Dimensionless, as :mod:`alma.mechanics.model`.
"""

from __future__ import annotations

from typing import cast

import numpy as np
import scipy.sparse as sp

from alma.floats import dot
from alma.mechanics.model import Model


def rates(model: Model, mechanism: np.ndarray) -> np.ndarray:
    """d = −Gᵀu of every bounded column (the power of its force at unit τ is −d)."""
    if not model.n_bounded:
        return np.zeros(0)
    return -(cast(sp.csc_matrix, model.bounded).T @ mechanism)


def rate_signs(d: np.ndarray, tolerance: float) -> np.ndarray:
    """The bounded columns' active set from their rates d (:func:`rates`): sign of d,
    |d| ≤ ``tolerance`` read as 0."""
    return np.where(d > tolerance, 1.0, np.where(d < -tolerance, -1.0, 0.0))


def force_bounds(model: Model, signs: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Bounds (lower, upper) on τ of a static LP with the bounded active set ``signs``
    (None: no set, 0 ≤ τ ≤ capacity)."""
    cap = model.capacity
    if signs is None:
        return np.zeros_like(cap), cap.copy()
    return np.where(signs > 0, cap, 0.0), np.where(signs < 0, 0.0, cap)


def force_signs(model: Model, tau: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """The widest rates a bounded field allows (complementarity): (may_grow, may_shrink).

    τ at its capacity allows d ≥ 0, τ at 0 allows d ≤ 0 (a column of capacity 0 allows both),
    τ strictly inside allows only d = 0; "at" is read to ``tolerance``.
    """
    cap = model.capacity
    return tau >= cap - tolerance, tau <= tolerance


def kinematic_rows(model: Model, may_grow: np.ndarray, may_shrink: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Rows over u of the bounded columns' kinematics: (equalities d = 0, inequalities A u ≤ 0).

    Columns that may neither grow nor shrink keep d = 0; those that may only grow get −d ≤ 0,
    those that may only shrink d ≤ 0; those that may do both get no row.
    """
    g_t = cast(sp.csc_matrix, model.bounded).T.tocsr()  # rows gᵢᵀ, d = −gᵢᵀu
    fixed = np.flatnonzero(~may_grow & ~may_shrink)
    grow = np.flatnonzero(may_grow & ~may_shrink)
    shrink = np.flatnonzero(may_shrink & ~may_grow)
    return g_t[fixed], sp.vstack([g_t[grow], -g_t[shrink]]).tocsr()


def residuals(
    model: Model, tau: np.ndarray, d: np.ndarray, force_scale: float, vel_scale: float
) -> tuple[float, float, float]:
    """(yield violation, mobilisation gap, dissipation) of a bounded field on a mechanism whose
    rates are d (:func:`rates`).

    Yield: how far τ leaves [0, capacity]; mobilisation: the largest capacity · max(0, d) − τ d
    (zero on the flow rule, module docstring), relative to ``force_scale`` × ``vel_scale``;
    dissipation: Σ capacity · max(0, d), dimensionless work.
    """
    cap = model.capacity
    violation = float(np.maximum(np.maximum(-tau, tau - cap), 0.0).max(initial=0.0))
    gap = float(np.abs(cap * np.maximum(d, 0.0) - tau * d).max(initial=0.0)) / (force_scale * vel_scale)
    return violation, gap, dot(cap, np.maximum(d, 0.0))
