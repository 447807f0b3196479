"""What a picture draws over the blocks: ties with their forces, settling supports' motions."""
from __future__ import annotations

from typing import Any

import numpy as np

TIE_COLOUR = "tab:purple"
SETTLEMENT_COLOUR = "tab:brown"


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
