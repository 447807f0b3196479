"""Foundation settlements: the crack pattern a prescribed support motion opens, and its statics.

A support (a fixed block) may carry a small rigid ``settlement`` (SPEC §2).  The free blocks
then take the motion u that is compatible with it (no interpenetration and the Coulomb flow
rule of Eq. 6 at every contact point, now relative to the moving support) and lets the dead
load do the most work — the piecewise-rigid-displacement approach of Iannuzzo et al.::

    W* = max  f₀ᵀu − cᵀ max(0, −(Gᵀu + g))   s.t.  Hᵀu + h ≥ 0                    (kinematic)
       = min  hᵀμ + gᵀτ          s.t.  H μ + G τ + f₀ = 0,  μ ≥ 0,  0 ≤ τ ≤ c   (static, its dual)

where h_j is the power of generator j under the support's own motion, and G, c the bounded
forces of cohesion and ties (:mod:`alma.mechanics.forces`) with g their power under it: a
cohesive joint's shear dissipates c l t |γ| as it slides, a tie its strength times its
elongation rate, as in the associative LP.  The static side is a
stress field in equilibrium with the dead load whose reactions on the settling supports do the
least work on the prescribed motion: for a spreading arch, the minimum thrust.  By virtual work
the two values meet at the optimum, and an admissible pair certifies W* from both sides.
Units: mm, rad, kN, kN·mm (work in kN·mm).
"""

from __future__ import annotations

import math
import time
import types
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import scipy.sparse as sp

from alma.associative.certificate import _repair_field
from alma.backends.clarabel_backend import solve_conic_lp
from alma.backends.highs_backend import solve_conic_form
from alma.floats import dot
from alma.geometry.contacts import Joints
from alma.geometry.scene import JointOverride, Scene, SceneError
from alma.geometry.validation import validated
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.forces import joint_values
from alma.mechanics.model import Model, build_model
from alma.results.joints import MOTION_TOLERANCE, multipliers_to_forces, physical, states_from_relative
from alma.results.types import BlockMotion, Bounds, JointResult, finite
from alma.settings import AssociativeSettings
from alma.settle_power import bounded_support_power, support_power, support_relative
from alma.status import Status


class SettleError(ValueError):
    """A scene the settlement analysis cannot answer (no settlement given, …): bad input, exit 2."""


@dataclass(frozen=True)
class SettlementResult:
    """The settlement mechanism, its dead-load work and the reactions of the settling supports."""

    status: Status
    message: str
    work: float  # kN·mm: the dead load's work on the mechanism (= the reactions' on the settlement)
    bounds: Bounds  # certified interval of the work
    reactions: tuple[dict[str, Any], ...]  # per settling support: block, force [Fx, Fy] kN, moment kN·mm
    blocks: tuple[BlockMotion, ...]  # displacements in mm (rad), for the prescribed settlement
    joints: Sequence[JointResult]
    residuals: dict[str, float]
    timings: dict[str, float]

    @property
    def opened(self) -> tuple[tuple[str, str], ...]:
        """The joints the settlement opens or slides (the crack pattern)."""
        return tuple(j.blocks for j in self.joints if j.state != "rest")

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``alma settle`` (SPEC §3)."""
        return {
            "status": str(self.status),
            "message": self.message,
            "work": finite(self.work),
            "bounds": {"lower": finite(self.bounds.lower), "upper": finite(self.bounds.upper)},
            "reactions": [dict(r) for r in self.reactions],
            "blocks": [{"id": b.id, "u": list(b.u)} for b in self.blocks],
            "joints": [
                {
                    "blocks": list(j.blocks),
                    "N": j.N,
                    "T": j.T,
                    "M": j.M,
                    "state": j.state,
                    "opening": list(j.opening),
                    "slip": j.slip,
                }
                for j in self.joints
            ],
            "residuals": {k: finite(v) for k, v in self.residuals.items()},
            "timings": dict(self.timings),
        }


def settle(
    scene: Scene, settings: AssociativeSettings | None = None, joints: Joints | None = None, crisp: float | None = None
) -> SettlementResult:
    """The settlement mechanism of ``scene`` and its certified dead-load work (module docstring).

    ``joints``: the scene's contacts when they are not its flat ones alone (a displaced
    configuration's point contacts, :func:`alma.push.motion.joints_after`); default: found.
    ``crisp``: when given, one vertex of the optimal face (:func:`_vertex`, its work within this
    relative slack of the optimum) instead of the interior point's blend of all of them.
    """
    s = settings or AssociativeSettings()
    scene, joints = _settling(scene, joints)
    t0 = time.perf_counter()
    model = build_model(scene, joints)
    if model.crushes:
        raise SceneError(
            "compressive_strength: the settlement analysis takes infinitely strong blocks only; "
            "remove compressive_strength from the scene"
        )
    h, g = support_power(model), bounded_support_power(model)
    n, k = model.equilibrium.shape
    q = model.n_bounded
    G = model.bounded if q and model.bounded is not None else sp.csc_matrix((n, 0))
    q_cost, A, b = _kinematic_lp(model, G, h, g)
    sol = solve_conic_lp(q_cost, A, b, 0, k + 2 * q, tolerance=s.tolerance, max_iter=s.max_iter)
    timings = {"build_s": 0.0, "solve_s": sol.solve_time}
    if sol.status in (Status.NO_EQUILIBRIUM, Status.NO_COLLAPSE):
        message = (
            "the structure cannot carry its dead load: the settlement mechanism is unbounded"
            if sol.status == Status.NO_EQUILIBRIUM
            else "the prescribed settlements are incompatible"
        )
        return _empty(model, Status(sol.status), message, timings)
    # With no settlement at all u = 0 is the mechanism (nothing moves); the LP still gives the field.
    moves = h.any() or g.any()
    x = _vertex(q_cost, A, b, sol.x, k, n, crisp) if moves and crisp is not None else sol.x
    u = x[:n] if moves else np.zeros(n)
    mu, tau, static_residual = _static_field(model, G, sol.duals, s)
    bounds, kinematic_residual = _work_bounds(model, G, h, g, u, mu, tau, static_residual, s)
    status, message = _verdict(bounds, static_residual, kinematic_residual, s)
    timings["certify_s"] = time.perf_counter() - t0 - sol.solve_time
    return _result(
        model,
        status,
        message,
        u,
        mu,
        tau,
        bounds,
        {"static_equilibrium": static_residual, "kinematic_compatibility": kinematic_residual},
        timings,
    )


def _settling(scene: Scene, joints: Joints | None) -> tuple[Scene, Joints | None]:
    """``scene`` validated and ``joints`` (the check's when not given); :class:`SettleError` when
    no support of it has a settlement."""
    if not scene.validated:
        scene, found = validated(scene)  # the check's joints serve the model unless given
        joints = found if joints is None else joints
    # An explicit zero settlement is answered (nothing moves, work 0); none at all is a mistake.
    if not any(b.settlement is not None for b in scene.blocks):
        raise SettleError(
            "no support of the scene has a 'settlement' (a fixed block's prescribed motion, "
            "SPEC §2): there is nothing to settle"
        )
    return scene, joints


def _kinematic_lp(
    model: Model, G: sp.csc_matrix, h: np.ndarray, g: np.ndarray
) -> tuple[np.ndarray, sp.csc_matrix, np.ndarray]:
    """(cost, A, b) of the kinematic LP of the module docstring in Clarabel's form A x + s = b,
    s ≥ 0, over x = (u, w) (model units, the work per unit force and length)."""
    H, q = model.equilibrium, model.n_bounded
    # x = (u, w): min −f₀ᵀu + cᵀw  s.t.  Hᵀu + h ≥ 0, w ≥ −(Gᵀu + g), w ≥ 0 (no equality rows);
    # the duals of the three row blocks are μ, τ and c − τ.
    eye = sp.identity(q, format="csc")
    A = sp.bmat([[-H.T, None], [-G.T, -eye], [None, -eye]], format="csc") if q else -H.T.tocsc()
    return np.concatenate([-model.dead, model.capacity]), A, np.concatenate([h, g, np.zeros(q)])


def _static_field(
    model: Model, G: sp.csc_matrix, duals: np.ndarray, s: AssociativeSettings
) -> tuple[np.ndarray, np.ndarray, float]:
    """(μ, τ, residual): the LP's duals repaired to a stress field in equilibrium with the dead
    load alone, H μ + G τ + f₀ = 0, μ ≥ 0, 0 ≤ τ ≤ c (the static side; residual in mean block
    weights)."""
    H, capacity = model.equilibrium, model.capacity
    (n, k), q = H.shape, model.n_bounded
    fields = np.clip(duals[: k + q], 0.0, np.concatenate([np.full(k, np.inf), capacity]))
    field = types.SimpleNamespace(dead=model.dead, live=np.zeros(n))
    # _repair_field reads only .dead and .live of its model: the settlement's field carries no live load.
    fields, _, static_residual = _repair_field(
        sp.hstack([H, G]).tocsc(),
        field,  # type: ignore[arg-type]
        fields,
        0.0,
        np.concatenate([np.full(k, np.inf), capacity]),
        0.0,
        s.residual_tolerance,
        s.gap_tolerance,
        s.feral_min_rows,
    )
    return fields[:k], fields[k:], static_residual


def _work_bounds(
    model: Model,
    G: sp.csc_matrix,
    h: np.ndarray,
    g: np.ndarray,
    u: np.ndarray,
    mu: np.ndarray,
    tau: np.ndarray,
    static_residual: float,
    s: AssociativeSettings,
) -> tuple[Bounds, float]:
    """The certified interval of W* in kN·mm (the kinematic side's f₀ᵀu − cᵀ max(0, −(Gᵀu + g))
    below, the static side's hᵀμ + gᵀτ above, each only when its residual is within tolerance)
    and the mechanism's compatibility residual."""
    H, capacity = model.equilibrium, model.capacity
    power = H.T @ u + h
    size = float((abs(H.T) @ np.abs(u)).max(initial=0.0)) + float(np.abs(h).max(initial=0.0))
    kinematic_residual = max(0.0, -float(power.min(initial=0.0))) / max(size, 1e-300)
    scale = model.force_scale * model.length_scale  # kN·mm per model work unit
    dissipation = dot(capacity, np.maximum(-(G.T @ u + g), 0.0))
    lower = (dot(model.dead, u) - dissipation) * scale if kinematic_residual <= s.residual_tolerance else -math.inf
    upper = (dot(h, mu) + dot(g, tau)) * scale if static_residual <= s.residual_tolerance else math.inf
    return Bounds(lower, upper), kinematic_residual


def _verdict(
    bounds: Bounds, static_residual: float, kinematic_residual: float, s: AssociativeSettings
) -> tuple[Status, str]:
    """``optimal`` when the certified bounds of W* meet within the gap tolerance, with its message."""
    lower, upper = bounds.lower, bounds.upper
    gap = (upper - lower) / max(1.0, abs(upper)) if math.isfinite(lower) and math.isfinite(upper) else math.inf
    status = Status.OPTIMAL if gap <= s.gap_tolerance else Status.NOT_CONVERGED
    message = (
        f"certified: relative gap {gap:.1e}"
        if status == Status.OPTIMAL
        else f"relative gap {gap:.2e}, residuals static {static_residual:.1e}, kinematic {kinematic_residual:.1e}"
    )
    return status, message


def _vertex(
    cost: np.ndarray, A: sp.csc_matrix, b: np.ndarray, x: np.ndarray, k: int, n: int, slack: float
) -> np.ndarray:
    """A vertex of the kinematic LP's optimal face: the least total power of the generators
    (Σ (Hᵀu + h), the L1 norm of the joints' relative motion) plus the bounded forces'
    dissipation variables, among the motions whose dead-load work is within ``slack`` (relative)
    of the interior point's ``x``.  A symmetric arch that spreads has two crown hinges of equal
    work; the interior point returns their blend, a four-hinge motion that is a mechanism of its
    own at the next configuration, the vertex one of them.  ``x`` itself when HiGHS finds none."""
    value = dot(cost, x)
    sparse = -np.asarray(A[:k, :].sum(axis=0)).ravel()
    sparse[n:] += 1.0
    cap = value + slack * abs(value)
    sol = solve_conic_form(sparse, sp.vstack([A, sp.csr_matrix(cost)]).tocsc(), np.append(b, cap), 0)
    if sol.status != Status.OPTIMAL:
        return x
    size = float((abs(A) @ np.abs(sol.x)).max(initial=0.0)) + float(np.abs(b).max(initial=0.0))
    return sol.x if float((A @ sol.x - b).max(initial=0.0)) <= 1e-9 * max(size, 1e-300) else x


def after_settlement(scene: Scene, result: SettlementResult | None = None) -> Scene:
    """``scene`` with its cohesion lost on every joint the settlement opened (the question
    ALMA 2.0 asks next: the collapse load of the settled structure).  Joint overrides of the
    other joints are kept; the settlements themselves stay on the supports (``solve`` ignores
    them)."""
    result = settle(scene) if result is None else result
    if result.status != Status.OPTIMAL:
        raise ValueError(
            f"the settlement analysis did not certify its mechanism ({result.status}: "
            f"{result.message}); the opened joints are not known"
        )
    opened = {(min(a, b), max(a, b)) for a, b in result.opened}
    kept = tuple(o for o in scene.joint_overrides if tuple(sorted(o.blocks)) not in opened)
    lost = tuple(
        JointOverride(blocks=pair, friction=_friction_of(scene, pair), cohesion=0.0) for pair in sorted(opened)
    )
    return replace(scene, joint_overrides=kept + lost, validated=False).validate()


def _friction_of(scene: Scene, pair: tuple[str, str]) -> float | None:
    for o in scene.joint_overrides:
        if tuple(sorted(o.blocks)) == tuple(sorted(pair)):
            return o.friction
    return None


def _result(
    model: Model,
    status: Status,
    message: str,
    u: np.ndarray,
    mu: np.ndarray,
    tau: np.ndarray,
    bounds: Bounds,
    residuals: dict[str, float],
    timings: dict[str, float],
) -> SettlementResult:
    normal, shear = multipliers_to_forces(model, mu)
    shear = shear + _cohesive_shear(model, tau)
    form = physical(model, u / model.n_free, normal, shear, True)
    blocks, joints = form.blocks, form.joints
    # ``physical`` reports a mechanism scaled by 1 / length_scale (translations read as mm); a
    # settlement's motion is real: translations in mm, rotations in rad.
    ls = model.length_scale
    blocks = tuple(BlockMotion(b.id, (b.u[0] * ls, b.u[1] * ls, b.u[2] * ls)) for b in blocks)
    support = support_relative(model)
    rel = (ContactPoints.from_model(model).relative_velocities(u) + support) * model.length_scale
    # Motions are real displacements here: the scale is the largest of the blocks' and supports'.
    scale = max(
        float(np.abs(rel).max(initial=0.0)),
        float(np.abs(support).max(initial=0.0)) * model.length_scale,
        float(np.abs(u).max(initial=0.0)) * model.length_scale,
        1e-300,
    )
    states = states_from_relative(rel, model.friction, MOTION_TOLERANCE * scale, dilatant=True)
    joints = replace(
        joints, state=np.asarray(states, dtype=str), slip=rel[:, :, 1].mean(axis=1), opening=rel[:, :, 0].copy()
    )
    work = 0.5 * (bounds.lower + bounds.upper) if math.isfinite(bounds.lower + bounds.upper) else bounds.lower
    return SettlementResult(
        status, message, work, bounds, _reactions(model, normal, shear, tau), blocks, joints, residuals, timings
    )


def _cohesive_shear(model: Model, tau: np.ndarray) -> np.ndarray:
    """(2m,) the cohesive shear τ₊ − τ₋ of each cohesive joint, half at each of its two contact
    points (a shear along the joint line has the same resultant and moment wherever it acts)."""
    out = np.zeros(2 * model.n_joints)
    scene = model.scene
    cohesive = np.flatnonzero(joint_values(scene, model.joints, "cohesion", scene.cohesion) > 0)
    if cohesive.size:
        net = tau[0 : 2 * cohesive.size : 2] - tau[1 : 2 * cohesive.size : 2]
        out[2 * cohesive] += 0.5 * net
        out[2 * cohesive + 1] += 0.5 * net
    return out


def _reactions(model: Model, normal: np.ndarray, shear: np.ndarray, tau: np.ndarray) -> tuple[dict[str, Any], ...]:
    """Force (kN) and moment about the settlement's ``about`` point (kN·mm) that the free blocks
    exert on each settling support, from the contact points' (N, T) and the ties' tensions
    (dimensionless)."""
    jt = model.joints
    points = np.stack([jt.start, jt.end], axis=1).reshape(-1, 2)  # (2m, 2) mm
    joint = np.repeat(np.arange(jt.count), 2)
    # The force of a contact point on block b is N n + T t; block a takes its opposite.
    on_b = (normal[:, None] * jt.normal[joint] + shear[:, None] * jt.tangent[joint]) * model.force_scale
    out = []
    for i, block in enumerate(model.scene.blocks):  # the few settling supports
        if block.settlement is None:
            continue
        sign = np.where(jt.block_b[joint] == i, 1.0, 0.0) - np.where(jt.block_a[joint] == i, 1.0, 0.0)
        force = sign[:, None] * on_b
        at, force = _with_ties(model, i, points, force, tau)
        r = at - np.asarray(block.settlement.about, dtype=float)
        moment = float((r[:, 0] * force[:, 1] - r[:, 1] * force[:, 0]).sum())
        total = force.sum(axis=0)
        out.append({"block": block.id, "force": [float(total[0]), float(total[1])], "moment": moment})
    return tuple(out)


def _empty(model: Model, status: Status, message: str, timings: dict[str, float]) -> SettlementResult:
    bound = -math.inf if status == Status.NO_EQUILIBRIUM else math.nan
    return SettlementResult(status, message, bound, Bounds(bound, bound), (), (), (), {}, timings)


def _with_ties(
    model: Model, support: int, points: np.ndarray, forces: np.ndarray, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``points`` and ``forces`` (kN) on scene block ``support`` with the pulls of the ties
    anchored on it appended (a tie's tension τ pulls each end towards the other)."""
    scene = model.scene
    if not scene.ties:
        return points, forces
    tension = tau[tau.shape[0] - len(scene.ties) :] * model.force_scale
    extra_at, extra_force = [], []
    for t, pull in zip(scene.ties, tension, strict=True):  # the scene's few ties
        a, b = np.asarray(t.from_point, dtype=float), np.asarray(t.to_point, dtype=float)
        d = (b - a) / np.hypot(*(b - a))
        if scene.blocks[support].id == t.from_block:
            extra_at.append(a)
            extra_force.append(pull * d)
        if scene.blocks[support].id == t.to_block:
            extra_at.append(b)
            extra_force.append(-pull * d)
    if not extra_at:
        return points, forces
    return np.vstack([points, extra_at]), np.vstack([forces, extra_force])
