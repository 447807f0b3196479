"""What acts on the structure, drawn as an engineer would (issue 36): the live load's direction,
dead and live point loads (an overburden is a row of them), gravity on a tilted table, ties
with their forces and the settling supports' motions."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from alma.display_settings import PictureSettings
from alma.geometry.scene import Scene
from alma.report.marks import DEAD_COLOUR, LIVE_COLOUR, SETTLEMENT_COLOUR, TIE_COLOUR, Mark, arrow, label
from alma.report.numbers import number


def load_marks(
    scene: Scene,
    result: Any,
    size: float,
    s: PictureSettings,
    *,
    gravity_deg: float | None = None,
    settling: bool = False,
) -> list[Mark]:
    """Arrows and symbols of the loads, ties and settlements of ``scene`` (sizes from ``s`` as
    shares of the scene ``size``, mm).  ``gravity_deg``: the table's tilt (``alma tilt``), which
    replaces the live load's arrow by gravity's; ``settling``: draw the settlements (and no live
    load: a settlement has no α)."""
    length, font = s.arrow * size, s.font * size
    marks = []
    if gravity_deg is not None:
        marks += _side_arrow(
            scene,
            "gravity",
            _turn(scene.gravity, gravity_deg),
            length,
            font,
            f"gravity, table tilted {number(gravity_deg)}°",
        )
    elif scene.live_self_weight and not settling:
        marks += _side_arrow(scene, "live", scene.live_load_direction, length, font, "α × weight")
    marks += _point_loads(scene, length, font)
    marks += _ties(scene, result, font)
    if settling:
        marks += _settlements(scene, length, font)
    return marks


def _turn(direction: tuple[float, float], degrees: float) -> np.ndarray:
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    x, y = direction
    return np.array([c * x - s * y, s * x + c * y])


def _side_arrow(scene: Scene, cls: str, direction: Any, length: float, font: float, text: str) -> list[Mark]:
    """One arrow beside the structure, pointing at it along ``direction``, labelled."""
    d = np.asarray(direction, dtype=float)
    d = d / max(float(np.hypot(*d)), 1e-300)
    xy = np.concatenate([b.vertices for b in scene.blocks if not b.fixed] or [b.vertices for b in scene.blocks])
    low, high = xy.min(axis=0), xy.max(axis=0)
    centre = 0.5 * (low + high)
    half = 0.5 * (high - low)
    exits = half / np.maximum(np.abs(d), 1e-12)  # where the ray from the centre leaves the box
    reach = float(exits.min()) + 0.3 * length
    head = centre - reach * d
    tail = head - 1.5 * length * d
    colour = LIVE_COLOUR if cls == "live" else DEAD_COLOUR
    anchor = "end" if d[0] > 0.3 else "start" if d[0] < -0.3 else "middle"
    return [
        *arrow(cls, tail, head, colour, 0.35 * length, width=2.5),
        label(cls, tail + np.array([0.0, 0.5 * font]), text, font, colour=colour, anchor=anchor),
    ]


def _point_loads(scene: Scene, length: float, font: float) -> list[Mark]:
    """Each point load as an arrow ending at its point (length ∝ its force, at least a third of
    the largest), dead grey and live black; one label per kind with the total."""
    if not scene.loads:
        return []
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    marks = []
    for cls, colour, key in (("dead", DEAD_COLOUR, "dead"), ("live", LIVE_COLOUR, "live")):
        loads = [(ld, np.asarray(getattr(ld, key), dtype=float)) for ld in scene.loads]
        loads = [(ld, f) for ld, f in loads if np.hypot(*f) > 0]
        if not loads:
            continue
        largest = max(float(np.hypot(*f)) for _, f in loads)
        tails, carriers = [], []
        for ld, f in loads:
            i = index[ld.block]
            point = np.asarray(ld.point if ld.point is not None else scene.blocks[i].centroid, dtype=float)
            n = float(np.hypot(*f))
            tail = point - max(n / largest, 1 / 3) * length * f / n
            marks += arrow(
                cls,
                tail,
                point,
                colour,
                0.3 * length,
                carrier=(i,),
                width=1.0,
                title=f"{cls} load on {ld.block}: [{f[0]:.4g}, {f[1]:.4g}] kN",
            )
            tails.append(tail)
            carriers.append(i)
        at = np.array(tails)
        # the label rides above the highest tail (the one nearest the middle), with its block
        top = int(np.lexsort((np.abs(at[:, 0] - at[:, 0].mean()), -np.round(at[:, 1], 6)))[0])
        total = np.sum([f for _, f in loads], axis=0)
        words = "α × " if cls == "live" else ""
        marks.append(
            label(
                cls,
                np.array([at[:, 0].mean(), at[top, 1] + 0.5 * font]),
                f"{words}{len(loads)} point load{'s' if len(loads) > 1 else ''}, "
                f"total {number(float(np.hypot(*total)))} kN",
                font,
                colour=colour,
                carrier=(carriers[top],),
            )
        )
    return marks


def _ties(scene: Scene, result: Any, font: float) -> list[Mark]:
    """Each tie as a dashed line between its two points, labelled with its force (kN)."""
    forces = {t["id"]: t["force"] for t in getattr(result, "ties", ()) or ()}
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    marks = []
    for tie in scene.ties:
        xy = np.array([tie.from_point, tie.to_point], dtype=float)
        carrier = (index[tie.from_block], index[tie.to_block])
        f = forces.get(tie.id)
        f = 0.0 if f is not None and abs(f) < 1e-9 * tie.strength else f  # solver round-off reads 0
        force = f"{number(f)} kN of {number(tie.strength)}" if f is not None else f"{number(tie.strength)} kN"
        marks.append(
            Mark("line", "tie", xy, carrier, stroke=TIE_COLOUR, width=1.8, dash=True, title=f"tie {tie.id}: {force}")
        )
        marks.append(
            label(
                "tie",
                xy.mean(axis=0) + np.array([0.0, 0.4 * font]),
                f"{tie.id}: {force}",
                font,
                colour=TIE_COLOUR,
                carrier=carrier,
            )
        )
    return marks


def _settlements(scene: Scene, length: float, font: float) -> list[Mark]:
    """An arrow under each settling support along its translation (rotations in words), the
    label beyond the arrow's head, clear of the support."""
    marks = []
    for block in scene.blocks:
        s = block.settlement
        if s is None:
            continue
        d = np.asarray(s.translation, dtype=float)
        norm = float(np.hypot(*d))
        low = block.vertices.min(axis=0)
        start = np.array([block.centroid[0], low[1]]) if norm == 0 or d[1] <= 0 else block.centroid
        words = f"{block.id} settles {number(norm)} mm" + (f", turns {number(s.rotation)} rad" if s.rotation else "")
        if norm > 0:
            head = start + 1.2 * length * d / norm
            marks += arrow("settlement", start, head, SETTLEMENT_COLOUR, 0.35 * length, width=2.5, title=words)
        else:
            head = start
        below = norm > 0 and d[1] < -0.5 * norm
        at = head + (np.array([0.0, -1.2 * font]) if below else 0.5 * font * (d / norm if norm else np.zeros(2)))
        marks.append(
            label(
                "settlement",
                at,
                words,
                font,
                colour=SETTLEMENT_COLOUR,
                anchor="middle" if below or norm == 0 else "start" if d[0] >= 0 else "end",
            )
        )
    return marks
