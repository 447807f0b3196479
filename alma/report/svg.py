"""A :class:`~alma.report.drawing.Drawing` as inline SVG (issue 36).

Coordinates are the scene's (mm) with y turned down; the viewBox is the drawing's box, so the
picture has the structure's aspect ratio and fills its frame.  Marks are drawn at rest, each
carried mark with the ``transform`` of its displacement (the small-rotation map of
:meth:`~alma.report.motion.Motion.affine`), so the page's script moves a mark by rewriting one
attribute; ``data-mark`` names the mark class (the legend's key), ``data-carrier`` its blocks.
"""

from __future__ import annotations

import html

import numpy as np

from alma.report.drawing import Drawing
from alma.report.marks import LEGEND, SUPPORT_FILL, LegendEntry, Mark


def render_svg(drawing: Drawing, key: str, *, pixels: float = 900.0) -> str:
    """The SVG element of ``drawing``; ``key`` makes its ids unique on a page, ``pixels`` the
    larger side of its natural size (CSS may scale it, keeping the aspect ratio)."""
    x0, y0, x1, y1 = drawing.box
    w, h = x1 - x0, y1 - y0
    k = pixels / max(w, h)
    hatch = 0.012 * drawing.size
    defs = (
        f'<defs><pattern id="{key}-hatch" patternUnits="userSpaceOnUse" width="{hatch:.4g}" height="{hatch:.4g}" '
        f'patternTransform="rotate(45)"><rect width="{hatch:.4g}" height="{hatch:.4g}" fill="{SUPPORT_FILL}"/>'
        f'<line x1="0" y1="0" x2="0" y2="{hatch:.4g}" stroke="#555" stroke-width="{0.25 * hatch:.4g}"/>'
        f"</pattern></defs>"
    )
    body = "".join(_element(m, drawing, key) for m in drawing.marks)
    return (
        f'<svg id="{key}" class="mechanism" xmlns="http://www.w3.org/2000/svg" viewBox="{x0:.6g} {-y1:.6g} '
        f'{w:.6g} {h:.6g}" width="{w * k:.0f}" height="{h * k:.0f}" preserveAspectRatio="xMidYMid meet">'
        f"{defs}{body}</svg>"
    )


def _element(m: Mark, drawing: Drawing, key: str) -> str:
    attrs = f' class="m-{m.cls}" data-mark="{m.cls}"'
    if m.carrier:
        b, e, f = drawing.motion.affine(m.carrier)
        attrs += (
            f' data-carrier="{",".join(map(str, m.carrier))}" transform="matrix(1 {-b:.6g} {b:.6g} 1 {e:.6g} {-f:.6g})"'
        )
    title = f"<title>{html.escape(m.title)}</title>" if m.title else ""
    stroke = (
        f' stroke="{m.stroke}" stroke-width="{m.width:.3g}" vector-effect="non-scaling-stroke"'
        if m.stroke
        else ' stroke="none"'
    )
    if m.kind == "polygon":
        fill = f"url(#{key}-hatch)" if m.hatch else (m.fill or "none")
        return (
            f'<polygon{attrs} points="{_points(m.xy)}" fill="{fill}"{stroke} stroke-linejoin="round">{title}</polygon>'
        )
    if m.kind == "line":
        dash = ' stroke-dasharray="7 4"' if m.dash else ""
        return (
            f'<polyline{attrs} points="{_points(m.xy)}" fill="none"{stroke}{dash} stroke-linecap="round">'
            f"{title}</polyline>"
        )
    if m.kind == "point":
        return _point(m, attrs, stroke, title)
    x, y = m.xy[0]
    return (
        f'<text{attrs} x="{x:.6g}" y="{-y:.6g}" font-size="{m.size:.4g}" text-anchor="{m.anchor}" '
        f'fill="{m.fill}" stroke="#fff" stroke-width="{0.18 * m.size:.4g}" paint-order="stroke" '
        f'stroke-linejoin="round">{html.escape(m.text)}</text>'
    )


def _point(m: Mark, attrs: str, stroke: str, title: str) -> str:
    x, y = m.xy[0]
    r = m.size
    if m.text == "x":
        d = f"M{x - r:.6g},{-y - r:.6g}L{x + r:.6g},{-y + r:.6g}M{x - r:.6g},{-y + r:.6g}L{x + r:.6g},{-y - r:.6g}"
        return f'<path{attrs} d="{d}" fill="none"{stroke}>{title}</path>'
    if m.text == "*":
        return f'<polygon{attrs} points="{_points(star(m.xy[0], r))}" fill="{m.fill}"{stroke}>{title}</polygon>'
    return f'<circle{attrs} cx="{x:.6g}" cy="{-y:.6g}" r="{r:.4g}" fill="{m.fill or "none"}"{stroke}>{title}</circle>'


def star(centre: np.ndarray, r: float) -> np.ndarray:
    """A five-pointed star of outer radius ``r`` (mm) about ``centre`` (the crushing mark)."""
    angle = np.pi / 2 + np.arange(10) * np.pi / 5
    radius = np.where(np.arange(10) % 2 == 0, r, 0.45 * r)
    return np.asarray(centre, dtype=float) + radius[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])


def _points(xy: np.ndarray) -> str:
    return " ".join(f"{x:.6g},{-y:.6g}" for x, y in np.asarray(xy, dtype=float).reshape(-1, 2))


def legend_html(classes: list[str]) -> str:
    """The legend of ``classes`` as an HTML list, each entry with a small SVG swatch."""
    return "".join(f'<li data-mark="{c}">{_swatch(LEGEND[c])}{html.escape(LEGEND[c].label)}</li>' for c in classes)


def _swatch(e: LegendEntry) -> str:
    inner = {
        "patch": f'<rect x="1" y="2" width="18" height="10" fill="{e.fill}" stroke="{e.colour}"/>'
        + ('<path d="M3,12L11,2M9,12L17,2" stroke="#555"/>' if e.hatch else ""),
        "line": f'<line x1="1" y1="7" x2="19" y2="7" stroke="{e.colour}" stroke-width="2.5"'
        + (' stroke-dasharray="4 2"' if e.dash else "")
        + "/>",
        "arrow": f'<line x1="1" y1="7" x2="13" y2="7" stroke="{e.colour}" stroke-width="2"/>'
        f'<polygon points="19,7 12,3 12,11" fill="{e.colour}"/>',
        "o": f'<circle cx="10" cy="7" r="4.5" fill="{e.fill}" stroke="{e.colour}" stroke-width="1.5"/>',
        "x": f'<path d="M6,3L14,11M6,11L14,3" stroke="{e.colour}" stroke-width="2"/>',
        "*": f'<polygon points="{_swatch_star()}" fill="{e.colour}"/>',
    }[e.swatch]
    return f'<svg class="swatch" width="20" height="14" viewBox="0 0 20 14">{inner}</svg>'


def _swatch_star() -> str:
    return " ".join(f"{x:.3g},{-y:.3g}" for x, y in star(np.array([10.0, -7.0]), 6.0))
