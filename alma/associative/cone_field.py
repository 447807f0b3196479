"""The lower bound of finite compressive strength: a stress field in equilibrium inside every cone.

Clarabel's field of the cone program (:mod:`alma.associative.crushing`) misses equilibrium (Eq. 3)
by round-off and may lie outside a cone 2 c N_p ≥ N² by its tolerance (c = σ_c l t; forces in mean
block weights).  The equilibrium repair of :mod:`alma.associative.certificate` removes the first;
for the second this module has two steps:

- :func:`repair_cone_field`, an equilibrium repair that moves each generator in proportion to its
  cone room, so that points the solver left inside stay inside;
- :func:`anchored_field`, when the field is still outside: a second solve (the *anchor*) with extra
  room at the joints the field left, and the convex blend (1 − θ) field + θ anchor with the
  smallest θ that puts every point inside its cone.  Equilibrium is affine and each cone convex,
  so the blend is in equilibrium at (1 − θ) α + θ α₀ and admissible: a certified lower bound
  a little below α (θ (α − α₀), measured ~1e-10 relative on the paper's panels).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from alma.associative.certificate import repair_field, static_correction
from alma.associative.crushing import (
    ConeMargins,
    cone_violation,
    crushing_joints,
    point_normals,
    solve_static_crushing,
    uniform_margins,
)
from alma.mechanics.model import Model
from alma.settings import AssociativeSettings

#: Bisection steps of the blend's θ per point: 2⁻⁶⁰ of [0, 1] is below double precision.
BISECTION_STEPS = 60


@dataclass(frozen=True)
class ConeField:
    """A static field (μ, τ) of the cone program at α, its admissibility residual (equilibrium or
    cone violation, mean block weights) and the anchor solve's cost when one ran."""

    fields: np.ndarray
    alpha: float
    residual: float
    solve_time: float = 0.0
    iterations: int = 0
    note: str = ""


def repair_cone_field(
    model: Model,
    static: sp.csc_matrix,
    fields: np.ndarray,
    alpha: float,
    bound: np.ndarray,
    feral_min_rows: int = AssociativeSettings().feral_min_rows,
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
        trial = static_correction(
            static, model, best[0].copy(), best[1], support, np.sqrt(room[support] / top), bound, feral_min_rows
        )
        if trial[2] >= best[2]:
            break
        best = trial
    return best


def missing_force(model: Model, mu: np.ndarray) -> np.ndarray:
    """(j, 2) normal force missing at each point of the crushing joints, max(0, N²/(2c) − N_p)."""
    joints = crushing_joints(model)
    normals = point_normals(mu)[joints]
    need = normals.sum(axis=1) ** 2 / (2.0 * model.crushing[joints])
    return np.maximum(need[:, None] - normals, 0.0)


def anchor_margins(model: Model, mu: np.ndarray, s: AssociativeSettings) -> ConeMargins:
    """The first solve's margins, with extra room at both points of every joint that ``mu`` leaves:
    ``anchor_factor`` × its missing force + ``anchor_margin``, and ``anchor_load_margin`` × N."""
    c = s.crushing
    base = uniform_margins(model, c)
    missing = missing_force(model, mu).max(axis=1)
    left = missing > 0.0
    extra = np.where(left, c.anchor_factor * missing + c.anchor_margin, 0.0)
    load = np.where(left, c.anchor_load_margin, 0.0)
    return ConeMargins(base.absolute + np.repeat(extra, 2), base.relative, base.load + np.repeat(load, 2))


def blend_theta(model: Model, mu: np.ndarray, anchor: np.ndarray) -> float | None:
    """The smallest θ ∈ [0, 1] with (1 − θ) μ + θ μ₀ inside every cone 2 c N_p ≥ N², or None.

    Along the segment g(θ) = 2 c N_p(θ) − N(θ)² is concave, so each point admits an interval of θ:
    [θ_p, 1] where μ is outside and μ₀ inside, [0, θ_p] where μ is inside and μ₀ outside.  Each
    end is found by bisection (vectorised over the points) and kept on its admissible side.
    """
    joints = crushing_joints(model)
    c = model.crushing[joints][:, None]
    n1, n0 = point_normals(mu)[joints], point_normals(anchor)[joints]
    t1, t0 = n1.sum(axis=1)[:, None], n0.sum(axis=1)[:, None]

    def g(theta: np.ndarray) -> np.ndarray:
        return 2.0 * c * (n1 + theta * (n0 - n1)) - (t1 + theta * (t0 - t1)) ** 2

    # the ends from the fields themselves: the interpolation's round-off must not move a point
    # across its cone at θ = 0 or 1
    start, end = 2.0 * c * n1 - t1**2, 2.0 * c * n0 - t0**2
    if np.any((start < 0.0) & (end < 0.0)):
        return None
    rising = start < 0.0  # outside at θ = 0: admissible from its root on
    low, high = np.zeros_like(n1), np.ones_like(n1)
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (low + high)
        inside = g(mid) >= 0.0
        to_high = inside == rising  # the root lies below mid
        high = np.where(to_high, mid, high)
        low = np.where(to_high, low, mid)
    lower = float(np.where(rising, high, 0.0).max(initial=0.0))
    upper = float(np.where(~rising & (end < 0.0), low, 1.0).min(initial=1.0))
    return lower if lower <= upper else None


def anchored_field(
    model: Model,
    H: sp.csc_matrix,
    static: sp.csc_matrix,
    bound: np.ndarray,
    best: ConeField,
    s: AssociativeSettings,
    max_iter: int,
    time_limit: float | None,
    refine: bool,
) -> ConeField:
    """The field ``best`` blended with an anchor solve into the cones (module docstring); ``best``
    itself when the anchor fails or its blend is not more admissible."""
    k = H.shape[1]
    anchor = solve_static_crushing(
        model,
        H,
        s.cone_tolerance,
        max_iter,
        time_limit,
        refine=refine,
        normalisation=s.normalisation,
        margins=anchor_margins(model, best.fields[:k], s),
    )
    kept = ConeField(
        best.fields, best.alpha, best.residual, best.solve_time + anchor.solve_time, best.iterations + anchor.iterations
    )
    if anchor.raw_status not in ("Solved", "AlmostSolved"):
        return dataclasses.replace(kept, note=f"; anchor solve: {anchor.raw_status}")
    fields0, alpha0, _ = repair_field(
        static,
        model,
        np.clip(anchor.x[1 : 1 + static.shape[1]], 0.0, bound),
        anchor.x[0],
        bound,
        best.alpha,
        s.residual_tolerance,
        s.gap_tolerance,
        s.feral_min_rows,
    )
    theta = blend_theta(model, best.fields[:k], fields0[:k])
    if theta is None:
        return dataclasses.replace(kept, note="; anchor solve: no blend inside the cones")
    fields = (1.0 - theta) * best.fields + theta * fields0
    alpha = (1.0 - theta) * best.alpha + theta * alpha0
    equilibrium = float(np.abs(static @ fields + model.dead + alpha * model.live).max(initial=0.0))
    residual = max(equilibrium, cone_violation(model, fields[:k]))
    if residual >= best.residual:
        return dataclasses.replace(kept, note="; anchor solve: blend not admissible")
    return dataclasses.replace(
        kept, fields=fields, alpha=float(alpha), residual=residual, note=f"; anchor solve, blend θ = {theta:.1e}"
    )


def admissible_field(
    model: Model,
    H: sp.csc_matrix,
    static: sp.csc_matrix,
    bound: np.ndarray,
    solver_fields: np.ndarray,
    solver_alpha: float,
    first: ConeField,
    s: AssociativeSettings,
    anchor: tuple[int, float | None, bool] | None,
) -> ConeField:
    """The best admissible field from the plain repair's ``first``: the cone-aware repair from it and
    from the solver's field (``solver_fields`` at ``solver_alpha``), then, given ``anchor`` =
    (Clarabel's iteration cap, time limit, refinement), the anchored blend when a cone is still
    left but equilibrium holds."""
    k = H.shape[1]
    best = ConeField(first.fields, first.alpha, max(first.residual, cone_violation(model, first.fields[:k])))
    for start, alpha0 in ((first.fields, first.alpha), (np.clip(solver_fields, 0.0, bound), solver_alpha)):
        if best.residual <= s.residual_tolerance:
            return best
        again, alpha_again, residual_again = repair_cone_field(model, static, start, alpha0, bound, s.feral_min_rows)
        residual_again = max(residual_again, cone_violation(model, again[:k]))
        if residual_again < best.residual:
            best = ConeField(again, alpha_again, residual_again)
    equilibrium = float(np.abs(static @ best.fields + model.dead + best.alpha * model.live).max(initial=0.0))
    if anchor is None or best.residual <= s.residual_tolerance or equilibrium > s.residual_tolerance:
        return best
    return anchored_field(model, H, static, bound, best, s, *anchor)
