"""What a picture draws over the blocks: ties with their forces, settling supports' motions."""
from __future__ import annotations

from typing import Any

import numpy as np

from alma.report.motion import Motion, joint_arrays

TIE_COLOUR = "tab:purple"
SETTLEMENT_COLOUR = "tab:brown"
THRUST_COLOUR = "#9400d3"


def draw_ties(ax: Any, scene: Any, result: Any) -> None:
    """Each tie as a dashed line between its two points, labelled with its force (kN) where the
    result gives one."""
    forces = {t["id"]: t["force"] for t in getattr(result, "ties", ()) or ()}
    for tie in getattr(scene, "ties", ()):
        (x0, y0), (x1, y1) = tie.from_point, tie.to_point
        ax.plot([x0, x1], [y0, y1], linestyle="--", color=TIE_COLOUR, linewidth=1.0)
        label = f"{tie.id}: {forces[tie.id]:.3g} kN" if tie.id in forces else tie.id
        ax.annotate(label, ((x0 + x1) / 2, (y0 + y1) / 2), color=TIE_COLOUR, fontsize=7,
                    ha="center", va="bottom")


def draw_settlements(ax: Any, scene: Any) -> None:
    """An arrow from each settling support's centroid along its prescribed translation (scaled to
    a tenth of the scene), labelled with the motion."""
    size = float(np.ptp(np.concatenate([b.vertices for b in scene.blocks]), axis=0).max())
    for block in scene.blocks:
        s = getattr(block, "settlement", None)
        if s is None:
            continue
        d = np.asarray(s.translation, dtype=float)
        norm = float(np.hypot(*d))
        c = block.centroid
        if norm > 0:
            step = 0.1 * size * d / norm
            ax.annotate("", xy=c + step, xytext=c, arrowprops={"arrowstyle": "->", "color": SETTLEMENT_COLOUR})
        ax.annotate(f"settles [{d[0]:.3g}, {d[1]:.3g}] mm, {s.rotation:.3g} rad", c, color=SETTLEMENT_COLOUR,
                    fontsize=7, ha="center", va="top")


#: Macro-blocks outlined and marked, the largest first: more than this only clutter the picture.
MAX_MARKED = 12
#: Macro-blocks slower than this share of the fastest block are not outlined (they barely move).
SLOW = 0.1


def draw_macro_blocks(ax: Any, scene: Any, result: Any, motion: Motion, speed: np.ndarray) -> None:
    """The mechanism as an engineer sketches it (issue 19).

    The crack (every joint between two different bodies, the ground and the blocks at rest
    counting as one) as a black line whose width grows with the joint's relative motion, drawn
    midway between its two displaced sides; the moving macro-blocks (the largest
    :data:`MAX_MARKED` that reach :data:`SLOW` of the peak speed) outlined in their displaced
    position where they hold two blocks or more, their rotation centres marked (x; a filled dot
    where the centre lies on the crack: a hinge) and their translations drawn as arrows.
    ``motion`` displaces the blocks' points; ``speed`` is each block's speed relative to the peak.
    """
    from matplotlib.collections import LineCollection
    from shapely import Polygon, unary_union

    macro = tuple(getattr(result, "macro_blocks", ()) or ())
    if not macro:
        return
    body = np.full(len(scene.blocks), -1)
    for k, m in enumerate(macro):
        body[motion.blocks(m.blocks)] = k
    j = joint_arrays(motion, result.joints)
    cracked = np.flatnonzero(body[j["a"]] != body[j["b"]])
    crack = np.hstack([motion.midway(j["a"][cracked], j["b"][cracked], j["start"][cracked]),
                       motion.midway(j["a"][cracked], j["b"][cracked], j["end"][cracked])])
    if crack.size:
        relative = np.array([abs(result.joints[i].slip) + np.abs(result.joints[i].opening).max() for i in cracked])
        width = 0.6 + 2.4 * relative / max(float(relative.max()), 1e-300)
        ax.add_collection(LineCollection(crack.reshape(-1, 2, 2), colors="k", linewidths=width, capstyle="round"))
    displaced = motion.outlines(scene)
    xy = np.concatenate([d for d, b in zip(displaced, scene.blocks) if not b.fixed])
    size = float(np.ptp(xy, axis=0).max())
    low, high = xy.min(axis=0) - 0.1 * np.ptp(xy, axis=0), xy.max(axis=0) + 0.1 * np.ptp(xy, axis=0)
    members = [motion.blocks(m.blocks) for m in macro]
    ranked = sorted((k for k in range(len(macro)) if speed[members[k]].max() >= SLOW), key=lambda k: -len(members[k]))
    colours = ("tab:red", "tab:blue", "tab:green", "tab:orange", "tab:purple", "tab:cyan", "tab:pink", "tab:olive")
    for rank, k in enumerate(ranked[:MAX_MARKED]):
        m, colour = macro[k], colours[rank % len(colours)]
        if len(members[k]) > 1:
            outline = unary_union([Polygon(displaced[i]).buffer(0) for i in members[k]])
            for part in getattr(outline, "geoms", [outline]):
                ax.plot(*part.exterior.xy, color=colour, linewidth=1.8)
        centre = None if m.centre is None else np.asarray(m.centre, dtype=float)
        if m.motion == "rotation" and centre is not None and np.all((low <= centre) & (centre <= high)):
            hinge = bool(crack.size) and _distance_to_segments(centre, crack) < 1e-3 * size
            ax.plot(*centre, marker="o" if hinge else "x", color=colour, markersize=7,
                    markeredgecolor="k" if hinge else colour)
        elif m.motion == "translation" and m.direction is not None:
            c = np.concatenate([displaced[i] for i in members[k]]).mean(axis=0)
            step = 0.05 * size * np.asarray(m.direction, dtype=float)
            ax.annotate("", xy=c + step, xytext=c, arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 1.5})


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


def thrust(result: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For the joints of :func:`thrust_joints`: each one's centre of pressure (its two contact
    points' normal forces weigh its two ends) and the two ends of a segment of its resultant's
    line of action, a quarter of the joint long each side (three (k, 2) arrays, mm)."""
    joints = [result.joints[i] for i in thrust_joints(result)]
    if not joints:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 2))
    s = np.array([j.start for j in joints], dtype=float)
    e = np.array([j.end for j in joints], dtype=float)
    n_point = np.array([[j.points[0][0], j.points[1][0]] for j in joints], dtype=float)
    total = n_point.sum(axis=1, keepdims=True)
    safe = np.where(total > 0, total, 1.0)
    point = np.where(total > 0, (n_point[:, :1] * s + n_point[:, 1:] * e) / safe, 0.5 * (s + e))
    n = np.array([j.normal for j in joints], dtype=float)  # from blocks[0] into blocks[1]
    force = np.array([j.N for j in joints])[:, None] * n + np.array([j.T for j in joints])[:, None] * \
        np.column_stack([-n[:, 1], n[:, 0]])  # the tangent is the normal turned +90°
    length = np.array([j.length for j in joints], dtype=float)[:, None]
    step = 0.25 * length * force / np.maximum(np.hypot(force[:, 0], force[:, 1]), 1e-300)[:, None]
    return point, point - step, point + step


def draw_thrust(ax: Any, result: Any, motion: Motion) -> None:
    """The line of thrust on a picture: each compressed joint's centre of pressure and its
    resultant's line of action, moved midway between the joint's two displaced sides."""
    from matplotlib.collections import LineCollection

    index = thrust_joints(result)
    if not index.size:
        return
    j = joint_arrays(motion, [result.joints[i] for i in index])
    point, start, end = (motion.midway(j["a"], j["b"], p) for p in thrust(result))
    ax.add_collection(LineCollection(np.stack([start, end], axis=1), colors=THRUST_COLOUR, linewidths=0.9))
    ax.plot(point[:, 0], point[:, 1], linestyle="none", marker=".", markersize=3, color=THRUST_COLOUR)
