"""Eq. 10's forms for the solvers, the dissipation of the bounded forces, and the judgement of its certificate.

:class:`LPSolution` is the associative LP's raw dimensionless answer; :func:`_kinematic_form` and
:func:`_engine_form` write Eq. 10 (with the bounded forces' dissipation variables) for Clarabel and
alma's interior point; :func:`_judge` reads the certificate's residuals and gap (loads per mean
block weight) into the status it proves.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import cast

import numpy as np
import scipy.sparse as sp

from alma.floats import dot
from alma.mechanics.model import Model
from alma.settings import AssociativeSettings
from alma.status import Status


@dataclass(frozen=True)
class LPSolution:
    """Raw dimensionless solution of the associative LP (turned into physical units by
    :mod:`alma.results`)."""

    status: Status  # optimal | no_collapse | no_equilibrium | not_converged | limit_reached
    message: str
    alpha: float
    lower: float
    upper: float
    mechanism: np.ndarray  # (3 n_free,) u, v, θ per free block, f_Lᵀu = 1
    multipliers: np.ndarray  # (4 m,) μ ≥ 0
    static_residual: float  # ‖H μ + f_0 + α_lower f_L‖_∞, loads per mean block weight
    kinematic_residual: float  # max(0, −min Hᵀu) / max(|Hᵀ| |u|): relative flow-rule violation
    iterations: int
    solve_time: float
    certify_time: float
    #: (q,) τ of the bounded forces (cohesion, ties: ``Model.bounded``), 0 ≤ τ ≤ capacity.
    bounded_forces: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: The interior point's own record (factorisations, solves, their seconds), when it ran.
    engine: dict[str, float] = field(default_factory=dict)

    @property
    def solved(self) -> bool:
        """True when α and the fields are meaningful (optimal, or a best value not certified)."""
        return self.status in (Status.OPTIMAL, Status.NOT_CONVERGED, Status.LIMIT_REACHED)


def dissipation(model: Model, u: np.ndarray) -> float:
    """Work of the bounded forces at their capacity on the mechanism u: Σ capacity · max(0, −Gᵀu)
    (cohesion c l t |γ|, ties strength · elongation rate), dimensionless."""
    if not model.n_bounded:
        return 0.0
    return dot(model.capacity, np.maximum(-(cast(sp.csc_matrix, model.bounded).T @ u), 0.0))


def _kinematic_form(
    model: Model, H: sp.csc_matrix, normalisation: float
) -> tuple[np.ndarray, sp.csc_matrix, np.ndarray]:
    """Eq. 10 for Clarabel: ``min qᵀx s.t. A x + s = b`` (first row an equality, the rest s ≥ 0).

    Without bounded forces x = u: min −f₀ᵀu, f_Lᵀu = N, Hᵀu ≥ 0.  With them the objective gains
    their dissipation through one variable per cohesive joint, v ≥ |γ| (rows v ≥ ∓g±ᵀu for its
    two columns ±t, whose duals τ± then sum to c l t), and one per tie, w ≥ max(0, −gᵀu).  The
    rows' duals are the bounded forces τ, in the order of the columns of G.
    """
    H_aug, dead, live = _engine_form(model, H)
    b = np.zeros(1 + H_aug.shape[1])
    b[0] = normalisation * float(model.n_free)
    return -dead, sp.vstack([sp.csr_matrix(live), -H_aug.T]).tocsc(), b


def _engine_form(model: Model, H: sp.csc_matrix) -> tuple[sp.csc_matrix, np.ndarray, np.ndarray]:
    """Eq. 10 with bounded forces in the engine's form ``min −f₀ᵀx s.t. f_Lᵀx = N, Hᵀx ≥ 0``.

    x = (u, v) with the dissipation variables v of :func:`_kinematic_form` as rows after u:
    H_aug = [[H, G, 0], [0, E, T]] (E: each bounded column on its v row, T: v ≥ 0 of the ties),
    f₀ extended by −capacity on v, f_L by 0.  Its duals are (μ, τ, w) with τ + w = capacity, so
    that 0 ≤ τ ≤ capacity (:mod:`alma.engine.auxiliary`).  Without bounded forces: (H, f₀, f_L).
    """
    q_count = model.n_bounded
    if not q_count:
        return H, model.dead, model.live
    n, k = H.shape
    var, n_var, tie = _dissipation_variables(model.bounded_labels)
    E = sp.csc_matrix((np.ones(q_count), (var, np.arange(q_count))), shape=(n_var, q_count))
    T = sp.csc_matrix((np.ones(tie.size), (var[tie], np.arange(tie.size))), shape=(n_var, tie.size))
    H_aug = sp.bmat([[H, model.bounded, sp.csc_matrix((n, tie.size))], [sp.csc_matrix((n_var, k)), E, T]], format="csc")
    cost = np.zeros(n_var)
    cost[var] = model.capacity
    return H_aug, np.concatenate([model.dead, -cost]), np.concatenate([model.live, np.zeros(n_var)])


def _dissipation_variables(labels: np.ndarray) -> tuple[np.ndarray, int, np.ndarray]:
    """For each bounded column its dissipation variable (a cohesive joint's two columns share
    one), their number, and the columns that are ties (their variable also needs w ≥ 0)."""
    text = np.array([str(x) for x in labels])
    tie = np.flatnonzero(np.char.startswith(text, "tie:"))
    key = np.where(np.char.startswith(text, "tie:"), text, np.char.rstrip(text, "+-"))
    _, first, var = np.unique(key, return_index=True, return_inverse=True)
    return var.ravel(), int(first.size), tie


def _force_terms(model: Model, H: sp.csc_matrix, static: sp.csc_matrix | None, fields: np.ndarray) -> float:
    """‖|H||μ|‖∞ with each joint's friction taken at most 1 (mean block weights): the size of the
    field's physical forces, whose round-off floors its equilibrium residual.  A friction f > 1
    multiplies the tangential terms f (μ₊ − μ₋), which cancel; counting them at f would excuse
    residuals of f ε — 1e-4 block weights at f = 1e12 — as round-off and certify a wrong α."""
    capped = np.repeat(np.minimum(model.friction, 1.0), H.shape[1] // max(model.n_joints, 1))
    terms = abs(model.normal_part) + abs(model.tangent_part) @ sp.diags(capped)
    if static is not None:
        terms = sp.hstack([terms, abs(static[:, H.shape[1] :])]).tocsc()
    return float((terms @ np.abs(fields)).max(initial=0.0))


def _judge(
    s: AssociativeSettings,
    solver_status: Status,
    raw: str,
    lower: float,
    upper: float,
    static_residual: float,
    kinematic_residual: float,
    forces: float = 0.0,
) -> tuple[Status, str, float, float]:
    """The status the certificate proves: both fields admissible and the bounds closed.

    ``forces``: the static field's largest force term ‖|H||μ|‖∞ (mean block weights), which sets
    the round-off floor of its equilibrium residual (``residual_roundoff``).
    """
    floor = s.residual_roundoff * float(np.finfo(float).eps) * forces
    static_ok = static_residual <= max(s.residual_tolerance, floor)
    kinematic_ok = kinematic_residual <= s.residual_tolerance
    gap = (upper - lower) / max(1.0, abs(upper))
    if not static_ok:
        lower = -float("inf")  # the stress field proves nothing
    if not kinematic_ok:
        upper = float("inf")  # the mechanism proves nothing
    zero = s.gap_tolerance * max(1.0, abs(upper) if np.isfinite(upper) else 1.0)
    if kinematic_ok and upper < -zero:
        # An admissible mechanism in which the dead load alone does positive work: α_c < 0.
        return Status.NO_EQUILIBRIUM, "the structure cannot carry its dead load (α_c < 0)", lower, upper
    # A lower bound above the upper one by more than the tolerance contradicts weak duality:
    # one of the two fields is wrong, so nothing is proven.
    if static_ok and kinematic_ok and abs(gap) <= s.gap_tolerance and solver_status == Status.OPTIMAL:
        return Status.OPTIMAL, f"certified: relative gap {gap:.1e} ({raw})", lower, upper
    status = Status.LIMIT_REACHED if solver_status == Status.LIMIT_REACHED else Status.NOT_CONVERGED
    return (
        status,
        (f"{raw}; relative gap {gap:.2e}, residuals static {static_residual:.1e}, kinematic {kinematic_residual:.1e}"),
        lower,
        upper,
    )


def _trivial(model: Model, status: Status, message: str, iterations: int = 0, solve_time: float = 0.0) -> LPSolution:
    nan = float("nan")
    bound = float("inf") if status == Status.NO_COLLAPSE else -float("inf")
    return LPSolution(
        status=status,
        message=message,
        alpha=bound,
        lower=bound,
        upper=bound,
        mechanism=np.zeros(3 * model.n_free),
        multipliers=np.zeros(4 * model.n_joints),
        static_residual=nan,
        kinematic_residual=nan,
        iterations=iterations,
        solve_time=solve_time,
        certify_time=0.0,
        bounded_forces=np.zeros(model.n_bounded),
    )
