"""The site keys of the 2019 checks at Z > 0 and at SLC (T1, xi1, ag_SLC, F0_SLC, Tc_star_SLC):
bad or missing values refused by name, in Python and on the CLI (exit 2, one JSON object)."""

from __future__ import annotations

import json
import subprocess
import sys
from typing import TypedDict

import pytest

import alma
from alma.seismic import Site


class SiteArgs(TypedDict):
    """The ground's keys of :class:`Site`."""

    ag: float
    F0: float
    Tc_star: float
    soil: str


class HeightArgs(TypedDict):
    """A mechanism's height in its building (keys of :class:`Site`)."""

    Z: float
    H: float
    storeys: int


SITE: SiteArgs = dict(ag=0.2, F0=2.4, Tc_star=0.3, soil="B")
HIGH: HeightArgs = dict(Z=6.0, H=9.0, storeys=3)
SCENE = {
    "thickness": 120.0,
    "unit_weight": 18.0,
    "friction": 0.8,
    "blocks": [
        {"id": "ground", "vertices": [[-480, -100], [720, -100], [720, 0], [-480, 0]], "fixed": True},
        {"id": "wall", "vertices": [[0, 0], [240, 0], [240, 600], [0, 600]]},
    ],
}


@pytest.mark.parametrize(
    ("extra", "name"),
    [
        ({"xi1": -5.0}, "xi1"),
        ({"xi1": "ten"}, "xi1"),
        ({"T1": 0.0}, "T1"),
        ({"T1": float("nan")}, "T1"),
        ({"ag_SLC": 0.25}, "F0_SLC"),
        ({"ag_SLC": 0.25, "F0_SLC": 2.5}, "Tc_star_SLC"),
        ({"ag_SLC": 0.25, "F0_SLC": -2.5, "Tc_star_SLC": 0.3}, "F0_SLC"),
        ({"ag_SLC": True, "F0_SLC": 2.5, "Tc_star_SLC": 0.3}, "ag_SLC"),
        ({"xi_1": 10.0}, "xi_1"),
    ],
)
def test_a_bad_key_is_named(extra, name):
    with pytest.raises(ValueError, match=name):
        Site.from_dict({**SITE, **extra})


def test_edition_2019_at_height_needs_xi1():
    scene = alma.Scene.from_dict(SCENE)
    with pytest.raises(ValueError, match="xi1") as info:
        alma.seismic(scene, {**SITE, **HIGH}, steps=4)
    assert "Z > 0" in str(info.value)


def test_edition_2009_refuses_the_2019_keys():
    scene = alma.Scene.from_dict(SCENE)
    with pytest.raises(ValueError, match=r"\['T1', 'xi1'\].*2019"):
        alma.seismic(scene, {**SITE, **HIGH, "xi1": 10.0, "T1": 0.3}, edition="2009", steps=4)
    with pytest.raises(ValueError, match="ag_SLC"):
        alma.seismic(scene, {**SITE, "ag_SLC": 0.3, "F0_SLC": 2.4, "Tc_star_SLC": 0.3}, edition="2009", steps=4)


def _cli(tmp_path, site: str, *extra: str) -> subprocess.CompletedProcess:
    (tmp_path / "scene.json").write_text(json.dumps(SCENE))
    (tmp_path / "site.toml").write_text(site)
    return subprocess.run(
        [sys.executable, "-m", "alma.cli", "seismic", "scene.json", "--site", "site.toml", "--steps", "4", *extra],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )


BASE = 'ag = 0.2\nF0 = 2.4\nTc_star = 0.3\nsoil = "B"\n'


@pytest.mark.parametrize(
    ("site", "name"),
    [
        (BASE + "Z = 6.0\nH = 9.0\nstoreys = 3\n", "xi1"),
        (BASE + "Z = 6.0\nH = 9.0\nstoreys = 3\nxi1 = 0\n", "xi1"),
        (BASE + "ag_SLC = 0.25\nTc_star_SLC = 0.3\n", "F0_SLC"),
    ],
)
def test_cli_refuses_by_name(tmp_path, site, name):
    out = _cli(tmp_path, site, "--json")
    assert out.returncode == 2 and name in out.stderr and "Traceback" not in out.stderr
    data = json.loads(out.stdout)
    assert data["status"] == "invalid_input" and name in data["message"]


def test_cli_text_gives_the_floor_and_slc_lines(tmp_path):
    high = _cli(tmp_path, BASE + "Z = 6.0\nH = 9.0\nstoreys = 3\nxi1 = 10.0\n")
    assert high.returncode == 0, high.stderr
    assert "a_Z(z)" in high.stdout and "nonlinear  not done" in high.stdout
    slc = _cli(tmp_path, BASE + "ag_SLC = 0.25\nF0_SLC = 2.5\nTc_star_SLC = 0.32\n", "--json")
    assert slc.returncode == 0, slc.stderr
    data = json.loads(slc.stdout)
    assert data["slc"]["xi"] == 10.0 and data["site"]["ag_SLC"] == 0.25
    assert data["nonlinear"]["governs"] in ("displacement", "a_g_SLD") and data["linear"]["governs"] == "ground"


def test_a_site_built_directly_is_checked():
    scene = alma.Scene.from_dict(SCENE)
    with pytest.raises(ValueError, match="xi1"):
        alma.seismic(scene, Site(**SITE, **HIGH, xi1=-10.0), steps=4)
