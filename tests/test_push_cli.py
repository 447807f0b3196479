"""``alma push`` and ``alma seismic`` on the command line (SPEC §3)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

ROCKING = {
    "name": "slender block",
    "thickness": 120,
    "unit_weight": 18,
    "friction": 0.8,
    "blocks": [
        {"id": "ground", "vertices": [[-500, -100], [800, -100], [800, 0], [-500, 0]], "fixed": True},
        {"id": "wall", "vertices": [[0, 0], [240, 0], [240, 600], [0, 600]]},
    ],
}
SITE = 'ag = 0.2\nF0 = 2.4\nTc_star = 0.3\nsoil = "B"\n'


def _alma(*args, cwd):
    return subprocess.run([sys.executable, "-m", "alma.cli", *args], capture_output=True, text=True, cwd=cwd)


@pytest.fixture()
def files(tmp_path):
    (tmp_path / "scene.json").write_text(json.dumps(ROCKING))
    (tmp_path / "site.toml").write_text(SITE)
    return tmp_path


def test_push_json_is_one_object_with_the_spec_fields(files):
    out = _alma("push", "scene.json", "--steps", "8", "--json", "--plot", "curve.png", cwd=files)
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["status"] == "optimal" and data["control"] == "wall"
    assert data["d0"] == pytest.approx(120.0, abs=1e-4)
    assert data["curve"][0] == {**data["curve"][0], "d": 0.0, "mechanism_changed": False}
    assert (files / "curve.png").stat().st_size > 0


def test_seismic_json(files):
    out = _alma(
        "seismic", "scene.json", "--site", "site.toml", "--steps", "8", "--json", "--html", "check.html", cwd=files
    )
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    for key in ("alpha0", "M_star", "e_star", "a0_star", "demand", "safety_index", "d0_star", "du_star", "Ts"):
        assert data[key] is not None, key
    assert data["nonlinear"]["safety_index"] > 0
    page = (files / "check.html").read_text()
    # α(d), the frames of the mechanism under the slider, a*(d*); no network reference
    assert page.count("<svg") == 3 and "a0_star" in page and "http://" not in page.replace("http://www.w3.org", "")


@pytest.mark.slow
def test_seismic_with_the_friction_model_gives_the_same_check_on_a_rocking_block(files):
    # the block rocks (f = 0.8 > b/h): Eq. 9's states are Eq. 10's, so the check is the same
    args = ("seismic", "scene.json", "--site", "site.toml", "--steps", "6", "--json")
    friction = json.loads(_alma(*args, "--model", "nonassociative", cwd=files).stdout)
    associative = json.loads(_alma(*args, cwd=files).stdout)
    assert friction["status"] == "feasible" and friction["push"]["model"] == "nonassociative"
    assert associative["status"] == "optimal" and associative["push"]["model"] == "associative"
    for key in ("alpha0", "e_star", "a0_star", "d0_star", "safety_index"):
        assert friction[key] == pytest.approx(associative[key], rel=1e-6), key


def test_push_html_has_one_frame_per_step_under_a_slider(files):
    out = _alma("push", "scene.json", "--steps", "8", "--json", "--html", "curve.html", cwd=files)
    assert out.returncode == 0, out.stderr
    steps = len(json.loads(out.stdout)["curve"])
    page = (files / "curve.html").read_text()
    assert page.count('class="frame"') == steps > 8
    assert [f'data-step="{k}"' in page for k in range(steps)] == [True] * steps
    assert f'type="range" min="0" max="{steps - 1}"' in page and page.count("data-x") == steps
    # frame 0 shows, the others wait for the slider
    assert page.count('style="display:none"') == steps - 1


@pytest.mark.parametrize(
    "args, word",
    [
        (("push", "scene.json", "--control", "nope"), "nope"),
        (("push", "scene.json", "--control", "ground"), "fixed"),
        (("seismic", "scene.json", "--site", "missing.toml"), "missing.toml"),
        (("push", "scene.json", "--plot", "scene.json"), "input"),
    ],
)
def test_bad_input_exits_2_with_one_json_object(files, args, word):
    out = _alma(*args, "--json", cwd=files)
    assert out.returncode == 2
    assert json.loads(out.stdout)["status"] == "invalid_input"
    assert word in out.stderr


def test_push_takes_the_compressive_strength_and_keeps_the_json_fields(files):
    """σ_c = 0.05 MPa on the 240 × 600 block: a = W/(σ_c t) = 51.84 mm, α_c = (b − a)/h = 0.3136
    and d₀ = (b − a)/2 = 94.08 mm (verification/test_push_crushing.py derives the curve)."""
    rigid = json.loads(_alma("push", "scene.json", "--steps", "8", "--json", cwd=files).stdout)
    out = _alma("push", "scene.json", "--steps", "8", "--compressive-strength", "0.05", "--json", cwd=files)
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert set(data) == set(rigid) and set(data["curve"][0]) == set(rigid["curve"][0])
    assert data["status"] == "optimal" and data["end"]["reason"] == "alpha_zero"
    assert data["alpha_c"] == pytest.approx(0.3136, abs=1e-7)
    assert data["d0"] == pytest.approx(94.08, abs=1e-4) and rigid["d0"] == pytest.approx(120.0, abs=1e-4)


@pytest.mark.parametrize("value", ["0", "-1", "nan"])
def test_push_refuses_a_bad_compressive_strength_by_name(files, value):
    out = _alma("push", "scene.json", f"--compressive-strength={value}", "--json", cwd=files)
    assert out.returncode == 2
    assert json.loads(out.stdout)["status"] == "invalid_input"
    assert "--compressive-strength" in out.stderr


def test_seismic_takes_the_compressive_strength(files):
    out = _alma(
        "seismic",
        "scene.json",
        "--site",
        "site.toml",
        "--steps",
        "8",
        "--compressive-strength",
        "0.05",
        "--json",
        cwd=files,
    )
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["alpha0"] == pytest.approx(0.3136, abs=1e-7)  # (b − W/(σ_c t))/h
    assert data["e_star"] == pytest.approx(1.0, abs=1e-9)
