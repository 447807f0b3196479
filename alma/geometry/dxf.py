"""DXF drawings in and out (SPEC §2), with ``ezdxf``.

One LWPOLYLINE (or 2D POLYLINE) per block, closed or ending on its first point; other entities
are ignored.  The outline is cleaned before validation: a closing duplicate, an outline drawn
past its closing point (a, b, c, d, a, b′ with b′ ≈ b), repeated and collinear vertices are
dropped, within a tolerance relative to the drawing's block size.  A block's id is
``LAYER/HANDLE``, so that every message of the validation names the polyline.  Supports: blocks
on a layer whose name contains ``fixed``, ``support`` or ``ground`` (any case), or, with
``supports="lowest"``, every block that reaches the drawing's lowest y.  Lengths in the
drawing's units, taken as mm.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from alma.geometry.parsing import SceneError

#: Vertices closer than this fraction of the median block size are one vertex, and a vertex this
#: close to the line of its neighbours is dropped: CAD round-off, far below the contact tolerance.
VERTEX_TOLERANCE = 1e-7
SUPPORT_WORDS = ("fixed", "support", "ground")


def read_dxf(path: str | Path, *, thickness: float = 120.0, unit_weight: float = 18.0,
             friction: float = 0.6, cohesion: float = 0.0, supports: str = "layers",
             name: str | None = None) -> Any:
    """A validated :class:`~alma.geometry.scene.Scene` from a DXF drawing (see the module docstring)."""
    import ezdxf

    from alma.geometry.scene import Scene

    if supports not in ("layers", "lowest"):
        raise SceneError(f"supports must be 'layers' or 'lowest', got {supports!r}")
    path = Path(path)
    try:
        document = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFError) as exc:
        raise SceneError(f"DXF file '{path}': cannot be read ({exc})") from exc
    outlines = _outlines(document)
    if not outlines:
        raise SceneError(f"DXF file '{path}': no LWPOLYLINE or POLYLINE (one per block is expected)")
    size = float(np.median([np.sqrt(abs(_area(v))) for _, _, v in outlines])) or 1.0
    blocks = []
    for layer, handle, vertices in outlines:
        cleaned = clean_outline(vertices, VERTEX_TOLERANCE * size)
        blocks.append({"id": f"{layer}/{handle}", "vertices": cleaned.tolist(), "layer": layer})
    _mark_supports(blocks, supports, VERTEX_TOLERANCE * size, path)
    data = {"name": name or path.stem, "thickness": thickness, "unit_weight": unit_weight,
            "friction": friction, "cohesion": cohesion,
            "blocks": [{k: v for k, v in b.items() if k != "layer"} for b in blocks]}
    try:
        return Scene.from_dict(data)
    except SceneError as exc:
        raise SceneError(f"DXF file '{path}': {exc} (blocks are named LAYER/HANDLE)") from exc


def write_dxf(scene: Any, path: str | Path) -> None:
    """Write ``scene`` as a DXF of the same convention: one closed LWPOLYLINE per block, supports on
    layer ``fixed``, the others on layer ``blocks`` (materials and loads are not drawn)."""
    import ezdxf

    document = ezdxf.new()
    space = document.modelspace()
    for block in scene.blocks:
        space.add_lwpolyline([tuple(map(float, v)) for v in block.vertices], close=True,
                             dxfattribs={"layer": "fixed" if block.fixed else "blocks"})
    document.saveas(str(path))


def clean_outline(vertices: np.ndarray, tol: float) -> np.ndarray:
    """The outline without a closing duplicate, without the part drawn past its closing point,
    without repeated and collinear vertices (``tol`` in drawing units)."""
    v = np.asarray(vertices, dtype=float)
    closes = np.flatnonzero(np.hypot(*(v[3:] - v[0]).T) <= tol)
    if closes.size:  # the outline comes back to its first vertex: what follows retraces it
        v = v[:3 + closes[0]]
    keep = np.hypot(*(v - np.roll(v, 1, axis=0)).T) > tol
    v = v[keep] if keep.any() else v[:1]
    while len(v) > 3:
        prev, nxt = np.roll(v, 1, axis=0), np.roll(v, -1, axis=0)
        chord = nxt - prev
        cross = chord[:, 0] * (v - prev)[:, 1] - chord[:, 1] * (v - prev)[:, 0]
        straight = np.abs(cross) <= tol * np.hypot(*chord.T)
        straight &= ((v - prev) * chord).sum(axis=1) > 0  # between its neighbours, not a spike
        if not straight.any():
            break
        v = np.delete(v, int(np.flatnonzero(straight)[0]), axis=0)
    return v


def _outlines(document: Any) -> list[tuple[str, str, np.ndarray]]:
    """(layer, handle, vertices) of every polyline of the model space, in drawing order."""
    out = []
    for entity in document.modelspace():
        kind = entity.dxftype()
        if kind == "LWPOLYLINE":
            points = np.array([p[:2] for p in entity.get_points("xy")], dtype=float)
        elif kind == "POLYLINE" and not (entity.is_3d_polyline or entity.is_poly_face_mesh
                                         or entity.is_polygon_mesh):
            points = np.array([tuple(v.dxf.location)[:2] for v in entity.vertices], dtype=float)
        else:
            continue
        out.append((str(entity.dxf.layer), str(entity.dxf.handle), points))
    return out


def _mark_supports(blocks: list[dict[str, Any]], supports: str, tol: float, path: Path) -> None:
    if supports == "lowest":
        lowest = min(float(np.min(np.asarray(b["vertices"])[:, 1])) for b in blocks)
        for b in blocks:
            b["fixed"] = bool(np.min(np.asarray(b["vertices"])[:, 1]) <= lowest + tol)
        return
    for b in blocks:
        b["fixed"] = any(word in b["layer"].lower() for word in SUPPORT_WORDS)
    if not any(b["fixed"] for b in blocks):
        layers = sorted({b["layer"] for b in blocks})
        raise SceneError(f"DXF file '{path}': no support — no block is on a layer named fixed, support or "
                         f"ground (layers: {layers}); use supports='lowest' (--supports lowest) to fix "
                         "every block that reaches the lowest y")


def _area(v: np.ndarray) -> float:
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
