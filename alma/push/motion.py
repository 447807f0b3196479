"""Finite rigid motions of blocks along a collapse mechanism, and the contacts they keep.

A mechanism of the limit analysis is a velocity field: its moving macro-blocks (bodies) turn
about instantaneous centres.  A finite step turns each body about its centre by the finite
angle ω s (the *predictor*, not the linearised displacement u s), then a Newton *corrector*
(:mod:`alma.push.corrector`) moves the bodies so that every contact point that the mechanism
keeps closed stays closed to round-off: the hinges (no relative velocity: both bodies meet at the point) and the sliding
points (the normal gap stays zero; the associative model's dilatancy is a property of its
flow rule, not a motion of the masonry, so the finite step does not lift a sliding block).
One more equation fixes the control block's horizontal displacement.  For a linkage (a portal
frame's four hinges) this follows the linkage's exact path, which proportional rotations about
the first centres would leave at second order.

Contacts after the step: :func:`alma.geometry.contacts.find_joints` on the displaced geometry
(the flat joints: those that stayed flat, and new flat contacts), plus the contact points of the
previous configuration that stayed closed (|T_a(p) − T_b(p)| ≤ the contact tolerance over the
step, and the point, at the corner where one block has it, within the tolerance of both displaced
outlines: a gap is measured on the geometry, not summed step by step) and are not on a flat
joint: the hinge about which a joint turned becomes a point contact (start = end),
whose normal is the face's that the other block's corner bears on (the bisector when two
corners meet).  A joint with a finite compressive strength turns about its *crushing hinge*
(the end its stress block presses in, :func:`classify`) and keeps its length on that face,
ending at the hinge, so that its capacity σ_c l t stays and the stress block forms at the hinge
(docs/decisions.md).  Lengths in mm, angles in rad; everything is vectorised over blocks and joints.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from alma.geometry.contacts import Joints, block_areas_and_centroids, find_joints
from alma.geometry.corners import covered, outline_distances, padded_outlines
from alma.geometry.edges import contact_lengths, scene_edges
from alma.geometry.scene import Scene
from alma.push.carried import carry, moved_loads, moved_ties
from alma.results.joints import MOTION_TOLERANCE
from alma.results.types import Result


class MotionError(RuntimeError):
    """The corrector (:mod:`alma.push.corrector`) could not keep the mechanism's contacts closed
    over the step."""


@dataclass(frozen=True)
class Pose:
    """Each block's rigid motion from the original scene: x = R(angle)(X − G₀) + G₀ + shift."""

    angle: np.ndarray  # (n,) rad, counter-clockwise
    shift: np.ndarray  # (n, 2) mm, the displacement of each block's original centroid

    @classmethod
    def rest(cls, n: int) -> Pose:
        return cls(np.zeros(n), np.zeros((n, 2)))


@dataclass(frozen=True)
class Bodies:
    """The moving macro-blocks of a mechanism: body index per block (−1: at rest or fixed), a
    reference point per body (mm), its rotation rate ω and the velocity at that point
    (per unit mechanism)."""

    of_block: np.ndarray  # (n,) int
    centre: np.ndarray  # (g, 2)
    omega: np.ndarray  # (g,)
    velocity: np.ndarray  # (g, 2)

    @property
    def count(self) -> int:
        return int(self.omega.shape[0])

    def velocity_at(self, blocks: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Velocity of ``blocks`` (rows, scene indices) at ``points``; zero for blocks at rest."""
        g = self.of_block[blocks]
        moving = g >= 0
        if self.count == 0:
            return np.zeros_like(points, dtype=float)
        gg = np.where(moving, g, 0)
        r = points - self.centre[gg]
        v = self.velocity[gg] + self.omega[gg, None] * np.column_stack([-r[:, 1], r[:, 0]])
        return np.where(moving[:, None], v, 0.0)


@dataclass(frozen=True)
class Contacts:
    """The contact points of a configuration sorted by what the mechanism does to them."""

    a: np.ndarray  # (p,) scene index of block a
    b: np.ndarray  # (p,) scene index of block b
    point: np.ndarray  # (p, 2) mm
    normal: np.ndarray  # (p, 2) from a into b
    hinge: np.ndarray  # (p,) bool: no relative velocity, two different bodies
    sliding: np.ndarray  # (p,) bool: tangential relative velocity, the normal one only dilatancy
    friction: np.ndarray  # (p,) the joint's friction coefficient
    crushing: np.ndarray  # (p,) bool: the joint has a finite compressive strength σ_c


def displaced(scene: Scene, pose: Pose) -> Scene:
    """``scene`` with every block moved by ``pose`` (a validated geometry stays valid: no check).

    A point load's point moves with its block (a carried floor, a vault's thrust stay where they
    act on the block); the forces keep their directions (gravity, the horizontal action).  A
    tie's end points move with their blocks, so its line and lever arms follow the displaced
    geometry (:mod:`alma.push.carried`; whether it is slack is the curve's history, not the pose's).
    """
    origin = _centroids(scene)
    moved, rows = outlines(scene, pose, origin)
    parts = np.split(moved, np.cumsum(np.bincount(rows, minlength=len(scene.blocks)))[:-1])
    blocks = tuple(dataclasses.replace(b, vertices=v) for b, v in zip(scene.blocks, parts, strict=True))
    return dataclasses.replace(
        scene,
        blocks=blocks,
        loads=moved_loads(scene, pose.angle, pose.shift, origin),
        ties=moved_ties(scene, pose.angle, pose.shift, origin),
        validated=True,
    )


def outlines(scene: Scene, pose: Pose, origin: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The blocks' outlines moved by ``pose``: their vertices (V, 2) mm one block after the other,
    and the block of each (V,); ``origin``: the blocks' centroids in ``scene`` when known."""
    origin = _centroids(scene) if origin is None else origin
    counts = np.array([len(b.vertices) for b in scene.blocks])
    rows = np.repeat(np.arange(counts.size), counts)
    return carry(np.concatenate([b.vertices for b in scene.blocks]), rows, pose.angle, pose.shift, origin), rows


def bodies_of(scene: Scene, result: Result) -> Bodies:
    """The moving macro-blocks of ``result`` (a solve of ``scene``) as rigid velocity fields."""
    index = {block.id: i for i, block in enumerate(scene.blocks)}
    n = len(scene.blocks)
    of_block = np.full(n, -1)
    for group, macro in enumerate(result.macro_blocks):
        of_block[[index[k] for k in macro.blocks]] = group
    count = len(result.macro_blocks)
    u = block_motions(scene, result)
    centroid = _centroids(scene)
    members = np.flatnonzero(of_block >= 0)
    g = of_block[members]
    size = np.bincount(g, minlength=count).astype(float)
    centre = np.column_stack([np.bincount(g, centroid[members, i], count) for i in (0, 1)]) / size[:, None]
    omega = np.bincount(g, u[members, 2], count) / size
    r = centre[g] - centroid[members]
    v = u[members, :2] + u[members, 2, None] * np.column_stack([-r[:, 1], r[:, 0]])
    velocity = np.column_stack([np.bincount(g, v[:, i], count) for i in (0, 1)]) / size[:, None]
    return Bodies(of_block, centre, omega, velocity)


def block_motions(scene: Scene, result: Result) -> np.ndarray:
    """The motion (u_x, u_y, ω) of every block of ``scene`` in ``result``'s mechanism, in the
    scene's block order (mm, rad; zero for the supports)."""
    index = {block.id: i for i, block in enumerate(scene.blocks)}
    u = np.zeros((len(scene.blocks), 3))
    rows = [index[b.id] for b in result.blocks]
    u[rows] = np.array([b.u for b in result.blocks], dtype=float).reshape(-1, 3)
    return u


def classify(joints: Joints, bodies: Bodies, friction: np.ndarray, crushing: np.ndarray | None = None) -> Contacts:
    """Every contact point of ``joints`` as a hinge, a sliding point or neither (it opens).

    ``crushing`` (m,) bool marks the joints with a finite compressive strength.  Their rocking
    turns about the inner edge of the stress block (Eq. 10's flow rule on the parabola of
    docs/compressive.md), so the end point at the stress block moves into the other block while
    the far end opens: that end point is the joint's *crushing hinge*, kept closed over a finite
    step as a hinge is (the rigid geometry neglects the crushed zone's own deformation).
    """
    a = np.repeat(joints.block_a, 2)
    b = np.repeat(joints.block_b, 2)
    point = np.stack([joints.start, joints.end], axis=1).reshape(-1, 2)
    normal = np.repeat(joints.normal, 2, axis=0)
    rel = bodies.velocity_at(b, point) - bodies.velocity_at(a, point)
    # the bodies' own speeds set the scale: a structure standing on one hinge has no other
    # relative velocity to compare with
    scale = max(float(np.abs(rel).max(initial=0.0)), float(np.abs(bodies.velocity).max(initial=0.0)), 1e-300)
    tol = MOTION_TOLERANCE * scale
    v_n = (rel * normal).sum(axis=1)
    v_t = np.abs(rel[:, 0] * normal[:, 1] - rel[:, 1] * normal[:, 0])
    apart = bodies.of_block[a] != bodies.of_block[b]
    hinge = apart & (np.hypot(rel[:, 0], rel[:, 1]) <= tol)
    crush = np.zeros(a.size, dtype=bool) if crushing is None else np.repeat(np.asarray(crushing, dtype=bool), 2)
    # a crushing hinge: this end presses in without slip while the joint's other end opens
    other = np.arange(a.size) ^ 1
    hinge |= crush & apart & (v_n < -tol) & (v_t <= tol) & (v_n[other] > tol)
    f = np.repeat(friction, 2)
    sliding = apart & ~hinge & (v_t > tol) & (v_n <= f * v_t * (1 + 1e-6) + tol)
    return Contacts(a, b, point, normal, hinge, sliding, f, crush)


def signature(scene: Scene, result: Result, contacts: Contacts) -> tuple:
    """What identifies a mechanism across configurations: its macro-blocks (members and kind of
    motion) and the block pairs it hinges or slides on (ids, so independent of block order)."""
    ids = np.asarray(scene.block_ids, dtype=object)
    macros = frozenset((frozenset(m.blocks), m.motion) for m in result.macro_blocks)
    pairs = lambda keep: frozenset(  # noqa: E731
        tuple(sorted(p)) for p in zip(ids[contacts.a[keep]].tolist(), ids[contacts.b[keep]].tolist(), strict=True)
    )
    return macros, pairs(contacts.hinge), pairs(contacts.sliding)


def predictor(bodies: Bodies, s: float) -> np.ndarray:
    """Increments (angle, shift of the body's centre) turning each body about its instantaneous
    centre by the finite angle ω s; a translating body (ω = 0) moves by v s.  Shape (g, 3)."""
    theta = bodies.omega * s
    half = 0.5 * theta
    a = s * half * np.sinc(half / np.pi) ** 2  # s (1 − cos θ)/θ, stable at θ = 0
    b = s * np.sinc(theta / np.pi)  # s sin θ / θ
    vx, vy = bodies.velocity[:, 0], bodies.velocity[:, 1]
    # (R(θ) − I)(c − q) with c − q = (v_y, −v_x)/ω, written with the two stable ratios above
    shift = np.column_stack([b * vx - a * vy, a * vx + b * vy])
    return np.column_stack([theta, shift])


def advance(pose: Pose, scene0: Scene, bodies: Bodies, z: np.ndarray) -> Pose:
    """The pose after moving each body by its increment ``z`` (angle, centre shift)."""
    g = bodies.of_block
    moving = g >= 0
    gg = np.where(moving, g, 0)
    origin = _centroids(scene0)
    current = origin + pose.shift
    new = _transform(current, z[gg, 0], bodies.centre[gg], z[gg, 1:])
    angle = np.where(moving, pose.angle + z[gg, 0], pose.angle)
    shift = np.where(moving[:, None], new - origin, pose.shift)
    return Pose(angle, shift)


def joints_after(scene: Scene, contacts: Contacts, bodies: Bodies, z: np.ndarray) -> Joints:
    """The joints of the displaced ``scene``: its flat contacts plus the previous contact points
    that stayed closed and lie on none of them (see the module docstring)."""
    found = find_joints(scene)
    snap, _ = contact_lengths(scene, scene_edges(scene))
    pa = _moved(bodies, z, contacts.a, contacts.point)
    pb = _moved(bodies, z, contacts.b, contacts.point)
    gap = pb - pa
    drawn = padded_outlines(scene)
    corner_a, corner_b = _at_vertex(drawn, contacts.a, pa, snap), _at_vertex(drawn, contacts.b, pb, snap)
    # a corner that slid on a face is where the contact is (the midpoint would leave the face)
    point = np.where(
        (corner_b & ~corner_a)[:, None], pb, np.where((corner_a & ~corner_b)[:, None], pa, 0.5 * (pa + pb))
    )
    # ... and it is a contact while it lies on both outlines: the copies' drift over one step
    # alone would let a gap grow a tolerance per step
    on_both = np.maximum(outline_distances(drawn, contacts.a, point)[0], outline_distances(drawn, contacts.b, point)[0])
    closed = (np.hypot(*gap.T) <= snap) & ((on_both <= snap) | contacts.crushing)
    # a sliding point stays a contact where it opened by no more than the associative dilatancy
    normal = contacts.normal
    opening = (gap * normal).sum(axis=1)
    slip = np.abs(gap[:, 0] * normal[:, 1] - gap[:, 1] * normal[:, 0])
    closed |= contacts.sliding & (opening <= contacts.friction * slip + snap)
    closed &= (bodies.of_block[contacts.a] >= 0) | (bodies.of_block[contacts.b] >= 0)
    found = _without_carried_corners(found, contacts.a[closed], contacts.b[closed], 0.5 * (pa + pb)[closed], snap)
    closed &= ~covered(found, contacts.a, contacts.b, 0.5 * (pa + pb), snap)
    if not closed.any():
        return found
    keep = np.flatnonzero(closed)
    point = point[keep]
    normal = _hinge_normal(bodies, z, contacts, keep, corner_a[keep], corner_b[keep])
    a, b = contacts.a[keep], contacts.b[keep]
    # one joint per pair of closed points of one previous joint, else a point contact
    joint = keep // 2
    pair = np.flatnonzero(np.diff(joint) == 0)
    single = np.ones(keep.size, dtype=bool)
    single[pair] = single[pair + 1] = False
    first = np.concatenate([pair, np.flatnonzero(single)])
    last = np.concatenate([pair + 1, np.flatnonzero(single)])
    end_point = point[last].copy()
    single_at = np.flatnonzero(single)
    end_point[pair.size :] = _crushing_segment(contacts, keep[single_at], point[single_at], normal[single_at])
    block_a = np.concatenate([found.block_a, a[first]])
    block_b = np.concatenate([found.block_b, b[first]])
    start = np.concatenate([found.start, point[first]])
    end = np.concatenate([found.end, end_point])
    normals = np.concatenate([found.normal, normal[first]])
    order = np.lexsort((start[:, 1], start[:, 0], block_b, block_a))
    return Joints(
        block_a=block_a[order], block_b=block_b[order], start=start[order], end=end[order], normal=normals[order]
    )


def face_first(scene: Scene, contacts: Contacts) -> Contacts:
    """``contacts`` with each corner-on-face point written from the face's block (a) to the
    corner's (b), normal flipped where that swaps them: the corrector turns a sliding point's
    normal with block a, so that a corner sliding on a face keeps the face's normal whichever
    block the scene lists first."""
    if contacts.a.size == 0:
        return contacts
    snap, _ = contact_lengths(scene, scene_edges(scene))
    drawn = padded_outlines(scene)
    swap = _at_vertex(drawn, contacts.a, contacts.point, snap) & ~_at_vertex(drawn, contacts.b, contacts.point, snap)
    if not swap.any():
        return contacts
    a, b = np.where(swap, contacts.b, contacts.a), np.where(swap, contacts.a, contacts.b)
    return dataclasses.replace(contacts, a=a, b=b, normal=np.where(swap[:, None], -contacts.normal, contacts.normal))


def _crushing_segment(contacts: Contacts, kept: np.ndarray, point: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """The far end of the joint a kept contact point becomes: the point itself (a point contact)
    for infinitely strong blocks; for a crushing joint, the point at the previous joint's length
    from it along the bearing face, towards where the joint lay (docs/decisions.md: the material
    under a crushing hinge is the joint's own, so the turned joint keeps its length, and its
    capacity σ_c l t, on the face the hinge bears on)."""
    crush = contacts.crushing[kept]
    if not crush.any():
        return point
    partner = contacts.point[kept ^ 1] - contacts.point[kept]
    length = np.hypot(partner[:, 0], partner[:, 1])
    face = _perp(normal)
    sense = np.where((partner * face).sum(axis=1) < 0, -1.0, 1.0)
    return np.where(crush[:, None], point + (sense * length)[:, None] * face, point)


# ---------------------------------------------------------------- helpers
def _centroids(scene: Scene) -> np.ndarray:
    return block_areas_and_centroids(scene)[1]


def _rotate(v: np.ndarray, angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.column_stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]])


def _perp(v: np.ndarray) -> np.ndarray:
    return np.column_stack([-v[:, 1], v[:, 0]])


def _transform(x: np.ndarray, angle: np.ndarray, centre: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """x ↦ R(angle)(x − centre) + centre + shift, row by row."""
    return _rotate(x - centre, angle) + centre + shift


def _moved(bodies: Bodies, z: np.ndarray, blocks: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``points`` carried by the increments of the bodies of ``blocks`` (at rest: unmoved)."""
    g = bodies.of_block[blocks]
    moving = g >= 0
    gg = np.where(moving, g, 0)
    if bodies.count == 0:
        return points.copy()
    out = _transform(points, z[gg, 0], bodies.centre[gg], z[gg, 1:])
    return np.where(moving[:, None], out, points)


def _without_carried_corners(found: Joints, a: np.ndarray, b: np.ndarray, points: np.ndarray, snap: float) -> Joints:
    """``found`` without its corner contacts (joints of zero length) at a carried contact point:
    the carried point keeps its history (a hinge's normal, a crushing joint's bearing length)."""
    corner = found.length == 0
    if not corner.any() or a.size == 0:
        return found
    carried = Joints(np.minimum(a, b), np.maximum(a, b), points, points, np.zeros_like(points))
    drop = np.zeros(found.count, dtype=bool)
    at = np.flatnonzero(corner)
    drop[at] = covered(carried, found.block_a[at], found.block_b[at], found.start[at], snap)
    keep = ~drop
    return Joints(
        found.block_a[keep], found.block_b[keep], found.start[keep], found.end[keep], found.normal[keep], found.warnings
    )


def _hinge_normal(
    bodies: Bodies, z: np.ndarray, contacts: Contacts, keep: np.ndarray, corner_a: np.ndarray, corner_b: np.ndarray
) -> np.ndarray:
    """The normal of each kept point contact after the step: the face's of the block the other's
    corner bears on (``corner_a``, ``corner_b``: the point is a corner of that block after the
    step); the bisector of the two turned normals where two corners meet."""
    a, b, n = contacts.a[keep], contacts.b[keep], contacts.normal[keep]
    angle = lambda blocks: np.where(  # noqa: E731
        bodies.of_block[blocks] >= 0, z[np.maximum(bodies.of_block[blocks], 0), 0] if bodies.count else 0.0, 0.0
    )
    na, nb = _rotate(n, angle(a)), _rotate(n, angle(b))
    bisector = na + nb
    bisector /= np.hypot(bisector[:, 0], bisector[:, 1])[:, None]
    out = np.where((corner_b & ~corner_a)[:, None], na, bisector)
    return np.where((corner_a & ~corner_b)[:, None], nb, out)


def _at_vertex(drawn: np.ndarray, blocks: np.ndarray, points: np.ndarray, snap: float) -> np.ndarray:
    """Per point: it is within ``snap`` of a vertex of its block (``drawn``: the displaced scene's
    :func:`alma.geometry.corners.padded_outlines`)."""
    return outline_distances(drawn, blocks, points)[1] <= snap
