"""Bad input on the command line: exit 2, a message naming the problem, no traceback, no work.

Every case starts from valid files (a single block on the ground, its DXF drawing, a scene with
a settlement) and breaks one thing: a file's bytes, an option's value, an output path.  Run in
the process (:func:`alma.cli.main.main`): an uncaught exception fails the test, and the message
on stderr must name what is wrong.  With ``--json`` the refusal is one JSON object on stdout.
A few cases run ``python -m alma.cli`` too, so that "Traceback" is looked for in real stderr.
"""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

import alma
from alma.cli.main import main
from alma.geometry.dxf import write_dxf

from helpers import single_block_dict

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def files(tmp_path, monkeypatch):
    """Valid and damaged input files in a folder of their own (the working directory)."""
    monkeypatch.chdir(tmp_path)
    scene = single_block_dict(200.0, 100.0, 0.6)
    Path("s.json").write_text(json.dumps(scene))
    write_dxf(alma.Scene.from_dict(scene), "s.dxf")
    Path("nested.json").write_text("[" * 100_000 + "]" * 100_000)
    Path("nested_blocks.json").write_text('{"blocks": ' + "[" * 50_000 + "]" * 50_000 + "}")
    Path("binary.json").write_bytes(b"\xff\xfe\x00\x81garbage\xc3\x28")
    Path("binary.dxf").write_bytes(b"\xff\xfe\x00\x81garbage\xc3\x28")
    Path("latin1.json").write_bytes(json.dumps(dict(scene, name="façade"), ensure_ascii=False).encode("latin-1"))
    Path("latin1.txt").write_bytes("4 4 4 # façade".encode("latin-1"))
    Path("empty.json").write_text("")
    Path("list.json").write_text("[1, 2, 3]")
    Path("huge.json").write_text(json.dumps(scene).replace('"thickness": 120.0', '"thickness": 1e999'))
    dxf = Path("s.dxf").read_bytes()
    Path("truncated.dxf").write_bytes(dxf[: len(dxf) // 3])
    Path("cut_early.dxf").write_bytes(dxf[:40])
    Path("folder.json").mkdir()
    Path("out.png").mkdir()  # a folder named like a picture
    return tmp_path


#: (argv, fragment of the message that names the problem).
CASES = [
    # scene files that are not scenes, for every command that reads one
    *[([cmd, "nested.json"], "nested too deeply") for cmd in ("solve", "tilt", "settle")],
    (["solve", "nested_blocks.json"], "nested too deeply"),
    *[([cmd, "binary.json"], "not UTF-8") for cmd in ("solve", "tilt", "settle")],
    *[([cmd, "latin1.json"], "not UTF-8") for cmd in ("solve", "tilt", "settle")],
    *[([cmd, "binary.dxf"], "cannot be read") for cmd in ("solve", "tilt", "settle")],
    *[([cmd, "truncated.dxf"], "cannot be read") for cmd in ("solve", "tilt", "settle")],
    (["solve", "cut_early.dxf"], "cannot be read"),
    (["solve", "empty.json"], "not valid JSON"),
    (["solve", "list.json"], "top level"),
    (["solve", "huge.json"], "thickness"),
    (["solve", "folder.json"], "cannot be read"),
    (["tilt", "missing.json"], "cannot be read"),
    # limits and scene options out of range
    (["solve", "s.json", "--time-limit", "0"], "--time-limit"),
    (["solve", "s.json", "--time-limit", "nan"], "--time-limit"),
    (["solve", "s.json", "--time-limit", "-3"], "--time-limit"),
    (["solve", "s.json", "--time-limit", "inf"], "--time-limit"),
    (["solve", "s.json", "--time-limit", "1e400"], "--time-limit"),
    (["solve", "s.json", "--time-limit", "soon"], "--time-limit"),
    (
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
            "--time-limit",
            "0",
        ],
        "--time-limit",
    ),
    (["solve", "s.json", "--friction", "-0.1"], "--friction"),
    (["tilt", "s.dxf", "--friction", "nan"], "--friction"),
    (["settle", "s.json", "--cohesion", "-5"], "--cohesion"),
    (["solve", "s.dxf", "--thickness", "0"], "--thickness"),
    (["tilt", "s.dxf", "--unit-weight", "-18"], "--unit-weight"),
    (["solve", "s.json", "--contact-tolerance", "0.5"], "contact_tolerance"),
    (["solve", "s.json", "--contact-tolerance", "-1e-4"], "--contact-tolerance"),
    (["solve", "s.json", "--supports", "lowest"], "--supports"),
    (["solve", "s.json", "--supports", "tallest"], "--supports"),
    (["solve", "s.json", "--model", "plastic"], "--model"),
    # settle without a settlement to analyse
    (["settle", "s.json"], "settlement"),
    (["settle", "s.dxf", "--supports", "lowest"], "settlement"),
    # generators
    (["wall", "--bond", "running", "--width", "960", "--height", "600", "--block", "0x60"], "--block"),
    (["wall", "--bond", "running", "--width", "960", "--height", "600", "--block", "240x"], "--block"),
    (["wall", "--bond", "running", "--width", "960", "--height", "600", "--block", "-240x60"], "--block"),
    (["wall", "--bond", "running", "--width", "960", "--height", "600", "--block", "nanx60"], "--block"),
    (["wall", "--bond", "running", "--width", "960", "--height", "600", "--block", "240x60x3"], "--block"),
    (["wall", "--bond", "running", "--width", "0", "--height", "600", "--block", "240x60"], "--width"),
    (["wall", "--bond", "running", "--width", "960", "--height", "inf", "--block", "240x60"], "--height"),
    (
        [
            "wall",
            "--bond",
            "running",
            "--width",
            "960",
            "--height",
            "600",
            "--block",
            "240x60",
            "--opening",
            "100,0,nan,120",
        ],
        "--opening",
    ),
    (
        [
            "wall",
            "--bond",
            "running",
            "--width",
            "960",
            "--height",
            "600",
            "--block",
            "240x60",
            "--opening",
            "100,0,-240,120",
        ],
        "--opening",
    ),
    (["wall", "--courses", "latin1.txt", "--block", "240x60"], "UTF-8"),
    (["arch", "--span", "2000", "--rise", "-1000", "--thickness", "300", "--voussoirs", "9"], "--rise"),
    # output paths: checked before any work
    (["solve", "s.json", "--plot", "no_such_folder/x.png"], "does not exist"),
    (["solve", "s.json", "--plot", "x.xyz"], "unknown file type"),
    (["solve", "s.json", "--plot", "picture"], "unknown file type"),
    (["solve", "s.json", "--plot", "out.png"], "is a folder"),
    (["solve", "s.json", "--html", "s.json"], "unknown file type"),
    (["solve", "s.json", "--html", "no_such_folder/x.html"], "does not exist"),
    (["settle", "s.json", "--plot", "no_such_folder/x.png"], "does not exist"),
    (["settle", "s.json", "--plot", "x.gif"], "unknown file type"),
    (
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
            "no_such_folder/p.json",
        ],
        "does not exist",
    ),
    (
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
            "p.txt",
        ],
        "unknown file type",
    ),
    (
        [
            "wall",
            "--bond",
            "running",
            "--width",
            "960",
            "--height",
            "600",
            "--block",
            "240x60",
            "--export-scene",
            "no_such_folder/w.dxf",
        ],
        "does not exist",
    ),
    (["doe", "--out", "s.json"], "not a folder"),
    (["paper", "--out", "s.json"], "not a folder"),
]


@pytest.mark.parametrize("argv,fragment", CASES, ids=[" ".join(c[0]) for c in CASES])
def test_refused_with_exit_2_and_the_problem_named(files, capsys, argv, fragment):
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert fragment.lower() in captured.err.lower(), captured.err
    assert "Traceback" not in captured.err
    assert captured.out == ""
    assert not Path("no_such_folder").exists()


#: Every fourth case, of the commands that have --json.
JSON_CASES = [case for case in CASES[::4] if case[0][0] not in ("doe", "paper")]


@pytest.mark.parametrize("argv,fragment", JSON_CASES, ids=[" ".join(c[0]) for c in JSON_CASES])
def test_refused_as_one_json_object_with_json(files, capsys, argv, fragment):
    assert main([*argv, "--json"]) == 2
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "invalid_input"
    assert fragment.lower() in out["message"].lower()


def test_an_output_over_the_input_scene_is_refused(files, capsys):
    before = Path("s.json").read_bytes()
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
                "s.json",
            ]
        )
        == 0
    )  # panel reads no scene: allowed
    capsys.readouterr()
    Path("s.json").write_bytes(before)
    Path("scene.html").write_bytes(before)
    assert main(["solve", "scene.html", "--html", "./scene.html"]) == 2
    assert "input file" in capsys.readouterr().err
    assert Path("scene.html").read_bytes() == before


@pytest.mark.skipif(sys.platform != "linux", reason="/proc is Linux's")
def test_an_output_folder_where_nothing_can_be_created(files, capsys):
    assert main(["solve", "s.json", "--html", "/proc/alma.html"]) == 2
    assert "not writable" in capsys.readouterr().err


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="a superuser writes into read-only folders")
def test_a_read_only_folder(files, capsys):
    Path("ro").mkdir()
    Path("ro").chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        assert main(["solve", "s.json", "--plot", "ro/x.png"]) == 2
        assert "not writable" in capsys.readouterr().err
    finally:
        Path("ro").chmod(stat.S_IRWXU)


@pytest.mark.parametrize(
    "argv",
    [
        ["solve", "nested.json", "--json"],
        ["tilt", "binary.json"],
        ["settle", "truncated.dxf"],
        ["wall", "--bond", "running", "--width", "960", "--height", "600", "--block", "0x60"],
        ["solve", "s.json", "--time-limit", "nan", "--json"],
    ],
)
def test_no_traceback_from_the_console(files, argv):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run(
        [sys.executable, "-m", "alma.cli", *argv], capture_output=True, text=True, env=env, timeout=120
    )
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert "alma: invalid input:" in done.stderr
