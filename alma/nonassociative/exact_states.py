"""The exact collapse state of a mechanism (Eq. 9): its active set fixed, the fixed-set static LP solved.

:func:`exact_state` and :func:`fast_exact_state` read a mechanism's active set (open points, slip
signs, the bounded columns' signs), solve the static LP with that set fixed (a HiGHS vertex or
Clarabel's interior field) and verify the pair (:func:`alma.nonassociative.states.verify`); α is
dimensionless (live load per its reference).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from alma.backends.linprog_backend import LPMethod
from alma.backends.termination import Termination
from alma.floats import dot
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative import bounded as bf
from alma.nonassociative.fixed_set_lps import FixedSetLPs
from alma.nonassociative.states import (
    CollapseState,
    ExactLimits,
    Tally,
    _allowed,
    active_set,
    bounded_active_set,
    force_active_set,
    verify,
)
from alma.nonassociative.static_lps import LP_METHOD, StaticLP
from alma.settings import StateTolerances


def _store(lps: FixedSetLPs | None, model: Model, points: ContactPoints) -> FixedSetLPs:
    """``lps`` when it is ``model``'s and ``points``'s store, a new one when None."""
    if lps is None:
        return FixedSetLPs(model, points)
    if not lps.serves(model, points):
        raise ValueError("the store of fixed-set LPs belongs to another model")
    return lps


def _fixed_set_field(
    lps: FixedSetLPs,
    open_points: np.ndarray,
    slip_sign: np.ndarray,
    signs: np.ndarray,
    method: LPMethod,
    limits: ExactLimits,
    tally: Tally,
) -> StaticLP:
    """The smallest α with the active set fixed: a HiGHS vertex, or Clarabel's interior field.

    Clarabel's field is written on the cone generators only; with bounded forces (``signs``, the
    bounded columns' set) HiGHS's interior point with crossover takes its place."""
    coulomb: dict[str, Any] = dict(open_points=open_points, slip_sign=slip_sign)
    if lps.model.n_bounded:
        coulomb["bounded_signs"] = signs
        method = LPMethod.IPM if method == LPMethod.CLARABEL else method
    if method != LPMethod.CLARABEL:
        lp = lps.static(**coulomb, max_pivots=limits.lp_pivots, method=method)
        tally.add(lp.pivots)
        return lp
    lp = lps.interior(open_points, slip_sign, max_iter=limits.interior_iterations)
    tally.add(lp.pivots)
    if lp.status == Termination.ERROR:  # Clarabel did not converge: HiGHS decides, within the vertex's iterations
        lp = lps.static(**coulomb, max_pivots=min(limits.lp_pivots, limits.vertex_pivots), method=LPMethod.IPM)
        tally.add(lp.pivots)
    return lp


def _vertex(
    lps: FixedSetLPs,
    open_points: np.ndarray,
    slip_sign: np.ndarray,
    signs: np.ndarray,
    limits: ExactLimits,
    tally: Tally,
) -> StaticLP:
    """A vertex of the fixed-set static LP by HiGHS's interior point with crossover (its widest
    set is read from it): 1.9 s on an 876-block panel's set, where HiGHS's simplex took 15.7 s
    with the set written as rows and 6.4 s on the cone generators."""
    extra = {"bounded_signs": signs} if lps.model.n_bounded else {}
    lp = lps.static(
        open_points, slip_sign, max_pivots=min(limits.lp_pivots, limits.vertex_pivots), method=LPMethod.IPM, **extra
    )
    tally.add(lp.pivots)
    return lp


def exact_state(
    model: Model,
    points: ContactPoints,
    mechanism: np.ndarray,
    start: str,
    *,
    dilatant: bool = False,
    method: LPMethod = LP_METHOD,
    limits: ExactLimits = ExactLimits(),
    tally: Tally | None = None,
    widest: bool = True,
    lps: FixedSetLPs | None = None,
) -> CollapseState | None:
    """Turn a candidate mechanism into an exact collapse state and verify it.

    Its active set is fixed (:func:`active_set`); one static LP takes the smallest
    α with that set (N = 0 where open, T = −f N sign γ where slipping, |T| ≤ f N
    elsewhere) and one kinematic LP (:func:`kinematic_lp`) a mechanism with the same
    set.  The pair satisfies Eq. 9 by construction; :func:`verify` checks it.  When no
    mechanism has exactly that set, the kinematic LP is asked for one within the widest set
    the static field allows (:func:`force_active_set`); failing that, the candidate's own
    mechanism is verified.  ``method``: HiGHS's simplex or interior point for the static LP (a
    vertex), or Clarabel (:func:`fixed_set_static_interior`; then, when no
    mechanism has exactly the set, a HiGHS vertex (:func:`_vertex`) gives the widest set).  With bounded
    forces their columns' signs (:func:`bounded_active_set`) are part of the set, in both LPs.
    ``widest=False``: the candidate's own set only (no vertex, no widest set).  ``lps``: the
    search's store of fixed-set LPs of ``model`` (:class:`~alma.nonassociative.fixed_set_lps.FixedSetLPs`;
    None: a store of this call's own).
    """
    tally = Tally() if tally is None else tally
    lps = _store(lps, model, points)
    work = dot(model.live, mechanism)
    if not work > 0:
        return None
    mechanism = mechanism * (model.n_free / work)
    tol = limits.tolerances
    open_points, slip_sign = active_set(
        model, points, mechanism, dilatant=dilatant, tolerance=tol.active, linkage=tol.linkage
    )
    signs = bounded_active_set(model, points, mechanism, tol.active, tol.linkage)
    lp = _fixed_set_field(lps, open_points, slip_sign, signs, method, limits, tally)
    if lp.status != Termination.OPTIMAL:
        return None
    clean, pivots = lps.kinematic(open_points, slip_sign, max_pivots=limits.lp_pivots, bounded_allowed=_allowed(signs))
    tally.add(pivots)
    if clean is None and not widest:
        return _verified_pair(model, points, lp, clean, mechanism, start, dilatant, tol)
    if clean is None and method == LPMethod.CLARABEL and not model.n_bounded:
        # Clarabel's field lies inside the optimal face, where fewest points are unloaded or at
        # the friction limit; the widest set is read from a vertex instead.
        vertex = _vertex(lps, open_points, slip_sign, signs, limits, tally)
        if vertex.status == Termination.OPTIMAL:
            lp = vertex
    if clean is None:
        # No mechanism has exactly the candidate's set: take the widest set the static field
        # allows (open and free slip where N = 0, slip where friction is at its limit, bounded
        # rates of either sign where their force is at a bound).
        may_open, may_slip, free = force_active_set(points, lp.normal, lp.shear, tol.force)
        allowed = bf.force_signs(model, lp.bounded, tol.force * max(1.0, float(np.abs(lp.normal).max(initial=0.0))))
        clean, pivots = lps.kinematic(
            may_open, may_slip, free_slip=free, max_pivots=limits.lp_pivots, bounded_allowed=allowed
        )
        tally.add(pivots)
    return _verified_pair(model, points, lp, clean, mechanism, start, dilatant, tol)


def _verified_pair(
    model: Model,
    points: ContactPoints,
    lp: StaticLP,
    clean: np.ndarray | None,
    mechanism: np.ndarray,
    start: str,
    dilatant: bool,
    tolerances: StateTolerances,
) -> CollapseState | None:
    """The field with the kinematic LP's mechanism, else with the candidate's own (first verified)."""
    best = None
    for u in (clean, mechanism) if clean is not None else (mechanism,):
        if dilatant and u is mechanism:
            continue  # an associative mechanism opens where it slips: never a non-associative state
        residuals, ok = verify(model, points, lp.alpha, lp.normal, lp.shear, u, lp.bounded, tolerances)
        state = CollapseState(
            alpha=lp.alpha,
            normal=lp.normal,
            shear=lp.shear,
            mechanism=u,
            start=start,
            residuals=residuals,
            verified=ok,
            bounded=lp.bounded,
        )
        if best is None or (ok and not best.verified):
            best = state
        if ok:
            break
    return best


def fast_exact_state(
    model: Model,
    points: ContactPoints,
    mechanism: np.ndarray,
    start: str,
    *,
    dilatant: bool = False,
    limits: ExactLimits = ExactLimits(),
    tally: Tally | None = None,
    lps: FixedSetLPs | None = None,
) -> CollapseState | None:
    """:func:`exact_state` with Clarabel's static LP; HiGHS's vertex within ``limits.vertex_pivots``.

    When a mechanism has exactly the candidate's set, it complements every optimal field, so the
    interior point of :func:`fixed_set_static_interior` serves as well as a vertex and is far
    cheaper on large panels.  A vertex is needed when the widest set of the field has to be read
    (see :func:`exact_state`) or when the interior field's round-off fails the verification.
    With bounded forces the static LP is HiGHS's interior point with crossover (a vertex) at once.
    ``lps``: as in :func:`exact_state`.
    """
    lps = _store(lps, model, points)
    common: dict[str, Any] = dict(dilatant=dilatant, tally=tally, lps=lps)
    if model.n_bounded:
        return exact_state(model, points, mechanism, start, method=LPMethod.IPM, limits=limits, **common)
    state = exact_state(model, points, mechanism, start, method=LPMethod.CLARABEL, limits=limits, **common)
    if state is not None and not state.verified:
        vertex_limits = dataclasses.replace(limits, lp_pivots=min(limits.lp_pivots, limits.vertex_pivots))
        state = exact_state(model, points, mechanism, start, method=LPMethod.IPM, limits=vertex_limits, **common)
    return state


def exact_state_by(
    method: LPMethod,
    model: Model,
    points: ContactPoints,
    mechanism: np.ndarray,
    start: str,
    *,
    limits: ExactLimits = ExactLimits(),
    tally: Tally | None = None,
    lps: FixedSetLPs | None = None,
) -> CollapseState | None:
    """:func:`fast_exact_state` when ``method`` is Clarabel (its field, a vertex where that does not
    verify), else :func:`exact_state` with ``method``'s vertex.  ``lps``: as in :func:`exact_state`."""
    if method == LPMethod.CLARABEL:
        return fast_exact_state(model, points, mechanism, start, limits=limits, tally=tally, lps=lps)
    return exact_state(model, points, mechanism, start, method=method, limits=limits, tally=tally, lps=lps)
