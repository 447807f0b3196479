"""The drawing layer's vocabulary (issue 36): a picture is a list of :class:`Mark`, each of a mark
class with one legend entry, drawn the same way by the SVG (:mod:`alma.report.svg`) and the
matplotlib (:mod:`alma.report.mpl`) renderers.

Colours: the joint states keep orange, red and blue; macro-blocks get colours of their own
(:data:`MACRO_COLOURS`, none of the joint states'); loads are black or grey, ties purple,
settlements brown, the line of thrust violet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Colours of the joint states (the joints at rest are not drawn).
STATE_COLOURS = {"hinging": "#ff7f0e", "sliding": "#d62728", "separating": "#1f77b4", "crushing": "#6a3d9a"}
#: Macro-block outlines, the largest macro-block first: no joint state's colour among them.
MACRO_COLOURS = ("#1b9e77", "#b8860b", "#17becf", "#66a61e", "#e7298a", "#7f7f7f")
THRUST_COLOUR = "#9400d3"
TIE_COLOUR = "#6a3d9a"
SETTLEMENT_COLOUR = "#8c510a"
LIVE_COLOUR = "#000000"
DEAD_COLOUR = "#555555"
REST_FILL = "#f2f2f2"
MOVING_FILL = "#e9dcc0"
SUPPORT_FILL = "#d9d9d9"


@dataclass(frozen=True, eq=False)
class Mark:
    """One thing drawn: a ``polygon`` (closed), a ``line`` (open polyline), a ``point`` (marker
    ``o`` hinge, ``x`` centre, ``*`` crushing, ``.`` dot) or a ``text``, of mark class ``cls``.

    ``xy`` (k, 2) in mm at rest; ``carrier`` the blocks (scene indices, −1 standing still) whose
    mean rigid motion carries the mark when the mechanism is drawn displaced.  ``width`` in
    points (pixels in SVG), ``size`` the marker's radius or the letters' height in mm.
    """

    kind: str
    cls: str
    xy: np.ndarray
    carrier: tuple[int, ...] = ()
    stroke: str | None = None
    fill: str | None = None
    width: float = 1.0
    dash: bool = False
    hatch: bool = False
    size: float = 0.0
    text: str = ""
    title: str = ""
    anchor: str = "middle"


@dataclass(frozen=True)
class LegendEntry:
    """How the legend shows a mark class: its words and a swatch (``line``, ``patch``, a marker)."""

    label: str
    swatch: str
    colour: str
    fill: str | None = None
    dash: bool = False
    hatch: bool = False


#: One entry per mark class, in the order the legend lists them.
LEGEND: dict[str, LegendEntry] = {
    "support": LegendEntry("support (fixed)", "patch", "#333333", SUPPORT_FILL, hatch=True),
    "block-rest": LegendEntry("block at rest", "patch", "#777777", REST_FILL),
    "block-moving": LegendEntry("moving block, drawn displaced", "patch", "#333333", MOVING_FILL),
    "crack": LegendEntry("crack (width ∝ relative motion)", "line", "#000000"),
    "macro": LegendEntry("rigid part of the mechanism (one colour each)", "line", MACRO_COLOURS[0]),
    "hinge": LegendEntry("hinge", "o", "#000000", "#ffffff"),
    "centre": LegendEntry("rotation centre", "x", MACRO_COLOURS[0]),
    "translation": LegendEntry("translation of a rigid part", "arrow", MACRO_COLOURS[0]),
    **{f"joint-{s}": LegendEntry(f"{s} joint", "line", c) for s, c in STATE_COLOURS.items() if s != "crushing"},
    "crushing": LegendEntry("crushing joint", "*", STATE_COLOURS["crushing"]),
    "thrust": LegendEntry("line of thrust (centres of pressure)", "line", THRUST_COLOUR),
    "live": LegendEntry("α × live load", "arrow", LIVE_COLOUR),
    "dead": LegendEntry("dead point load", "arrow", DEAD_COLOUR),
    "gravity": LegendEntry("gravity on the tilted table", "arrow", DEAD_COLOUR),
    "tie": LegendEntry("tie (force)", "line", TIE_COLOUR, dash=True),
    "settlement": LegendEntry("prescribed settlement", "arrow", SETTLEMENT_COLOUR),
}


def arrow(
    cls: str,
    tail: np.ndarray,
    head: np.ndarray,
    colour: str,
    head_size: float,
    *,
    carrier: tuple[int, ...] = (),
    width: float = 1.5,
    title: str = "",
) -> list[Mark]:
    """An arrow from ``tail`` to ``head`` (mm) as a shaft and a filled head ``head_size`` mm long:
    explicit geometry, so that SVG and matplotlib draw the same arrow."""
    tail, head = np.asarray(tail, dtype=float), np.asarray(head, dtype=float)
    d = head - tail
    length = float(np.hypot(*d))
    if length == 0:
        return []
    d = d / length
    n = np.array([-d[1], d[0]])
    size = min(head_size, 0.6 * length)
    base = head - size * d
    tip = np.array([head, base + 0.4 * size * n, base - 0.4 * size * n])
    shaft = np.array([tail, base + 0.1 * size * d])
    return [
        Mark("line", cls, shaft, carrier, stroke=colour, width=width, title=title),
        Mark("polygon", cls, tip, carrier, stroke=colour, fill=colour, width=0.5, title=title),
    ]


def label(
    cls: str,
    at: np.ndarray,
    text: str,
    size: float,
    *,
    colour: str = "#000000",
    carrier: tuple[int, ...] = (),
    anchor: str = "middle",
) -> Mark:
    """Words at ``at`` (mm, the baseline's anchor point), ``size`` the letters' height (mm)."""
    return Mark(
        "text",
        cls,
        np.asarray(at, dtype=float).reshape(1, 2),
        carrier,
        fill=colour,
        size=size,
        text=text,
        anchor=anchor,
    )
