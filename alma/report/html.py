"""The HTML report (issues 18, 36; SPEC §3 ``--html``): one self-contained page per command.

:func:`write_html` for ``solve``/``panel``/``wall``/``arch`` (both models side by side, one
scale), :func:`write_settlement_html` for ``settle``, :func:`write_tilt_html` for ``tilt``.
Each builds the drawings (:mod:`alma.report.drawing`), says the result in words
(:mod:`alma.report.summary`) and lays out the page (:mod:`alma.report.page`).  Lengths in mm,
forces in kN, moments in kN·mm, as in the JSON of SPEC §3.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from alma.geometry.scene import Scene
from alma.report.drawing import draw
from alma.report.numbers import number
from alma.report.page import Frame, build_page
from alma.report.picture import StillPicture
from alma.report.summary import caption, parts, settle_header, solve_header, tilt_header


def write_html(scene: Scene, result: Any, path: str | Path, *, title: str | None = None, thrust: bool = False) -> Path:
    """Write the report of ``result`` (a result of :func:`alma.solve`, ``both`` included) on
    ``scene``; the line of thrust shown from the start with ``thrust`` (a switch on the page)."""
    results = parts(result)
    drawings = [draw(scene, r) for r in results]
    frames = [Frame(caption(r, d), d) for r, d in zip(results, drawings, strict=True)]
    page = build_page(title or scene.name or "alma", solve_header(result, drawings), frames, thrust=thrust)
    return _write(path, page)


def write_settlement_html(scene: Scene, result: Any, path: str | Path, *, title: str | None = None) -> Path:
    """Write the report of :func:`alma.settle`: the settling support moved by its settlement,
    the mechanism it drives, the crack pattern and the reactions."""
    drawing = draw(scene, StillPicture.of(result), settling=True)
    frame = Frame(f"settlement mechanism: {len(result.opened)} joints open", drawing)
    header = settle_header(scene, result, drawing)
    return _write(path, build_page(title or scene.name or "alma settle", header, [frame]))


def write_tilt_html(
    scene: Scene, result: Any, collapse: Any | None, path: str | Path, *, title: str | None = None
) -> Path:
    """Write the report of :func:`alma.tilt`; ``collapse`` is the solve of the scene on the table
    tilted to θ_c (:func:`alma.tilt.tilted`), whose mechanism the page draws (None: the scene
    at rest)."""
    picture = collapse if collapse is not None else StillPicture.of(result, status="no_collapse")
    angle = result.angle_deg if math.isfinite(result.angle_deg) else 0.0
    drawing = draw(scene, picture, gravity_deg=angle)
    frame = Frame(f"collapse on the table tilted to {caption_angle(result)}", drawing)
    return _write(path, build_page(title or scene.name or "alma tilt", tilt_header(result, drawing), [frame]))


def caption_angle(result: Any) -> str:
    """ "θ_c = 27.31°" (— where no angle is proven)."""
    return f"θ_c = {number(result.angle_deg)}°"


def _write(path: str | Path, page: str) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(page, encoding="utf-8")
    return path
