"""The mechanism at every step of a capacity curve, as SVG frames under one slider.

Each point of ``alma.push``'s curve carries the blocks' pose (rigid motions from the original
scene); a frame draws the displaced blocks to scale (moving blocks filled, blocks at rest and
supports grey) in one viewBox shared by all frames, so the slider shows the structure move.  A
marker on the α(d) chart follows the slider.  The page stays standalone: the frames and the few
lines of script that switch them are inline.  Lengths in mm (y turned down in SVG).
"""

from __future__ import annotations

import html
import json

import numpy as np

from alma.geometry.scene import Scene
from alma.push import PushResult
from alma.push.motion import displaced

#: Frame outline colours: supports, blocks at rest since d = 0, blocks moved.
_FILL = {"fixed": "#bbbbbb", "rest": "#e8e8e8", "moved": "#f4a582"}


def frames_svg(scene: Scene, result: PushResult, *, pixels: float = 520.0) -> str:
    """One SVG with a ``<g class="frame" data-step="k">`` per curve point (k = 0, 1, …); only
    frame 0 is shown until the slider moves."""
    outlines = [[b.vertices for b in displaced(scene, p.pose).blocks] for p in result.curve]
    flat = np.concatenate([np.concatenate(o) for o in outlines])
    x0, y0 = flat.min(axis=0)
    x1, y1 = flat.max(axis=0)
    pad = 0.03 * max(x1 - x0, y1 - y0)
    x0, y0, x1, y1 = x0 - pad, y0 - pad, x1 + pad, y1 + pad
    w, h = x1 - x0, y1 - y0
    k = pixels / max(w, h)
    fixed = np.array([b.fixed for b in scene.blocks])
    groups = []
    for step, (point, polygons) in enumerate(zip(result.curve, outlines, strict=True)):
        moved = (np.abs(point.pose.angle) > 0) | (np.abs(point.pose.shift).max(axis=1) > 0)
        kind = np.where(fixed, "fixed", np.where(moved, "moved", "rest"))
        body = "".join(
            f'<polygon points="{_points(v)}" fill="{_FILL[c]}" stroke="#333" stroke-width="{0.6 / k:.4g}"/>'
            for v, c in zip(polygons, kind, strict=True)
        )
        shown = "" if step == 0 else ' style="display:none"'
        groups.append(
            f'<g class="frame" data-step="{step}" data-d="{point.d:.6g}" '
            f'data-alpha="{point.alpha:.6g}"{shown}>{body}</g>'
        )
    return (
        f'<svg id="frames" xmlns="http://www.w3.org/2000/svg" viewBox="{x0:.6g} {-y1:.6g} {w:.6g} {h:.6g}" '
        f'width="{w * k:.0f}" height="{h * k:.0f}">{"".join(groups)}</svg>'
    )


def slider_html(result: PushResult, name: str = "d", unit: str = "mm") -> str:
    """The range input over the steps, its label (``name`` = value ``unit``) and the script that
    shows one frame."""
    n = len(result.curve)
    points = json.dumps([[p.d, p.alpha] for p in result.curve])
    return (
        f'<div><input id="step" type="range" min="0" max="{n - 1}" value="0" step="1" style="width:520px">'
        f'<span id="steplabel"></span></div>'
        "<script>(function(){var f=document.querySelectorAll('#frames .frame');"
        f"var pts={html.escape(points, quote=False)};var s=document.getElementById('step');"
        "var l=document.getElementById('steplabel');var m=document.getElementById('curvemark');"
        "function show(k){for(var i=0;i<f.length;i++){f[i].style.display=(i==k)?'':'none';}"
        f"l.textContent=' step '+k+': {html.escape(name)} = '+pts[k][0].toPrecision(4)+' {html.escape(unit)}, "
        "\u03b1 = '+pts[k][1].toPrecision(4);"
        "if(m){m.setAttribute('cx',m.dataset['x'+k]);m.setAttribute('cy',m.dataset['y'+k]);}}"
        "s.addEventListener('input',function(){show(+s.value);});show(0);})();</script>"
    )


def _points(xy: np.ndarray) -> str:
    return " ".join(f"{x:.6g},{-y:.6g}" for x, y in np.asarray(xy, dtype=float).reshape(-1, 2))
