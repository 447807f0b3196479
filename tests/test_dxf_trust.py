"""DXF drawings as CAD programs write them (issue 32, item 2): units, mirrored polylines (OCS),
3-D polylines, block INSERTs, arcs (bulges), open polylines, drawings without blocks, and the
export of everything a drawing cannot hold.  Every drawing is made here with ezdxf.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest

import alma
from alma.geometry.dxf import write_dxf
from alma.settings import DRAWING

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
GROUND = [(-300.0, -100.0), (700.0, -100.0), (700.0, 0.0), (-300.0, 0.0)]
BRICK = [(0.0, 0.0), (250.0, 0.0), (250.0, 120.0), (0.0, 120.0)]
WALL = [(0.0, 120.0), (250.0, 120.0), (250.0, 600.0), (0.0, 600.0)]  # a pier on the brick


def _doc(units: int = 0):
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = units
    return doc


def _save(doc, path: Path) -> Path:
    doc.saveas(str(path))
    return path


def _alpha(path: Path, **options) -> float:
    result = alma.solve(alma.load_scene(path, **options))
    assert result.status == "optimal"
    return result.alpha


def _plain(tmp_path: Path, scale: float = 1.0, units: int = 0) -> Path:
    doc = _doc(units)
    msp = doc.modelspace()
    for layer, pts in (("ground", GROUND), ("0", BRICK), ("0", WALL)):
        msp.add_lwpolyline([(x * scale, y * scale) for x, y in pts], close=True, dxfattribs={"layer": layer})
    return _save(doc, tmp_path / f"plain_{units}.dxf")


MATERIALS = dict(friction=0.6, cohesion=20.0, thickness=250.0, unit_weight=18.0)


# ------------------------------------------------------------------------------------------ units


@pytest.mark.parametrize("units, scale", [(6, 1e-3), (5, 0.1), (1, 1 / 25.4), (2, 1 / 304.8), (4, 1.0)])
def test_insunits_are_converted_to_mm(tmp_path, units, scale):
    """Sliding with cohesion, so α depends on the size (f + c l t / W): read 1000 times too
    small, the cohesion would dominate and the stack would rock at 250/600 instead."""
    sliding = dict(MATERIALS, friction=0.3, cohesion=1.0)
    reference = _alpha(_plain(tmp_path), **sliding)
    assert 0.3 < reference < 0.4  # sliding on the ground, cohesion counted
    assert _alpha(_plain(tmp_path, scale, units), **sliding) == pytest.approx(reference, rel=1e-9)


def test_unitless_is_mm_and_unknown_units_are_refused(tmp_path):
    scene = alma.load_scene(_plain(tmp_path, 1.0, 0), **MATERIALS)
    assert np.ptp(scene.blocks[1].vertices[:, 0]) == pytest.approx(250.0)
    doc = ezdxf.readfile(str(_plain(tmp_path)))
    doc.header["$INSUNITS"] = 99
    with pytest.raises(alma.SceneError, match=r"unknown drawing units \$INSUNITS = 99"):
        alma.load_scene(_save(doc, tmp_path / "odd.dxf"))


# ------------------------------------------------------------------------- OCS, 3-D, INSERT


def test_a_polyline_mirrored_in_cad_is_placed_by_its_ocs(tmp_path):
    """Extrusion −Z: OCS x is world −x (the arbitrary axis algorithm)."""
    doc = _doc()
    msp = doc.modelspace()
    msp.add_lwpolyline(GROUND, close=True, dxfattribs={"layer": "ground"})
    for pts in (BRICK, WALL):
        msp.add_lwpolyline([(-x, y) for x, y in pts], close=True, dxfattribs={"layer": "0", "extrusion": (0, 0, -1)})
    mirrored = _save(doc, tmp_path / "mirrored.dxf")
    scene = alma.load_scene(mirrored, **MATERIALS)
    assert np.allclose(np.sort(scene.blocks[1].vertices, axis=0), np.sort(np.array(BRICK), axis=0))
    assert _alpha(mirrored, **MATERIALS) == pytest.approx(_alpha(_plain(tmp_path), **MATERIALS), rel=1e-9)


def test_a_mirrored_2d_polyline_with_an_arc_is_the_lwpolyline(tmp_path):
    """The old POLYLINE entity, mirrored (extrusion −Z, OCS x = −x) with a bulged top, reads as
    the plain LWPOLYLINE drawn in the world (the mirror turns the bulge's sense too)."""

    def drawing(kind: str) -> Path:
        doc = _doc()
        msp = doc.modelspace()
        msp.add_lwpolyline(GROUND, close=True, dxfattribs={"layer": "ground"})
        top = [(0, 0, 0), (250, 0, 0), (250, 120, 0.4), (0, 120, 0)]
        if kind == "plain":
            msp.add_lwpolyline(top, format="xyb", close=True)
        else:
            mirrored = [(-x, y, -b) for x, y, b in top]
            msp.add_polyline2d(mirrored, format="xyb", close=True, dxfattribs={"extrusion": (0, 0, -1)})
        return _save(doc, tmp_path / f"{kind}.dxf")

    plain, mirrored = alma.load_scene(drawing("plain")), alma.load_scene(drawing("mirrored"))
    a, b = plain.blocks[1].vertices, mirrored.blocks[1].vertices
    assert len(a) == len(b) > 4
    assert np.allclose(np.sort(a, axis=0), np.sort(b, axis=0), atol=1e-9)
    assert mirrored.blocks[1].area == pytest.approx(plain.blocks[1].area, rel=1e-12)


def test_plane_3d_polylines_are_read_and_others_refused(tmp_path):
    doc = _doc()
    msp = doc.modelspace()
    msp.add_lwpolyline(GROUND, close=True, dxfattribs={"layer": "ground"})
    for pts in (BRICK, WALL):
        msp.add_polyline3d([(x, y, 7.5) for x, y in pts], close=True)
    assert _alpha(_save(doc, tmp_path / "p3d.dxf"), **MATERIALS) == pytest.approx(
        _alpha(_plain(tmp_path), **MATERIALS), rel=1e-9
    )
    tilted = msp.add_polyline3d([(x, y, 0.1 * x) for x, y in BRICK], close=True)
    with pytest.raises(alma.SceneError, match=f"3-D polyline {tilted.dxf.handle} does not lie in a plane"):
        alma.load_scene(_save(doc, tmp_path / "tilted.dxf"), **MATERIALS)


def test_block_inserts_nested_rotated_and_arrayed_are_exploded(tmp_path):
    doc = _doc()
    brick = doc.blocks.new("BRICK")
    brick.add_lwpolyline([(-125, 0), (125, 0), (125, 120), (-125, 120)], close=True)  # layer 0: the insert's
    pier = doc.blocks.new("PIER")
    pier.add_lwpolyline([(-240, -125), (240, -125), (240, 125), (-240, 125)], close=True)
    pair = doc.blocks.new("PAIR")  # nested: a brick in a block
    pair.add_blockref("BRICK", (0, 0))
    msp = doc.modelspace()
    msp.add_lwpolyline(GROUND, close=True, dxfattribs={"layer": "ground"})
    msp.add_blockref("PAIR", (125, 0), dxfattribs={"layer": "masonry"})
    msp.add_blockref("PIER", (125, 360), dxfattribs={"rotation": 90})  # 250 x 480, on the brick
    scene = alma.load_scene(_save(doc, tmp_path / "inserts.dxf"), **MATERIALS)
    assert len(scene.blocks) == 3 and [b.fixed for b in scene.blocks] == [True, False, False]
    assert scene.blocks[1].id.startswith("masonry/")  # layer 0 inside takes the insert's layer
    assert _alpha(tmp_path / "inserts.dxf", **MATERIALS) == pytest.approx(
        _alpha(_plain(tmp_path), **MATERIALS), rel=1e-9
    )
    arrayed = _doc()
    row = arrayed.blocks.new("ROW")
    row.add_lwpolyline([(0, 0), (100, 0), (100, 50), (0, 50)], close=True)
    msp = arrayed.modelspace()
    msp.add_lwpolyline(GROUND, close=True, dxfattribs={"layer": "ground"})
    msp.add_blockref("ROW", (0, 0)).grid(size=(1, 3), spacing=(50, 100))  # three bricks side by side
    assert len(alma.load_scene(_save(arrayed, tmp_path / "minsert.dxf"), **MATERIALS).blocks) == 4


# ---------------------------------------------------------------------------------- bulges


def test_an_arc_side_is_chords_within_the_stated_sagitta(tmp_path):
    """A brick with a semicircular top (bulge 1): its area is the exact one within the chords'
    stated tolerance, every chord's sagitta is at most arc_sagitta × r."""
    doc = _doc()
    msp = doc.modelspace()
    msp.add_lwpolyline(GROUND, close=True, dxfattribs={"layer": "ground"})
    r = 125.0
    msp.add_lwpolyline([(0, 0, 0), (250, 0, 0), (250, 120, 1.0), (0, 120, 0)], format="xyb", close=True)
    scene = alma.load_scene(_save(doc, tmp_path / "arc.dxf"), **MATERIALS)
    block = scene.blocks[1]
    exact = 250 * 120 + math.pi * r**2 / 2
    step = 2 * math.acos(1 - DRAWING.arc_sagitta)
    assert block.area < exact and (exact - block.area) / (math.pi * r**2 / 2) <= step**2 / 6 * 1.01
    top = block.vertices[block.vertices[:, 1] > 120 + 1e-9]
    assert np.allclose(np.hypot(top[:, 0] - 125, top[:, 1] - 120), r)  # on the arc
    assert len(top) == math.ceil(math.pi / step) - 1
    assert alma.solve(scene).status == "optimal"


def test_two_blocks_sharing_an_arc_share_its_chords(tmp_path):
    """A fixed seat with a concave arc and a block with the convex arc sitting in it: every
    chord is a joint (the two sides are cut at the same points)."""
    doc = _doc()
    msp = doc.modelspace()
    # The seat runs along the arc from (250, 0) to (0, 0) below y = 0 (clockwise, bulge −1)...
    msp.add_lwpolyline(
        [(-100, -300, 0), (350, -300, 0), (350, 0, 0), (250, 0, -1.0), (0, 0, 0), (-100, 0, 0)],
        format="xyb",
        close=True,
        dxfattribs={"layer": "support"},
    )
    # ... and the block's bottom is the same arc from (0, 0) to (250, 0) (counter-clockwise, bulge 1).
    msp.add_lwpolyline([(0, 0, 1.0), (250, 0, 0), (250, 100, 0), (0, 100, 0)], format="xyb", close=True)
    scene = alma.load_scene(_save(doc, tmp_path / "seat.dxf"), **MATERIALS)
    chords = len(scene.blocks[1].vertices) - 3
    assert alma.find_joints(scene).count == chords > 50
    assert alma.solve(scene).status in ("optimal", "no_collapse")


# ---------------------------------------------------------------------- refusals, not guesses


def test_an_open_polyline_is_refused_naming_its_handle(tmp_path):
    doc = _doc()
    msp = doc.modelspace()
    msp.add_lwpolyline(GROUND, close=True, dxfattribs={"layer": "ground"})
    ell = msp.add_lwpolyline([(0, 0), (200, 0), (200, 60), (60, 60), (60, 200), (0, 200)])  # an open L
    with pytest.raises(alma.SceneError, match=f"polyline 0/{ell.dxf.handle} is open"):
        alma.load_scene(_save(doc, tmp_path / "open.dxf"))


def test_a_drawing_without_blocks_says_what_it_holds(tmp_path):
    doc = _doc()
    msp = doc.modelspace()
    for a, b in zip(BRICK, BRICK[1:] + BRICK[:1], strict=True):
        msp.add_line(a, b)
    msp.add_circle((0, 0), 50)
    with pytest.raises(alma.SceneError, match=r"no block .* holds 1 CIRCLE, 4 LINE"):
        alma.load_scene(_save(doc, tmp_path / "lines.dxf"))


def test_a_cut_drawing_is_a_clear_error(tmp_path):
    data = (EXAMPLES / "facade.dxf").read_bytes()
    cut = tmp_path / "cut.dxf"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(alma.SceneError, match="cannot be read"):
        alma.load_scene(cut)


# ----------------------------------------------------------------------------- export, import


def _everything() -> alma.Scene:
    """A façade with overburden, cohesion, a tie, a joint override, a settlement, a weight."""
    wall = alma.wall("running", 1440.0, 720.0, 240.0, 60.0, openings=[(480, 240, 480, 240)], overburden_kpa=50.0)
    data = wall.to_dict()
    data.update(
        cohesion=5.0,
        friction=0.55,
        unit_weight=20.0,
        thickness=250.0,
        gravity=[0.05, -1.0],
        live_load={"direction": [0.8, 0.6], "self_weight": True},
    )
    free = [b for b in data["blocks"] if not b.get("fixed")]
    ground = next(b for b in data["blocks"] if b.get("fixed"))
    top = max(free, key=lambda b: min(v[1] for v in b["vertices"]))
    data["ties"] = [
        {
            "id": "chain",
            "from": {"block": top["id"], "point": np.mean(top["vertices"], axis=0).tolist()},
            "to": {"block": ground["id"], "point": np.mean(ground["vertices"], axis=0).tolist()},
            "strength": 3.0,
        }
    ]
    low = min(free, key=lambda b: min(v[1] for v in b["vertices"]))
    data["joints"] = [{"blocks": [ground["id"], low["id"]], "friction": 0.4, "cohesion": 0.0}]
    ground["settlement"] = {"translation": [0.0, -1.0], "rotation": 0.0, "about": [0.0, 0.0]}
    free[3]["weight"] = 0.05
    return alma.Scene.from_dict(data)


def _scenes() -> dict[str, alma.Scene]:
    scenes = {p.name: alma.load_scene(p) for p in sorted(EXAMPLES.glob("*.json"))}
    scenes["facade.dxf"] = alma.load_scene(EXAMPLES / "facade.dxf")
    scenes["everything"] = _everything()
    return scenes


@pytest.mark.parametrize("name", list(_scenes()))
def test_export_keeps_what_a_drawing_cannot_hold(name, tmp_path):
    scene = _scenes()[name]
    path = tmp_path / "out.dxf"
    write_dxf(scene, path)
    back = alma.load_scene(path)
    original, read = scene.to_dict(), back.to_dict()
    for data in (original, read):
        for block in data["blocks"]:
            block.pop("vertices")
    assert read == original  # ids, supports, materials, loads, ties, overrides, settlements
    assert np.array_equal(
        np.concatenate([b.vertices for b in back.blocks]), np.concatenate([b.vertices for b in scene.blocks])
    )
    a, b = alma.solve(scene), alma.solve(back)
    assert a.status == b.status and a.alpha == pytest.approx(b.alpha, rel=1e-9, abs=1e-12)


def test_options_override_the_stored_materials(tmp_path):
    path = tmp_path / "out.dxf"
    write_dxf(_everything(), path)
    assert alma.load_scene(path).friction == 0.55
    assert alma.load_scene(path, friction=0.3).friction == 0.3


def test_the_overburden_survives_the_cli_export(tmp_path, capsys):
    from alma.cli import main

    out = tmp_path / "facade.dxf"
    assert (
        main(
            [
                "wall",
                "--bond",
                "running",
                "--width",
                "1440",
                "--height",
                "720",
                "--block",
                "240x60",
                "--overburden",
                "50",
                "--export-scene",
                str(out),
                "--json",
            ]
        )
        == 0
    )
    alpha = json.loads(capsys.readouterr().out)["alpha"]
    assert main(["solve", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["alpha"] == pytest.approx(alpha, rel=1e-9)


def _with_brick(kind: str):
    doc = _doc()
    msp = doc.modelspace()
    msp.add_lwpolyline(GROUND, close=True, dxfattribs={"layer": "ground"})
    if kind == "nan bulge":
        e = msp.add_lwpolyline([(0, 0, math.nan), (100, 0, 0), (100, 400, 0), (0, 400, 0)], format="xyb", close=True)
    elif kind == "inf vertex":
        e = msp.add_lwpolyline([(0, 0), (100, 0), (100, math.inf), (0, 400)], close=True)
    elif kind == "full circle bulge":
        e = msp.add_lwpolyline([(0, 0, 1e308), (100, 0, 0), (100, 400, 0), (0, 400, 0)], format="xyb", close=True)
    elif kind == "damaged record":
        e = msp.add_lwpolyline(BRICK, close=True)
        doc.rootdict.add_xrecord("ALMA_SCENE").reset([(1, '{"blocks": 5}')])
    else:  # an arc under a non-uniform scale: CAD explodes it into an ellipse and lines
        brick = doc.blocks.new("B")
        brick.add_lwpolyline([(0, 0, 0.5), (100, 0, 0), (100, 400, 0), (0, 400, 0)], format="xyb", close=True)
        e = msp.add_blockref("B", (0, 0), dxfattribs={"xscale": 2, "yscale": 0.5})
    return doc, e.dxf.handle


@pytest.mark.parametrize(
    "kind, message",
    [
        ("nan bulge", "polyline {h}: vertex 0 is not a finite number"),
        ("inf vertex", "polyline {h}: vertex 2 is not a finite number"),
        ("full circle bulge", "polyline {h}: the bulge 1e\\+308 at vertex 0 draws an arc of nearly a full circle"),
        ("damaged record", "alma record ALMA_SCENE is damaged"),
        (
            "stretched arc",
            "every closed polyline is a support, and the drawing's other entities are not blocks "
            "\\(1 ELLIPSE, 3 LINE\\)",
        ),
    ],
)
def test_bad_entities_are_refused_by_name(kind, message, tmp_path):
    doc, handle = _with_brick(kind)
    with pytest.raises(alma.SceneError, match=message.format(h=handle)):
        alma.load_scene(_save(doc, tmp_path / "bad.dxf"))
