"""One picture of a mechanism for both renderers (issue 36): :func:`draw` turns a scene and a
result into a :class:`Drawing` (marks at rest, the motion that displaces them, the box that fits
them); :mod:`alma.report.svg` and :mod:`alma.report.mpl` draw it the same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from alma.display_settings import PictureSettings
from alma.geometry.scene import Scene
from alma.report.load_marks import load_marks
from alma.report.marks import LEGEND, MOVING_FILL, REST_FILL, STATE_COLOURS, SUPPORT_FILL, Mark
from alma.report.mechanism_marks import mechanism_marks, tint
from alma.report.motion import Motion, joint_arrays
from alma.status import SOLVED


@dataclass(frozen=True)
class Drawing:
    """Marks (mm, at rest), the ``motion`` that displaces them (scaled so that the fastest point
    moves ``displacement`` × the scene size), the scene ``size`` (mm, its largest extent) and the
    ``box`` (xmin, ymin, xmax, ymax; mm) that holds every displaced mark with a margin."""

    marks: tuple[Mark, ...]
    motion: Motion
    size: float
    box: tuple[float, float, float, float]
    moving: int  # blocks that move (the header's count)

    def placed(self, mark: Mark) -> np.ndarray:
        """The mark's points where the picture draws them (displaced with their carrier)."""
        return self.motion.carry(mark.carrier, mark.xy)

    def classes(self) -> list[str]:
        """The mark classes the drawing uses, in the legend's order."""
        used = {m.cls for m in self.marks}
        return [c for c in LEGEND if c in used]


def draw(
    scene: Scene,
    result: Any,
    *,
    thrust: bool = True,
    macro_blocks: bool = True,
    settling: bool = False,
    gravity_deg: float | None = None,
    settings: PictureSettings | None = None,
) -> Drawing:
    """The drawing of ``result`` (a solve, settle or kept result) on ``scene``.

    Blocks displaced along the mechanism (supports hatched, moving blocks tinted by their rigid
    part), joints by state, the crack, rigid parts, hinges and rotation centres
    (:func:`~alma.report.mechanism_marks.mechanism_marks`), the line of thrust (``thrust``; a
    renderer may hide it), loads, ties and settlements (:func:`~alma.report.load_marks.load_marks`).
    ``settling`` moves the settling supports by their settlement (``alma settle``);
    ``gravity_deg`` draws gravity turned by that angle (``alma tilt``).
    """
    s = settings or PictureSettings()
    xy = np.concatenate([b.vertices for b in scene.blocks])
    size = float(np.ptp(xy, axis=0).max())
    motion = Motion.of(scene, result, settling=settling)
    speeds = motion.speeds(scene)
    peak = float(speeds.max()) if speeds.size else 0.0
    solved = str(result.status) in SOLVED or (settling and str(result.status) == "optimal")
    scale = s.displacement * size / peak if solved and peak > 0 else 0.0
    motion = motion.scaled(scale)
    share = speeds / peak if peak > 0 else speeds
    overlay, colour_of = (
        mechanism_marks(scene, result, motion, share, thrust=thrust, macro_blocks=macro_blocks, settings=s)
        if scale > 0
        else ([], {})
    )
    marks = _blocks(scene, result, share, colour_of, s) + _joints(result, motion, size, crack_drawn=bool(colour_of))
    marks += overlay + load_marks(scene, result, size, s, gravity_deg=gravity_deg, settling=settling)
    moving = int(np.count_nonzero(share >= s.moving)) if scale > 0 else 0
    drawing = Drawing(tuple(marks), motion, size, (0.0, 0.0, 0.0, 0.0), moving)
    return Drawing(drawing.marks, motion, size, _box(drawing, s.margin * size), moving)


def _blocks(scene: Scene, result: Any, share: np.ndarray, colour_of: dict[int, str], s: PictureSettings) -> list[Mark]:
    """One polygon per block: supports hatched, blocks at rest pale, moving blocks tinted."""
    motion = {m.id: m.u for m in result.blocks}
    marks = []
    for i, b in enumerate(scene.blocks):
        if b.fixed:
            cls, fill = "support", SUPPORT_FILL
        elif share[i] >= s.moving:
            cls, fill = "block-moving", tint(colour_of[i]) if i in colour_of else MOVING_FILL
        else:
            cls, fill = "block-rest", REST_FILL
        u = motion.get(b.id)
        title = (
            f"block {b.id}"
            + (" (support)" if b.fixed else "")
            + (f": u = {u[0]:.4g} mm, v = {u[1]:.4g} mm, θ = {u[2]:.4g} rad" if u is not None and not b.fixed else "")
        )
        marks.append(
            Mark(
                "polygon",
                cls,
                np.asarray(b.vertices, dtype=float),
                (i,),
                stroke="#444444",
                fill=fill,
                width=0.4,
                hatch=b.fixed,
                title=title,
            )
        )
    return marks


def _joints(result: Any, motion: Motion, size: float, *, crack_drawn: bool) -> list[Mark]:
    """The joints that move, coloured by state, midway between their two displaced sides; thin
    under a drawn crack.  A crushing joint also gets a star at its middle."""
    joints = [j for j in result.joints if j.state != "rest"]
    if not joints:
        return []
    ends = joint_arrays(motion, joints)
    marks = []
    for k, j in enumerate(joints):
        carrier = (int(ends["a"][k]), int(ends["b"][k]))
        colour = STATE_COLOURS.get(j.state, "#000000")
        cls = "crushing" if j.state == "crushing" else f"joint-{j.state}" if f"joint-{j.state}" in LEGEND else "crack"
        xy = np.array([ends["start"][k], ends["end"][k]])
        marks.append(
            Mark("line", cls, xy, carrier, stroke=colour, width=0.8 if crack_drawn else 1.6, title=_joint_text(j))
        )
        if j.state == "crushing":
            marks.append(
                Mark(
                    "point",
                    "crushing",
                    xy.mean(axis=0, keepdims=True),
                    carrier,
                    stroke=colour,
                    fill=colour,
                    size=0.012 * size,
                    text="*",
                    title=_joint_text(j),
                )
            )
    return marks


def _joint_text(j: Any) -> str:
    a, b = getattr(j, "blocks", ("?", "?"))
    text = f"joint {a} | {b} ({j.state})"
    if hasattr(j, "N"):
        text += (
            f": N = {j.N:.4g} kN, T = {j.T:.4g} kN, M = {j.M:.4g} kN·mm, slip {j.slip:.3g} mm, length {j.length:.4g} mm"
        )
    return text


def _box(drawing: Drawing, margin: float) -> tuple[float, float, float, float]:
    """The smallest box holding every displaced mark (letters by their estimated extent) and the
    block vertices at rest, grown by ``margin`` mm each side."""
    points = []
    for m in drawing.marks:
        xy = drawing.placed(m)
        if m.kind == "text":
            width = 0.55 * m.size * len(m.text)
            left = {"start": 0.0, "middle": -0.5, "end": -1.0}[m.anchor] * width
            xy = xy + np.array([[left, -0.3 * m.size], [left + width, 1.0 * m.size]])
        elif m.kind == "point":
            xy = xy + np.array([[-m.size, -m.size], [m.size, m.size]])
        points.append(xy)
    xy = np.concatenate(points)
    low, high = xy.min(axis=0) - margin, xy.max(axis=0) + margin
    return float(low[0]), float(low[1]), float(high[0]), float(high[1])
