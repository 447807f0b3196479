"""What a picture draws over the blocks: ties with their forces, settling supports' motions."""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

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


def draw_macro_blocks(ax: Any, scene: Any, result: Any, move: Callable[[str, np.ndarray], np.ndarray],
                      speed: dict[str, float]) -> None:
    """The mechanism as an engineer sketches it (issue 19).

    The crack (every joint between two different bodies, the ground and the blocks at rest
    counting as one) as a black line whose width grows with the joint's relative motion, drawn
    midway between its two displaced sides; the moving macro-blocks (the largest
    :data:`MAX_MARKED` that reach :data:`SLOW` of the peak speed) outlined in their displaced
    position where they hold two blocks or more, their rotation centres marked (x; a filled dot where the centre
    lies on the crack: a hinge) and their translations drawn as arrows.  ``move`` displaces
    points of a block (mm), ``speed`` is each free block's largest speed relative to the peak.
    """
    from matplotlib.collections import LineCollection
    from shapely import Polygon, unary_union

    macro = tuple(getattr(result, "macro_blocks", ()) or ())
    if not macro:
        return
    body = {b: k for k, m in enumerate(macro) for b in m.blocks}
    cracked = [j for j in result.joints if body.get(j.blocks[0], -1) != body.get(j.blocks[1], -1)]
    crack = np.array([np.concatenate([_midway(move, j, j.start), _midway(move, j, j.end)]) for j in cracked],
                     dtype=float).reshape(-1, 4)
    if crack.size:
        motion = np.array([abs(j.slip) + max(abs(j.opening[0]), abs(j.opening[1])) for j in cracked])
        width = 0.6 + 2.4 * motion / max(float(motion.max()), 1e-300)
        ax.add_collection(LineCollection(crack.reshape(-1, 2, 2), colors="k", linewidths=width, capstyle="round"))
    shapes = {b.id: b.vertices for b in scene.blocks if not b.fixed}
    xy = np.concatenate([move(i, v) for i, v in shapes.items()])
    low, high = xy.min(axis=0) - 0.1 * np.ptp(xy, axis=0), xy.max(axis=0) + 0.1 * np.ptp(xy, axis=0)
    ranked = sorted((k for k, m in enumerate(macro) if max(speed.get(b, 0.0) for b in m.blocks) >= SLOW),
                    key=lambda k: -len(macro[k].blocks))
    colours = ("tab:red", "tab:blue", "tab:green", "tab:orange", "tab:purple", "tab:cyan", "tab:pink", "tab:olive")
    for rank, k in enumerate(ranked[:MAX_MARKED]):
        m, colour = macro[k], colours[rank % len(colours)]
        outline = unary_union([Polygon(move(b, shapes[b])).buffer(0) for b in m.blocks if b in shapes])
        for part in getattr(outline, "geoms", [outline]) if len(m.blocks) > 1 else ():
            if not part.is_empty:
                ax.plot(*part.exterior.xy, color=colour, linewidth=1.8)
        centre = None if m.centre is None else np.asarray(m.centre, dtype=float)
        if m.motion == "rotation" and centre is not None and np.all((low <= centre) & (centre <= high)):
            hinge = bool(crack.size) and _distance_to_segments(centre, crack) < 1e-3 * float(np.ptp(xy, axis=0).max())
            ax.plot(*centre, marker="o" if hinge else "x", color=colour, markersize=7,
                    markeredgecolor="k" if hinge else colour)
        elif m.motion == "translation" and m.direction is not None:
            c = np.mean(np.concatenate([move(b, shapes[b]) for b in m.blocks if b in shapes]), axis=0)
            step = 0.05 * float(np.ptp(xy, axis=0).max()) * np.asarray(m.direction, dtype=float)
            ax.annotate("", xy=c + step, xytext=c, arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 1.5})


def _midway(move: Callable[[str, np.ndarray], np.ndarray], joint: Any, point: Any) -> np.ndarray:
    p = np.asarray(point, dtype=float).reshape(1, 2)
    return (0.5 * (move(joint.blocks[0], p) + move(joint.blocks[1], p)))[0]


def _distance_to_segments(p: np.ndarray, seg: np.ndarray) -> float:
    a, b = seg[:, :2], seg[:, 2:]
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    return float(np.min(np.hypot(*(a + t[:, None] * d - p).T)))


def thrust_joints(result: Any) -> list[tuple[int, Any]]:
    """(index, joint) of the joints in compression, which the line of thrust passes (none for the
    pictures a study keeps, which carry no forces)."""
    normal = np.array([getattr(j, "N", 0.0) for j in result.joints], dtype=float)
    if not normal.size or not normal.max() > 0:
        return []
    return [(int(i), result.joints[i]) for i in np.flatnonzero(normal > 1e-9 * normal.max())]


def thrust(result: Any) -> list[tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]]:
    """Each compressed joint's centre of pressure (the contact points' normal forces weigh its two
    ends) and a segment of its resultant's line of action, a quarter of the joint long each side."""
    out = []
    for _, j in thrust_joints(result):
        s, e = np.asarray(j.start, dtype=float), np.asarray(j.end, dtype=float)
        (n_s, _), (n_e, _) = j.points
        total = n_s + n_e
        point = (n_s * s + n_e * e) / total if total > 0 else 0.5 * (s + e)
        n = np.asarray(j.normal, dtype=float)  # from blocks[0] into blocks[1]; the tangent is n turned +90°
        force = j.N * n + j.T * np.array([-n[1], n[0]])
        step = 0.25 * j.length * force / max(float(np.hypot(*force)), 1e-300)
        out.append((point, (point - step, point + step)))
    return out


def draw_thrust(ax: Any, result: Any, move: Callable[[str, np.ndarray], np.ndarray]) -> None:
    """The line of thrust on a picture: each compressed joint's centre of pressure and its
    resultant's line of action, moved midway between the joint's two displaced sides."""
    from matplotlib.collections import LineCollection

    joints = thrust_joints(result)
    if not joints:
        return
    moved = [[_midway(move, j, p) for p in (ends[0], point, ends[1])]
             for (_, j), (point, ends) in zip(joints, thrust(result))]
    moved = np.asarray(moved, dtype=float)
    ax.add_collection(LineCollection(moved[:, [0, 2]], colors=THRUST_COLOUR, linewidths=0.9))
    ax.plot(moved[:, 1, 0], moved[:, 1, 1], linestyle="none", marker=".", markersize=3, color=THRUST_COLOUR)
