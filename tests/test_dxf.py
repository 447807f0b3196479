"""DXF drawings in and out (SPEC §2): cleaning, supports, errors naming the polyline, round trip."""

from __future__ import annotations

import json

import ezdxf
import numpy as np
import pytest

import alma
from alma.cli import main
from alma.geometry.dxf import clean_outline, write_dxf


def _drawing(path, polylines, closed=True):
    """polylines: (layer, points) pairs, written as LWPOLYLINEs."""
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 0  # unitless, read as mm (ezdxf's default is metres)
    msp = doc.modelspace()
    handles = []
    for layer, points in polylines:
        e = msp.add_lwpolyline(points, close=closed, dxfattribs={"layer": layer})
        handles.append(e.dxf.handle)
    msp.add_text("a note, ignored", dxfattribs={"layer": "text"})
    doc.saveas(str(path))
    return handles


GROUND = [(-100, -50), (500, -50), (500, 0), (-100, 0)]
BLOCK = [(0, 0), (100, 0), (100, 400), (0, 400)]


def test_layers_name_the_supports_and_alpha_is_the_rocking_value(tmp_path):
    path = tmp_path / "block.dxf"
    _drawing(path, [("Ground", GROUND), ("0", BLOCK)])
    scene = alma.load_scene(path, thickness=250, friction=0.6)
    assert [b.fixed for b in scene.blocks] == [True, False]
    assert scene.thickness == 250
    assert alma.solve(scene).alpha == pytest.approx(100 / 400, rel=1e-7)  # rocking: b/h


def test_lowest_supports_for_drawings_all_on_layer_0(tmp_path):
    path = tmp_path / "block.dxf"
    _drawing(path, [("0", GROUND), ("0", BLOCK)])
    with pytest.raises(alma.SceneError, match=r"no support.*lowest"):
        alma.load_scene(path)
    scene = alma.load_scene(path, supports="lowest")
    assert [b.fixed for b in scene.blocks] == [True, False]


def test_closing_duplicate_repeated_and_collinear_vertices_are_dropped(tmp_path):
    path = tmp_path / "messy.dxf"
    messy = [(0, 0), (50, 0), (50, 0), (100, 0), (100, 400), (0, 400), (0, 0)]  # open, ends on its start
    _drawing(path, [("fixed", [*GROUND, GROUND[0]]), ("0", messy)], closed=False)
    scene = alma.load_scene(path)
    assert len(scene.blocks[1].vertices) == 4


def test_an_outline_drawn_past_its_closing_point_is_cleaned():
    a, b, c, d = (0.0, 0.0), (100.0, 0.0), (100.0, 50.0), (0.0, 50.0)
    cleaned = clean_outline(np.array([a, b, c, d, a, (100.0 + 1e-12, 1e-12)]), 1e-6)
    assert cleaned.tolist() == [list(a), list(b), list(c), list(d)]


def test_a_self_intersecting_polyline_is_refused_naming_layer_and_handle(tmp_path):
    path = tmp_path / "bad.dxf"
    bow = [(0, 0), (100, 400), (100, 0), (0, 400)]
    handles = _drawing(path, [("fixed", GROUND), ("bricks", bow)])
    with pytest.raises(alma.SceneError, match=f"bricks/{handles[1]}"):
        alma.load_scene(path)


def test_a_non_convex_free_block_is_refused_but_a_notched_support_is_accepted(tmp_path):
    notch = [(-100, -50), (500, -50), (500, 0), (100, 0), (100, -20), (0, -20), (0, 0), (-100, 0)]
    ell = [(0, -20), (100, -20), (100, 100), (50, 100), (50, 200), (0, 200)]
    path = tmp_path / "notch.dxf"
    _drawing(path, [("support", notch), ("0", [(0, -20), (100, -20), (100, 200), (0, 200)])])
    assert alma.solve(alma.load_scene(path)).status in ("optimal", "no_collapse")
    path = tmp_path / "ell.dxf"
    handles = _drawing(path, [("support", notch), ("0", ell)])
    with pytest.raises(alma.SceneError, match=f"0/{handles[1]}.*not convex"):
        alma.load_scene(path)


def test_round_trip_keeps_joints_and_alpha(tmp_path):
    panel = alma.paper_panel("english", "2:1", "2:1", 0.6)
    path = tmp_path / "panel.dxf"
    write_dxf(panel, path)
    back = alma.load_scene(path, thickness=panel.thickness, unit_weight=panel.unit_weight, friction=panel.friction)
    assert alma.find_joints(back).count == alma.find_joints(panel).count
    assert alma.solve(back).alpha == pytest.approx(alma.solve(panel).alpha, rel=1e-9)


def test_cli_solves_a_dxf_with_materials_and_exports_one(tmp_path, capsys):
    out = tmp_path / "panel.dxf"
    assert (
        main(
            [
                "panel",
                "--bond",
                "stack",
                "--panel-ratio",
                "2:1",
                "--block-ratio",
                "4:1",
                "--friction",
                "0.6",
                "--export-scene",
                str(out),
                "--json",
            ]
        )
        == 0
    )
    panel_alpha = json.loads(capsys.readouterr().out)["alpha"]
    assert main(["solve", str(out), "--friction", "0.6", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["alpha"] == pytest.approx(panel_alpha, rel=1e-9)
    json_scene = tmp_path / "scene.json"
    json_scene.write_text(json.dumps(alma.paper_panel("stack", "2:1", "4:1", 0.6).to_dict()))
    # A JSON scene holds its own materials; an option given replaces the top-level value, never
    # silently ignored.
    assert main(["solve", str(json_scene), "--friction", "0.3", "--json"]) == 0
    expected = alma.solve(alma.paper_panel("stack", "2:1", "4:1", 0.3)).alpha
    assert json.loads(capsys.readouterr().out)["alpha"] == pytest.approx(expected, rel=1e-9)


def test_unreadable_dxf_is_a_clear_error(tmp_path):
    path = tmp_path / "broken.dxf"
    path.write_text("not a drawing")
    with pytest.raises(alma.SceneError, match="cannot be read"):
        alma.load_scene(path)
