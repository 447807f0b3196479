"""The compressive-strength factor of a study (issue 34): ``alma doe --compressive-strength`` and
the design key ``compressive_strength``.

Level 0 is the panel with infinitely strong blocks: its rows keep the keys of a study without the
factor and resume from one; a level > 0 puts σ_c on every joint, as the scene key does.  One small
panel only (2:1 with 4:1 blocks, stack bond, f = 0.6: it rocks; under a second per solve).
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
from pathlib import Path

import pandas as pd
import pytest

import alma
from alma.cli import study as study_cli
from alma.study.design import Design, load_design
from alma.study.doe import COLUMNS, PAPER_DESIGN, panel_key, read_results, run_doe
from alma.study.integrity import row_checksum

SMALL = 'panel_ratio = ["2:1"]\nblock_ratio = ["4:1"]\nbond = ["stack"]\nfriction = [0.6]\n'
VALUES = ["panel_ratio", "block_ratio", "bond", "friction", "compressive_strength", "status", "alpha_c", "key"]


def cli(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="alma")
    study_cli.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(argv)
    return args.func(args)


def test_design_takes_the_levels_and_checks_them(tmp_path):
    path = tmp_path / "d.toml"
    path.write_text('bond = ["stack"]\ncompressive_strengths = [0, 2, 5.5]\n')
    d = load_design(path)
    assert d.compressive_strength == (0.0, 2.0, 5.5) and len(d) == 27 * 3
    assert d.runs()[27] == (*d.panels()[0], 0.0, 2.0)  # the strength is the slowest factor
    assert Design(compressive_strength=[0]) == PAPER_DESIGN  # type: ignore[arg-type]  # a list of levels, normalised
    for text, match in [
        ("compressive_strength = [-1]", "bad compressive_strength level -1"),
        ("compressive_strength = [2, 2]", "repeated compressive_strength level"),
        ('compressive_strength = ["hard"]', "bad compressive_strength level 'hard'"),
    ]:
        path.write_text(text + "\n")
        with pytest.raises(ValueError, match=match):
            load_design(path)


def test_zero_keeps_the_key_and_a_strength_changes_it():
    plain = panel_key("2:1", "4:1", "running", 0.6, "associative")
    assert panel_key("2:1", "4:1", "running", 0.6, "associative", compressive_strength=0.0) == plain
    two = panel_key("2:1", "4:1", "running", 0.6, "associative", compressive_strength=2.0)
    assert two != plain and two != panel_key("2:1", "4:1", "running", 0.6, "associative", compressive_strength=5.0)


def test_doe_command_solves_each_strength_as_the_scene_key_does(tmp_path, capsys):
    design = tmp_path / "small.toml"
    design.write_text(SMALL)
    out = tmp_path / "doe"
    argv = [
        "doe",
        "--out",
        str(out),
        "--design",
        str(design),
        "--compressive-strength",
        "0,2,0.2",
        "--workers",
        "1",
        "--quiet",
    ]
    assert cli(argv) == 0
    assert "3 results in" in capsys.readouterr().out
    df = read_results(out / "results.csv").set_index("compressive_strength")
    scene = alma.paper_panel("stack", "2:1", "4:1", 0.6)
    for sigma in (2.0, 0.2):
        direct = alma.solve(dataclasses.replace(scene, compressive_strength=sigma))
        assert df.loc[sigma, "status"] == "optimal" == str(direct.status)
        assert df.loc[sigma, "alpha_c"] == pytest.approx(direct.alpha, rel=1e-12)
    rigid = alma.solve(scene)
    assert df.loc[0.0, "alpha_c"] == pytest.approx(rigid.alpha, rel=1e-12)
    assert df.loc[0.0, "key"] == panel_key("2:1", "4:1", "stack", 0.6, "associative")
    # the crushing strength lowers α below the rigid one, more at the lower strength
    assert df.loc[0.2, "alpha_c"] < df.loc[2.0, "alpha_c"] < df.loc[0.0, "alpha_c"]
    size = (out / "results.csv").stat().st_size
    assert cli(argv) == 0 and (out / "results.csv").stat().st_size == size  # resumed: nothing solved


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--compressive-strength", "2,x"], "expected numbers"),
        (["--compressive-strength", "2,-1"], "bad compressive_strength level -1"),
        (["--compressive-strength", "2,,5"], "separated by commas"),
        (["--compressive-strength", "2", "--model", "both"], "non-associative model"),
    ],
)
def test_doe_refuses_bad_levels(tmp_path, capsys, extra, message):
    design = tmp_path / "small.toml"
    design.write_text(SMALL)
    out = tmp_path / "doe"
    assert cli(["doe", "--out", str(out), "--design", str(design), "--workers", "1", "--quiet", *extra]) == 2
    assert message in capsys.readouterr().err
    assert not (out / "results.csv").exists() or len((out / "results.csv").read_text().splitlines()) <= 1


def test_a_results_file_from_before_the_column_resumes(tmp_path):
    design = Design(panel_ratio=("2:1",), block_ratio=("4:1",), bond=("running",), friction=(0.27, 0.6))
    before = run_doe(tmp_path, design=design, workers=1, progress=False)
    path = tmp_path / "results.csv"
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    column = COLUMNS.index("compressive_strength")
    with open(path, "w", newline="") as fh:  # as the study wrote it before the column: chain, then checksum
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(rows[0][:column] + rows[0][column + 1 :])
        for r in rows[1:]:
            fields = r[:column] + r[column + 1 : -1]
            writer.writerow([*fields, row_checksum(fields)])
    assert "compressive_strength" not in path.read_text().splitlines()[0]
    assert list(read_results(path)["compressive_strength"]) == [0.0, 0.0]
    again = run_doe(tmp_path, design=design, workers=1, progress=False)
    text = Path(path).read_text().splitlines()
    assert text[0] == ",".join(COLUMNS) and len(text) == 3  # the header gained the column; nothing solved
    pd.testing.assert_frame_equal(again[VALUES], before[VALUES])
