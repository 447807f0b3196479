"""The closure corrector of a finite step: Newton's method on the contacts a mechanism keeps.

A finite rotation of each moving body about its instantaneous centre (the predictor of
:func:`alma.push.motion.predictor`) leaves a linkage's hinges open at second order in the step
(a portal frame's lintel hinges by O(θ Δθ h)).  The corrector moves the bodies (3 unknowns each:
the angle and the shift of its reference point) so that every hinge of the mechanism closes
(both bodies meet at the point), every sliding point keeps a zero normal gap, and the control
block's centroid moves horizontally by the step's target, to round-off.

Each Newton step is the least-squares step of smallest norm (a mechanism with spare freedoms
moves least): the regularised normal equations JᵀJ + λI by one sparse LDLᵀ factorisation (QDLDL,
which calls no BLAS: the same bits on every CPU) with two refinement sweeps (a dense SVD instead
up to ``PushSettings.dense_columns`` unknowns, none by default); J has a handful of entries per
contact, so the factorisation costs milliseconds where an iterative solver (LSMR) took seconds
and stalled at 1e-8 mm.  A Newton step that does not reduce the residual by
``PushSettings.corrector_contraction`` has stalled (the contacts kept over-constrain the motion: a
dilatant mechanism's sliding points) and ends the iteration at once.  Hinges that close a
mechanism only to first order (three collinear hinges among three bodies lock at finite motion)
make one of them open: :func:`one_hinge_opened` keeps the step that opens a hinge least without
interpenetration.  Lengths in mm, angles in rad.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp

from alma.backends.qdldl_backend import regularised_solver
from alma.push.motion import Bodies, Contacts, MotionError, _moved, _perp, _rotate
from alma.settings import PushSettings


def corrected(
    bodies: Bodies,
    contacts: Contacts,
    start: np.ndarray,
    control: tuple[int, np.ndarray] | None,
    target: float,
    length: float,
    settings: PushSettings,
    prescribed: np.ndarray | None = None,
) -> np.ndarray:
    """Increments (g, 3) that close every hinge and sliding point of ``contacts`` and move the
    control point (``control``: its block and its current position, mm) horizontally by
    ``target`` mm, by Newton's method from ``start``.  ``prescribed`` (g,) bool: bodies whose
    increment is ``start``'s and stays so (a settling support's own motion); with it,
    ``control`` may be None.

    Raises
    ------
    MotionError
        When the residual stalls above ``settings.corrector_tolerance`` × 10³ × ``length``.
    """
    z = start.copy()
    scale = np.tile([1.0, length, length], bodies.count)
    tol = settings.corrector_tolerance * length
    previous = np.inf
    size = np.inf
    for _ in range(settings.corrector_iterations):
        residual, jacobian = _equations(bodies, contacts, z, control, target, prescribed, start, length)
        size = float(np.abs(residual).max(initial=0.0))
        if size <= tol:
            return z
        if size > settings.corrector_contraction * previous:
            break
        previous = size
        step = _least_squares(jacobian @ sp.diags(scale), residual, settings.dense_columns)
        z = z - (step * scale).reshape(-1, 3)
    else:
        size = float(
            np.abs(_equations(bodies, contacts, z, control, target, prescribed, start, length)[0]).max(initial=0.0)
        )
    if size <= tol * 1e3:
        return z
    raise MotionError(
        f"the mechanism's contacts cannot stay closed over this step (residual {size:.3g} mm "
        "where Newton's method stalled)"
    )


def one_hinge_opened(
    bodies: Bodies,
    contacts: Contacts,
    start: np.ndarray,
    control: tuple[int, np.ndarray] | None,
    target: float,
    length: float,
    settings: PushSettings,
) -> np.ndarray:
    """Increments as :func:`corrected`'s, with one hinge of ``contacts`` released (its sliding
    points kept as given): the hinges of a mechanism that moves only infinitesimally with all of
    them closed (three collinear hinges among three bodies) cannot all stay closed over a finite step.

    Each hinge is released in turn; a release counts when the others then close and the released
    point's two corners do not overlap (normal gap ≥ −``corrector_tolerance`` × 10³ × ``length``).
    Of those, the one whose corners end closest together is kept: the motion nearest to the
    mechanism's own, an opening of second order in the step where the lock is (a tie, as in a
    symmetric linkage, goes to the point first along the push, then the lower one).

    Raises
    ------
    MotionError
        When no single released hinge lets the others close.
    """
    hinges = np.flatnonzero(contacts.hinge)
    floor = -settings.corrector_tolerance * 1e3 * length
    sense = 1.0 if target >= 0 else -1.0
    best: tuple[tuple[float, float, float], np.ndarray] | None = None
    for k in hinges:
        kept = dataclasses.replace(contacts, hinge=contacts.hinge & (np.arange(contacts.hinge.size) != k))
        try:
            z = corrected(bodies, kept, start, control, target, length, settings)
        except MotionError:
            continue
        gap = _moved(bodies, z, contacts.b[k : k + 1], contacts.point[k : k + 1])[0]
        gap = gap - _moved(bodies, z, contacts.a[k : k + 1], contacts.point[k : k + 1])[0]
        if float(gap @ contacts.normal[k]) < floor:
            continue
        key = (float(np.hypot(*gap)), -sense * float(contacts.point[k, 0]), float(contacts.point[k, 1]))
        if best is None or key < best[0]:
            best = (key, z)
    if best is None:
        raise MotionError(
            f"the mechanism's contacts cannot stay closed over this step, nor with any one of its {hinges.size} "
            "hinges opened"
        )
    return best[1]


def _least_squares(jacobian: sp.spmatrix, residual: np.ndarray, dense_columns: int) -> np.ndarray:
    """The least-squares step of (nearly) least norm: the regularised normal equations by QDLDL's
    LDLᵀ with two refinement sweeps (a dense SVD up to ``dense_columns`` unknowns)."""
    n = jacobian.shape[1]
    if n <= dense_columns:
        return np.linalg.lstsq(jacobian.toarray(), residual, rcond=None)[0]
    J = sp.csr_matrix(jacobian)
    gram = (J.T @ J).tocsc()
    # λ far below every curvature of the scaled system, enough to make a mechanism's spare
    # freedoms (zero columns of JᵀJ's range) invertible with a zero step along them
    lam = 1e-12 * max(float(gram.diagonal().max(initial=0.0)), 1.0)
    solve = regularised_solver(gram, lam)  # QDLDL: no BLAS, the same bits on every CPU
    x = solve(J.T @ residual)
    for _ in range(2):
        x = x + solve(J.T @ (residual - J @ x) - lam * x)
    return x


def _equations(
    bodies: Bodies,
    contacts: Contacts,
    z: np.ndarray,
    control: tuple[int, np.ndarray] | None,
    target: float,
    prescribed: np.ndarray | None = None,
    start: np.ndarray | None = None,
    length: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Residual and Jacobian (columns: angle, shift x, shift y of each body) of the corrector;
    a prescribed body's rows hold its increment at ``start``'s (the angle's times ``length``, mm)."""
    g_count = bodies.count
    rows_r, cols, vals = [], [], []
    residual = []
    row = 0

    def side(blocks: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        g = bodies.of_block[blocks]
        gg = np.where(g >= 0, g, 0)
        arm = _rotate(points - bodies.centre[gg], z[gg, 0])
        moved = np.where((g >= 0)[:, None], arm + bodies.centre[gg] + z[gg, 1:], points)
        return g, moved, _perp(arm)

    h = np.flatnonzero(contacts.hinge)
    if h.size:
        ga, xa, da = side(contacts.a[h], contacts.point[h])
        gb, xb, db = side(contacts.b[h], contacts.point[h])
        residual.append((xa - xb).reshape(-1))
        r = row + 2 * np.arange(h.size)
        for g, d, sign in ((ga, da, 1.0), (gb, db, -1.0)):
            m = g >= 0
            for k in (0, 1):
                rows_r += [r[m] + k, r[m] + k]
                cols += [3 * g[m], 3 * g[m] + 1 + k]
                vals += [sign * d[m, k], np.full(int(m.sum()), sign)]
        row += 2 * h.size
    s = np.flatnonzero(contacts.sliding)
    if s.size:
        ga, xa, da = side(contacts.a[s], contacts.point[s])
        gb, xb, db = side(contacts.b[s], contacts.point[s])
        na = np.where(
            (ga >= 0)[:, None], _rotate(contacts.normal[s], z[np.where(ga >= 0, ga, 0), 0]), contacts.normal[s]
        )
        gap = xb - xa
        residual.append((gap * na).sum(axis=1))
        r = row + np.arange(s.size)
        ma, mb = ga >= 0, gb >= 0
        rows_r += [r[ma], r[ma], r[ma], r[mb], r[mb], r[mb]]
        cols += [3 * ga[ma], 3 * ga[ma] + 1, 3 * ga[ma] + 2, 3 * gb[mb], 3 * gb[mb] + 1, 3 * gb[mb] + 2]
        vals += [
            (-(da * na).sum(axis=1) + (gap * _perp(na)).sum(axis=1))[ma],
            -na[ma, 0],
            -na[ma, 1],
            (db * na).sum(axis=1)[mb],
            na[mb, 0],
            na[mb, 1],
        ]
        row += s.size
    if control is not None:
        block, where = control
        gc, moved, dc = side(np.array([block]), where[None, :])
        residual.append(np.array([moved[0, 0] - where[0] - target]))
        rows_r += [np.array([row]), np.array([row])]
        cols += [np.array([3 * gc[0]]), np.array([3 * gc[0] + 1])]
        vals += [np.array([dc[0, 0]]), np.array([1.0])]
        row += 1
    if prescribed is not None and start is not None and prescribed.any():
        row = _prescribed_rows(z, start, prescribed, length, row, (residual, rows_r, cols, vals))
    jac = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows_r).astype(int), np.concatenate(cols).astype(int))),
        shape=(row, 3 * g_count),
    )
    return np.concatenate(residual), jac


def _prescribed_rows(
    z: np.ndarray,
    start: np.ndarray,
    prescribed: np.ndarray,
    length: float,
    row: int,
    out: tuple[list, list, list, list],
) -> int:
    """Append the rows z_g = start_g of the prescribed bodies (the angle's times ``length``, mm)
    to ``out`` (residual, rows, columns, values); returns the next row."""
    residual, rows_r, cols, vals = out
    fixed = np.flatnonzero(prescribed)
    weight = np.array([length, 1.0, 1.0])
    residual.append(((z[fixed] - start[fixed]) * weight).reshape(-1))
    rows_r.append(row + np.arange(3 * fixed.size))
    cols.append((3 * fixed[:, None] + np.arange(3)).reshape(-1))
    vals.append(np.tile(weight, fixed.size))
    return row + 3 * fixed.size
