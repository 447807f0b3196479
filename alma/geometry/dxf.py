"""DXF drawings in and out (SPEC §2), with ``ezdxf``.

One closed polyline per block (LWPOLYLINE, 2-D or plane 3-D POLYLINE, also inside block
INSERTs; :mod:`alma.geometry.dxf_entities` reads each, in mm and world coordinates).  An open
polyline is refused, naming its handle, unless it ends on its first point.  The outline is
cleaned before validation: a closing duplicate, an outline drawn past its closing point (a, b,
c, d, a, b′ with b′ ≈ b), repeated and collinear vertices are dropped, within a tolerance
relative to the drawing's block size.  A block's id is ``LAYER/HANDLE``, so that every message
of the validation names the polyline.  Supports: blocks on a layer whose name contains
``fixed``, ``support`` or ``ground`` (any case), or, with ``supports="lowest"``, every block
that reaches the drawing's lowest y.

What a drawing cannot hold — materials, gravity, live load, point loads, ties, settlements,
per-block weights, joint overrides — :func:`write_dxf` stores as the scene's JSON (without the
vertices) in an XRECORD ``ALMA_SCENE`` of the drawing's root dictionary, and each block's id as
XDATA (application ``ALMA``) on its polyline; :func:`read_dxf` reads them back, so an exported
scene is the same scene.  Options given to :func:`read_dxf` (the command line's) override the
stored materials.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from alma.floats import dot
from alma.geometry.dxf_entities import Outline, mm_per_unit, read_outlines
from alma.geometry.parsing import SceneError

#: Vertices closer than this fraction of the median block size are one vertex, and a vertex this
#: close to the line of its neighbours is dropped: CAD round-off, far below the contact tolerance.
VERTEX_TOLERANCE = 1e-7
SUPPORT_WORDS = ("fixed", "support", "ground")
#: Where alma keeps what a drawing cannot hold: an XRECORD of the root dictionary, and the
#: application name of each polyline's XDATA (the block's id).
RECORD = "ALMA_SCENE"
APPID = "ALMA"
#: Characters per string tag of the record (DXF caps a string at 255 bytes in older releases).
_CHUNK = 200
#: Materials a drawing takes from the caller, with their defaults (SPEC §4).
MATERIAL_DEFAULTS = {"thickness": 120.0, "unit_weight": 18.0, "friction": 0.6, "cohesion": 0.0}


def read_dxf(
    path: str | Path, *, supports: str | None = None, name: str | None = None, **materials: float | None
) -> dict[str, Any]:
    """The scene data (SPEC §2) of a DXF drawing (see the module docstring); ``materials``:
    thickness, unit_weight, friction, cohesion or any other top-level scene key (None: the
    drawing's stored value, else the default of SPEC §4).  Validation is the caller's
    (:meth:`Scene.from_dict`)."""
    import ezdxf

    if supports not in (None, "layers", "lowest"):
        raise SceneError(f"supports must be 'layers' or 'lowest', got {supports!r}")
    path = Path(path)
    try:
        document = ezdxf.readfile(str(path))
    except Exception as exc:  # a cut or corrupt file raises from deep inside the parser
        raise SceneError(f"DXF file '{path}': cannot be read ({type(exc).__name__}: {exc})") from exc
    try:
        outlines, skipped = read_outlines(document, mm_per_unit(document))
    except SceneError as exc:
        raise SceneError(f"DXF file '{path}': {exc}") from exc
    if not outlines:
        found = ", ".join(f"{n} {kind}" for kind, n in sorted(skipped.items())) or "no drawing entity"
        raise SceneError(
            f"DXF file '{path}': no block — a block is one closed LWPOLYLINE or POLYLINE (also "
            f"inside a block INSERT); the drawing holds {found}"
        )
    stored = _stored_scene(document, path)
    if not isinstance(stored.get("blocks", []), list):
        raise SceneError(f"DXF file '{path}': its alma record {RECORD} is damaged ('blocks' is not a list)")
    size = float(np.median([np.sqrt(abs(_area(o.vertices))) for o in outlines])) or 1.0
    tol = VERTEX_TOLERANCE * size
    blocks = [_block(o, tol, path) for o in outlines]
    _mark_supports(blocks, supports or "layers", tol, path)
    found = ", ".join(f"{n} {kind}" for kind, n in sorted(skipped.items()))
    if skipped and all(b["fixed"] for b in blocks):
        raise SceneError(
            f"DXF file '{path}': every closed polyline is a support, and the drawing's other "
            f"entities are not blocks ({found}); draw each block as one closed LWPOLYLINE or "
            "POLYLINE"
        )
    if skipped:
        warnings.warn(f"DXF file '{path}': {found} ignored (not closed polylines, so not blocks)", stacklevel=3)
    data = {k: v for k, v in stored.items() if k != "blocks"}
    extras = {b.get("id"): b for b in stored.get("blocks", []) if isinstance(b, dict)}
    data["name"] = name or data.get("name") or path.stem
    for key, default in MATERIAL_DEFAULTS.items():
        data.setdefault(key, default)
    data.update({key: value for key, value in materials.items() if value is not None})  # the caller's win
    data["blocks"] = [
        {
            **{k: v for k, v in extras.get(b["id"], {}).items() if k not in ("id", "vertices", "fixed")},
            **{k: v for k, v in b.items() if k != "layer"},
        }
        for b in blocks
    ]
    return data


def _block(outline: Outline, tol: float, path: Path) -> dict[str, Any]:
    """A block of the scene from a polyline: its id (stored XDATA, else LAYER/HANDLE) and its
    cleaned outline; an open polyline is refused."""
    vertices = outline.vertices
    if len(vertices) < 3:
        raise SceneError(
            f"DXF file '{path}': polyline {outline.layer}/{outline.handle} has {len(vertices)} "
            "vertices; a block needs at least 3"
        )
    if not outline.closed and len(vertices) and not np.any(np.hypot(*(vertices[2:] - vertices[0]).T) <= tol):
        raise SceneError(
            f"DXF file '{path}': polyline {outline.layer}/{outline.handle} is open (it ends at "
            f"{vertices[-1].tolist()}, not on its first point {vertices[0].tolist()}); close it in "
            "the CAD program"
        )
    block_id = _xdata_id(outline.entity) or f"{outline.layer}/{outline.handle}"
    return {"id": block_id, "vertices": clean_outline(vertices, tol).tolist(), "layer": outline.layer}


def _xdata_id(entity: Any) -> str | None:
    if entity is None or not entity.has_xdata(APPID):
        return None
    values = [tag.value for tag in entity.get_xdata(APPID) if tag.code == 1000]
    return str(values[0]) if values else None


def _stored_scene(document: Any, path: Path) -> dict[str, Any]:
    """What :func:`write_dxf` stored of the scene (``{}`` for another program's drawing)."""
    record = document.rootdict.get(RECORD)
    if record is None or record.dxftype() != "XRECORD":
        return {}
    text = "".join(str(tag.value) for tag in record.tags if tag.code == 1)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SceneError(f"DXF file '{path}': its alma record {RECORD} is damaged ({exc.msg})") from exc
    if not isinstance(data, dict):
        raise SceneError(f"DXF file '{path}': its alma record {RECORD} is not a scene")
    return data


def write_dxf(scene: Any, path: str | Path) -> None:
    """Write ``scene`` as a DXF of the same convention: one closed LWPOLYLINE per block (its id
    as XDATA), supports on layer ``fixed``, the others on layer ``blocks``, in mm
    (``$INSUNITS`` 4), and the rest of the scene in the XRECORD :data:`RECORD`."""
    import ezdxf

    document = ezdxf.new()
    document.header["$INSUNITS"] = 4
    document.appids.add(APPID)
    space = document.modelspace()
    data = scene.to_dict()
    for block, entry in zip(scene.blocks, data["blocks"], strict=True):
        polyline = space.add_lwpolyline(
            [tuple(map(float, v)) for v in block.vertices],
            close=True,
            dxfattribs={"layer": "fixed" if block.fixed else "blocks"},
        )
        polyline.set_xdata(APPID, [(1000, str(block.id))])
        entry.pop("vertices")
    text = json.dumps(data, allow_nan=False, separators=(",", ":"))
    record = document.rootdict.add_xrecord(RECORD)
    record.reset([(1, text[k : k + _CHUNK]) for k in range(0, len(text), _CHUNK)])
    document.saveas(str(path))


def clean_outline(vertices: np.ndarray, tol: float) -> np.ndarray:
    """The outline without a closing duplicate, without the part drawn past its closing point,
    without repeated and collinear vertices (``tol`` in drawing units)."""
    v = np.asarray(vertices, dtype=float)
    closes = np.flatnonzero(np.hypot(*(v[3:] - v[0]).T) <= tol)
    if closes.size:  # the outline comes back to its first vertex: what follows retraces it
        v = v[: 3 + closes[0]]
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
        raise SceneError(
            f"DXF file '{path}': no support — no block is on a layer named fixed, support or "
            f"ground (layers: {layers}); use supports='lowest' (--supports lowest) to fix "
            "every block that reaches the lowest y"
        )


def _area(v: np.ndarray) -> float:
    x, y = v[:, 0], v[:, 1]
    return 0.5 * (dot(x, np.roll(y, -1)) - dot(np.roll(x, -1), y))
