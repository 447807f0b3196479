"""The associative LP with a finite compressive strength (Eq. 10 on Clarabel's cone program), certified.

The static cone program gives the stress field (the lower bound); the solver's mechanism with each
crushing joint's exact dissipation gives the upper one (loads per mean block weight).
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import scipy.sparse as sp

from alma.associative.certificate import certify_pair, repair_mechanism
from alma.associative.cone_field import ConeField, admissible_field
from alma.associative.crushing import crushing_work, rigid_columns, solve_static_crushing, uniform_margins
from alma.associative.lp_forms import LPSolution, _judge, _trivial, dissipation
from alma.backends.termination import SolverResult
from alma.floats import dot
from alma.mechanics.model import Model
from alma.settings import AssociativeSettings
from alma.status import Status


def _solve_crushing(
    model: Model, H: sp.csc_matrix, s: AssociativeSettings, iters: int, time_limit: float | None
) -> LPSolution:
    """Eq. 10 with finite compressive strength (:mod:`alma.associative.crushing`): Clarabel's
    second-order cone program always (alma's interior point and the simplex take LPs only),
    certified as the LP: the repaired stress field inside the cones gives the lower bound, the
    mechanism with the crushing joints' exact dissipation the upper one.

    Clarabel's iterative refinement helps on some near-rigid cones (σ_c l t ≫ N) and hurts on
    others; when the first pair does not certify, the other setting is tried (deterministic: the
    same scene takes the same path) and the first certified pair is kept.
    """
    first = _crushing_pair(model, H, s, iters, time_limit, s.cone_refinement)
    if first.status != Status.NOT_CONVERGED:
        return first
    second = _crushing_pair(model, H, s, iters, time_limit, not s.cone_refinement)
    if second.status == Status.OPTIMAL:
        return dataclasses.replace(
            second,
            message=f"{second.message} (refinement {'on' if not s.cone_refinement else 'off'}, after: {first.message})",
            solve_time=first.solve_time + second.solve_time,
            iterations=first.iterations + second.iterations,
        )
    return first


def _crushing_pair(
    model: Model, H: sp.csc_matrix, s: AssociativeSettings, iters: int, time_limit: float | None, refine: bool
) -> LPSolution:
    """One certified attempt of :func:`_solve_crushing` (``refine``: Clarabel's refinement; the
    tolerance is ``s.cone_tolerance``, not the LP's)."""
    sol = solve_static_crushing(
        model,
        H,
        s.cone_tolerance,
        iters,
        time_limit,
        refine=refine,
        normalisation=s.normalisation,
        margins=uniform_margins(model, s.crushing),
    )
    if sol.status in (Status.NO_COLLAPSE, Status.NO_EQUILIBRIUM):
        return _crushing_trivial(model, sol)
    t0 = time.perf_counter()
    n, k = H.shape
    static = sp.hstack([H, model.bounded]).tocsc() if model.n_bounded else H
    bound = np.concatenate([np.full(k, np.inf), model.capacity])
    rigid = rigid_columns(model, H.T @ sol.duals[:n], s.crushing.rest)
    mechanisms, first = _crushing_candidates(model, H, sol, static, bound, rigid, s)
    field = _crushing_field(model, H, sol, static, bound, mechanisms, first, s, (iters, time_limit, refine))
    return _crushing_solution(model, H, sol, static, rigid, mechanisms, field, s, t0)


def _crushing_trivial(model: Model, sol: SolverResult) -> LPSolution:
    """The answer of Eq. 10 with finite compressive strength when Clarabel proves that no
    mechanism does positive live-load work or that no stress field carries the dead load."""
    message = (
        "no kinematically admissible mechanism with positive live-load work"
        if sol.status == Status.NO_COLLAPSE
        else "no statically admissible stress field for any load multiplier: the joints cannot carry "
        "the dead load within their compressive strength (a joint crushes, N > σ_c l t, or no "
        "stress block fits the moment)"
    )
    return _trivial(
        model,
        sol.status,
        f"{message} (Clarabel: {sol.raw_status})",
        iterations=sol.iterations,
        solve_time=sol.solve_time,
    )


def _crushing_candidates(
    model: Model,
    H: sp.csc_matrix,
    sol: SolverResult,
    static: sp.csc_matrix,
    bound: np.ndarray,
    rigid: np.ndarray,
    s: AssociativeSettings,
) -> tuple[tuple, ConeField]:
    """The two candidate mechanisms of the upper bound ((u, held columns, their flow-rule
    residual), ...) and the plain repair of the solver's stress field (loads per mean block
    weight): the mechanism held to the flow rule on the ``rigid`` columns, and the solver's held
    on the infinitely strong joints only."""
    n, k = H.shape
    q_count = model.n_bounded
    u, fields, lower, equilibrium_residual, held_residual = certify_pair(
        H[:, rigid],
        model,
        sol.duals[:n],
        sol.x[1 : 1 + k + q_count].copy(),
        sol.x[0],
        s.residual_tolerance,
        s.gap_tolerance,
        static=static,
        upper=bound,
        feral_min_rows=s.feral_min_rows,
    )
    # A second mechanism: the solver's, held to the flow rule on the infinitely strong joints only,
    # every crushing joint counted with its exact dissipation (holding the joints at rest moved
    # the upper bound by 1.2e-7 on english 1:2 2:1 f = 1 at 2 MPa).
    strong = np.flatnonzero(np.repeat(~np.isfinite(model.crushing), 4))
    strong_u, strong_residual = repair_mechanism(
        H[:, strong], model, sol.duals[:n], s.residual_tolerance, s.feral_min_rows
    )
    mechanisms = ((u, rigid, held_residual), (strong_u, strong, strong_residual))
    return mechanisms, ConeField(fields, lower, equilibrium_residual)


def _crushing_field(
    model: Model,
    H: sp.csc_matrix,
    sol: SolverResult,
    static: sp.csc_matrix,
    bound: np.ndarray,
    mechanisms: tuple,
    first: ConeField,
    s: AssociativeSettings,
    attempt: tuple[int, float | None, bool],
) -> ConeField:
    """The admissible stress field of the lower bound (:func:`admissible_field`) from the plain
    repair ``first``; ``attempt`` = (Clarabel's iteration cap, time limit, refinement)."""
    k = H.shape[1]
    # The anchor solve (cone_field) only pays when a mechanism can prove the upper bound.
    _, _, kinematic_residual = _crushing_mechanism(model, H, mechanisms, first.fields[:k], s)
    anchor = attempt if (sol.status == Status.OPTIMAL and kinematic_residual <= s.residual_tolerance) else None
    return admissible_field(model, H, static, bound, sol.x[1 : 1 + k + model.n_bounded], sol.x[0], first, s, anchor)


def _crushing_solution(
    model: Model,
    H: sp.csc_matrix,
    sol: SolverResult,
    static: sp.csc_matrix,
    rigid: np.ndarray,
    mechanisms: tuple,
    field: ConeField,
    s: AssociativeSettings,
    t0: float,
) -> LPSolution:
    """The certified pair of Eq. 10 with finite compressive strength: the lower bound of ``field``,
    the lowest proven upper bound of ``mechanisms``, judged by the gap (loads per mean block
    weight); ``t0``: when certification started (s, for the certify time)."""
    k = H.shape[1]
    fields, lower, static_residual = field.fields, field.alpha, field.residual
    mu, tau = fields[:k], fields[k:]
    u, upper, kinematic_residual = _crushing_mechanism(model, H, mechanisms, mu, s)
    forces = float((abs(static) @ np.abs(fields)).max(initial=0.0))
    status, message, lower, upper = _judge(
        s,
        sol.status,
        f"Clarabel cone program: {sol.raw_status}",
        lower,
        upper,
        static_residual,
        kinematic_residual,
        forces,
    )
    alpha = (
        upper
        if np.isfinite(upper)
        else float(
            crushing_work(model, H, u, mu, rigid, dissipation(model, u), np.inf, s.residual_tolerance)[0]
            / dot(model.live, u)
        )
    )
    return LPSolution(
        status=status,
        message=message + field.note,
        alpha=alpha,
        lower=lower,
        upper=upper,
        mechanism=u,
        multipliers=mu,
        static_residual=static_residual,
        kinematic_residual=kinematic_residual,
        iterations=sol.iterations + field.iterations,
        solve_time=sol.solve_time + field.solve_time,
        certify_time=time.perf_counter() - t0 - field.solve_time,
        bounded_forces=tau,
    )


def _crushing_mechanism(
    model: Model, H: sp.csc_matrix, mechanisms: tuple, mu: np.ndarray, s: AssociativeSettings
) -> tuple[np.ndarray, float, float]:
    """The mechanism of ``mechanisms`` ((u, held columns, their flow-rule residual), ...) proving
    the lowest upper bound (:func:`crushing_work`): (u, upper bound, residual); the first one with
    its residual when none proves one."""
    bounds = []
    for u, held, residual in mechanisms:
        work, proof = crushing_work(model, H, u, mu, held, dissipation(model, u), residual, s.residual_tolerance)
        bounds.append((u, float(work / dot(model.live, u)), proof))
    proven = [b for b in bounds if b[2] <= s.residual_tolerance]
    return min(proven, key=lambda b: b[1]) if proven else bounds[0]
