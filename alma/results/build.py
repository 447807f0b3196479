"""From the solvers' dimensionless solutions to the typed results of :mod:`alma.results.types`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from alma.associative.lp_forms import LPSolution
from alma.mechanics.model import Model
from alma.results.joints import bounded_forces, multipliers_to_forces, physical
from alma.results.types import AssociativeResult, Bounds, Comparison, NonAssociativeResult, finite
from alma.status import Status

#: Relative gap under which a certificate's lower bound closes on the best state (as Eq. 10).
PROOF_GAP = 1e-7


def associative_result(model: Model, lp: LPSolution, timings: dict[str, float]) -> AssociativeResult:
    """The certified result of Eq. 10 in physical units."""
    normal, shear = multipliers_to_forces(model, lp.multipliers)
    cohesive_shear, ties = bounded_forces(model, lp.bounded_forces, lp.mechanism)
    form = physical(model, lp.mechanism, normal, shear + cohesive_shear, lp.solved, dilatant=True)
    return AssociativeResult(
        model="associative",
        status=Status(lp.status),
        message=lp.message,
        alpha=lp.alpha,
        bounds=Bounds(
            lower=lp.lower,
            upper=lp.upper,
            lower_is="static field (Eq. 10's lower bound)",
            upper_is="mechanism (Eq. 10's upper bound)",
        ),
        alpha_associative=lp.alpha,
        blocks=form.blocks,
        joints=form.joints,
        mechanism_class=form.mechanism_class,
        macro_blocks=form.macro_blocks,
        residuals={"static_equilibrium": lp.static_residual, "kinematic_flow_rule": lp.kinematic_residual},
        timings=dict(timings),
        n_blocks=model.n_free,
        n_joints=model.n_joints,
        iterations=lp.iterations,
        ties=ties,
    )


def nonassociative_result(
    model: Model,
    associative: AssociativeResult,
    solution: Any,
    timings: dict[str, float],
    certificate: Any = None,
    radenkovic: float = -math.inf,
) -> NonAssociativeResult:
    """The result of Eq. 9 from the search's ``solution`` (and a MILP ``certificate``, if any).

    The status says what is shown: ``feasible`` for a verified state, ``optimal`` only when the
    certificate's proven lower bound meets it, ``limit_reached`` when the user's time cap cut the
    search, ``not_converged`` when no state was verified.  ``bounds.upper`` is the best state's α;
    ``bounds.lower`` the larger of what the certificate proves and Radenkovic's bound
    (:mod:`alma.associative.radenkovic`).
    """
    best = solution.best
    # The MILP's bound counts when it proved its problem, or when a node or time limit left it a
    # positive bound; its 0.0 placeholder of a failure proves nothing.
    proven = certificate is not None and (
        certificate.status == "proven" or (certificate.status != "failed" and certificate.lower > 0)
    )
    lower = max(float(certificate.lower) if proven else -math.inf, radenkovic)
    lower_is = _lower_is(certificate if proven and lower == certificate.lower else None, lower, radenkovic)
    record = _record(solution, certificate)
    record["search"]["radenkovic_lower_bound"] = finite(radenkovic)
    if best is None:
        status, message = _unverified(associative, solution)
        if status == Status.NO_EQUILIBRIUM:
            lower = -math.inf
        form = physical(
            model, np.zeros(3 * model.n_free), np.zeros(2 * model.n_joints), np.zeros(2 * model.n_joints), False
        )
        return NonAssociativeResult(
            model="nonassociative",
            status=status,
            message=message,
            alpha=float("nan"),
            bounds=Bounds(
                lower=lower,
                upper=associative.bounds.upper,
                lower_is=lower_is,
                upper_is="associative α (Radenkovic: α_NL ≤ α_LP); no state verified",
            ),
            alpha_associative=associative.alpha,
            blocks=form.blocks,
            joints=form.joints,
            mechanism_class=form.mechanism_class,
            residuals={},
            timings=dict(timings),
            n_blocks=model.n_free,
            n_joints=model.n_joints,
            associative=associative,
            **record,
        )
    status, message, lower = _verified(associative, solution, best, lower, radenkovic)
    shear = best.shear
    ties: tuple[dict[str, float | str], ...] = ()
    if model.n_bounded:  # the joints' shear with their cohesive part, and the ties' forces
        cohesive_shear, ties = bounded_forces(model, best.bounded, best.mechanism / model.n_free)
        shear = shear + cohesive_shear
    form = physical(model, best.mechanism / model.n_free, best.normal, shear, True)
    return NonAssociativeResult(
        model="nonassociative",
        status=status,
        message=message,
        alpha=best.alpha,
        bounds=Bounds(lower=lower, upper=best.alpha, lower_is=lower_is, upper_is="verified collapse state (α_NL)"),
        alpha_associative=associative.alpha,
        blocks=form.blocks,
        joints=form.joints,
        mechanism_class=form.mechanism_class,
        residuals=dict(best.residuals),
        timings=dict(timings),
        macro_blocks=form.macro_blocks,
        n_blocks=model.n_free,
        n_joints=model.n_joints,
        associative=associative,
        start=best.start,
        ties=ties,
        **record,
    )


def _lower_is(certificate: Any, lower: float, radenkovic: float) -> str:
    """What the non-associative lower bound is: the certificate's proof (complete or stopped by its
    budget), Radenkovic's bound, or nothing."""
    if certificate is not None:
        backend = {"highs": "HiGHS", "scip": "SCIP"}.get(getattr(certificate, "backend", "highs"), "MIP")
        if certificate.status == "proven":
            return f"proven bound (MILP certificate, {backend})"
        return f"proven bound (MILP certificate, {backend}, stopped by {certificate.status.replace('_', ' ')})"
    if math.isfinite(lower) and lower == radenkovic:
        return "Radenkovic's bound (the associative LP at f = 0)"
    return ""


def comparison(associative: AssociativeResult, nonassociative: NonAssociativeResult) -> Comparison:
    """``model="both"``: the two results whole."""
    return Comparison(associative=associative, nonassociative=nonassociative)


def _stopped(solution: Any) -> bool:
    return bool(getattr(solution, "stopped_by_limit", False))


def _unverified(associative: AssociativeResult, solution: Any) -> tuple[Status, str]:
    if associative.status == Status.NO_EQUILIBRIUM:
        # Radenkovic: α_NL ≤ α_LP, and the associative structure already cannot stand.
        return Status.NO_EQUILIBRIUM, "α_nonassociative ≤ α_associative < 0 (Radenkovic)"
    if _stopped(solution):
        return Status.LIMIT_REACHED, f"the time limit stopped the search: {solution.message}"
    return Status.NOT_CONVERGED, solution.message


def _verified(
    associative: AssociativeResult, solution: Any, best: Any, lower: float, radenkovic: float
) -> tuple[Status, str, float]:
    message = solution.message
    if best.alpha < 0:
        lower = min(lower, best.alpha)
        if associative.status == Status.NO_EQUILIBRIUM:
            return Status.NO_EQUILIBRIUM, f"{message}; α_nonassociative ≤ α_associative < 0 (Radenkovic)", lower
        message = (
            f"{message}: a verified collapse state at α = {best.alpha:.6g} < 0, so the structure "
            f"may collapse under its dead load alone (the associative LP carries it: "
            f"α_associative = {associative.alpha:.6g})"
        )
    if _stopped(solution):
        return Status.LIMIT_REACHED, f"the time limit stopped the search; {message}", lower
    gap = (best.alpha - lower) / max(1.0, abs(best.alpha))
    if gap <= PROOF_GAP:
        how = "the certificate" if lower != radenkovic else "Radenkovic's bound"
        return Status.OPTIMAL, f"{message}; proven minimum ({how}, gap {gap:.1e})", lower
    return Status.FEASIBLE, message, lower


def _record(solution: Any, certificate: Any) -> dict[str, Any]:
    """The search record: every candidate, every start run, what the search spent and skipped."""
    candidates = tuple(
        {"start": c.start, "alpha": finite(c.alpha), "verified": c.verified} for c in solution.candidates
    )
    starts = tuple(
        {
            "start": r.start,
            "time_s": r.time_s,
            "iterations": r.iterations,
            "alpha": finite(r.alpha),
            "verified": r.verified,
        }
        for r in solution.starts
    )
    search = {
        "stopped_by_limit": _stopped(solution),
        "skipped": list(getattr(solution, "skipped", ()) or ()),
        "work": {k: v for k, v in getattr(solution, "work", {}).items()},
    }
    cert = None
    if certificate is not None:
        cert = {
            "status": certificate.status,
            "message": certificate.message,
            "lower": certificate.lower,
            "upper": finite(certificate.upper),
            "gap": finite(certificate.gap),
            "time_s": certificate.time_s,
            "velocity_bound": finite(certificate.velocity_bound),
            "velocity_bound_active": certificate.velocity_bound_active,
            "backend": getattr(certificate, "backend", "highs"),
            "nodes": int(getattr(certificate, "nodes", 0)),
        }
    return {"candidates": candidates, "starts": starts, "search": search, "certificate": cert}
