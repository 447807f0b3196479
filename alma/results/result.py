"""Results: the collapse multiplier, its certified bounds, the mechanism and joint forces.

A :class:`Result` is plain, frozen data in physical units (mm, rad, kN,
kN·mm) and serialises to the JSON object of SPEC §3 with :meth:`Result.to_dict`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from alma.associative.lp import LPSolution
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model

#: Relative velocity below this fraction of the largest one counts as zero (the interior-point
#: mechanism carries traces of the other optimal mechanisms at about this level).
MOTION_TOLERANCE = 1e-4

JOINT_STATES = ("rest", "hinging", "sliding", "separating")


@dataclass(frozen=True)
class Bounds:
    """Proven interval of the collapse multiplier: lower (static) ≤ α_c ≤ upper (kinematic)."""

    lower: float
    upper: float

    @property
    def gap(self) -> float:
        """Relative gap (upper − lower) / max(1, |upper|)."""
        if not (math.isfinite(self.lower) and math.isfinite(self.upper)):
            return float("nan")
        return (self.upper - self.lower) / max(1.0, abs(self.upper))


@dataclass(frozen=True)
class BlockMotion:
    """Collapse velocity of a free block: (u, v) at its centroid in mm, θ in rad."""

    id: str
    u: tuple[float, float, float]


@dataclass(frozen=True)
class JointResult:
    """Generalised stresses of a joint (N compression > 0 and T in kN, M in kN·mm about its centre)."""

    blocks: tuple[str, str]
    N: float
    T: float
    M: float
    state: str
    length: float
    slip: float  # tangential relative velocity, mm per unit mechanism
    opening: tuple[float, float]  # normal relative velocity at the two ends
    start: tuple[float, float]  # end points of the contact segment, mm
    end: tuple[float, float]


@dataclass(frozen=True)
class Result:
    """The outcome of an analysis, shaped like ``scipy.optimize.OptimizeResult``."""

    model: str
    status: str
    message: str
    alpha: float
    bounds: Bounds
    alpha_associative: float
    blocks: tuple[BlockMotion, ...]
    joints: tuple[JointResult, ...]
    mechanism_class: str
    residuals: dict[str, float]
    timings: dict[str, float]
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return self.status == "optimal"

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of SPEC §3 (non-finite numbers become null)."""
        out: dict[str, Any] = {
            "model": self.model,
            "status": self.status,
            "message": self.message,
            "alpha": _finite(self.alpha),
            "bounds": {"lower": _finite(self.bounds.lower), "upper": _finite(self.bounds.upper),
                       "gap": _finite(self.bounds.gap)},
            "alpha_associative": _finite(self.alpha_associative),
            "mechanism_class": self.mechanism_class,
            "blocks": [{"id": b.id, "u": [float(x) for x in b.u]} for b in self.blocks],
            "joints": [{"blocks": list(j.blocks), "N": j.N, "T": j.T, "M": j.M, "state": j.state,
                        "length": j.length, "slip": j.slip, "opening": list(j.opening)}
                       for j in self.joints],
            "residuals": {k: _finite(v) for k, v in self.residuals.items()},
            "timings": dict(self.timings),
        }
        for key, value in self.extra.items():
            out[key] = _finite(value) if isinstance(value, float) else value
        return out


def _finite(value: float) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None


def joint_states(model: Model, mechanism: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """State of every joint under a mechanism, and the relative velocities (m, 2, 2).

    sliding: tangential slip; hinging: one end opens, the other stays closed;
    separating: both ends open; rest: no relative motion.
    """
    rel = ContactPoints.from_model(model).relative_velocities(mechanism)
    scale = max(float(np.abs(rel).max(initial=0.0)), float(np.abs(mechanism).max(initial=0.0)), 1e-300)
    tol = MOTION_TOLERANCE * scale
    slip = rel[:, :, 1].mean(axis=1)
    opening = rel[:, :, 0]
    state = np.full(model.n_joints, "rest", dtype=object)
    open_ends = (opening > tol).sum(axis=1)
    state[open_ends == 1] = "hinging"
    state[open_ends == 2] = "separating"
    state[np.abs(slip) > tol] = "sliding"
    return state, rel


def mechanism_class(model: Model, mechanism: np.ndarray, states: np.ndarray) -> str:
    """'sliding' (translations only, joints slide or separate), 'rocking' (no joint slides), 'mixed', 'none'."""
    if not np.any(states != "rest"):
        return "none"
    rel_scale = max(float(np.abs(mechanism.reshape(-1, 3)[:, :2]).max(initial=0.0)), 1e-300)
    rotation = np.abs(mechanism.reshape(-1, 3)[:, 2]).max(initial=0.0)  # dimensionless: per length unit
    sliding = np.any(states == "sliding")
    if not sliding:
        return "rocking"
    if not np.any(states == "hinging") and rotation <= MOTION_TOLERANCE * rel_scale:
        return "sliding"
    return "mixed"


def build_result(model: Model, lp: LPSolution, timings: dict[str, float], name: str = "associative") -> Result:
    """Turn a dimensionless LP solution into a physical :class:`Result`."""
    scene = model.scene
    ids = scene.block_ids
    mech = lp.mechanism
    # f_Lᵀu = 1 in solver units (loads per mean block weight); reported so that the
    # weight-averaged displacement along the live load is 1 mm: Σ (w_i / W) d·u_i = 1.
    motion = mech.reshape(-1, 3) * model.n_free
    motion[:, 2] /= model.length_scale
    # Python floats in bulk (ndarray.tolist), not one float() per entry: per object only the
    # dataclass construction is left.
    blocks = tuple(BlockMotion(id=ids[i], u=tuple(row))
                   for i, row in zip(model.free_blocks.tolist(), motion.tolist()))
    joints = model.joints
    if lp.status in ("optimal", "not_converged") and model.n_joints:
        states, rel = joint_states(model, mech)
        klass = mechanism_class(model, mech, states)
    else:
        states = np.full(model.n_joints, "rest", dtype=object)
        rel = np.zeros((model.n_joints, 2, 2))
        klass = "none"
    mu = lp.multipliers.reshape(-1, 2, 2) * model.force_scale  # (m, point, ±) in kN
    normal_force = mu.sum(axis=2)  # (m, 2)
    tangent_force = (mu[:, :, 0] - mu[:, :, 1]) * model.friction[:, None]
    centre = joints.centre
    moment = np.zeros(model.n_joints)
    tangent = joints.tangent
    for p, point in enumerate((joints.start, joints.end)):
        r = point - centre
        force = normal_force[:, p, None] * joints.normal + tangent_force[:, p, None] * tangent
        moment += r[:, 0] * force[:, 1] - r[:, 1] * force[:, 0]
    length = joints.length
    scale_u = model.n_free  # relative velocities in the reported mechanism's units (mm)
    slip = rel[:, :, 1].mean(axis=1) * scale_u
    opening = rel[:, :, 0] * scale_u
    joint_results = tuple(
        JointResult(blocks=(ids[a], ids[b]), N=n, T=t, M=mo, state=s, length=le, slip=sl,
                    opening=tuple(op), start=tuple(p), end=tuple(q))
        for a, b, n, t, mo, s, le, sl, op, p, q in zip(
            joints.block_a.tolist(), joints.block_b.tolist(), normal_force.sum(axis=1).tolist(),
            tangent_force.sum(axis=1).tolist(), moment.tolist(), states.astype(str).tolist(),
            np.asarray(length, dtype=float).tolist(), slip.tolist(), opening.tolist(),
            np.asarray(joints.start, dtype=float).tolist(), np.asarray(joints.end, dtype=float).tolist())
    )
    return Result(
        model=name, status=lp.status, message=lp.message, alpha=lp.alpha,
        bounds=Bounds(lower=lp.lower, upper=lp.upper), alpha_associative=lp.alpha,
        blocks=blocks, joints=joint_results, mechanism_class=klass,
        residuals={"static_equilibrium": lp.static_residual, "kinematic_flow_rule": lp.kinematic_residual},
        timings=timings,
        extra={"iterations": lp.iterations, "n_blocks": model.n_free, "n_joints": model.n_joints},
    )


def build_nonassociative_result(model: Model, lp: LPSolution, solution, timings: dict[str, float],
                                certificate=None, name: str = "nonassociative") -> Result:
    """A :class:`Result` for the non-associative model (Eq. 9) from its best verified state.

    ``bounds.upper`` is the α of the best verified collapse state (never above the
    associative α); ``bounds.lower`` is the certified lower bound, 0 when not certified.
    """
    from dataclasses import replace

    best = solution.best
    if best is None:
        base = build_result(model, lp, timings, name=name)
        status, message = "not_converged", solution.message
        lower = certificate.lower if certificate else 0.0
        if lp.status == "no_equilibrium":
            # Radenkovic: α_NL ≤ α_LP, and the associative structure already cannot stand.
            status, message, lower = "no_equilibrium", "α_nonassociative ≤ α_associative < 0 (Radenkovic)", -np.inf
        return replace(base, status=status, message=message, alpha=float("nan"),
                       bounds=Bounds(lower=lower, upper=lp.upper), alpha_associative=lp.alpha,
                       extra=dict(base.extra, start=None, candidates=_candidates(solution),
                                  starts=_starts(solution)))
    # Express the state in the LP's generator form so the shared joint/force code applies:
    # N n + T t = μ⁺ (n + f t) + μ⁻ (n − f t) with μ± = (N ± T/f)/2 (f > 0).
    friction = np.repeat(model.friction, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        plus = np.where(friction > 0, 0.5 * (best.normal + best.shear / friction), 0.5 * best.normal)
        minus = np.where(friction > 0, 0.5 * (best.normal - best.shear / friction), 0.5 * best.normal)
    multipliers = np.column_stack([plus, minus]).ravel()
    lower = certificate.lower if certificate is not None else 0.0
    state_lp = LPSolution(status=solution.status, message=solution.message, alpha=best.alpha,
                          lower=lower, upper=best.alpha, mechanism=best.mechanism / model.n_free,
                          multipliers=multipliers, static_residual=best.residuals.get("equilibrium", np.nan),
                          kinematic_residual=best.residuals.get("interpenetration", np.nan),
                          iterations=0, solve_time=0.0, certify_time=0.0)
    base = build_result(model, state_lp, timings, name=name)
    extra = dict(base.extra, start=best.start, candidates=_candidates(solution), starts=_starts(solution))
    if certificate is not None:
        extra["certificate"] = {"status": certificate.status, "message": certificate.message,
                                "lower": certificate.lower, "upper": _finite(certificate.upper),
                                "gap": _finite(certificate.gap), "time_s": certificate.time_s,
                                "velocity_bound": _finite(certificate.velocity_bound),
                                "velocity_bound_active": certificate.velocity_bound_active}
    return replace(base, alpha_associative=lp.alpha, residuals=dict(best.residuals), extra=extra)


def _candidates(solution) -> list[dict[str, Any]]:
    return [{"start": c.start, "alpha": _finite(c.alpha), "verified": c.verified} for c in solution.candidates]


def _starts(solution) -> list[dict[str, Any]]:
    """Each start of the search in the order it ran: its time, iterations and what it gave."""
    return [{"start": r.start, "time_s": r.time_s, "iterations": r.iterations, "alpha": _finite(r.alpha),
             "verified": r.verified} for r in solution.starts]
