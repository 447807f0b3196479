"""The settings that change no result: how pictures are drawn and how drawings are read.

Neither is part of :class:`alma.settings.Settings`, so neither enters its digest; both are
reached from :mod:`alma.settings` as well.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PictureSettings:
    """How ``alma.report`` draws a mechanism (PNG and HTML alike).  Not part of :class:`Settings`:
    no number here changes a result, so none enters its digest."""

    #: Largest displacement drawn, as a share of the scene size: large enough to see a hinge open,
    #: small enough that the blocks keep their place.
    displacement: float = 0.08
    #: Margin around everything drawn, as a share of the scene size (the picture fits the structure).
    margin: float = 0.04
    #: A block moves when its speed reaches this share of the fastest block's (the header's count).
    moving: float = 1e-3
    #: Macro-blocks slower than this share of the fastest block are not outlined (they barely move).
    slow: float = 0.1
    #: Macro-blocks outlined and marked, the largest first: more only clutter the picture.
    max_marked: int = 12
    #: Rigid parts smaller than this share of the largest one's blocks are not marked: they are
    #: the small change of a blended mechanism, and marking them hides the large parts.
    part_share: float = 0.1
    #: Rigid parts of one block are marked only when the mechanism has at most this many parts:
    #: a blend of many single-block parts reads as noise, a few are the mechanism.
    single_parts: int = 4
    #: Significant digits of the numbers a person reads (the JSON keeps the full precision).
    digits: int = 4
    #: Length of a load arrow, as a share of the scene size.
    arrow: float = 0.07
    #: Height of a label's letters, as a share of the scene size (SVG and PNG alike).
    font: float = 0.022


@dataclass(frozen=True)
class DrawingSettings:
    """Reading DXF drawings (``alma.geometry.dxf``); not part of an analysis's settings."""

    #: Sagitta of the chords that replace an arc (bulge) side, as a fraction of its radius: a
    #: 1.6° step; the chords miss 0.014 % of a circular sector's area (below masonry's tolerances).
    arc_sagitta: float = 1e-4
    #: Largest |bulge| read (an arc of 359.5°): beyond it the arc is a whole circle drawn through
    #: two nearly equal points, no side of a block.
    max_bulge: float = 1e3
    #: Spread of z, relative to the outline's size, under which a 3-D polyline is plane: CAD
    #: round-off, not a drawing out of the plane.
    plane_tolerance: float = 1e-9


#: The drawing settings in use.
DRAWING = DrawingSettings()
