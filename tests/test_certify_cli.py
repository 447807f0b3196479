"""`alma solve --certify --certify-backend highs|scip [--certify-nodes N]` and the friction interval.

The interval of the friction model is printed as [lower, α_NL] with what each side is, in the
text and in the JSON (``bounds.lower_is``, ``bounds.upper_is``); never ``nan`` or ``inf``.
"""

from __future__ import annotations

import json

import pytest
from hypothesis import given, strategies as st

from alma.backends import scip_backend
from alma.cli.main import main
from alma.results.types import Bounds

SCENE = {
    "name": "single block on the ground",
    "thickness": 120,
    "unit_weight": 18.0,
    "friction": 0.6,
    "blocks": [
        {"id": "ground", "vertices": [[-100, -50], [400, -50], [400, 0], [-100, 0]], "fixed": True},
        {"id": "b1", "vertices": [[0, 0], [240, 0], [240, 60], [0, 60]]},
    ],
}


@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(SCENE))
    return str(path)


def test_scip_backend_without_pyscipopt_says_install_the_extra(scene, capsys, monkeypatch):
    monkeypatch.setattr(scip_backend, "pyscipopt", None)
    code = main(["solve", scene, "--model", "nonassociative", "--certify", "--certify-backend", "scip", "--json"])
    captured = capsys.readouterr()
    assert code == 2
    out = json.loads(captured.out)  # exactly one JSON object
    assert out["status"] == "invalid_input" and "alma[scip]" in out["message"]
    assert "alma[scip]" in captured.err and "Traceback" not in captured.err


def test_certify_nodes_must_be_positive(scene, capsys):
    assert main(["solve", scene, "--model", "nonassociative", "--certify", "--certify-nodes", "0"]) == 2
    assert "--certify-nodes" in capsys.readouterr().err


def test_text_interval_names_both_sides_without_nan(scene, capsys):
    assert main(["solve", scene, "--model", "nonassociative"]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if s.strip().startswith("bounds"))
    assert "Radenkovic" in line and "verified collapse state" in line
    assert "nan" not in line and "inf" not in line


@pytest.mark.skipif(not scip_backend.available(), reason="PySCIPOpt is not installed (pip install 'alma[scip]')")
def test_scip_certificate_in_the_json(scene, capsys):
    code = main(["solve", scene, "--model", "nonassociative", "--certify", "--certify-backend", "scip", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["status"] == "optimal"
    assert out["certificate"]["backend"] == "scip" and out["certificate"]["status"] == "proven"
    assert "SCIP" in out["bounds"]["lower_is"] and out["bounds"]["upper_is"].startswith("verified collapse state")
    assert out["bounds"]["lower"] == pytest.approx(0.6, abs=1e-6)


@given(lower=st.floats(allow_nan=True, allow_infinity=True), upper=st.floats(allow_nan=True, allow_infinity=True))
def test_interval_text_never_prints_inf_or_nan(lower, upper):
    text = Bounds(lower, upper, "proven bound (MILP certificate, SCIP)", "verified collapse state (α_NL)").describe()
    assert "inf" not in text and "nan" not in text
    assert text.startswith("[") and "lower: proven bound" in text and "upper: verified collapse state" in text
