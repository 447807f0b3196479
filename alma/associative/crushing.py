"""Eq. 10 with finite compressive strength: the static problem as a second-order cone program.

A joint of length l and thickness t whose blocks crush at σ_c carries, with a rectangular
stress block, N ≤ σ_c l t and |M| ≤ N (l/2 − N/(2 σ_c t)) (M about the joint's centre).  On the
joint's two contact points (N = N₀ + N₁, M = (N₁ − N₀) l/2) the parabola reads

    N l/2 ∓ M ≥ N² / (2 σ_c t)   ⇔   2 c N_p ≥ N²  at each point p,  c = σ_c l t,

two rotated second-order cones per joint (their sum gives N ≤ c).  The Coulomb cone of each
point stays as it is (generators n ± f t, μ ≥ 0), so the equilibrium H μ + G τ + f₀ + α f_L = 0
of the rigid model is unchanged; the cones only bound μ.

Static form (Clarabel's primal, x = (α, μ, τ))::

    max α   s.t.  f_L α + H μ + G τ = −f₀,   μ ≥ 0,   0 ≤ τ ≤ capacity,
                  (√c (N_p + 1), √c (N_p − 1), √2 N) ∈ Q³   (2 c N_p ≥ N², scaled by √c)

The duals of the equilibrium rows are a mechanism u (Eq. 10's kinematic side).
For any u the dissipation of a crushing joint, sup over its yield set of the power −μᵀHᵀu, is
finite and has the closed form :func:`crushing_dissipation`; so every mechanism proves an upper
bound without a flow-rule repair on the crushing joints.  All quantities are dimensionless
(:mod:`alma.mechanics.model`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from alma.associative.certificate import static_correction
from alma.backends.clarabel_backend import solve_static_cone
from alma.backends.termination import SolverResult
from alma.mechanics.model import Model
from alma.settings import AssociativeSettings


#: The solver's cones are 2 c (N_p − margin) ≥ N² (margin in mean block weights): the stress field keeps this
#: much room to the exact cone for the certificate's equilibrium repair (~1e-9), at a cost in α of
#: ~margin × crushing points / total weight (< 1e-9 relative on the paper's panels).
CONE_MARGIN = 1e-8
#: ... and 2 c ((1 − κ) N_p − margin) ≥ N²: room in proportion to the force for the joints at the
#: base of the tall panels (N ~ 150 mean block weights, where 1e-8 absolute is round-off).
CONE_RELATIVE_MARGIN = 5e-8
#: A crushing joint whose generator powers are all below this fraction of the largest is at rest
#: (the interior point's blend leaves traces of ~1e-9 there; a moving joint's are ≥ 1e-4).
REST = 1e-7


def crushing_joints(model: Model) -> np.ndarray:
    """Indices of the joints with a finite crushing capacity."""
    return np.flatnonzero(np.isfinite(model.crushing))


def static_cone_form(model: Model, H: sp.csc_matrix, normalisation: float = 1.0
                     ) -> tuple[np.ndarray, sp.csc_matrix, np.ndarray, int, int, int]:
    """The static problem (module docstring) as ``min qᵀx s.t. A x + s = b`` for Clarabel.

    The objective is −normalisation · n_free · α, so that the duals (the mechanism) come with
    f_Lᵀu = normalisation · n_free, the scale of Eq. 10's kinematic form
    (:class:`alma.settings.AssociativeSettings`): at f_Lᵀu = 1 the block velocities are
    ~1/n_free and Clarabel's absolute tolerances stop the largest panel at a gap of 1e-6 (6e-8
    with the scale, in 74 instead of 91 iterations).

    Rows: equilibrium (3 n_free, zero cone), μ ≥ 0 and 0 ≤ τ ≤ capacity (non-negative cone), then
    three rows per contact point of each crushing joint (Q³).  Returns (q, A, b, n_zero, n_nonneg,
    n_soc3).
    """
    n, k = H.shape
    q_count = model.n_bounded
    G = model.bounded if q_count else sp.csc_matrix((n, 0))
    n_x = 1 + k + q_count
    equilibrium = sp.hstack([sp.csc_matrix(model.live[:, None]), H, G]).tocsc()
    eye_mu = sp.csc_matrix((-np.ones(k), (np.arange(k), 1 + np.arange(k))), shape=(k, n_x))
    tau_cols = 1 + k + np.arange(q_count)
    eye_tau = sp.csc_matrix((np.ones(q_count), (np.arange(q_count), tau_cols)), shape=(q_count, n_x))
    cones, cone_b = _cone_rows(model, n_x)
    A = sp.vstack([equilibrium, eye_mu, -eye_tau, eye_tau, cones]).tocsc()
    b = np.concatenate([-model.dead, np.zeros(k + q_count), model.capacity, cone_b])
    q = np.zeros(n_x)
    q[0] = -normalisation * float(model.n_free)
    return q, A, b, n, k + 2 * q_count, cone_b.size // 3


def _cone_rows(model: Model, n_x: int) -> tuple[sp.csc_matrix, np.ndarray]:
    """Rows −A x of (√c (N_p + 1), √c (N_p − 1), √2 N) for every point p of every crushing joint,
    with their b = (√c, −√c, 0): s = b − A x is the scaled rotated cone 2 c N_p ≥ N²."""
    joints = crushing_joints(model)
    root = np.sqrt(model.crushing[joints])
    point = np.repeat(2 * joints, 2) + np.tile([0, 1], joints.size)  # global point index 2k + p
    scale = np.repeat(root, 2)
    n_points = point.size
    base = 3 * np.arange(n_points)
    rows, cols, vals = [], [], []
    for sign in (0, 1):  # the point's two generators: columns 1 + 2 (2k + p) + sign
        col = 1 + 2 * point + sign
        rows += [base, base + 1]
        cols += [col, col]
        vals += [-scale, -scale]
    for gen in range(4):  # N: the joint's four generators
        col = 1 + 4 * np.repeat(joints, 2) + gen
        rows.append(base + 2)
        cols.append(col)
        vals.append(np.full(n_points, -np.sqrt(2.0)))
    A = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(3 * n_points, n_x))
    b = np.zeros(3 * n_points)
    b[0::3], b[1::3] = scale * (1.0 - CONE_MARGIN), -scale * (1.0 + CONE_MARGIN)
    keep = sp.diags(np.tile([1.0 - CONE_RELATIVE_MARGIN, 1.0 - CONE_RELATIVE_MARGIN, 1.0], n_points))
    A = (keep @ A).tocsc()  # (1 − κ) N_p in the first two rows
    return A, b


def solve_static_crushing(model: Model, H: sp.csc_matrix, tolerance: float, max_iter: int,
                          time_limit: float | None = None, refine: bool = True,
                          normalisation: float = 1.0) -> SolverResult:
    """Clarabel's primal–dual pair of the static cone program (:func:`static_cone_form`)."""
    q, A, b, n_zero, n_nonneg, n_soc = static_cone_form(model, H, normalisation)
    return solve_static_cone(q, A, b, n_zero, n_nonneg, n_soc, tolerance=tolerance, max_iter=max_iter,
                             time_limit=time_limit, refine=refine)


def point_normals(mu: np.ndarray) -> np.ndarray:
    """(m, 2) normal force N_p at each contact point from the generator multipliers μ (4 m)."""
    return mu.reshape(-1, 2, 2).sum(axis=2)


def cone_violation(model: Model, mu: np.ndarray) -> float:
    """Largest violation of 2 c N_p ≥ N² on the crushing joints, as the normal force missing at a
    point, max(0, N²/(2c) − N_p), in mean block weights or, where the joint carries more than one,
    relative to its N (the equilibrium residual's round-off floor also grows with the forces)."""
    joints = crushing_joints(model)
    if joints.size == 0:
        return 0.0
    normals = point_normals(mu)[joints]
    total = normals.sum(axis=1)
    need = total**2 / (2.0 * model.crushing[joints])
    missing = np.maximum(need[:, None] - normals, 0.0) / np.maximum(total, 1.0)[:, None]
    return float(missing.max(initial=0.0))


def crushing_dissipation(model: Model, power: np.ndarray, among: np.ndarray | None = None) -> float:
    """Σ over the crushing joints (those of the mask ``among``, default all) of
    sup_{μ in the joint's yield set} (−μᵀ g), g = Hᵀu (4 m).

    A point's two generators share its N_p, so the point does work a_p N_p at most, a_p =
    −min(g₊, g₋).  With a_hi ≥ a_lo the joint's two values, the best split puts N²/(2c) on the
    point of a_lo, and over N ∈ [0, c]: 0 when a_hi ≤ 0; c (a_hi + a_lo)/2 (N = c, the stress
    block over the whole joint) when a_lo ≥ 0; else c a_hi² / (2 (a_hi − a_lo)).
    """
    joints = crushing_joints(model)
    if among is not None:
        joints = joints[among[joints]]
    if joints.size == 0:
        return 0.0
    a = -power.reshape(-1, 2, 2).min(axis=2)[joints]  # (j, point)
    hi, lo = a.max(axis=1), a.min(axis=1)
    c = model.crushing[joints]
    inner = c * hi**2 / (2.0 * np.maximum(hi - lo, np.finfo(float).tiny))
    value = np.where(hi <= 0.0, 0.0, np.where(lo >= 0.0, 0.5 * c * (hi + lo), inner))
    return float(value.sum())


def rigid_columns(model: Model, power: np.ndarray | None = None) -> np.ndarray:
    """Generator columns (4 per joint) on which the mechanism is held to the flow rule Hᵀu ≥ 0:
    the joints without a crushing capacity, and -- given the solver's powers ``power`` = Hᵀu --
    the crushing joints that crush nowhere: at each point the smaller power of its two generators
    (−a_p, :func:`crushing_dissipation`) below :data:`REST` of the largest power (at rest, sliding
    with dilatancy, or separating).

    Such a joint dissipates c |noise| on the solver's round-off (c = σ_c l t is 10³-10⁹ mean
    block weights); the repair removes the noise so that its dissipation is ~0."""
    rigid = ~np.isfinite(model.crushing)
    if power is not None:
        size = max(float(np.abs(power).max(initial=0.0)), 1e-300)
        closing = np.abs(power.reshape(-1, 2, 2).min(axis=2)).max(axis=1)
        rigid |= closing <= REST * size
    return np.flatnonzero(np.repeat(rigid, 4))



def repair_cone_field(model: Model, static: sp.csc_matrix, fields: np.ndarray, alpha: float,
                      bound: np.ndarray, feral_min_rows: int = AssociativeSettings().feral_min_rows
                      ) -> tuple[np.ndarray, float, float]:
    """The static field (μ, τ) put in equilibrium (Eq. 3) at a corrected α, kept inside the cones.

    An affine-scaled minimum-norm correction (as :func:`alma.associative.certificate.certify_pair`'s
    second pass) in which every generator of a crushing point moves in proportion to its room: the
    smallest of μ, the point's cone slack N_p − N²/(2c) and the other point's slack times c/N, so
    that the hinge points, a solver's margin away from their cones, keep their place.  Returns
    (fields, α, equilibrium residual).
    """
    k = model.equilibrium.shape[1]
    mu = np.clip(fields, 0.0, bound)
    best = (mu, alpha, float(np.abs(static @ mu + model.dead + alpha * model.live).max(initial=0.0)))
    for _ in range(3):  # each round takes the rooms of the last field: the residual falls ~1000x
        room = np.minimum(best[0], bound - best[0])
        joints = crushing_joints(model)
        if joints.size:
            normals = point_normals(best[0][:k])
            slack = np.full(normals.shape, np.inf)
            total = normals[joints].sum(axis=1)
            need = total**2 / (2.0 * model.crushing[joints])
            own = np.maximum(normals[joints] - need[:, None], 0.0)
            # a point's force lowers its own slack when it falls and, through N, the other
            # point's when it rises (need grows by N ΔN / c): both bound its room
            other = own[:, ::-1] * model.crushing[joints][:, None] / np.maximum(total, 1e-300)[:, None]
            slack[joints] = np.minimum(own, other)
            room[:k] = np.minimum(room[:k], np.repeat(slack.ravel(), 2))
        top = max(float(best[0].max(initial=0.0)), 1e-300)
        support = np.flatnonzero(room > 1e-14 * top)
        trial = static_correction(static, model, best[0].copy(), best[1], support, np.sqrt(room[support] / top),
                                  bound, feral_min_rows)
        if trial[2] >= best[2]:
            break
        best = trial
    return best
