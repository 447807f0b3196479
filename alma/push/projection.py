"""A finite step no closure holds: the motion nearest the mechanism that keeps every contact
unilateral.

The closure corrector (:mod:`alma.push.corrector`) keeps a mechanism's hinges closed and its
sliding points on their faces.  A mechanism of many bodies can be a first-order mechanism only:
its hinges cannot all stay closed over any finite step, and no single hinge opened frees it (the
paper's 4:1 panels at f = 0.6, 151 hinges, lock 1.44 mm into their curve).  The contacts of rigid
blocks are unilateral, though: a hinge may open.  This step asks only that: of the motions that
move the control point horizontally by the step's target and drive no contact point into its
neighbour, the one nearest the mechanism's predictor, a sequential QP on the linearised gaps

    min ½ ‖(z − z_p) / s‖²   s.t.  gap(z_k) + ∂gap (z − z_k) ≥ 0,   control(z_k) + ∂control (z − z_k) = 0

(s = (h/L, h, h) per body, h the control's step: unknowns of order one), re-linearised at
each round's z until every gap lies within the entering tolerance of the step and the control
moves to the corrector's tolerance.  Clarabel solves each QP (:mod:`alma.backends`).  The next
configuration's analysis then finds the contacts where they are.  Lengths in mm, angles in rad.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp

from alma.backends.clarabel_backend import solve_conic_lp
from alma.backends.termination import Termination
from alma.push.corrector import _equations
from alma.push.motion import Bodies, Contacts, MotionError
from alma.settings import PushSettings

#: Clarabel's tolerance on each QP (unknowns of order one): a body the step need not move stays
#: within ~1e-7 of the step's size (1e-5 at 1e-10: an interior point's error is the root of its gap).
QP_TOLERANCE = 1e-12
#: Clarabel iterations of each QP.
QP_ITERATIONS = 200


def projected_step(
    bodies: Bodies,
    contacts: Contacts,
    start: np.ndarray,
    control: tuple[int, np.ndarray],
    target: float,
    length: float,
    settings: PushSettings,
    entering: float,
) -> np.ndarray:
    """Increments (g, 3) nearest ``start`` (the mechanism's predictor) that move the control point
    (its block and position, mm) horizontally by ``target`` mm and carry no contact point of
    ``contacts`` into its neighbour by more than ``entering`` mm (module docstring).

    Raises
    ------
    MotionError
        When a QP has no solution (no such motion to first order) or the rounds
        (``settings.projection_rounds``) end with a point entering or the control off its target.
    """
    every = dataclasses.replace(contacts, hinge=np.zeros_like(contacts.hinge), sliding=np.ones_like(contacts.sliding))
    # unknowns of order one: the step's own size in each body's angle and shifts
    size = max(abs(target), settings.corrector_tolerance * length)
    scale = np.tile([size / length, size, size], bodies.count)
    target_tol = settings.corrector_tolerance * 1e3 * length
    z = start.copy()
    gaps, jacobian = _equations(bodies, every, z, control, target)
    for _ in range(settings.projection_rounds):
        x = _qp(z, start, gaps, jacobian, scale)
        if x is None:
            raise MotionError("no motion of the step keeps the contacts from entering each other")
        z = z + (x * scale).reshape(-1, 3)
        gaps, jacobian = _equations(bodies, every, z, control, target)  # the next round's linearisation too
        if gaps[:-1].min(initial=0.0) >= -entering and abs(gaps[-1]) <= target_tol:
            return z
    raise MotionError(
        f"the step's contacts stay more than {entering:.3g} mm into each other after "
        f"{settings.projection_rounds} rounds of the unilateral step"
    )


def _qp(
    z: np.ndarray, start: np.ndarray, rows: np.ndarray, jacobian: sp.spmatrix, scale: np.ndarray
) -> np.ndarray | None:
    """The scaled increment x of one round: min ½‖x + (z − start)/s‖² with the control's row an
    equality (the last row) and the gaps' rows (the others) ≥ 0; None when Clarabel finds none."""
    J = sp.csr_matrix(jacobian) @ sp.diags(scale)
    n = J.shape[1]
    A = sp.vstack([J[-1:], -J[:-1]]).tocsc()
    b = np.concatenate([-rows[-1:], rows[:-1]])
    q = ((z - start).reshape(-1)) / scale
    result = solve_conic_lp(
        q,
        A,
        b,
        1,
        J.shape[0] - 1,
        tolerance=QP_TOLERANCE,
        max_iter=QP_ITERATIONS,
        quadratic=sp.identity(n, format="csc"),
    )
    # the gaps are measured after the round: an inaccurate optimum is judged by them
    if result.termination not in (Termination.OPTIMAL, Termination.OPTIMAL_INACCURATE):
        return None
    return result.x
