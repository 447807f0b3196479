"""The associative (dilatant) limit-analysis LP, Eq. 10, and its static dual.

Kinematic form (Eq. 10, written on contact-point generators)::

    α_c = min  -f_0ᵀ u      s.t.  f_Lᵀ u = 1,   Hᵀ u ≥ 0      (flow rule, Eq. 6)

Static form (its dual)::

    α_c = max  α            s.t.  H μ + f_0 + α f_L = 0,  μ ≥ 0  (Eqs. 3–5)

Clarabel solves the kinematic form as a primal–dual pair: ``x`` is the mechanism u and the
dual ``z`` gives (−α, μ).  :mod:`alma.associative.certificate` then repairs both fields to
admissibility, which turns them into an upper bound (the mechanism) and a lower bound (the
stress field) that certify each other.  The certificate, not the solver's flag, decides the
status.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import cast

import numpy as np
import scipy.sparse as sp

from alma.associative.certificate import certify_pair, cone_residual, repair_mechanism
from alma.associative.cone_field import ConeField, admissible_field
from alma.associative.crushing import crushing_work, rigid_columns, solve_static_crushing, uniform_margins
from alma.backends.clarabel_backend import solve_conic_lp
from alma.backends.highs_backend import solve_conic_form
from alma.backends.termination import SolverResult, Termination, termination
from alma.engine.pattern_cache import PatternCache, structure_key
from alma.engine.select import choose, solve_with_engine
from alma.engine.types import IPMSettings
from alma.mechanics.model import Model
from alma.settings import AssociativeSettings, Engine
from alma.status import Status

#: The default normalisation of Eq. 10 (see :class:`alma.settings.AssociativeSettings`).
NORMALISATION = AssociativeSettings().normalisation
#: f_Lᵀu per free block for the simplex fallback, tried in turn: HiGHS's dual simplex fails on
#: the interior point's scale (1000) and its absolute tolerances (1e-10) leave a flow-rule
#: violation above the certificate's on some vertices at f_Lᵀu = 1, none at 10 per block.
SIMPLEX_NORMALISATIONS = (1e-3, 10.0)


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


def solve_lp(
    model: Model,
    settings: AssociativeSettings | None = None,
    *,
    tolerance: float | None = None,
    max_iter: int | None = None,
    equilibrium: sp.csc_matrix | None = None,
    time_limit: float | None = None,
    engine: str | None = None,
    ipm_settings: IPMSettings | None = None,
    patterns: PatternCache | None = None,
) -> LPSolution:
    """Solve Eq. 10 (Clarabel, or alma's interior point) and certify the value from both sides.

    ``tolerance``, ``max_iter`` and ``engine`` override the fields of ``settings``, and
    ``ipm_settings`` its interior point's (``settings.ipm``: e.g. its factorisation backend); ``time_limit`` (s)
    is a user's cap (its cut gives ``limit_reached``).  ``equilibrium`` replaces the model's H.
    ``patterns``: the caller's cache of the interior point's normal-equations patterns (the
    frictions of one geometry share one; the answer is the same with or without it).
    """
    s = settings or AssociativeSettings()
    if engine is not None:
        s = dataclasses.replace(s, engine=cast(Engine, engine))  # any string: AssociativeSettings checks it
    if ipm_settings is not None:
        s = dataclasses.replace(s, ipm=ipm_settings)
    tol = s.tolerance if tolerance is None else tolerance
    iters = s.max_iter if max_iter is None else max_iter
    H = model.equilibrium if equilibrium is None else equilibrium
    _, k = H.shape
    if k == 0:  # no joint: any motion is free, no load can be carried
        return _trivial(model, Status.NO_EQUILIBRIUM, "no joint carries the free blocks")
    if model.crushes:
        return _solve_crushing(model, H, s, iters, time_limit)
    sol, label, note, record = _solve_pair(model, H, s, tol, iters, time_limit, patterns)
    if sol.status in (Status.NO_COLLAPSE, Status.NO_EQUILIBRIUM):
        message = (
            "no kinematically admissible mechanism with positive live-load work"
            if sol.status == Status.NO_COLLAPSE
            else "no statically admissible stress field for any load multiplier"
        )
        return _trivial(model, sol.status, message + note, iterations=sol.iterations, solve_time=sol.solve_time)
    result = _certified(model, H, s, sol, label, note, record)
    if result.status == Status.NOT_CONVERGED and s.simplex_fallback:
        # An interior point ends ill-conditioned on a degenerate optimal face (a noisy drawing
        # of a wall that slides at α = f); a simplex vertex of the same LP certifies exactly.
        for normalisation in SIMPLEX_NORMALISATIONS:
            q, A, b = _kinematic_form(model, H, normalisation)
            vertex = solve_conic_form(q, A, b, 1, time_limit=time_limit)
            if vertex.status != Status.OPTIMAL:
                continue
            again = _certified(
                model,
                H,
                s,
                vertex,
                "HiGHS simplex",
                f" (after {label}: {sol.raw_status}, not certified)" + note,
                record,
            )
            if again.status == Status.OPTIMAL:
                return dataclasses.replace(
                    again, solve_time=sol.solve_time + vertex.solve_time, iterations=sol.iterations + vertex.iterations
                )
    return result


def _certified(
    model: Model,
    H: sp.csc_matrix,
    s: AssociativeSettings,
    sol: SolverResult,
    label: str,
    note: str,
    record: dict[str, float],
) -> LPSolution:
    """The certificate of a primal–dual pair of Eq. 10 (``certify_pair``) and the status it proves."""
    n, k = H.shape
    q_count = model.n_bounded
    t0 = time.perf_counter()
    static = sp.hstack([H, model.bounded]).tocsc() if q_count else None
    bound = np.concatenate([np.full(k, np.inf), model.capacity]) if q_count else None
    u, fields, lower, static_residual, kinematic_residual = certify_pair(
        H,
        model,
        sol.x[:n],
        sol.duals[1 : 1 + k + q_count].copy(),
        -sol.duals[0],
        s.residual_tolerance,
        s.gap_tolerance,
        static=static,
        upper=bound,
        feral_min_rows=s.feral_min_rows,
    )
    mu, tau = fields[:k], fields[k:]
    kinematic_residual = max(kinematic_residual, cone_residual(model, u))
    # A mechanism that breaks the flow rule by v_j only proves α ≤ (−f_0ᵀu + D(u) + Σ v_j μ*_j) / f_Lᵀu:
    # the violation work is charged with the certified stress field's multipliers; D(u) is the
    # dissipation of the bounded forces, Σ capacity · max(0, −Gᵀu).
    violation_work = float(np.maximum(-(H.T @ u), 0.0) @ mu)
    upper = float((-model.dead @ u + dissipation(model, u) + violation_work) / (model.live @ u))
    forces = _force_terms(model, H, static, fields)
    status, message, lower, upper = _judge(
        s, sol.status, f"{label}: {sol.raw_status}", lower, upper, static_residual, kinematic_residual, forces
    )
    message += note
    alpha = upper if np.isfinite(upper) else float((-model.dead @ u + dissipation(model, u)) / (model.live @ u))
    return LPSolution(
        status=status,
        message=message,
        alpha=alpha,
        lower=lower,
        upper=upper,
        mechanism=u,
        multipliers=mu,
        static_residual=static_residual,
        kinematic_residual=kinematic_residual,
        iterations=sol.iterations,
        solve_time=sol.solve_time,
        certify_time=time.perf_counter() - t0,
        bounded_forces=tau,
        engine=record,
    )


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
    t0 = time.perf_counter()
    n, k = H.shape
    q_count = model.n_bounded
    static = sp.hstack([H, model.bounded]).tocsc() if q_count else H
    bound = np.concatenate([np.full(k, np.inf), model.capacity])
    rigid = rigid_columns(model, H.T @ sol.duals[:n], s.crushing.rest)
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
    # The anchor solve (cone_field) only pays when a mechanism can prove the upper bound.
    _, _, kinematic_residual = _crushing_mechanism(model, H, mechanisms, fields[:k], s)
    anchor = (
        (iters, time_limit, refine)
        if (sol.status == Status.OPTIMAL and kinematic_residual <= s.residual_tolerance)
        else None
    )
    field = admissible_field(
        model,
        H,
        static,
        bound,
        sol.x[1 : 1 + k + q_count],
        sol.x[0],
        ConeField(fields, lower, equilibrium_residual),
        s,
        anchor,
    )
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
            / (model.live @ u)
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
        bounds.append((u, float(work / (model.live @ u)), proof))
    proven = [b for b in bounds if b[2] <= s.residual_tolerance]
    return min(proven, key=lambda b: b[1]) if proven else bounds[0]


def _solve_pair(
    model: Model,
    H: sp.csc_matrix,
    s: AssociativeSettings,
    tol: float,
    iters: int,
    time_limit: float | None,
    patterns: PatternCache | None = None,
) -> tuple[SolverResult, str, str, dict[str, float]]:
    """The primal–dual pair of Eq. 10 from the chosen engine: (solution, solver label, note, the
    interior point's record).

    alma's interior point (``alma.engine``) takes Eq. 10 with the bounded forces' dissipation
    variables as auxiliary rows (:func:`_engine_form`); when it does not converge Clarabel solves
    the problem and the note says so.  Its normal-equations pattern comes from ``patterns`` when
    the same structure was solved before, and goes there (the caller's cache, not the model).
    """
    if (
        choose(
            s.engine,
            model.n_free,
            bool(model.n_bounded),
            min_blocks=s.auto_min_blocks,
            min_blocks_bounded=s.auto_min_blocks_bounded,
        )
        == "ipm"
    ):
        start = time.perf_counter()
        H_aug, dead, live = _engine_form(model, H)
        key = structure_key(H_aug, H.shape[0]) if patterns is not None else b""
        ans = solve_with_engine(
            H_aug,
            dead,
            live,
            s.normalisation * float(model.n_free),
            s.ipm,
            n_primary=H.shape[0],
            pattern=patterns.get(key) if patterns is not None else None,
        )
        if patterns is not None and ans.result.pattern is not None:
            patterns.put(key, ans.result.pattern)
        term = termination("engine", ans.status)
        if term is Termination.OPTIMAL:
            return (
                SolverResult(
                    term, ans.status, ans.x, ans.duals, ans.iterations, time.perf_counter() - start, ans.label
                ),
                ans.label,
                "",
                dict(ans.result.timings),
            )
        note = f"; {ans.label}: {ans.status} after {ans.iterations} iterations, Clarabel used"
    else:
        note = ""
    q, A, b = _kinematic_form(model, H, s.normalisation)
    sol = solve_conic_lp(q, A, b, 1, A.shape[0] - 1, tolerance=tol, max_iter=iters, time_limit=time_limit)
    return sol, "Clarabel", note, {}


def dissipation(model: Model, u: np.ndarray) -> float:
    """Work of the bounded forces at their capacity on the mechanism u: Σ capacity · max(0, −Gᵀu)
    (cohesion c l t |γ|, ties strength · elongation rate), dimensionless."""
    if not model.n_bounded:
        return 0.0
    return float(model.capacity @ np.maximum(-(cast(sp.csc_matrix, model.bounded).T @ u), 0.0))


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
