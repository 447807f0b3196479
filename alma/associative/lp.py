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
from typing import cast

import numpy as np
import scipy.sparse as sp

from alma.associative.certificate import certify_pair, cone_residual
from alma.associative.falling import falling_ray
from alma.associative.lp_crushing import _solve_crushing
from alma.associative.lp_forms import (
    LPSolution,
    _engine_form,
    _force_terms,
    _judge,
    _kinematic_form,
    _trivial,
    dissipation,
)
from alma.backends.clarabel_backend import solve_conic_lp
from alma.backends.highs_backend import solve_conic_form
from alma.backends.termination import SolverResult, Termination, termination
from alma.engine.pattern_cache import PatternCache, structure_key
from alma.engine.select import choose, solve_with_engine
from alma.engine.types import IPMSettings
from alma.floats import dot
from alma.mechanics.model import Model
from alma.settings import AssociativeSettings, Engine
from alma.status import Status

#: The default normalisation of Eq. 10 (see :class:`alma.settings.AssociativeSettings`).
NORMALISATION = AssociativeSettings().normalisation
#: f_Lᵀu per free block for the simplex fallback, tried in turn: HiGHS's dual simplex fails on
#: the interior point's scale (1000) and its absolute tolerances (1e-10) leave a flow-rule
#: violation above the certificate's on some vertices at f_Lᵀu = 1, none at 10 per block.
SIMPLEX_NORMALISATIONS = (1e-3, 10.0)


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
        # of a wall that slides at α = f); a vertex of the same LP certifies exactly.
        unbounded = False
        for normalisation in SIMPLEX_NORMALISATIONS:
            q, A, b = _kinematic_form(model, H, normalisation)
            vertex = _vertex(q, A, b, time_limit)
            unbounded |= vertex.status == Status.NO_EQUILIBRIUM
            if vertex.status != Status.OPTIMAL:
                continue
            again = _certified(
                model, H, s, vertex, vertex.solver, f" (after {label}: {sol.raw_status}, not certified)" + note, record
            )
            if again.status == Status.OPTIMAL:
                return dataclasses.replace(
                    again, solve_time=sol.solve_time + vertex.solve_time, iterations=sol.iterations + vertex.iterations
                )
        if unbounded:
            return _falling_or(result, model, s, f" (after {label}: {sol.raw_status}, not certified)" + note)
    return result


def _vertex(q: np.ndarray, A: sp.csc_matrix, b: np.ndarray, time_limit: float | None) -> SolverResult:
    """A vertex of Eq. 10's kinematic form: HiGHS's interior point with crossover (half its dual
    simplex's time on a 444-block panel next to a loss of equilibrium), and its dual simplex where
    that does not end optimal (the simplex tells an unbounded form from an infeasible one)."""
    vertex = solve_conic_form(q, A, b, 1, time_limit=time_limit, solver="ipm")
    if vertex.status == Status.OPTIMAL:
        return vertex
    return solve_conic_form(q, A, b, 1, time_limit=time_limit)


def _falling_or(result: LPSolution, model: Model, s: AssociativeSettings, note: str) -> LPSolution:
    """``no_equilibrium`` when a falling mode proves it (:mod:`alma.associative.falling`: next to a
    linkage's loss of equilibrium the interior point ends ill-conditioned and the simplex finds
    Eq. 10's kinematic form unbounded), else ``result`` as it is."""
    ray = falling_ray(model)
    if ray is None or not ray.proves(model.n_free, s.falling_margin):
        return result
    return _trivial(
        model,
        Status.NO_EQUILIBRIUM,
        "no statically admissible stress field for any load multiplier: a falling mode proves it "
        f"(work of the weights {ray.dead_work:.3g}, round-off {ray.breach:.1g}){note}",
        iterations=result.iterations,
        solve_time=result.solve_time,
    )


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
    violation_work = dot(np.maximum(-(H.T @ u), 0.0), mu)
    upper = (-dot(model.dead, u) + dissipation(model, u) + violation_work) / dot(model.live, u)
    forces = _force_terms(model, H, static, fields)
    status, message, lower, upper = _judge(
        s, sol.status, f"{label}: {sol.raw_status}", lower, upper, static_residual, kinematic_residual, forces
    )
    message += note
    alpha = upper if np.isfinite(upper) else (-dot(model.dead, u) + dissipation(model, u)) / dot(model.live, u)
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
    variables as auxiliary rows (:func:`~alma.associative.lp_forms._engine_form`); when it does not
    converge Clarabel solves the problem and the note says so.  Its normal-equations pattern comes
    from ``patterns`` when the same structure was solved before, and goes there (the caller's
    cache, not the model).
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
