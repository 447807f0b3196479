"""A step that drives one block into another stops where they first touch.

The blocks move along the mechanism of the last configuration; only its contacts are held
(:mod:`alma.push.corrector`).  A corner that the mechanism moves towards a block it does not
touch yet (a face that opened at first order, a course turning into the one above) would pass
through it over a finite step.  After each step the overlaps of the blocks' outlines are
measured (depth = 2 area / perimeter of the intersection, the width of a sliver, as
:func:`alma.geometry.polygons.find_overlaps` measures them), each against its depth in the
drawing (a drawing's own overlaps within the contact tolerance stay as they are).  When one has
grown by more than half the contact tolerance, the step is bisected to where it has grown by
between an eighth and a half of it: the corner then lies within the tolerance of the face, so
:func:`alma.geometry.contacts.find_joints` finds it as a contact (a corner on a face, a joint of
zero length) and the next analysis carries it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from alma.geometry.polygons import overlap_depths as outline_overlaps
from alma.geometry.scene import Scene

#: A trial's growth that the landing's secant uses, as a share of the contact tolerance: the
#: overlaps' round-off (1e-10 to 1e-5 of it, measured on the paper panels) would send the secant
#: anywhere; real growth past the touch is linear from there.
GREW = 1e-2


def overlap_depths(scene: Scene) -> dict[tuple[int, int], float]:
    """Each pair of blocks (i < j) whose outlines overlap, with the overlap's depth (mm)."""
    counts = [len(b.vertices) for b in scene.blocks]
    return depths(np.concatenate([b.vertices for b in scene.blocks]), np.repeat(np.arange(len(counts)), counts))


def depths(vertices: np.ndarray, owner: np.ndarray, among: np.ndarray | None = None) -> dict[tuple[int, int], float]:
    """:func:`overlap_depths` of outlines given as ``vertices`` (V, 2) mm and the block of each
    (V,); ``among`` (bool per block): only the pairs with at least one such block."""
    a, b, depth = outline_overlaps(vertices, owner, among)
    return {(int(x), int(y)): float(z) for x, y, z in zip(a, b, depth, strict=True) if z > 0}


def grown(before: dict[tuple[int, int], float], after: dict[tuple[int, int], float]) -> float:
    """The largest growth of an overlap from ``before`` to ``after`` (mm; 0 when none grew)."""
    return max((depth - before.get(pair, 0.0) for pair, depth in after.items()), default=0.0)


def landing(
    growth_at: Callable[[float], float | None],
    lo: float,
    hi: float,
    snap: float,
    iterations: int,
    at_hi: float | None = None,
    width: float = 0.0,
) -> float | None:
    """The control displacement in (lo, hi) where the first new contact touches.

    ``growth_at(d)``: the overlaps' largest growth at d (mm), None where no motion reaches d;
    at ``lo`` none has grown, at ``hi`` one has grown by more than ``snap`` / 2 (``at_hi`` when
    the caller measured it).  Returns a d where the growth lies in (``snap`` / 8, ``snap`` / 2],
    else the largest d reached with less growth, or None when no d past ``lo`` was reached
    within ``iterations`` trials or before the bracket is ``width`` mm wide (where the growth
    jumps across the band, as where the corrector's motion changes branch, no trial lands in it).

    The growth is zero until the blocks touch and then about proportional to d: once two
    trials have grown by more than ``GREW`` × ``snap``, the next is the secant's point of the
    band's middle (``snap`` / 4) through the two such trials of least d (nearest the touch);
    until then, and where that point leaves (lo, hi), the bisection.
    """
    best, grew = None, [] if at_hi is None else [(hi, at_hi)]
    for _ in range(iterations):
        if hi - lo <= width:
            break
        mid = 0.5 * (lo + hi)
        if len(grew) >= 2:
            (d1, g1), (d2, g2) = sorted(grew)[:2]
            guess = d1 + (0.25 * snap - g1) * (d2 - d1) / (g2 - g1) if g2 != g1 else math.nan
            mid = guess if lo < guess < hi else mid
        growth = growth_at(mid)
        if growth is None or growth > 0.5 * snap:
            hi = mid
        elif growth > 0.125 * snap:
            return mid
        else:
            lo = best = mid
        if growth is not None and growth > GREW * snap:
            grew.append((mid, growth))
    return best
