"""``alma settle SCENE --capacity`` (issue 33, item 4): one JSON object, a picture, clear errors."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

# A lintel on a fixed support and on a frictionless pier that sinks (verification/test_settlement_capacity.py):
# s_u = (b − c) f / √(1 + f²) = 300 · 0.5 / √1.25 mm.
LINTEL = {
    "name": "lintel over a sinking pier",
    "thickness": 100,
    "unit_weight": 20,
    "friction": 0.5,
    "blocks": [
        {"id": "support", "vertices": [[-200, -100], [100, -100], [100, 0], [-200, 0]], "fixed": True},
        {
            "id": "pier",
            "vertices": [[100, -100], [700, -100], [700, 0], [100, 0]],
            "fixed": True,
            "settlement": {"translation": [0, -1]},
        },
        {"id": "lintel", "vertices": [[0, 0], [400, 0], [400, 300], [0, 300]]},
    ],
    "joints": [{"blocks": ["lintel", "pier"], "friction": 0.0}],
}


def _alma(*args, cwd):
    return subprocess.run([sys.executable, "-m", "alma.cli", *args], capture_output=True, text=True, cwd=cwd)


def _scene(tmp_path: Path, scene: dict, name: str = "scene.json") -> Path:
    (tmp_path / name).write_text(json.dumps(scene))
    return tmp_path


def test_capacity_json_is_one_object_with_s_u_the_curve_and_the_cracks(tmp_path):
    out = _alma("settle", "scene.json", "--capacity", "--json", "--plot", "cap.png", cwd=_scene(tmp_path, LINTEL))
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)  # exactly one object: json.loads refuses anything after it
    assert data["status"] == "optimal" and data["support"] == "pier" and data["unit"] == "mm"
    assert data["s_u"] == pytest.approx(150 / math.sqrt(1.25), rel=1e-6)
    lo, hi = data["s_u_bracket"]
    assert lo <= data["s_u"] <= hi and hi - lo < 1e-4
    assert data["factor_u"] == pytest.approx(data["s_u"])  # the scene's settlement is 1 mm
    first, last = data["curve"][0], data["curve"][-1]
    assert (
        first["s"] == 0.0
        and first["alpha"] > 0
        and sorted(first["cracked"]) == [["lintel", "pier"], ["lintel", "support"]]
    )
    assert last["alpha"] is None or last["alpha"] <= 0
    assert (tmp_path / "cap.png").stat().st_size > 0


def test_capacity_with_the_friction_model_says_which_model(tmp_path):
    # with friction the lintel rests wholly on the frictionless pier and slides at α = 0: no capacity
    out = _alma(
        "settle", "scene.json", "--capacity", "--model", "nonassociative", "--json", cwd=_scene(tmp_path, LINTEL)
    )
    data = json.loads(out.stdout)
    assert data["model"] == "nonassociative" and data["status"] == "no_equilibrium", out.stderr
    assert "before any settlement" in data["message"] and "Traceback" not in out.stderr


def test_capacity_html_has_one_frame_per_step_under_a_slider(tmp_path):
    out = _alma("settle", "scene.json", "--capacity", "--html", "cap.html", cwd=_scene(tmp_path, LINTEL))
    assert out.returncode == 0, out.stderr
    page = (tmp_path / "cap.html").read_text()
    points = page.count('class="frame"')
    assert points > 5 and page.count("cracked at s = ") == points
    assert 'type="range"' in page and "s_u" in page and "http://" not in page.replace("http://www.w3.org", "")


def test_capacity_text_names_the_support_and_s_u(tmp_path):
    out = _alma("settle", "scene.json", "--capacity", cwd=_scene(tmp_path, LINTEL))
    assert out.returncode == 0, out.stderr
    assert "s_u        134.164 mm" in out.stdout and "pier" in out.stdout


def test_shipped_spreading_arch_runs(tmp_path):
    out = _alma("settle", str(EXAMPLES / "spreading_arch.json"), "--capacity", "--json", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["status"] == "optimal" and data["support"] == "abutment_right"
    # three hinges open at once (a spreading arch), and s_u is a finite spread in mm
    assert len(data["curve"][0]["cracked"]) == 3
    assert 0 < data["s_u"] < 1000


def _without_settlement() -> dict:
    scene = json.loads(json.dumps(LINTEL))
    del scene["blocks"][1]["settlement"]
    return scene


def _settlement_on_a_free_block() -> dict:
    scene = json.loads(json.dumps(LINTEL))
    scene["blocks"][2]["settlement"] = {"translation": [0, -1]}
    return scene


def _zero_settlement() -> dict:
    scene = json.loads(json.dumps(LINTEL))
    scene["blocks"][1]["settlement"] = {"translation": [0, 0], "rotation": 0}
    return scene


@pytest.mark.parametrize(
    ("scene", "words"),
    [(_without_settlement(), "settlement"), (_settlement_on_a_free_block(), "lintel"), (_zero_settlement(), "zero")],
)
def test_bad_scene_is_refused_with_exit_2(tmp_path, scene, words):
    out = _alma("settle", "scene.json", "--capacity", "--json", cwd=_scene(tmp_path, scene))
    assert out.returncode == 2
    assert "Traceback" not in out.stderr and words in out.stderr
    assert json.loads(out.stdout)["status"] == "invalid_input"


@pytest.mark.parametrize(
    "extra", [["--steps", "0"], ["--html", "scene.json"], ["--plot", "scene.json"], ["--plot", "nowhere/cap.png"]]
)
def test_bad_options_are_refused_with_exit_2(tmp_path, extra):
    out = _alma("settle", "scene.json", "--capacity", *extra, cwd=_scene(tmp_path, LINTEL))
    assert out.returncode == 2 and "Traceback" not in out.stderr and "invalid input" in out.stderr


@pytest.mark.parametrize("extra", [["--model", "nonassociative"], ["--steps", "5"]])
def test_capacity_options_without_capacity_are_refused(tmp_path, extra):
    out = _alma("settle", "scene.json", *extra, cwd=_scene(tmp_path, LINTEL))
    assert out.returncode == 2 and "Traceback" not in out.stderr and "--capacity" in out.stderr
