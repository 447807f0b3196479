"""With ``--json`` standard output holds exactly one JSON object, whatever prints at the C level.

highspy 1.16 prints a banner on file descriptor 1 while ``Highs()`` is constructed, before any
option can switch it off (issue 32).  Two layers of tests:

- every command and model, in the process, with ``highspy.Highs`` replaced by a constructor
  that writes a banner to fd 1 on *every* construction (what highspy 1.16 does once per
  process), and standard output captured at the descriptor (``capfd``): it parses as one
  object only if alma creates every HiGHS object with fd 1 silenced;
- a few runs of ``python -m alma.cli`` in fresh processes with the installed highspy, which
  ``make test-latest-subset`` runs against the newest releases.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import highspy
import pytest

from alma.cli.main import main

ROOT = Path(__file__).resolve().parents[1]
BANNER = b"Running HiGHS 9.9.9 (simulated banner on fd 1)\n"

SCENE = {
    "name": "two blocks on the ground",
    "thickness": 120,
    "unit_weight": 18.0,
    "friction": 0.6,
    "cohesion": 0.0,
    "blocks": [
        {"id": "ground", "vertices": [[-100, -50], [500, -50], [500, 0], [-100, 0]], "fixed": True},
        {"id": "b1", "vertices": [[0, 0], [200, 0], [200, 100], [0, 100]]},
        {"id": "b2", "vertices": [[0, 100], [200, 100], [200, 200], [0, 200]]},
    ],
}
PANEL = ["--bond", "stack", "--panel-ratio", "2:1", "--block-ratio", "4:1", "--friction", "0.6"]


@pytest.fixture
def scenes(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("s.json").write_text(json.dumps(SCENE))
    settled = json.loads(json.dumps(SCENE))
    settled["blocks"][0]["settlement"] = {"translation": [0.0, -1.0]}
    Path("settle.json").write_text(json.dumps(settled))
    Path("results.csv").write_text((ROOT / "verification/data/table5_collapse_multipliers.csv").read_text())
    return tmp_path


@pytest.fixture
def loud_highs(monkeypatch):
    """``highspy.Highs`` printing a banner on fd 1 at every construction (highspy 1.16's manner)."""
    real = highspy.Highs

    def loud(*args, **kwargs):
        os.write(1, BANNER)
        return real(*args, **kwargs)

    monkeypatch.setattr(highspy, "Highs", loud)


#: Every command with --json, each model and switch, on small scenes.
COMMANDS = [
    ["solve", "s.json"],
    ["solve", "s.json", "--model", "nonassociative"],
    ["solve", "s.json", "--model", "both"],
    ["solve", "s.json", "--model", "nonassociative", "--certify"],
    ["solve", "s.json", "--model", "both", "--certify"],
    ["solve", "s.json", "--crisp"],
    ["solve", "s.json", "--model", "nonassociative", "--effort", "fast", "--time-limit", "60"],
    ["solve", "settle.json", "--after-settlement"],
    ["panel", *PANEL],
    ["panel", *PANEL, "--model", "both", "--effort", "fast"],
    ["panel", *PANEL, "--chain", "690:5", "--model", "nonassociative", "--effort", "fast"],
    ["settle", "settle.json"],
    ["tilt", "s.json"],
    ["wall", "--bond", "running", "--width", "480", "--height", "180", "--block", "240x60"],
    [
        "wall",
        "--bond",
        "running",
        "--width",
        "480",
        "--height",
        "180",
        "--block",
        "240x60",
        "--model",
        "both",
        "--effort",
        "fast",
    ],
    ["arch", "--span", "1000", "--rise", "500", "--thickness", "150", "--voussoirs", "5"],
    ["anova", "results.csv"],
    ["anova", "results.csv", "--order", "1"],
]


def _one_object(text: str) -> dict:
    """The JSON object that ``text`` is, whole (json.loads refuses anything before or after it)."""
    value = json.loads(text)
    assert isinstance(value, dict), text[:200]
    return value


@pytest.mark.parametrize("argv", COMMANDS, ids=[" ".join(a) for a in COMMANDS])
def test_stdout_is_one_json_object_with_a_loud_highs(scenes, loud_highs, capfd, argv):
    code = main([*argv, "--json"])
    out, err = capfd.readouterr()
    assert code == 0, err
    assert BANNER.decode() not in out
    assert "NaN" not in out and "Infinity" not in out
    _one_object(out)


def test_the_banner_is_dropped_and_earlier_output_kept(loud_highs, capfd):
    from alma.backends.highs_backend import new_highs

    print("before", flush=False)  # still in Python's buffer when HiGHS is created
    new_highs()
    print("after")
    out, _ = capfd.readouterr()
    assert out == "before\nafter\n"


@pytest.mark.parametrize(
    "argv",
    [
        ["solve", "s.json", "--model", "both", "--certify"],
        ["panel", *PANEL, "--model", "nonassociative", "--effort", "fast"],
        ["solve", "s.json", "--crisp"],
    ],
)
def test_fresh_process_stdout_is_one_json_object(scenes, argv):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run(
        [sys.executable, "-m", "alma.cli", *argv, "--json"], capture_output=True, text=True, env=env, timeout=300
    )
    assert done.returncode == 0, done.stderr
    _one_object(done.stdout)
