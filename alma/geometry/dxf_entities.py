"""The outlines of a DXF drawing's entities, in the world's XY plane and in millimetres.

What a CAD program may hold for one block, and how each is read:

- LWPOLYLINE and 2-D POLYLINE: vertices in the entity's object coordinate system (OCS), turned
  into world coordinates by the entity's extrusion (a polyline mirrored in CAD has extrusion −Z
  and its x reversed); an extrusion out of the Z axis puts the block out of the drawing's plane
  and is refused, naming the handle;
- 3-D POLYLINE: accepted when all its vertices lie in one plane z = const, refused otherwise;
- INSERT (a block reference, also nested and arrayed): its virtual entities, placed by the
  insert's transformation; entities on layer ``0`` take the insert's layer, as CAD draws them;
- bulges (arc segments): replaced by chords whose sagitta is at most
  :attr:`DrawingSettings.arc_sagitta` of the arc's radius, in equal angle steps, so that two
  blocks sharing an arc share its vertices;
- ``$INSUNITS``: lengths converted to mm; unitless (0: no unit chosen in the CAD program) is
  read as mm; an unknown code is refused.

Other entities (LINE, ARC, CIRCLE, TEXT, HATCH, ...) are not blocks: they are counted, so that
a drawing without any block says what it holds instead.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from alma.display_settings import DRAWING
from alma.geometry.parsing import SceneError

#: Millimetres per drawing unit for each ``$INSUNITS`` code (exact definitions, not ezdxf's
#: rounded table); 0 (unitless) is read as mm.
MM_PER_UNIT: dict[int, float] = {
    0: 1.0,
    1: 25.4,
    2: 304.8,
    3: 1_609_344.0,
    4: 1.0,
    5: 10.0,
    6: 1000.0,
    7: 1e6,
    8: 2.54e-5,
    9: 0.0254,
    10: 914.4,
    11: 1e-7,
    12: 1e-6,
    13: 1e-3,
    14: 100.0,
    15: 1e4,
    16: 1e5,
    17: 1e12,
    21: 1200.0 / 3937.0 * 1000.0,
    22: 1200.0 / 3937.0 * 1000.0 / 12.0,
    23: 1200.0 / 3937.0 * 3000.0,
    24: 1200.0 / 3937.0 * 1000.0 * 5280.0,
}
#: Names of the entity types that can hold a block.
_POLYLINES = ("LWPOLYLINE", "POLYLINE")
#: Entities that never draw a block and are not worth naming (annotations, settings).
_ANNOTATIONS = frozenset(
    {
        "TEXT",
        "MTEXT",
        "DIMENSION",
        "LEADER",
        "MLEADER",
        "ATTDEF",
        "ATTRIB",
        "VIEWPORT",
        "POINT",
        "TOLERANCE",
        "IMAGE",
        "WIPEOUT",
    }
)


@dataclass(frozen=True)
class Outline:
    """One polyline read as a block outline: world XY coordinates in mm."""

    layer: str
    handle: str
    vertices: np.ndarray  # (k, 2), mm
    closed: bool
    entity: Any = None  # the DXF entity (for its XDATA), None for a virtual one


def mm_per_unit(document: Any) -> float:
    """Millimetres per drawing unit from ``$INSUNITS`` (SceneError for an unknown code)."""
    code = document.header.get("$INSUNITS", 0)
    try:
        return MM_PER_UNIT[int(code)]
    except (KeyError, TypeError, ValueError):
        raise SceneError(
            f"unknown drawing units $INSUNITS = {code!r}; set them to "
            "millimetres (4), metres (6) or another length unit in the CAD program"
        ) from None


def read_outlines(document: Any, scale: float) -> tuple[list[Outline], Counter[str]]:
    """The outlines of the model space in drawing order (scaled by ``scale`` to mm), and the
    count of the entity types that hold no block."""
    outlines: list[Outline] = []
    skipped: Counter[str] = Counter()
    for entity, layer, handle in _flat_entities(document.modelspace(), None, ""):
        kind = entity.dxftype()
        if kind in _POLYLINES and not _is_mesh(entity):
            points, closed = _entity_points(entity, handle)
            outlines.append(Outline(layer, handle, scale * points, closed, entity if not handle.count(":") else None))
        elif kind not in _ANNOTATIONS:
            skipped["POLYLINE (mesh)" if kind == "POLYLINE" else kind] += 1
    return outlines, skipped


def _flat_entities(space: Any, insert_layer: str | None, prefix: str) -> Iterator[tuple[Any, str, str]]:
    """(entity, layer, handle) of every entity, with INSERTs replaced by their virtual entities
    (recursively; a virtual entity's handle is ``INSERT:k``)."""
    for k, entity in enumerate(space):
        handle = str(entity.dxf.handle) if not prefix else f"{prefix}:{k}"
        layer = str(entity.dxf.layer)
        if insert_layer is not None and layer == "0":
            layer = insert_layer
        if entity.dxftype() != "INSERT":
            yield entity, layer, handle
            continue
        inserts = list(entity.multi_insert()) if entity.mcount > 1 else [entity]
        for m, insert in enumerate(inserts):
            try:
                virtual = list(insert.virtual_entities())
            except Exception as exc:  # e.g. a non-uniform scale of an arc: not a rigid copy
                raise SceneError(f"INSERT {handle} (block {entity.dxf.name!r}) cannot be exploded ({exc})") from exc
            yield from _flat_entities(virtual, layer, handle if len(inserts) == 1 else f"{handle}:{m}")


def _is_mesh(entity: Any) -> bool:
    return entity.dxftype() == "POLYLINE" and (entity.is_poly_face_mesh or entity.is_polygon_mesh)


def _entity_points(entity: Any, handle: str) -> tuple[np.ndarray, bool]:
    """World XY points of a polyline (bulges replaced by chords) and whether it is closed."""
    if entity.dxftype() == "LWPOLYLINE":
        xyb = np.array([p for p in entity.get_points("xyb")], dtype=float).reshape(-1, 3)
        closed = bool(entity.closed)
        elevation = float(entity.dxf.elevation)
    elif entity.is_3d_polyline:
        xyz = np.array([tuple(v.dxf.location) for v in entity.vertices], dtype=float).reshape(-1, 3)
        _check_finite(xyz, handle)
        return _in_one_plane(xyz, handle), bool(entity.is_closed)
    else:
        vertices = list(entity.vertices)
        xyb = np.array([(*tuple(v.dxf.location)[:2], v.dxf.bulge) for v in vertices], dtype=float).reshape(-1, 3)
        closed = bool(entity.is_closed)
        elevation = float(entity.dxf.elevation[2]) if entity.dxf.hasattr("elevation") else 0.0
    _check_finite(xyb, handle)
    ocs_points = _flatten_bulges(xyb, closed)
    extrusion = tuple(entity.dxf.extrusion) if entity.dxf.hasattr("extrusion") else (0.0, 0.0, 1.0)
    if abs(abs(extrusion[2]) - math.hypot(*extrusion)) > 1e-9 * math.hypot(*extrusion):
        raise SceneError(
            f"polyline {handle} is not drawn in the XY plane (extrusion {extrusion}); alma reads plane drawings"
        )
    ocs = entity.ocs()
    wcs = np.array([tuple(p) for p in ocs.points_to_wcs([(x, y, elevation) for x, y in ocs_points])], dtype=float)
    return wcs.reshape(-1, 3)[:, :2], closed


def _check_finite(values: np.ndarray, handle: str) -> None:
    """Refuse NaN or infinite coordinates or bulges, and bulges of nearly a full circle."""
    bad = ~np.isfinite(values).all(axis=1)
    if bad.any():
        raise SceneError(
            f"polyline {handle}: vertex {int(np.flatnonzero(bad)[0])} is not a finite number "
            f"({values[bad][0].tolist()})"
        )
    if values.shape[1] == 3 and np.any(np.abs(values[:, 2]) > DRAWING.max_bulge):
        k = int(np.flatnonzero(np.abs(values[:, 2]) > DRAWING.max_bulge)[0])
        raise SceneError(
            f"polyline {handle}: the bulge {values[k, 2]:.6g} at vertex {k} draws an arc of nearly a "
            "full circle, which is no side of a block"
        )


def _in_one_plane(xyz: np.ndarray, handle: str) -> np.ndarray:
    """The XY of a 3-D polyline's vertices, which must share one z (refused otherwise)."""
    if len(xyz):
        extent = float(np.ptp(xyz[:, :2], axis=0).max()) or 1.0
        spread = float(np.ptp(xyz[:, 2]))
        if spread > DRAWING.plane_tolerance * extent:
            raise SceneError(
                f"3-D polyline {handle} does not lie in a plane z = const (its z spans {spread:.6g} "
                "drawing units); alma reads plane drawings"
            )
    return xyz[:, :2]


def _flatten_bulges(xyb: np.ndarray, closed: bool) -> np.ndarray:
    """The points of a polyline with each bulged segment replaced by chords on its arc (OCS)."""
    n = len(xyb)
    out = []
    for k in range(n):
        out.append(xyb[k, :2])
        bulge = xyb[k, 2]
        if bulge == 0.0 or (k == n - 1 and not closed):
            continue
        out.extend(arc_points(xyb[k, :2], xyb[(k + 1) % n, :2], float(bulge)))
    return np.array(out, dtype=float).reshape(-1, 2)


def arc_points(start: np.ndarray, end: np.ndarray, bulge: float) -> list[np.ndarray]:
    """The inner points of the chords approximating the arc from ``start`` to ``end`` of
    ``bulge`` (tan of a quarter of its angle, positive counter-clockwise): equal angle steps,
    each chord's sagitta at most :attr:`DrawingSettings.arc_sagitta` × the radius."""
    chord = end - start
    length = math.hypot(*chord)
    if length == 0.0:
        return []
    angle = 4.0 * math.atan(bulge)  # signed sweep
    radius = length / (2.0 * abs(math.sin(angle / 2.0)))
    step = 2.0 * math.acos(1.0 - DRAWING.arc_sagitta)
    count = max(1, math.ceil(abs(angle) / step - 1e-9))
    # Centre: on the chord's perpendicular bisector, to the left for a positive bulge.
    normal = np.array([-chord[1], chord[0]]) / length
    centre = 0.5 * (start + end) + normal * radius * math.cos(angle / 2.0) * math.copysign(1.0, angle)
    first = math.atan2(start[1] - centre[1], start[0] - centre[0])
    return [
        centre + radius * np.array([math.cos(first + angle * i / count), math.sin(first + angle * i / count)])
        for i in range(1, count)
    ]
