"""A :class:`~alma.report.drawing.Drawing` on matplotlib axes (issue 36): the same marks, in the
same order, with the same colours, widths and sizes as :mod:`alma.report.svg`."""

from __future__ import annotations

from typing import Any

import numpy as np

from alma.report.drawing import Drawing
from alma.report.marks import LEGEND, Mark
from alma.report.svg import star


def render_axes(ax: Any, drawing: Drawing, *, thrust: bool = False) -> None:
    """Draw ``drawing`` on ``ax`` (its limits the drawing's box, equal aspect, no axes frame);
    the line of thrust only with ``thrust``."""
    import matplotlib.patheffects as effects
    from matplotlib.collections import LineCollection, PolyCollection

    x0, y0, x1, y1 = drawing.box
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.figure.canvas.draw_idle()
    ax.apply_aspect()
    box = ax.get_window_extent()
    points_per_mm = min(box.width / (x1 - x0), box.height / (y1 - y0)) * 72.0 / ax.figure.dpi
    marks = [m for m in drawing.marks if thrust or m.cls != "thrust"]
    for z, run in enumerate(_runs(marks)):
        kind, placed = run[0].kind, [drawing.placed(m) for m in run]
        if kind == "polygon":
            ax.add_collection(
                PolyCollection(
                    placed,
                    facecolors=[m.fill or "none" for m in run],
                    edgecolors=[m.stroke or "none" for m in run],
                    linewidths=[0.75 * m.width for m in run],
                    hatch="////" if run[0].hatch else None,
                    zorder=z,
                    joinstyle="round",
                )
            )
        elif kind == "line":
            ax.add_collection(
                LineCollection(
                    placed,
                    colors=[m.stroke for m in run],
                    linewidths=[0.75 * m.width for m in run],
                    linestyles="--" if run[0].dash else "-",
                    capstyle="round",
                    zorder=z,
                )
            )
        elif kind == "point":
            for m, xy in zip(run, placed, strict=True):
                _point(ax, m, xy[0], z)
        else:
            for m, xy in zip(run, placed, strict=True):
                ax.text(
                    *xy[0],
                    m.text,
                    fontsize=m.size * points_per_mm,
                    color=m.fill,
                    zorder=z,
                    ha={"start": "left", "middle": "center", "end": "right"}[m.anchor],
                    va="baseline",
                    path_effects=[effects.withStroke(linewidth=2.5, foreground="white")],
                )


def _runs(marks: list[Mark]) -> list[list[Mark]]:
    """Consecutive marks of one kind, class and hatching: one collection each, in order."""
    runs: list[list[Mark]] = []
    for m in marks:
        last = runs[-1][0] if runs else None
        if last is not None and (last.kind, last.cls, last.hatch, last.dash) == (m.kind, m.cls, m.hatch, m.dash):
            runs[-1].append(m)
        else:
            runs.append([m])
    return runs


def _point(ax: Any, m: Mark, xy: np.ndarray, z: int) -> None:
    from matplotlib.patches import Circle, Polygon

    if m.text == "x":
        r = m.size
        ax.plot(
            [xy[0] - r, xy[0] + r, np.nan, xy[0] - r, xy[0] + r],
            [xy[1] - r, xy[1] + r, np.nan, xy[1] + r, xy[1] - r],
            color=m.stroke,
            linewidth=0.75 * m.width,
            zorder=z,
        )
    elif m.text == "*":
        ax.add_patch(Polygon(star(xy, m.size), closed=True, facecolor=m.fill, edgecolor=m.stroke, zorder=z))
    else:
        ax.add_patch(
            Circle(
                (float(xy[0]), float(xy[1])),
                m.size,
                facecolor=m.fill or "none",
                edgecolor=m.stroke or "none",
                linewidth=0.75 * m.width,
                zorder=z,
            )
        )


def legend_handles(classes: list[str]) -> list[Any]:
    """Matplotlib legend handles of ``classes`` (the same words and symbols as the page's)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles: list[Any] = []  # Patch and Line2D
    for c in classes:
        e = LEGEND[c]
        if e.swatch == "patch":
            handles.append(
                Patch(facecolor=e.fill, edgecolor=e.colour, hatch="////" if e.hatch else None, label=e.label)
            )
        elif e.swatch in ("line", "arrow"):
            handles.append(
                Line2D(
                    [],
                    [],
                    color=e.colour,
                    linewidth=2,
                    linestyle="--" if e.dash else "-",
                    marker=">" if e.swatch == "arrow" else None,
                    label=e.label,
                )
            )
        else:
            handles.append(
                Line2D(
                    [],
                    [],
                    linestyle="none",
                    marker={"o": "o", "x": "x", "*": "*"}[e.swatch],
                    markerfacecolor=e.fill or e.colour,
                    markeredgecolor=e.colour,
                    color=e.colour,
                    markersize=8,
                    label=e.label,
                )
            )
    return handles
