"""min α of Eq. 9 by enumerating every active set of a tiny scene, with scipy's ``linprog`` and
none of alma's certification code: each point open or closed, each joint slipping +t, −t or
sticking, each bounded force at its capacity, unloaded or between; per active set one static LP
(min α) and one kinematic feasibility LP.  The independent check of ``alma.certify``'s proofs."""

from __future__ import annotations

import itertools

import numpy as np
from scipy.optimize import linprog

from alma.mechanics.contact_points import ContactPoints


def _static_min(model, pts, opened, slip, rate) -> float:
    """min α over the static fields of one active set (−inf when unbounded, inf when empty)."""
    P, q = pts.count, model.n_bounded
    Nn, Tt = pts.normal.toarray(), pts.tangent.toarray()
    G = model.bounded.toarray() if q else np.zeros((Nn.shape[0], 0))
    f = pts.friction
    A_eq = [np.hstack([model.live[:, None], Nn, Tt, G])]
    b_eq = [-model.dead]
    A_ub, b_ub = [], []
    for p in range(P):

        def row(a, b, q=q):
            return np.concatenate([[0.0], a, b, np.zeros(q)])

        e = np.eye(P)[p]
        A_ub += [row(-f[p] * e, e), row(-f[p] * e, -e)]  # |T| ≤ f N
        b_ub += [0.0, 0.0]
        s = slip[pts.joint[p]]
        if s:  # slipping +t: T = −f N; −t: T = +f N
            A_eq.append(row(f[p] * e, s * e)[None, :])
            b_eq.append(np.zeros(1))
    bounds = [(None, None)] + [(0.0, 0.0) if o else (0.0, None) for o in opened] + [(None, None)] * P
    bounds += [
        ((c, c) if r > 0 else (0.0, 0.0) if r < 0 else (0.0, c)) for c, r in zip(model.capacity, rate, strict=True)
    ]
    cost = np.zeros(1 + 2 * P + q)
    cost[0] = 1.0
    res = linprog(
        cost,
        A_ub=np.array(A_ub),
        b_ub=b_ub,
        A_eq=np.vstack(A_eq),
        b_eq=np.concatenate(b_eq),
        bounds=bounds,
        method="highs",
    )
    return {0: res.fun if res.status == 0 else np.nan, 2: np.inf, 3: -np.inf}.get(res.status, np.nan)


def _kinematic(model, pts, opened, slip, rate, U: float) -> bool:
    """Is there a mechanism of the active set with f_Lᵀu = n_free and |u|∞ ≤ U?"""
    Nn, Tt = pts.normal.toarray().T, pts.tangent.toarray().T
    G = model.bounded.toarray().T if model.n_bounded else np.zeros((0, Nn.shape[1]))
    first = [np.flatnonzero(pts.joint == j)[0] for j in range(len(slip))]
    A_eq = [model.live[None, :]] + [Nn[[p]] for p in range(pts.count) if not opened[p]]
    A_eq += [Tt[[first[j]]] for j, s in enumerate(slip) if s == 0] + [G[[i]] for i, r in enumerate(rate) if r == 0]
    A_ub = [-Nn] + [-s * Tt[[first[j]]] for j, s in enumerate(slip) if s]
    A_ub += [r * G[[i]] for i, r in enumerate(rate) if r]  # d = −Gᵀu has the sign of r
    b_eq = np.zeros(len(A_eq))
    b_eq[0] = model.n_free
    ub = np.vstack(A_ub)
    res = linprog(
        np.zeros(Nn.shape[1]),
        A_ub=ub,
        b_ub=np.zeros(ub.shape[0]),
        A_eq=np.vstack(A_eq),
        b_eq=b_eq,
        bounds=[(-U, U)] * Nn.shape[1],
        method="highs",
    )
    return res.status == 0


def enumerated_minimum(model, U: float) -> float:
    """min α of Eq. 9 over every active set, with |u|∞ ≤ U (α clipped at 0 like the MILP's column)."""
    pts = ContactPoints.from_model(model)
    m = int(pts.joint.max()) + 1
    best = np.inf
    for slip in itertools.product((0, 1, -1), repeat=m):
        for rate in itertools.product((0, 1, -1), repeat=model.n_bounded):
            if not _kinematic(model, pts, (True,) * pts.count, slip, rate, U):
                continue  # closing points only adds constraints: no active set of this slip and rate moves
            for opened in itertools.product((False, True), repeat=pts.count):
                if _kinematic(model, pts, opened, slip, rate, U):
                    best = min(best, _static_min(model, pts, opened, slip, rate))
    return max(0.0, best)
