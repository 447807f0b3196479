"""The scene options every scene-reading command shares (SPEC §3): solve, tilt and settle read a
DXF drawing of LACT³'s convention (every block on layer 0, supports the lowest blocks) the same
way, and a JSON scene takes an option as a replacement of its own top-level value."""

from __future__ import annotations

import json
import math

import ezdxf
import pytest

import alma
from alma.cli.main import main


def _drawing(path, blocks) -> None:
    """A DXF with every block on layer 0, as LACT³ draws them (no support layer)."""
    document = ezdxf.new()
    document.header["$INSUNITS"] = 4  # mm (ezdxf's new drawings say metres)
    space = document.modelspace()
    for vertices in blocks:
        space.add_lwpolyline(vertices, close=True, dxfattribs={"layer": "0"})
    document.saveas(str(path))


def _rect(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


@pytest.fixture
def block_dxf(tmp_path):
    """A 200 × 100 block on a ground slab, both on layer 0."""
    path = tmp_path / "block.dxf"
    _drawing(path, [_rect(-200, -50, 400, 0), _rect(0, 0, 200, 100)])
    return path


def test_tilt_reads_a_dxf_with_the_scene_options(block_dxf, capsys):
    argv = [
        "tilt",
        str(block_dxf),
        "--supports",
        "lowest",
        "--friction",
        "0.577",
        "--thickness",
        "1",
        "--unit-weight",
        "25",
        "--json",
    ]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    # A block of b/h = 2 on a tilting table slides first: tan θ_c = f.
    assert out["status"] == "optimal"
    assert out["angle_deg"] == pytest.approx(math.degrees(math.atan(0.577)), abs=1e-6)


def test_tilt_of_a_slender_block_rocks_at_atan_b_over_h(tmp_path, capsys):
    path = tmp_path / "slender.dxf"
    _drawing(path, [_rect(-200, -50, 400, 0), _rect(0, 0, 100, 300)])
    assert main(["tilt", str(path), "--supports", "lowest", "--friction", "0.9", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["angle_deg"] == pytest.approx(math.degrees(math.atan(100 / 300)), abs=1e-6)


def test_solve_and_tilt_read_one_drawing_alike(block_dxf, capsys):
    options = ["--supports", "lowest", "--friction", "0.4", "--thickness", "250", "--unit-weight", "20"]
    assert main(["solve", str(block_dxf), *options, "--json"]) == 0
    solved = json.loads(capsys.readouterr().out)
    assert solved["alpha"] == pytest.approx(0.4, rel=1e-7)
    weight = 200 * 100 * 250 * 20e-9  # kN
    assert sum(j["N"] for j in solved["joints"]) == pytest.approx(weight, rel=1e-7)
    scene = alma.load_scene(block_dxf, supports="lowest", friction=0.4, thickness=250, unit_weight=20)
    assert main(["tilt", str(block_dxf), *options, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["angle_deg"] == pytest.approx(alma.tilt(scene).angle_deg, abs=1e-9)


def test_a_json_scene_takes_the_options_as_its_top_level_values(tmp_path, capsys):
    data = {
        "thickness": 120,
        "unit_weight": 18,
        "friction": 0.6,
        "blocks": [
            {"id": "ground", "vertices": _rect(-200, -50, 400, 0), "fixed": True},
            {"id": "b1", "vertices": _rect(0, 0, 200, 100)},
        ],
    }
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    assert main(["tilt", str(path), "--friction", "0.3", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["angle_deg"] == pytest.approx(math.degrees(math.atan(0.3)), abs=1e-6)
    data["joints"] = [{"blocks": ["ground", "b1"], "friction": 0.5}]  # an override keeps its value
    path.write_text(json.dumps(data))
    assert main(["tilt", str(path), "--friction", "0.3", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["angle_deg"] == pytest.approx(math.degrees(math.atan(0.5)), abs=1e-6)


def test_settle_reads_the_options_and_refuses_a_drawing_without_settlement(block_dxf, capsys):
    assert main(["settle", str(block_dxf), "--supports", "lowest", "--friction", "0.5"]) == 2
    assert "settlement" in capsys.readouterr().err


def test_every_scene_command_has_the_same_scene_options(capsys):
    for command in ("solve", "tilt", "settle"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = capsys.readouterr().out
        for flag in ("--thickness", "--unit-weight", "--friction", "--cohesion", "--supports", "--contact-tolerance"):
            assert flag in text, (command, flag)
