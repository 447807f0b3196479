"""Pictures of collapse mechanisms as PNG (issue 36): the drawing of :mod:`alma.report.drawing`
rendered by matplotlib (:mod:`alma.report.mpl`), the same picture as the HTML report's SVG, with
the result in words above it and a legend of every mark below."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from alma.display_settings import PictureSettings
from alma.geometry.scene import Scene
from alma.report.drawing import Drawing, draw
from alma.report.mpl import legend_handles, render_axes
from alma.report.picture import MechanismPicture, PictureJoint
from alma.report.summary import caption, parts

__all__ = ["MechanismPicture", "PictureJoint", "plot_drawings", "plot_mechanism", "plot_side_by_side"]


def plot_mechanism(
    scene: Scene,
    result: Any,
    path: str | Path,
    *,
    title: str | None = None,
    displacement: float | None = None,
    ax: Any = None,
    macro_blocks: bool = True,
    line_of_thrust: bool = False,
    settling: bool = False,
    gravity_deg: float | None = None,
    caption_text: str | None = None,
) -> Path:
    """Draw the mechanism of ``result`` on ``scene`` and save it as PNG (or draw on ``ax``).

    The blocks displaced along the mechanism so that the fastest point moves ``displacement`` ×
    the scene size (default :attr:`PictureSettings.displacement`), supports hatched, the rigid
    parts outlined in colours of their own, the crack, hinges, loads, ties and settlements
    (:func:`alma.report.drawing.draw`); the line of thrust with ``line_of_thrust``.  The title:
    ``title`` and the result in words (α, status, class, how many blocks move).
    """
    if len(parts(result)) > 1 and ax is None:  # model="both": the two side by side
        return plot_side_by_side(
            scene, parts(result), path, suptitle=title, displacement=displacement, line_of_thrust=line_of_thrust
        )
    settings = PictureSettings() if displacement is None else replace(PictureSettings(), displacement=displacement)
    drawing = draw(
        scene,
        result,
        thrust=line_of_thrust,
        macro_blocks=macro_blocks,
        settling=settling,
        gravity_deg=gravity_deg,
        settings=settings,
    )
    words = caption_text if caption_text is not None else caption(result, drawing)
    text = (title + "\n" if title else "") + words
    if ax is not None:
        render_axes(ax, drawing, thrust=line_of_thrust)
        ax.set_title(text, fontsize=9)
        return Path(path)
    return plot_drawings([drawing], [text], path, thrust=line_of_thrust)


def plot_side_by_side(
    scene: Scene,
    results: Any,
    path: str | Path,
    *,
    titles: list[str | None] | None = None,
    suptitle: str | None = None,
    displacement: float | None = None,
    line_of_thrust: bool = False,
) -> Path:
    """Draw the mechanisms of several results of the same scene side by side, at one scale, and
    save a PNG (typically the associative and the non-associative solution of one panel)."""
    results = list(results)
    if not results:
        raise ValueError("no result to draw")
    titles = list(titles) if titles is not None else [None] * len(results)
    if len(titles) != len(results):
        raise ValueError(f"{len(titles)} titles for {len(results)} results")
    settings = PictureSettings() if displacement is None else replace(PictureSettings(), displacement=displacement)
    drawings = [draw(scene, r, thrust=line_of_thrust, settings=settings) for r in results]
    texts = [(t + "\n" if t else "") + caption(r, d) for t, r, d in zip(titles, results, drawings, strict=True)]
    return plot_drawings(drawings, texts, path, suptitle=suptitle, thrust=line_of_thrust)


def plot_drawings(
    drawings: list[Drawing],
    texts: list[str],
    path: str | Path,
    *,
    suptitle: str | None = None,
    thrust: bool = False,
    width: float = 7.0,
    dpi: int = 110,
) -> Path:
    """Save ``drawings`` side by side at one scale (one box holds them all), each under its
    text, with one legend of every mark class used below them (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    box = np.array([d.box for d in drawings])
    union = (*box[:, :2].min(axis=0), *box[:, 2:].max(axis=0))
    four = (float(union[0]), float(union[1]), float(union[2]), float(union[3]))
    drawings = [replace(d, box=four) for d in drawings]
    aspect = (union[3] - union[1]) / (union[2] - union[0])
    n = len(drawings)
    classes = [c for c in dict.fromkeys(c for d in drawings for c in d.classes()) if thrust or c != "thrust"]
    legend_rows = -(-len(classes) // (2 if n == 1 else 4))
    height = width * aspect + 0.55 + 0.2 * legend_rows + (0.3 if suptitle else 0.0)
    fig = plt.figure(figsize=(width * n, height))
    bottom = (0.2 * legend_rows + 0.15) / height
    top = 1.0 - (0.55 + (0.3 if suptitle else 0.0)) / height
    for k, (d, text) in enumerate(zip(drawings, texts, strict=True)):
        ax = fig.add_axes((k / n + 0.01, bottom, 1.0 / n - 0.02, top - bottom))
        render_axes(ax, d, thrust=thrust)
        ax.set_title(text, fontsize=9)
    fig.legend(
        handles=legend_handles(classes), loc="lower center", ncol=2 if n == 1 else 4, fontsize=7.5, frameon=False
    )
    if suptitle:
        fig.suptitle(suptitle, fontsize=11)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
