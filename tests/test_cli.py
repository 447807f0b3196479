"""Command-line contract of SPEC §3 (exit codes, one JSON object, scene export)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from alma.cli.main import main

SCENE = {
    "name": "single block on the ground",
    "thickness": 120,
    "unit_weight": 18.0,
    "friction": 0.6,
    "cohesion": 0.0,
    "blocks": [
        {"id": "ground", "vertices": [[-100, -50], [400, -50], [400, 0], [-100, 0]], "fixed": True},
        {"id": "b1", "vertices": [[0, 0], [240, 0], [240, 60], [0, 60]]},
    ],
    "live_load": {"direction": [1, 0]},
}


def test_solve_json_is_one_object(tmp_path, capsys):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(SCENE))
    assert main(["solve", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "optimal"
    assert out["alpha"] == pytest.approx(0.6, abs=1e-9)
    assert out["bounds"]["lower"] <= out["alpha"] <= out["bounds"]["upper"]
    assert out["blocks"][0]["id"] == "b1"
    u, v, theta = out["blocks"][0]["u"]
    assert (u, v, theta) == pytest.approx((1.0, 0.6, 0.0), abs=1e-7)  # dilatant sliding, f_Lᵀu = 1
    (joint,) = out["joints"]
    assert joint["blocks"] == ["ground", "b1"] and joint["state"] == "sliding"
    weight = 240 * 60 * 120 * 18e-9
    assert joint["N"] == pytest.approx(weight, rel=1e-7)
    assert joint["T"] == pytest.approx(0.6 * weight, rel=1e-7)
    assert set(out["timings"]) >= {"build_s", "solve_s"}


def test_bad_scene_exit_code_2(tmp_path, capsys):
    bad = dict(SCENE, thickness=-1)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(bad))
    assert main(["solve", str(path)]) == 2
    err = capsys.readouterr().err
    assert "thickness" in err


def test_missing_file_exit_code_2(tmp_path, capsys):
    assert main(["solve", str(tmp_path / "nope.json")]) == 2
    assert "cannot be read" in capsys.readouterr().err


def test_panel_export_scene_round_trip(tmp_path, capsys):
    out_scene = tmp_path / "panel.json"
    plot = tmp_path / "panel.png"
    assert (
        main(
            [
                "panel",
                "--bond",
                "running",
                "--panel-ratio",
                "2:1",
                "--block-ratio",
                "4:1",
                "--friction",
                "0.6",
                "--json",
                "--export-scene",
                str(out_scene),
                "--plot",
                str(plot),
            ]
        )
        == 0
    )
    first = json.loads(capsys.readouterr().out)
    assert plot.stat().st_size > 10_000
    assert main(["solve", str(out_scene), "--json"]) == 0
    second = json.loads(capsys.readouterr().out)
    assert second["alpha"] == pytest.approx(first["alpha"], abs=1e-9)


def test_model_both_reports_ratio(capsys):
    code = main(
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
            "--model",
            "both",
            "--json",
            "--effort",
            "fast",
        ]
    )
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["model"] == "both"
    assert out["alpha_nonassociative"] == out["alpha"] <= out["alpha_associative"] + 1e-7
    assert out["ratio"] == pytest.approx(out["alpha"] / out["alpha_associative"])
    assert out["start"] and out["candidates"]


def test_certify_needs_nonassociative_model(capsys):
    code = main(
        ["panel", "--bond", "stack", "--panel-ratio", "2:1", "--block-ratio", "4:1", "--friction", "0.6", "--certify"]
    )
    assert code == 2
    assert "non-associative" in capsys.readouterr().err


def test_console_script_entry_point(tmp_path):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(SCENE))
    proc = subprocess.run(
        [sys.executable, "-m", "alma.cli", "solve", str(path), "--json"], capture_output=True, text=True, check=True
    )
    assert json.loads(proc.stdout)["status"] == "optimal"


def test_certify_json_stdout_is_one_object(tmp_path):
    """HiGHS' MIP prints on the C-level stdout; --json must still print exactly one object."""
    blocks = [{"id": "g", "vertices": [[-1, -1], [4, -1], [4, 0], [-1, 0]], "fixed": True}]
    blocks += [{"id": f"b{i}", "vertices": [[i, 0], [i + 1, 0], [i + 1, 2], [i, 2]]} for i in range(3)]
    path = tmp_path / "three.json"
    path.write_text(json.dumps({"friction": 1.0, "blocks": blocks}))
    proc = subprocess.run(
        [sys.executable, "-m", "alma.cli", "solve", str(path), "--model", "nonassociative", "--certify", "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    out = json.loads(proc.stdout)
    assert out["alpha"] == pytest.approx(0.5, abs=1e-7)
    assert out["certificate"]["status"] == "proven"
    assert out["bounds"]["lower"] == pytest.approx(0.5, abs=1e-6)
