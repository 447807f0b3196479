"""Joint states, mechanism class and the physical form of a solution (blocks and joints).

Both models hand over the same thing: a mechanism u (dimensionless, f_Lᵀu = 1) and the normal
and tangential force (N, T) at every contact point (dimensionless, two points per joint, in the
order of :class:`alma.mechanics.contact_points.ContactPoints`).  This module turns them into
:class:`~alma.results.types.BlockMotion` and :class:`~alma.results.types.JointResult` in mm,
rad, kN and kN·mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.results.joint_table import JointTable
from alma.results.macro_blocks import macro_blocks
from alma.results.types import BlockMotion, MacroBlock

#: Relative velocity below this fraction of the largest one counts as zero (the interior-point
#: mechanism carries traces of the other optimal mechanisms at about this level).
MOTION_TOLERANCE = 1e-4

JOINT_STATES = ("rest", "hinging", "sliding", "separating", "crushing")
#: A moving joint whose N reaches this fraction of its capacity σ_c l t is ``crushing`` (the
#: stress block spans the joint); the certified fields meet the cone to ~1e-9 of the forces.
CRUSHING_FRACTION = 1.0 - 1e-6


def joint_states(model: Model, mechanism: np.ndarray, *, dilatant: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """State of every joint under a mechanism, and the relative velocities (m, 2, 2).

    separating: both ends open (whether or not the joint also slips); sliding: tangential slip
    with at least one end closed; hinging: one end opens, the other stays closed, no slip; rest:
    no relative motion.  ``dilatant``: the mechanism obeys the associative flow rule (Eq. 6), in
    which a sliding end opens by f |γ|; an end counts as open only beyond that.
    """
    rel = ContactPoints.from_model(model).relative_velocities(mechanism)
    scale = max(float(np.abs(rel).max(initial=0.0)), float(np.abs(mechanism).max(initial=0.0)), 1e-300)
    return states_from_relative(rel, model.friction, MOTION_TOLERANCE * scale, dilatant=dilatant), rel


def states_from_relative(rel: np.ndarray, friction: np.ndarray, tol: float, *, dilatant: bool) -> np.ndarray:
    """Joint states (see :func:`joint_states`) from relative velocities (m, point, (normal, tangent))."""
    slip = rel[:, :, 1].mean(axis=1)
    opening = rel[:, :, 0]
    if dilatant:
        opening = opening - friction[:, None] * np.abs(rel[:, :, 1])
    state = np.full(rel.shape[0], "rest", dtype=object)
    open_ends = (opening > tol).sum(axis=1)
    state[open_ends == 1] = "hinging"
    state[np.abs(slip) > tol] = "sliding"
    state[open_ends == 2] = "separating"
    return state


def mechanism_class(model: Model, mechanism: np.ndarray, states: np.ndarray) -> str:
    """'sliding' (translations only, joints slide or separate), 'rocking' (no joint slides), 'mixed', 'none'."""
    if not np.any(states != "rest"):
        return "none"
    rel_scale = max(float(np.abs(mechanism.reshape(-1, 3)[:, :2]).max(initial=0.0)), 1e-300)
    rotation = np.abs(mechanism.reshape(-1, 3)[:, 2]).max(initial=0.0)  # dimensionless: per length unit
    if not np.any(states == "sliding"):
        return "rocking"
    if not np.any(states == "hinging") and rotation <= MOTION_TOLERANCE * rel_scale:
        return "sliding"
    return "mixed"


def describe(model: Model, mechanism: np.ndarray, rel: np.ndarray | None = None) -> tuple[tuple[MacroBlock, ...], str]:
    """The moving macro-blocks of a mechanism and its class in the paper's words
    (:mod:`alma.results.macro_blocks`)."""
    if not model.n_joints or not np.any(mechanism):
        return (), "none"
    if rel is None:
        rel = ContactPoints.from_model(model).relative_velocities(mechanism)
    scale = max(float(np.abs(rel).max(initial=0.0)), float(np.abs(mechanism).max(initial=0.0)), 1e-300)
    bodies, klass = macro_blocks(model, mechanism, rel, MOTION_TOLERANCE * scale)
    ids = model.scene.block_ids
    out = tuple(
        MacroBlock(
            blocks=tuple(ids[model.free_blocks[i]] for i in b["members"]),
            motion=b["motion"],
            centre=b["centre"],
            direction=b["direction"],
        )
        for b in bodies
    )
    return out, klass


def multipliers_to_forces(model: Model, multipliers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, T) at each contact point from the cone multipliers μ± of Eq. 10 (N = μ⁺ + μ⁻,
    T = f (μ⁺ − μ⁻)), dimensionless."""
    mu = multipliers.reshape(-1, 2, 2)  # (m, point, ±)
    normal = mu.sum(axis=2).ravel()
    shear = ((mu[:, :, 0] - mu[:, :, 1]) * model.friction[:, None]).ravel()
    return normal, shear


@dataclass(frozen=True)
class Physical:
    """A solution in physical form: block motions, joints, mechanism class, moving macro-blocks."""

    blocks: tuple[BlockMotion, ...]
    joints: JointTable
    mechanism_class: str
    macro_blocks: tuple[MacroBlock, ...]


def physical(
    model: Model, mechanism: np.ndarray, normal: np.ndarray, shear: np.ndarray, moving: bool, *, dilatant: bool = False
) -> Physical:
    """Blocks, joints, mechanism class and macro-blocks of a solution (see the module docstring).

    ``moving``: the mechanism is a real one (else every joint is at rest, the class 'none' and
    no macro-block moves); ``dilatant``: it obeys the associative flow rule (:func:`joint_states`).
    Block motions are reported so that the weight-averaged displacement along the live load is
    1 mm: Σ (w_i / W) d·u_i = 1.
    """
    ids = model.scene.block_ids
    motion = mechanism.reshape(-1, 3) * model.n_free
    motion[:, 2] /= model.length_scale
    blocks = tuple(
        BlockMotion(id=ids[i], u=tuple(row)) for i, row in zip(model.free_blocks.tolist(), motion.tolist(), strict=True)
    )
    macros: tuple[MacroBlock, ...] = ()
    if moving and model.n_joints:
        states, rel = joint_states(model, mechanism, dilatant=dilatant)
        macros, klass = describe(model, mechanism, rel)
    else:
        states = np.full(model.n_joints, "rest", dtype=object)
        rel = np.zeros((model.n_joints, 2, 2))
        klass = "none"
    if model.crushes:
        states = _crushing_states(model, normal, states, rel)
    return Physical(blocks, _joint_table(model, normal, shear, states, rel), klass, macros)


def model_mechanism(model: Model, motions: np.ndarray) -> np.ndarray:
    """The mechanism vector of ``model`` (3 n_free, dimensionless) whose free blocks move as
    ``motions`` (n_blocks, 3) in the scene's block order, in :func:`physical`'s units (mm, rad):
    the inverse of its scaling, up to the normalisation f_Lᵀu = 1."""
    motion = np.array(motions, dtype=float)[model.free_blocks]
    motion[:, 2] *= model.length_scale
    return motion.ravel() / model.n_free


def _crushing_states(model: Model, normal: np.ndarray, states: np.ndarray, rel: np.ndarray) -> np.ndarray:
    """``states`` with ``crushing`` where a moving joint's stress block spans it (N ≥ σ_c l t up to
    :data:`CRUSHING_FRACTION`) or where the mechanism closes both its ends (the joint shortens
    over its whole length: the normal of the parabola at N = σ_c l t)."""
    N = normal.reshape(-1, 2).sum(axis=1)
    scale = max(float(np.abs(rel).max(initial=0.0)), 1e-300)
    closing = (rel[:, :, 0] < -MOTION_TOLERANCE * scale).all(axis=1)
    full = N >= CRUSHING_FRACTION * model.crushing
    out = states.copy()
    out[np.isfinite(model.crushing) & (closing | (full & (states != "rest")))] = "crushing"
    return out


def _joint_table(
    model: Model, normal: np.ndarray, shear: np.ndarray, states: np.ndarray, rel: np.ndarray
) -> JointTable:
    """The joints' forces (kN), moments about their centres (kN·mm) and motions as columns."""
    joints = model.joints
    n_point = normal.reshape(-1, 2) * model.force_scale  # (m, point) kN
    t_point = shear.reshape(-1, 2) * model.force_scale
    moment = np.zeros(model.n_joints)
    for p, point in enumerate((joints.start, joints.end)):
        r = point - joints.centre
        force = n_point[:, p, None] * joints.normal + t_point[:, p, None] * joints.tangent
        moment += r[:, 0] * force[:, 1] - r[:, 1] * force[:, 0]
    ids = np.asarray(model.scene.block_ids, dtype=object)
    pairs = np.stack([ids[np.asarray(joints.block_a, dtype=int)], ids[np.asarray(joints.block_b, dtype=int)]], axis=1)
    capacity, block = _stress_blocks(model, normal) if model.crushes else (None, None)
    return JointTable(
        blocks=pairs.reshape(-1, 2),
        N=n_point.sum(axis=1),
        T=t_point.sum(axis=1),
        M=moment,
        state=states.astype(str),
        length=np.asarray(joints.length, dtype=float),
        slip=rel[:, :, 1].mean(axis=1) * model.n_free,
        opening=rel[:, :, 0] * model.n_free,
        start=np.asarray(joints.start, dtype=float).reshape(-1, 2),
        end=np.asarray(joints.end, dtype=float).reshape(-1, 2),
        points=np.stack([n_point, t_point], axis=2),
        normal=np.asarray(joints.normal, dtype=float).reshape(-1, 2),
        capacity=capacity,
        stress_block=block,
    )


def _stress_blocks(model: Model, normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Capacity σ_c l t (kN) and the stress block's segment (m, 2, 2) mm of every joint.

    The resultant acts at N_end/N of the joint from its start (the points' tangential forces have
    no moment about the joint line); the block of extent N/(σ_c t), i.e. the fraction N/(σ_c l t)
    of the joint, is centred there.  NaN on joints without a strength or without a force.
    """
    joints = model.joints
    n_point = normal.reshape(-1, 2)
    N = n_point.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        where = np.where(N > 0, n_point[:, 1] / N, np.nan)
        half = 0.5 * N / model.crushing
    span = joints.end - joints.start
    lo = joints.start + (where - half)[:, None] * span
    hi = joints.start + (where + half)[:, None] * span
    block = np.stack([lo, hi], axis=1)
    block[~np.isfinite(model.crushing)] = np.nan
    return model.crushing * model.force_scale, block


def bounded_forces(
    model: Model, tau: np.ndarray, mechanism: np.ndarray
) -> tuple[np.ndarray, tuple[dict[str, float | str], ...]]:
    """The bounded forces (:mod:`alma.mechanics.forces`) in physical form.

    Returns the cohesive shear of each contact point (dimensionless, half of each joint's
    τ⁺ − τ⁻ at each of its two points: a shear along the joint line has no moment about its
    centre) and, for every tie, its id, force (kN) and elongation rate (mm per unit mechanism).
    """
    shear = np.zeros(2 * model.n_joints)
    labels = model.bounded_labels
    if not model.n_bounded:
        return shear, ()
    cohesive = np.array([str(x).startswith("j") for x in labels])
    if cohesive.any():
        joint = np.array([int(str(x)[1:-1]) for x in labels[cohesive]])
        sign = np.array([1.0 if str(x).endswith("+") else -1.0 for x in labels[cohesive]])
        net = np.zeros(model.n_joints)
        np.add.at(net, joint, sign * tau[cohesive])
        shear += np.repeat(0.5 * net, 2)
    assert model.bounded is not None  # called for a model with bounded forces only
    power = model.bounded.T @ mechanism if mechanism.size else np.zeros(model.n_bounded)
    ties: tuple[dict[str, float | str], ...] = tuple(
        {"id": str(x)[4:], "force": float(f * model.force_scale), "elongation": float(-p * model.n_free)}
        for x, f, p, c in zip(labels, tau, power, cohesive, strict=True)
        if not c
    )
    return shear, ties
