"""The mechanism as an engineer sketches it (issues 19, 36): the crack, the rigid parts outlined
in colours of their own, hinges and rotation centres, translations; and the line of thrust."""

from __future__ import annotations

from typing import Any

import numpy as np
from shapely import Polygon, unary_union

from alma.display_settings import PictureSettings
from alma.geometry.scene import Scene
from alma.report.marks import MACRO_COLOURS, THRUST_COLOUR, Mark, arrow
from alma.report.motion import Motion, joint_arrays


def mechanism_marks(
    scene: Scene,
    result: Any,
    motion: Motion,
    share: np.ndarray,
    *,
    thrust: bool,
    macro_blocks: bool,
    settings: PictureSettings,
) -> tuple[list[Mark], dict[int, str]]:
    """The crack, outlines, hinges, centres and translations of ``result``'s macro-blocks (when
    ``macro_blocks``) and the line of thrust (when ``thrust``), with the colour of each block
    of an outlined macro-block (scene index → colour).  ``share``: each block's speed relative
    to the fastest."""
    size = float(np.ptp(np.concatenate([b.vertices for b in scene.blocks]), axis=0).max())
    marks: list[Mark] = []
    colour_of: dict[int, str] = {}
    macro = tuple(getattr(result, "macro_blocks", ()) or ()) if macro_blocks else ()
    if macro:
        crack, cracked = _crack(scene, result, motion, macro, settings.slow)
        hinges = _hinges(result, motion, cracked, size)
        marks += crack
        marks += _parts(
            scene, macro, motion, share, np.array([h.xy[0] for h in hinges]).reshape(-1, 2), size, settings, colour_of
        )
        marks += hinges
    if thrust:
        marks += thrust_marks(result, motion, size, np.array([b.fixed for b in scene.blocks], dtype=bool))
    return marks, colour_of


def tint(colour: str, amount: float = 0.7) -> str:
    """``colour`` mixed with ``amount`` of white (a block's fill in its part's colour)."""
    rgb = np.array([int(colour[k : k + 2], 16) for k in (1, 3, 5)], dtype=float)
    r, g, b = np.round(rgb + amount * (255.0 - rgb)).astype(int)
    return f"#{r:02x}{g:02x}{b:02x}"


def _crack(scene: Scene, result: Any, motion: Motion, macro: tuple, slow: float) -> tuple[list[Mark], np.ndarray]:
    """Every joint between two different bodies (the supports and the blocks at rest count as
    one) whose relative motion reaches ``slow`` of the largest, width growing with it; and
    those joints' indices."""
    body = np.full(len(scene.blocks), -1)
    for k, m in enumerate(macro):
        body[motion.blocks(m.blocks)] = k
    j = joint_arrays(motion, result.joints)
    a_body = np.where(j["a"] >= 0, body[np.maximum(j["a"], 0)], -1)
    b_body = np.where(j["b"] >= 0, body[np.maximum(j["b"], 0)], -1)
    cracked = np.flatnonzero(a_body != b_body)
    if not cracked.size:
        return [], cracked
    relative = np.array([abs(result.joints[i].slip) + np.abs(result.joints[i].opening).max() for i in cracked])
    wide = relative >= slow * max(float(relative.max()), 1e-300)
    cracked, relative = cracked[wide], relative[wide]
    width = 0.6 + 2.4 * relative / max(float(relative.max()), 1e-300)
    marks = [
        Mark(
            "line",
            "crack",
            np.array([j["start"][i], j["end"][i]]),
            (int(j["a"][i]), int(j["b"][i])),
            stroke="#000000",
            width=float(w),
        )
        for i, w in zip(cracked, width, strict=True)
    ]
    return marks, cracked


def _hinges(result: Any, motion: Motion, cracked: np.ndarray, size: float) -> list[Mark]:
    """A hinge at the pivot of each hinging joint of the crack (its end that does not open),
    one mark where several meet."""
    hinging = [i for i in cracked if result.joints[i].state == "hinging"]
    if not hinging:
        return []
    j = joint_arrays(motion, [result.joints[i] for i in hinging])
    opening = np.abs(np.array([result.joints[i].opening for i in hinging], dtype=float).reshape(-1, 2))
    pivot = np.where((opening[:, 0] <= opening[:, 1])[:, None], j["start"], j["end"])
    _, first = np.unique(np.round(pivot / (1e-3 * size)), axis=0, return_index=True)
    return [
        Mark(
            "point",
            "hinge",
            pivot[k].reshape(1, 2),
            (int(j["a"][k]), int(j["b"][k])),
            stroke="#000000",
            fill="#ffffff",
            width=1.5,
            size=0.011 * size,
            text="o",
            title="hinge",
        )
        for k in np.sort(first)
    ]


def _parts(
    scene: Scene,
    macro: tuple,
    motion: Motion,
    share: np.ndarray,
    hinges: np.ndarray,
    size: float,
    s: PictureSettings,
    colour_of: dict[int, str],
) -> list[Mark]:
    """The largest :attr:`~PictureSettings.max_marked` macro-blocks reaching
    :attr:`~PictureSettings.slow` of the peak speed (single blocks only among at most
    :attr:`~PictureSettings.single_parts`; none below :attr:`~PictureSettings.part_share` of the
    largest): outlined (two blocks or more), their rotation centre
    marked (× where no hinge already marks it), their translation an arrow."""
    members = [motion.blocks(m.blocks) for m in macro]
    members = [k[k >= 0] for k in members]
    xy = np.concatenate([b.vertices for b in scene.blocks])
    low, high = xy.min(axis=0), xy.max(axis=0)
    centroid = np.array([b.centroid for b in scene.blocks]).reshape(-1, 2)  # ties: by place, not by order
    ranked = sorted(
        (k for k in range(len(macro)) if members[k].size and share[members[k]].max() >= s.slow),
        key=lambda k: (-len(members[k]), *np.round(centroid[members[k]].mean(axis=0), 6)),
    )
    if len(ranked) > s.single_parts:
        ranked = [k for k in ranked if len(members[k]) > 1]
    if ranked:
        largest = len(members[ranked[0]])
        ranked = [k for k in ranked if len(members[k]) >= s.part_share * largest]
    marks = []
    for rank, k in enumerate(ranked[: s.max_marked]):
        m, colour, carrier = macro[k], MACRO_COLOURS[rank % len(MACRO_COLOURS)], (int(members[k][0]),)
        colour_of.update({int(i): colour for i in members[k]})
        if len(members[k]) > 1:
            marks += _outline([scene.blocks[i].vertices for i in members[k]], carrier, colour, size)
        centre = None if m.centre is None else np.asarray(m.centre, dtype=float)
        near = hinges.size and float(np.hypot(*(hinges - centre).T).min()) < 1e-2 * size if centre is not None else True
        if m.motion == "rotation" and centre is not None and not near and np.all((low <= centre) & (centre <= high)):
            marks.append(
                Mark(
                    "point",
                    "centre",
                    centre.reshape(1, 2),
                    (),
                    stroke=colour,
                    width=2.0,
                    size=0.011 * size,
                    text="x",
                    title=f"rotation centre of a part of {len(members[k])} blocks",
                )
            )
        elif m.motion == "translation" and m.direction is not None:
            c = np.concatenate([scene.blocks[i].vertices for i in members[k]]).mean(axis=0)
            step = 0.06 * size * np.asarray(m.direction, dtype=float) / max(float(np.hypot(*m.direction)), 1e-300)
            marks += arrow(
                "translation",
                c,
                c + step,
                colour,
                0.02 * size,
                carrier=carrier,
                width=2.0,
                title=f"translation of a part of {len(members[k])} blocks",
            )
    return marks


def _outline(polygons: list[np.ndarray], carrier: tuple[int, ...], colour: str, size: float) -> list[Mark]:
    """The outline of blocks that move as one, closing the hairline gaps between them."""
    eps = 1e-3 * size
    union = unary_union([Polygon(v).buffer(eps, join_style="mitre") for v in polygons]).buffer(-eps, join_style="mitre")
    return [
        Mark("polygon", "macro", np.asarray(part.exterior.coords)[:-1], carrier, stroke=colour, width=2.2)
        for part in getattr(union, "geoms", [union])
        if not part.is_empty
    ]


def _distance_to_segments(p: np.ndarray, seg: np.ndarray) -> float:
    a, b = seg[:, :2], seg[:, 2:]
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    return float(np.min(np.hypot(*(a + t[:, None] * d - p).T)))


def thrust_joints(result: Any) -> np.ndarray:
    """Indices of the joints in compression, which the line of thrust passes (none for the
    pictures a study keeps, which carry no forces)."""
    normal = np.array([getattr(j, "N", 0.0) for j in result.joints], dtype=float)
    if not normal.size or not normal.max() > 0:
        return np.zeros(0, dtype=int)
    return np.flatnonzero(normal > 1e-9 * normal.max())


def centres_of_pressure(result: Any) -> np.ndarray:
    """Each joint of :func:`thrust_joints`: its centre of pressure (its two contact points'
    normal forces weigh its two ends; (k, 2) mm)."""
    joints = [result.joints[i] for i in thrust_joints(result)]
    if not joints:
        return np.zeros((0, 2))
    s = np.array([j.start for j in joints], dtype=float)
    e = np.array([j.end for j in joints], dtype=float)
    n_point = np.array([[j.points[0][0], j.points[1][0]] for j in joints], dtype=float)
    total = n_point.sum(axis=1, keepdims=True)
    safe = np.where(total > 0, total, 1.0)
    return np.where(total > 0, (n_point[:, :1] * s + n_point[:, 1:] * e) / safe, 0.5 * (s + e))


def thrust_marks(result: Any, motion: Motion, size: float, fixed: np.ndarray) -> list[Mark]:
    """The line of thrust: a dot at each compressed joint's centre of pressure (midway between the
    joint's displaced sides) and, through each block with exactly two compressed joints (an
    arch's voussoir, a pier's course; not a support) the segment joining their centres, carried by that block:
    along an arch or a column the segments join into one line from support to support."""
    index = thrust_joints(result)
    if not index.size:
        return []
    j = joint_arrays(motion, [result.joints[i] for i in index])
    point = centres_of_pressure(result)
    marks = [
        Mark(
            "point",
            "thrust",
            p.reshape(1, 2),
            (int(a), int(b)),
            stroke=THRUST_COLOUR,
            fill=THRUST_COLOUR,
            size=0.004 * size,
            text=".",
        )
        for p, a, b in zip(point, j["a"], j["b"], strict=True)
    ]
    sides = np.concatenate([j["a"], j["b"]])
    joint = np.concatenate([np.arange(index.size)] * 2)
    order = np.argsort(sides, kind="stable")
    sides, joint = sides[order], joint[order]
    blocks, first, counts = np.unique(sides, return_index=True, return_counts=True)
    pair = (counts == 2) & (blocks >= 0)
    pair[pair] = ~fixed[blocks[pair]]
    for block, f in zip(blocks[pair], first[pair], strict=True):
        marks.append(
            Mark("line", "thrust", point[[joint[f], joint[f + 1]]], (int(block),), stroke=THRUST_COLOUR, width=2.0)
        )
    return marks
