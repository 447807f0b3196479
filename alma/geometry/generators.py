"""Generators of the structures users bring (SPEC §3 ``alma wall``, ``alma arch``).

- :func:`facade`: a bonded wall (any bond of :mod:`alma.geometry.panels`) with rectangular
  openings (windows, doors), a lintel over each (one block spanning the opening and a bearing on
  each side, one course high), the piers between them, and an optional overburden written as
  dead point loads on the top course;
- :func:`coursed_wall`: a wall laid course by course from a pattern of block lengths (gaps for
  openings), as the walls of the literature are drawn (Ferris & Tin-Loi's walls, LMGC90's and
  HybriDFEM's pattern walls);
- :func:`arch`: semicircular, segmental or pointed arches of any number of voussoirs with radial
  joints, on fixed abutments or on piers standing on a ground (a portal).

Lengths in mm, overburden in kPa.  Geometry only: the scene is validated like any other.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np

from alma.floats import dot
from alma.geometry import panels
from alma.geometry.loads import PointLoad
from alma.geometry.panels import BLOCK_HEIGHT, course_lengths
from alma.geometry.parsing import SceneError
from alma.geometry.scene import Block, Scene

KINDS = ("semicircular", "segmental", "pointed")


def facade(
    bond: str,
    width: float,
    height: float,
    block_length: float,
    block_height: float = BLOCK_HEIGHT,
    *,
    openings: Sequence[Sequence[float]] = (),
    bearing: float | None = None,
    overburden_kpa: float = 0.0,
    friction: float = 0.6,
    thickness: float = 120.0,
    unit_weight: float = 18.0,
    name: str | None = None,
) -> Scene:
    """A wall ``width`` × ``height`` on a fixed ground with ``openings`` (x, y, w, h) cut out.

    Openings must start and end on course lines; each gets a lintel in the course above it,
    ``bearing`` (default half a block) beyond each jamb.  ``overburden_kpa`` acts on the top
    course as a dead load q·t·l at the top centre of each of its blocks.
    """
    courses = int(round(height / block_height))
    if courses < 1 or abs(courses * block_height - height) > 1e-9 * height:
        raise SceneError(f"wall height {height} is not a whole number of courses of {block_height}")
    holes = _openings(openings, width, height, block_height)
    bearing = 0.5 * block_length if bearing is None else float(bearing)
    boxes: list[tuple[float, float, float, float]] = []
    lintels: list[tuple[float, float, float, float]] = []
    for course in range(courses):
        y0, y1 = course * block_height, (course + 1) * block_height
        x = np.concatenate([[0.0], np.cumsum(course_lengths(bond, block_length, width, course))])
        x[-1] = width
        cuts = [(hx, hx + hw) for hx, hy, hw, hh in holes if hy < y1 - 1e-9 and hy + hh > y0 + 1e-9]
        spans = [
            (max(0.0, hx - bearing), min(width, hx + hw + bearing))
            for hx, hy, hw, hh in holes
            if abs(hy + hh - y0) <= 1e-9 and hy + hh < height - 1e-9
        ]
        lintels += [(a, b, y0, y1) for a, b in spans]
        for x0, x1 in itertools.pairwise(x):
            for a, b in _subtract((x0, x1), cuts + spans):
                boxes.append((a, b, y0, y1))
    blocks = [Block(id="ground", vertices=_box(0.0, width, -block_height, 0.0), fixed=True)]
    blocks += [Block(id=f"b{k + 1}", vertices=_box(*box)) for k, box in enumerate(boxes)]
    blocks += [Block(id=f"lintel{k + 1}", vertices=_box(*box)) for k, box in enumerate(lintels)]
    loads = _overburden(blocks, overburden_kpa, thickness, height)
    return Scene(
        blocks=tuple(blocks),
        thickness=thickness,
        unit_weight=unit_weight,
        friction=friction,
        loads=loads,
        name=name or f"{bond} facade {width:g}x{height:g} with {len(holes)} opening(s)",
    )


def coursed_wall(
    courses: Sequence[Sequence[float]],
    block_length: float,
    block_height: float = BLOCK_HEIGHT,
    *,
    friction: float = 0.6,
    thickness: float = 120.0,
    unit_weight: float = 18.0,
    name: str | None = None,
) -> Scene:
    """A wall laid from ``courses`` (bottom course first) on a fixed ground as wide as the widest.

    Each course lists its pieces from the left in units of ``block_length``: a positive entry is a
    block of that length, a negative one a gap (an opening) of that length; every course is
    ``block_height`` high.  ``[[.5, 1, 1, .5], [1, 1, 1]]`` is a running bond three blocks wide.
    """
    if not courses:
        raise SceneError("coursed wall: give at least one course")
    if block_length <= 0 or block_height <= 0:
        raise SceneError(f"coursed wall: block length and height must be > 0 mm, got {block_length} x {block_height}")
    blocks = []
    width = 0.0
    for c, course in enumerate(courses):
        pieces = np.asarray(course, dtype=float).ravel()
        if pieces.size == 0 or not np.all(np.isfinite(pieces)) or np.any(pieces == 0):
            raise SceneError(
                f"coursed wall: course {c + 1} (from the bottom) needs non-zero finite lengths, got {list(course)}"
            )
        ends = np.concatenate([[0.0], np.cumsum(np.abs(pieces))]) * block_length
        solid = np.flatnonzero(pieces > 0)
        blocks += [
            Block(id=f"c{c + 1}b{k + 1}", vertices=_box(ends[i], ends[i + 1], c * block_height, (c + 1) * block_height))
            for k, i in enumerate(solid)
        ]
        width = max(width, float(ends[-1]))
    ground = Block(id="ground", vertices=_box(0.0, width, -block_height, 0.0), fixed=True)
    return Scene(
        blocks=(ground, *blocks),
        thickness=thickness,
        unit_weight=unit_weight,
        friction=friction,
        name=name or f"coursed wall, {len(courses)} courses",
    )


def arch(
    span: float,
    rise: float,
    thickness: float,
    voussoirs: int,
    *,
    kind: str = "semicircular",
    springing: str = "fixed",
    pier_height: float = 0.0,
    pier_width: float | None = None,
    pier_courses: int = 1,
    friction: float = 0.6,
    depth: float = 120.0,
    unit_weight: float = 18.0,
    name: str | None = None,
) -> Scene:
    """An arch of ``voussoirs`` blocks with radial joints; ``span`` and ``rise`` of its centre
    line, ``thickness`` radial (mm); ``depth`` the out-of-plane thickness of the scene.

    ``springing="fixed"``: the springing faces rest on fixed abutments; ``"piers"``: on two piers
    of ``pier_courses`` blocks (``pier_height`` × ``pier_width``) standing on a fixed ground.
    """
    if kind not in KINDS:
        raise SceneError(f"arch: kind must be one of {KINDS}, got {kind!r}")
    if not (span > 0 and rise > 0 and 0 < thickness and voussoirs >= 2):
        raise SceneError("arch: span, rise and thickness must be > 0 and voussoirs >= 2")
    if springing not in ("fixed", "piers"):
        raise SceneError(f"arch: springing must be 'fixed' or 'piers', got {springing!r}")
    faces = _radial_faces(span, rise, thickness, voussoirs, kind)
    blocks = [
        Block(id=f"v{k + 1}", vertices=_ccw(np.array([faces[k][0], faces[k][1], faces[k + 1][1], faces[k + 1][0]])))
        for k in range(voussoirs)
    ]
    width = pier_width if pier_width is not None else 1.5 * thickness
    if springing == "fixed":
        blocks += [
            _seat(faces[0], width, 2 * thickness, "abutment_right", fixed=True),
            _seat(faces[-1], width, 2 * thickness, "abutment_left", fixed=True),
        ]
    else:
        if not pier_height > 0:
            raise SceneError("arch: piers need pier_height > 0")
        blocks += _pier(faces[0], width, pier_height, pier_courses, "right")
        blocks += _pier(faces[-1], width, pier_height, pier_courses, "left")
        lo = min(float(b.vertices[:, 1].min()) for b in blocks)
        x = [float(b.vertices[:, 0].min()) for b in blocks] + [float(b.vertices[:, 0].max()) for b in blocks]
        blocks.append(Block(id="ground", vertices=_box(min(x) - width, max(x) + width, lo - thickness, lo), fixed=True))
    return Scene(
        blocks=tuple(blocks),
        thickness=depth,
        unit_weight=unit_weight,
        friction=friction,
        name=name or f"{kind} arch, span {span:g}, rise {rise:g}, t {thickness:g}, {voussoirs} voussoirs",
    )


def _radial_faces(span: float, rise: float, t: float, n: int, kind: str) -> list[np.ndarray]:
    """The n + 1 joint faces (intrados point, extrados point), right springing to left springing."""
    half = span / 2
    if kind == "semicircular":
        if abs(rise - half) > 1e-9 * span:
            raise SceneError(f"arch: a semicircular arch has rise = span / 2 = {half:g}, got {rise:g}")
        return _arc_faces((0.0, 0.0), half, t, 0.0, math.pi, n)
    if kind == "segmental":
        if not rise < half:
            raise SceneError(f"arch: a segmental arch has rise < span / 2 = {half:g}, got {rise:g}")
        radius = (half * half + rise * rise) / (2 * rise)
        opening = math.asin(half / radius)
        return _arc_faces((0.0, rise - radius), radius, t, math.pi / 2 - opening, math.pi / 2 + opening, n)
    if not rise > half:
        raise SceneError(f"arch: a pointed arch has rise > span / 2 = {half:g}, got {rise:g}")
    if n % 2:
        raise SceneError("arch: a pointed arch needs an even number of voussoirs (a vertical crown joint)")
    radius = (half * half + rise * rise) / span
    top = math.atan2(rise, half - (half - radius))  # crown angle seen from the right arc's centre
    right = _arc_faces((half - radius, 0.0), radius, t, 0.0, top, n // 2)
    right[-1] = _crown(half - radius, radius, t)
    left = [np.column_stack([-f[:, 0], f[:, 1]]) for f in reversed(right[:-1])]
    return right + left


def _arc_faces(centre, radius: float, t: float, a0: float, a1: float, n: int) -> list[np.ndarray]:
    angles = np.linspace(a0, a1, n + 1)
    c = np.asarray(centre, dtype=float)
    return [
        np.array(
            [
                c + (radius - t / 2) * np.array([math.cos(a), math.sin(a)]),
                c + (radius + t / 2) * np.array([math.cos(a), math.sin(a)]),
            ]
        )
        for a in angles
    ]


def _crown(cx: float, radius: float, t: float) -> np.ndarray:
    """The vertical crown face (x = 0) of a pointed arch's right arc."""
    return np.array(
        [[0.0, math.sqrt((radius - t / 2) ** 2 - cx * cx)], [0.0, math.sqrt((radius + t / 2) ** 2 - cx * cx)]]
    )


def _seat_line(face: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray]:
    """The two ends of the springing face's line, ``width`` long and centred on the face."""
    p, q = face
    d = (q - p) / np.hypot(*(q - p))
    mid = 0.5 * (p + q)
    return mid - d * width / 2, mid + d * width / 2


def _seat(face: np.ndarray, width: float, depth: float, name: str, *, fixed: bool) -> Block:
    """A block whose top edge is the line of a springing face, ``width`` wide around it."""
    a, b = _seat_line(face, width)
    bottom = min(a[1], b[1]) - depth
    return Block(id=name, vertices=_ccw(np.array([a, b, [b[0], bottom], [a[0], bottom]])), fixed=fixed)


def _pier(face: np.ndarray, width: float, height: float, courses: int, side: str) -> list[Block]:
    """A pier of ``courses`` blocks under a springing face; its top follows the face's line."""
    top = np.array(_seat_line(face, width))
    top = top[np.argsort(-top[:, 0])]  # right end first: the cap's outline runs counter-clockwise
    x0, x1 = float(top[1, 0]), float(top[0, 0])
    levels = np.linspace(float(top[:, 1].min()) - height, float(top[:, 1].min()), courses + 1)
    blocks = [
        Block(id=f"pier_{side}{k + 1}", vertices=_box(x0, x1, levels[k], levels[k + 1])) for k in range(courses - 1)
    ]
    cap = np.array([[x0, levels[-2]], [x1, levels[-2]], top[0], top[1]])
    blocks.append(Block(id=f"pier_{side}{courses}", vertices=_ccw(_dedupe(cap))))
    return blocks


def _openings(openings, width: float, height: float, course: float) -> list[tuple[float, float, float, float]]:
    holes = []
    for k, raw in enumerate(openings):
        if len(raw) != 4:
            raise SceneError(f"opening #{k + 1}: give x, y, w, h (mm), got {list(raw)}")
        x, y, w, h = (float(v) for v in raw)
        if not (w > 0 and h > 0 and x > 0 and x + w < width and y >= 0 and y + h <= height):
            raise SceneError(
                f"opening #{k + 1} ({x:g}, {y:g}, {w:g}, {h:g}): must lie inside the wall "
                f"(0 < x, x + w < {width:g}, 0 <= y, y + h <= {height:g}) with w, h > 0"
            )
        for edge in (y, y + h):
            if abs(edge / course - round(edge / course)) > 1e-9:
                raise SceneError(f"opening #{k + 1}: y = {edge:g} is not on a course line (courses of {course:g})")
        holes.append((x, y, w, h))
    for i, a in enumerate(holes):
        for j, b in enumerate(holes[:i]):
            if (
                a[0] < b[0] + b[2]
                and b[0] < a[0] + a[2]
                and a[1] < b[1] + b[3] + course
                and b[1] < a[1] + a[3] + course
            ):
                raise SceneError(f"openings #{j + 1} and #{i + 1} overlap or leave no course between them")
    return holes


def _subtract(span: tuple[float, float], cuts: list[tuple[float, float]]) -> list[tuple[float, float]]:
    pieces = [span]
    for a, b in cuts:
        pieces = [p for lo, hi in pieces for p in ((lo, min(hi, a)), (max(lo, b), hi)) if p[1] - p[0] > 1e-9]
    return pieces


def _overburden(blocks: list[Block], q: float, thickness: float, height: float) -> tuple[PointLoad, ...]:
    if q < 0:
        raise SceneError(f"overburden must be >= 0 kPa, got {q}")
    if q == 0:
        return ()
    top = [b for b in blocks if not b.fixed and abs(float(b.vertices[:, 1].max()) - height) <= 1e-9]
    return tuple(
        PointLoad(
            block=b.id,
            point=(float(b.vertices[:, 0].mean()), height),
            dead=(0.0, -q * thickness * float(np.ptp(b.vertices[:, 0])) * 1e-6),
        )
        for b in top
    )


def _box(x0: float, x1: float, y0: float, y1: float) -> np.ndarray:
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)


def _ccw(v: np.ndarray) -> np.ndarray:
    x, y = v[:, 0], v[:, 1]
    return v if dot(x, np.roll(y, -1)) - dot(np.roll(x, -1), y) >= 0 else v[::-1].copy()


def _dedupe(v: np.ndarray) -> np.ndarray:
    keep = np.hypot(*(v - np.roll(v, 1, axis=0)).T) > 1e-9
    return v[keep]


def wall(
    bond: str,
    panel_length: float,
    panel_height: float,
    block_length: float,
    block_height: float = BLOCK_HEIGHT,
    *,
    openings: Sequence[Sequence[float]] = (),
    overburden_kpa: float = 0.0,
    bearing: float | None = None,
    **options,
) -> Scene:
    """``alma.wall``: the bonded wall of :func:`alma.geometry.panels.wall`, or, with ``openings``
    or an ``overburden_kpa``, the :func:`facade` with them."""
    if not openings and not overburden_kpa:
        return panels.wall(bond, panel_length, panel_height, block_length, block_height, **options)
    return facade(
        bond,
        panel_length,
        panel_height,
        block_length,
        block_height,
        openings=openings,
        bearing=bearing,
        overburden_kpa=overburden_kpa,
        **options,
    )
