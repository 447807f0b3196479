"""The certificate of Eq. 10: the interior-point pair repaired into two admissible fields.

A mechanism that satisfies the flow rule (Eq. 6) proves an upper bound on α_c; a stress field in
equilibrium (Eq. 3) inside the yield domain (Eq. 5) proves a lower bound.  The interior point
leaves round-off in both; :func:`certify_pair` removes it by minimum-norm corrections solved
with a sparse factorisation (``alma.backends.gram_backend``: QDLDL, feral on large walls), so
that the two bounds certify each other.  All quantities are dimensionless (``alma.mechanics.model``).
"""

from __future__ import annotations

from typing import cast

import numpy as np
import scipy.sparse as sp

from alma.backends.gram_backend import regularised_solver
from alma.floats import dot
from alma.mechanics.model import Model
from alma.settings import AssociativeSettings

#: The default of :attr:`alma.settings.AssociativeSettings.feral_min_rows`.
_FERAL_MIN_ROWS = AssociativeSettings().feral_min_rows


def certify_pair(
    H: sp.csc_matrix,
    model: Model,
    u: np.ndarray,
    mu: np.ndarray,
    alpha: float,
    residual_tolerance: float = 1e-9,
    gap_tolerance: float = 1e-7,
    *,
    static: sp.csc_matrix | None = None,
    upper: np.ndarray | None = None,
    feral_min_rows: int = _FERAL_MIN_ROWS,
) -> tuple[np.ndarray, np.ndarray, float, float, float]:
    """Repair the interior-point pair into admissible fields (the two bounds).

    Both repairs are minimum-norm corrections solved with a sparse factorisation:

    - static: on the support S of μ and on α, (μ_S, α) += [H_S f_L]ᵀ y with
      (H_S H_Sᵀ + f_L f_Lᵀ) y = −r removes the equilibrium residual
      r = H μ + f_0 + α f_L (the rank-one term by Sherman–Morrison); μ stays in its bounds
      because the step is far below the support threshold, and α moves by the matching amount;
    - kinematic: the flow-rule rows V that the interior point violates
      (Hᵀu < 0, by round-off) are closed by u += H_V w with (H_Vᵀ H_V) w = −H_Vᵀu
      (solved in velocity space) while nearly active rows are held; the first step that
      does not reduce the largest violation ends the repair; finally f_Lᵀu is restored
      by scaling.

    ``static`` replaces H in the equilibrium (e.g. [H G] with the bounded columns of cohesion
    and ties, :mod:`alma.mechanics.forces`) and ``upper`` bounds its multipliers above (∞ for
    the cone generators); the flow rule stays Hᵀu ≥ 0.  ``feral_min_rows``: the Gram solves'
    choice of factorisation (:attr:`alma.settings.AssociativeSettings.feral_min_rows`).

    Returns (u, μ, α_lower, static residual, kinematic residual).
    """
    norm = float(model.n_free)
    u, kinematic_residual = _repair_mechanism(
        H, model.live, u * (norm / dot(model.live, u)), norm, residual_tolerance, feral_min_rows
    )
    A = H if static is None else static
    bound = np.full(A.shape[1], np.inf) if upper is None else np.asarray(upper, dtype=float)
    u_final = u / norm
    upper_estimate = -dot(model.dead, u_final) / dot(model.live, u_final)
    mu, alpha, static_residual = _repair_field(
        A,
        model,
        np.clip(mu, 0.0, bound),
        alpha,
        bound,
        upper_estimate,
        residual_tolerance,
        gap_tolerance,
        feral_min_rows,
    )
    return u_final, mu, float(alpha), static_residual, kinematic_residual


def repair_mechanism(
    H: sp.csc_matrix,
    model: Model,
    u: np.ndarray,
    residual_tolerance: float = 1e-9,
    feral_min_rows: int = _FERAL_MIN_ROWS,
) -> tuple[np.ndarray, float]:
    """The kinematic repair of :func:`certify_pair` alone, on the flow-rule columns of H: returns
    (u with f_Lᵀu = 1, its relative flow-rule violation)."""
    norm = float(model.n_free)
    u, residual = _repair_mechanism(
        H, model.live, u * (norm / dot(model.live, u)), norm, residual_tolerance, feral_min_rows
    )
    return u / norm, residual


def _repair_mechanism(
    H: sp.csc_matrix,
    live: np.ndarray,
    u: np.ndarray,
    norm: float,
    residual_tolerance: float,
    feral_min_rows: int = _FERAL_MIN_ROWS,
) -> tuple[np.ndarray, float]:
    """The kinematic repair (see :func:`certify_pair`); returns u and its relative violation."""
    HT = H.T.tocsr(copy=True)  # a view would share H's arrays, which abs() may sort in place
    abs_HT = abs(HT)
    violated = np.zeros(HT.shape[0], dtype=bool)

    def violation(x: np.ndarray) -> float:
        """Largest flow-rule violation relative to the size of its terms, max(0, −Hᵀu) / (|Hᵀ| |u|)."""
        power = HT @ x
        size = float((abs_HT @ np.abs(x)).max(initial=0.0))
        return max(0.0, -float(power.min(initial=0.0))) / max(size, 1e-300)

    best = violation(u)
    for _ in range(4):
        if best <= 0.1 * residual_tolerance:
            break
        power = HT @ u
        # Violated rows are closed; nearly active rows are held where they are (target 0 change).
        violated |= power < 1e-8 * float(np.abs(power).max(initial=0.0))
        HV = HT[np.flatnonzero(violated)]
        # The minimum-norm step H_V w, (H_Vᵀ H_V + ε I) w = t, is computed in velocity space as
        # (H_V H_Vᵀ + ε I)⁻¹ H_V t (the same vector): that Gram matrix has the size of u (3 per
        # block) instead of one row per held generator, which is 3x larger and much denser.
        eps = 1e-12 * max(float(np.max(np.asarray(HV.multiply(HV).sum(axis=1)), initial=1.0)), 1.0)
        solve_u = regularised_solver(HV.T @ HV, eps, feral_min_rows=feral_min_rows)
        candidate = u.copy()
        for _ in range(3):
            candidate = candidate + solve_u(HV.T @ np.maximum(-(HV @ candidate), 0.0))
        candidate = candidate * (norm / dot(live, candidate))
        value = violation(candidate)
        if value >= best:
            # Rejected: u and hence the next round's row set and step would be the same again.
            break
        u, best = candidate, value
    return u, best


def _repair_field(
    A: sp.csc_matrix,
    model: Model,
    mu: np.ndarray,
    alpha: float,
    bound: np.ndarray,
    upper_estimate: float,
    residual_tolerance: float,
    gap_tolerance: float,
    feral_min_rows: int = _FERAL_MIN_ROWS,
) -> tuple[np.ndarray, float, float]:
    """The static repair (see :func:`certify_pair`).

    Two correction spaces: the plain support of μ (multipliers strictly inside their bounds),
    then an affine-scaled one (column j moves in proportion to its room, so every multiplier
    off its bounds can take part and the bounds hold) -- the second only when the first is not
    admissible or leaves a gap near the tolerance, since it costs another factorisation.
    """
    best_static: tuple[np.ndarray, float, float] | None = None
    top = max(float(mu.max(initial=0.0)), 1e-300)
    room = np.minimum(mu, bound - mu)
    for affine in (False, True):
        if affine:
            plain = cast("tuple[np.ndarray, float, float]", best_static)  # the first pass set it
            ok = plain[2] <= 0.1 * residual_tolerance
            gap = (upper_estimate - plain[1]) / max(1.0, abs(upper_estimate))
            if ok and gap <= 0.1 * gap_tolerance:
                break
            support = np.flatnonzero(room > 1e-14 * top)
            weight = np.sqrt(room[support] / top)
        else:
            support = np.flatnonzero(room > 1e-9 * top)
            weight = np.ones(support.size)
        trial = static_correction(A, model, mu.copy(), alpha, support, weight, bound, feral_min_rows)
        if best_static is None or _better(trial, best_static, residual_tolerance):
            best_static = trial
    return cast("tuple[np.ndarray, float, float]", best_static)  # the loop ran: it is set


def repair_field(
    A: sp.csc_matrix,
    model: Model,
    mu: np.ndarray,
    alpha: float,
    bound: np.ndarray,
    upper_estimate: float,
    residual_tolerance: float,
    gap_tolerance: float,
    feral_min_rows: int = _FERAL_MIN_ROWS,
) -> tuple[np.ndarray, float, float]:
    """The static repair of :func:`certify_pair` alone (a field without its mechanism): returns
    (μ, α, equilibrium residual)."""
    return _repair_field(A, model, mu, alpha, bound, upper_estimate, residual_tolerance, gap_tolerance, feral_min_rows)


def _better(trial: tuple, best: tuple, residual_tolerance: float) -> bool:
    """Prefer an admissible field (residual below tolerance) with the larger α, else the smaller residual."""
    ok_t, ok_b = trial[2] <= 0.1 * residual_tolerance, best[2] <= 0.1 * residual_tolerance
    if ok_t and ok_b:
        return trial[1] > best[1]
    return ok_t or (not ok_b and trial[2] < best[2])


def static_correction(
    H: sp.csc_matrix,
    model: Model,
    mu: np.ndarray,
    alpha: float,
    support: np.ndarray,
    weight: np.ndarray,
    bound: np.ndarray,
    feral_min_rows: int = _FERAL_MIN_ROWS,
) -> tuple[np.ndarray, float, float]:
    """Minimum-norm correction of (μ_S, α) removing the equilibrium residual (Eq. 3)."""
    live = model.live
    HS = H[:, support] @ sp.diags(weight)
    solve_g = regularised_solver(HS @ HS.T, feral_min_rows=feral_min_rows)
    g_live = solve_g(live)
    # α takes part with a small weight first: the correction goes to the stresses, and α only
    # absorbs what they cannot (the "matching reduction" of the multiplier) when the weight grows.
    for alpha_weight in (1e-6, 1e-3, 1.0):
        denom = 1.0 / alpha_weight**2 + dot(live, g_live)
        for _ in range(4):  # iterative refinement of the regularised solve
            residual = H @ mu + model.dead + alpha * live
            if np.abs(residual).max(initial=0.0) <= 1e-15:
                break
            x = solve_g(-residual)
            y = x - g_live * dot(live, x) / denom  # (G + w² f_L f_Lᵀ)⁻¹(−r), Sherman–Morrison
            candidate = mu.copy()
            candidate[support] += weight * (HS.T @ y)
            np.clip(candidate, 0.0, bound, out=candidate)
            new_alpha = alpha + dot(live, y) * alpha_weight**2
            if np.abs(H @ candidate + model.dead + new_alpha * live).max() >= np.abs(residual).max():
                break
            mu, alpha = candidate, new_alpha
        if np.abs(H @ mu + model.dead + alpha * live).max(initial=0.0) <= 1e-13:
            break
    residual = H @ mu + model.dead + alpha * live
    return mu, float(alpha), float(np.abs(residual).max(initial=0.0))


def cone_residual(model: Model, u: np.ndarray) -> float:
    """Largest distance of a contact point's relative velocity (ξ, γ) (Eq. 2) from the flow
    rule's cone ξ ≥ f |γ| (Eq. 6), relative to the largest relative velocity or block velocity.

    The rows of Hᵀu ≥ 0 are ξ ± f γ: at a large f they are nearly parallel, so an interpenetration
    ξ < 0 hides under the round-off of f γ (f = 1e12: ε f ≈ 2e-4), and a small violation of each
    row is a large distance from their intersection.  Measured on (ξ, γ) themselves, from the
    contact-point columns (the generators' ``+`` columns, without f).  Dimensionless.
    """
    opening = model.normal_part[:, 0::2].T @ u
    slip = np.abs(model.tangent_part[:, 0::2].T @ u)
    f = np.repeat(model.friction, 2)
    with np.errstate(over="ignore", invalid="ignore"):
        inside = opening >= f * slip
        polar = f * opening + slip <= 0.0  # nearest point of the cone is its apex
        to_edge = (f * slip - opening) / np.hypot(1.0, f)
        distance = np.where(inside, 0.0, np.where(polar, np.hypot(opening, slip), to_edge))
    # Relative to the mechanism's own speed too: a structure turning about one point contact has
    # relative velocities of round-off only, and their ratio would mean nothing.
    size = max(float(np.hypot(opening, slip).max(initial=0.0)), float(np.abs(u).max(initial=0.0)))
    worst = float(distance.max(initial=0.0))
    if not np.isfinite(worst) or not np.isfinite(size):
        return np.inf
    return worst / size if size > 0 else 0.0
