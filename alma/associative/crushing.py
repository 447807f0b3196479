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

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from alma.backends.clarabel_backend import solve_static_cone
from alma.backends.termination import SolverResult
from alma.floats import dot
from alma.mechanics.model import Model
from alma.settings import CrushingSettings


@dataclass(frozen=True)
class ConeMargins:
    """Room the solver's cones keep at each contact point of the crushing joints (in the order of
    :func:`crushing_joints`, two points each): 2 c ((1 − relative) N_p − load N − absolute) ≥ N²,
    forces in mean block weights (:class:`alma.settings.CrushingSettings`)."""

    absolute: np.ndarray
    relative: np.ndarray
    load: np.ndarray


def uniform_margins(model: Model, settings: CrushingSettings) -> ConeMargins:
    """The margins of the first solve: the same absolute and relative room at every point."""
    points = 2 * crushing_joints(model).size
    return ConeMargins(
        np.full(points, settings.cone_margin), np.full(points, settings.cone_relative_margin), np.zeros(points)
    )


def crushing_joints(model: Model) -> np.ndarray:
    """Indices of the joints with a finite crushing capacity."""
    return np.flatnonzero(np.isfinite(model.crushing))


def static_cone_form(
    model: Model, H: sp.csc_matrix, normalisation: float = 1.0, margins: ConeMargins | None = None
) -> tuple[np.ndarray, sp.csc_matrix, np.ndarray, int, int, int]:
    """The static problem (module docstring) as ``min qᵀx s.t. A x + s = b`` for Clarabel.

    The objective is −normalisation · n_free · α, so that the duals (the mechanism) come with
    f_Lᵀu = normalisation · n_free, the scale of Eq. 10's kinematic form
    (:class:`alma.settings.AssociativeSettings`): at f_Lᵀu = 1 the block velocities are
    ~1/n_free and Clarabel's absolute tolerances stop the largest panel at a gap of 1e-6 (6e-8
    with the scale, in 74 instead of 91 iterations).

    Rows: equilibrium (3 n_free, zero cone), μ ≥ 0 and 0 ≤ τ ≤ capacity (non-negative cone), then
    three rows per contact point of each crushing joint (Q³), with ``margins`` (default
    :func:`uniform_margins` of the default settings).  Returns (q, A, b, n_zero, n_nonneg, n_soc3).
    """
    n, k = H.shape
    q_count = model.n_bounded
    G = model.bounded if q_count else sp.csc_matrix((n, 0))
    n_x = 1 + k + q_count
    equilibrium = sp.hstack([sp.csc_matrix(model.live[:, None]), H, G]).tocsc()
    eye_mu = sp.csc_matrix((-np.ones(k), (np.arange(k), 1 + np.arange(k))), shape=(k, n_x))
    tau_cols = 1 + k + np.arange(q_count)
    eye_tau = sp.csc_matrix((np.ones(q_count), (np.arange(q_count), tau_cols)), shape=(q_count, n_x))
    cones, cone_b = _cone_rows(model, n_x, margins or uniform_margins(model, CrushingSettings()))
    A = sp.vstack([equilibrium, eye_mu, -eye_tau, eye_tau, cones]).tocsc()
    b = np.concatenate([-model.dead, np.zeros(k + q_count), model.capacity, cone_b])
    q = np.zeros(n_x)
    q[0] = -normalisation * float(model.n_free)
    return q, A, b, n, k + 2 * q_count, cone_b.size // 3


def _cone_rows(model: Model, n_x: int, margins: ConeMargins) -> tuple[sp.csc_matrix, np.ndarray]:
    """Rows −A x of (√c (L_p + 1), √c (L_p − 1), √2 N) for every point p of every crushing joint,
    L_p = (1 − relative) N_p − load N − absolute (:class:`ConeMargins`): s = b − A x is the scaled
    rotated cone 2 c L_p ≥ N²."""
    joints = crushing_joints(model)
    root = np.sqrt(model.crushing[joints])
    point = np.repeat(2 * joints, 2) + np.tile([0, 1], joints.size)  # global point index 2k + p
    scale = np.repeat(root, 2)
    n_points = point.size
    base = 3 * np.arange(n_points)
    own = -scale * (1.0 - margins.relative)
    rows, cols, vals = [], [], []
    for sign in (0, 1):  # the point's two generators: columns 1 + 2 (2k + p) + sign
        col = 1 + 2 * point + sign
        rows += [base, base + 1]
        cols += [col, col]
        vals += [own, own]
    for gen in range(4):  # N: the joint's four generators, in the third row and in L_p's load term
        col = 1 + 4 * np.repeat(joints, 2) + gen
        rows += [base + 2, base, base + 1]
        cols += [col, col, col]
        vals += [np.full(n_points, -np.sqrt(2.0)), scale * margins.load, scale * margins.load]
    A = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(3 * n_points, n_x))
    A.eliminate_zeros()  # the load terms are zero outside an anchor solve
    b = np.zeros(3 * n_points)
    b[0::3], b[1::3] = scale * (1.0 - margins.absolute), -scale * (1.0 + margins.absolute)
    return A, b


def solve_static_crushing(
    model: Model,
    H: sp.csc_matrix,
    tolerance: float,
    max_iter: int,
    time_limit: float | None = None,
    refine: bool = True,
    normalisation: float = 1.0,
    margins: ConeMargins | None = None,
) -> SolverResult:
    """Clarabel's primal–dual pair of the static cone program (:func:`static_cone_form`)."""
    q, A, b, n_zero, n_nonneg, n_soc = static_cone_form(model, H, normalisation, margins)
    return solve_static_cone(
        q, A, b, n_zero, n_nonneg, n_soc, tolerance=tolerance, max_iter=max_iter, time_limit=time_limit, refine=refine
    )


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


def rigid_columns(model: Model, power: np.ndarray | None = None, rest: float = CrushingSettings().rest) -> np.ndarray:
    """Generator columns (4 per joint) on which the mechanism is held to the flow rule Hᵀu ≥ 0:
    the joints without a crushing capacity, and -- given the solver's powers ``power`` = Hᵀu --
    the crushing joints that crush nowhere: at each point the smaller power of its two generators
    (−a_p, :func:`crushing_dissipation`) below ``rest`` of the largest power (at rest, sliding
    with dilatancy, or separating).

    Such a joint dissipates c |noise| on the solver's round-off (c = σ_c l t is 10³-10⁹ mean
    block weights); the repair removes the noise so that its dissipation is ~0."""
    rigid = ~np.isfinite(model.crushing)
    if power is not None:
        size = max(float(np.abs(power).max(initial=0.0)), 1e-300)
        closing = np.abs(power.reshape(-1, 2, 2).min(axis=2)).max(axis=1)
        rigid |= closing <= rest * size
    return np.flatnonzero(np.repeat(rigid, 4))


def flow_violation(H: sp.csc_matrix, u: np.ndarray) -> float:
    """Largest flow-rule violation (Eq. 6) of u on the columns of H, relative to the size of its
    terms: max(0, −min Hᵀu) / max |Hᵀ| |u| (as the certificate's kinematic repair measures it)."""
    if H.shape[1] == 0:
        return 0.0
    power = H.T @ u
    size = float((abs(H).T @ np.abs(u)).max(initial=0.0))
    return max(0.0, -float(power.min(initial=0.0))) / max(size, 1e-300)


def crushing_work(
    model: Model,
    H: sp.csc_matrix,
    u: np.ndarray,
    mu: np.ndarray,
    held: np.ndarray,
    bounded_work: float,
    held_residual: float,
    tolerance: float,
) -> tuple[float, float]:
    """The work −f₀ᵀu + D(u) of a mechanism u of Eq. 10 with finite compressive strength (its upper
    bound is work / f_Lᵀu) and the flow-rule residual the bound rests on.

    The joints in ``held`` (generator columns, :func:`rigid_columns`) are held to Hᵀu ≥ 0 and
    their round-off violations are charged with the field's μ, as the LP's; the other crushing
    joints dissipate exactly (:func:`crushing_dissipation`).  When the held joints break the flow
    rule beyond ``tolerance`` (``held_residual``), the crushing ones among them are counted with
    their exact dissipation too, which holds for any u: only the infinitely strong joints then
    need the flow rule.  ``bounded_work`` is the bounded forces' dissipation (cohesion, ties).
    """
    power = H.T @ u
    moving = np.ones(model.n_joints, dtype=bool)
    moving[held[::4] // 4] = False
    charged = dot(np.maximum(-power[held], 0.0), mu[held])
    work = -dot(model.dead, u) + crushing_dissipation(model, power, moving) + bounded_work + charged
    if held_residual <= tolerance:
        return work, held_residual
    strong = np.flatnonzero(np.repeat(~np.isfinite(model.crushing), 4))
    residual = flow_violation(H[:, strong], u)
    if residual > tolerance:
        return work, held_residual
    charged = dot(np.maximum(-power[strong], 0.0), mu[strong])
    return -dot(model.dead, u) + crushing_dissipation(model, power) + bounded_work + charged, residual
