"""A standalone page (no network) of a capacity curve: α(d) and, with the seismic check, a*(d*)
with its demand, as inline SVG, the numbers of the check in a table, and with the scene the
mechanism at every step under a slider (:mod:`alma.report.capacity_frames`, a few lines of
inline script)."""

from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np

from alma.geometry.scene import Scene
from alma.push import PushResult
from alma.report.capacity import linear_line, nonlinear_value
from alma.report.capacity_frames import frames_svg, slider_html
from alma.seismic import SeismicResult

_W, _H, _PAD = 520, 320, 48


def write_capacity_html(
    result: PushResult,
    path: str | Path,
    *,
    check: SeismicResult | None = None,
    title: str = "",
    scene: Scene | None = None,
    abscissa: tuple[str, str, str] | None = None,
    rows: list[tuple[str, str]] | None = None,
) -> Path:
    """Write the page for ``result`` (and ``check``) to ``path``; with ``scene`` (the one pushed)
    the displaced structure at every step beside the curve, under a slider.  ``abscissa`` (axis
    label, name of the root, unit) and ``rows`` (the table) for another abscissa than the control
    block's displacement (the settlement capacity's s)."""
    label, root, unit = abscissa or (f"d: horizontal displacement of {result.control} [mm]", "d₀", "mm")
    d = np.array([p.d for p in result.curve])
    alpha = np.array([p.alpha for p in result.curve])
    figures = [_svg(d, alpha, label, "α", marks=[(root, result.d0, None)], marker=scene is not None)]
    if scene is not None:
        figures = [
            f"<div style='display:flex;flex-wrap:wrap;align-items:flex-start'>{figures[0]}"
            f"{frames_svg(scene, result)}</div>{slider_html(result, label.split(':')[0], unit)}"
        ]
    rows = rows or [
        ("status", str(result.status)),
        ("message", result.message),
        ("control block", str(result.control)),
        ("α_c", f"{result.alpha_c:.6g}"),
        ("d₀ [mm]", f"{result.d0:.6g}"),
        ("LP solves", str(result.solves)),
        ("end", str(result.end.get("text", result.end.get("reason", "")))),
    ]
    if check is not None and check.curve_star:
        ds, a = np.array(check.curve_star).T
        figures.append(
            _svg(
                ds * 1e3,
                a,
                "d* [mm]",
                "a* [m/s²]",
                marks=[
                    ("d_SLV" if check.edition == "2019" else "d_u*", nonlinear_value(check, "du_star") * 1e3, None),
                    ("demand", nonlinear_value(check, "demand") * 1e3, None),
                    ("linear check", None, linear_line(check)),
                ],
            )
        )
        rows += [
            (k, json.dumps(v))
            for k, v in check.to_dict().items()
            if k not in ("curve_star", "push", "message", "status", "control")
        ]
    table = "".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(v)}</td></tr>" for k, v in rows)
    page = (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title or 'capacity curve')}</title>"
        "<style>body{font-family:sans-serif;margin:1em}th{text-align:left;padding-right:1em}"
        "td{font-family:monospace;word-break:break-all}svg{margin:0.5em;border:1px solid #ccc}</style>"
        f"</head><body><h1>{html.escape(title or 'capacity curve')}</h1>{''.join(figures)}"
        f"<table>{table}</table></body></html>"
    )
    path = Path(path)
    path.write_text(page, encoding="utf-8")
    return path


def _svg(
    x: np.ndarray,
    y: np.ndarray,
    xlabel: str,
    ylabel: str,
    marks: list[tuple[str, float | None, float | None]],
    marker: bool = False,
) -> str:
    """A line chart with axes through 0; ``marks``: (label, vertical line at x, horizontal at y);
    ``marker``: a dot with the chart position of every point (data-x0, data-y0, …) for the slider."""
    ok = np.isfinite(x) & np.isfinite(y)
    every = np.flatnonzero(ok)
    x, y = x[ok], y[ok]
    x_hi = max([float(x.max(initial=0.0))] + [v for _, v, _ in marks if v is not None and np.isfinite(v)] + [1e-12])
    y_hi = max([float(y.max(initial=0.0))] + [v for _, _, v in marks if v is not None and np.isfinite(v)] + [1e-12])
    y_lo = min(0.0, float(y.min(initial=0.0)))
    sx = lambda v: _PAD + (v / x_hi) * (_W - 2 * _PAD)  # noqa: E731
    sy = lambda v: _H - _PAD - (v - y_lo) / (y_hi - y_lo) * (_H - 2 * _PAD)  # noqa: E731
    points = " ".join(f"{sx(a):.1f},{sy(b):.1f}" for a, b in zip(x, y, strict=True))
    parts = [
        f"<svg xmlns='http://www.w3.org/2000/svg' width='{_W}' height='{_H}'>",
        f"<line x1='{_PAD}' y1='{sy(0):.1f}' x2='{_W - _PAD}' y2='{sy(0):.1f}' stroke='black'/>",
        f"<line x1='{_PAD}' y1='{_PAD}' x2='{_PAD}' y2='{_H - _PAD}' stroke='black'/>",
        f"<polyline fill='none' stroke='#1f77b4' stroke-width='2' points='{points}'/>",
        f"<text x='{_W / 2}' y='{_H - 10}' text-anchor='middle' font-size='12'>{html.escape(xlabel)}</text>",
        f"<text x='12' y='{_H / 2}' font-size='12' transform='rotate(-90 12 {_H / 2})'>{html.escape(ylabel)}</text>",
        f"<text x='{_PAD - 4}' y='{sy(y_hi) + 4:.1f}' text-anchor='end' font-size='10'>{y_hi:.3g}</text>",
        f"<text x='{_W - _PAD}' y='{sy(0) + 14:.1f}' text-anchor='end' font-size='10'>{x_hi:.3g}</text>",
    ]
    for label, vx, vy in marks:
        if vx is not None and np.isfinite(vx):
            parts.append(
                f"<line x1='{sx(vx):.1f}' y1='{_PAD}' x2='{sx(vx):.1f}' y2='{_H - _PAD}' stroke='#d62728' "
                f"stroke-dasharray='4 3'/><text x='{sx(vx) + 3:.1f}' y='{_PAD + 10}' font-size='10'>"
                f"{html.escape(label)} {vx:.3g}</text>"
            )
        if vy is not None and np.isfinite(vy):
            parts.append(
                f"<line x1='{_PAD}' y1='{sy(vy):.1f}' x2='{_W - _PAD}' y2='{sy(vy):.1f}' stroke='#d62728' "
                f"stroke-dasharray='4 3'/><text x='{_W - _PAD}' y='{sy(vy) - 3:.1f}' text-anchor='end' "
                f"font-size='10'>{html.escape(label)} {vy:.3g}</text>"
            )
    if marker and x.size:
        at = np.maximum.accumulate(np.where(ok, np.arange(ok.size), 0))  # a point without α: the last with one
        pos = {k: (sx(x[np.searchsorted(every, at[k])]), sy(y[np.searchsorted(every, at[k])])) for k in range(ok.size)}
        data = "".join(f" data-x{k}='{px:.1f}' data-y{k}='{py:.1f}'" for k, (px, py) in pos.items())
        parts.append(f"<circle id='curvemark' r='5' fill='#d62728' cx='{pos[0][0]:.1f}' cy='{pos[0][1]:.1f}'{data}/>")
    parts.append("</svg>")
    return "".join(parts)
