"""The chain factor of a study (``alma doe --design FILE`` with ``chain = [...]``).

A chain level of 0 is the panel as it is: its rows have the keys of a study without the chain
factor and resume from one; a level > 0 is :func:`alma.geometry.chains.with_chain` at the
design's height, solved by the associative LP; ``alma anova`` then has the Chain rows.  Small
designs only (the 2:1 and 1:1 panels with 4:1 and 2:1 blocks solve in milliseconds).
"""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import pandas as pd
import pytest

import alma
from alma.cli import study as study_cli
from alma.geometry.chains import with_chain
from alma.stats.anova import anova, load_results
from alma.study.design import Design, load_design
from alma.study.doe import COLUMNS, PAPER_DESIGN, panel_key, read_results, run_doe

ROOT = Path(__file__).resolve().parents[1]
TABLE5 = ROOT / "verification" / "data" / "table5_collapse_multipliers.csv"
VALUES = ["panel_ratio", "block_ratio", "bond", "friction", "chain", "model", "status", "alpha_c", "key"]
# Every factor at two levels (the ANOVA needs them all varying): 32 runs, ~2 s on one core.
FACTORS_TOML = (
    'panel_ratio = ["2:1", "1:1"]\nblock_ratio = ["4:1", "2:1"]\nbond = ["running", "stack"]\nfriction = [0.27, 0.6]\n'
)


def cli(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="alma")
    study_cli.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(argv)
    return args.func(args)


def test_design_file_takes_the_chain_and_checks_it(tmp_path):
    path = tmp_path / "d.toml"
    path.write_text('bond = ["stack"]\nchains = [0, 0.5, 5]\nchain_height = 0.5\nchain_anchored = true\n')
    d = load_design(path)
    assert d.chain == (0.0, 0.5, 5.0) and d.chain_height == 0.5 and d.chain_anchored
    assert len(d) == 27 * 3 and d.runs()[:27] == [(*p, 0.0, 0.0) for p in d.panels()]
    # Mid-height of the course at chain_height x H: 0.5 x 720 mm = 360 mm is the foot of course 7.
    assert (d.chain_y("2:1"), Design().chain_y("2:1"), Design().chain_y("1:2")) == (390.0, 690.0, 2850.0)
    assert load_design(ROOT / "examples" / "design_chain.toml").chain == (0.0, 0.25, 1.0, 5.0)
    assert Design(chain=[0]) == PAPER_DESIGN and len(PAPER_DESIGN) == 108  # type: ignore[arg-type]  # a list, normalised
    for text, match in [
        ("chain = [-1]", "bad chain level -1"),
        ("chain = [1, 1]", "repeated chain level"),
        ('chain = ["strong"]', "bad chain level 'strong'"),
        ("chain = []", "chain needs at least one"),
        ("chain_height = 0", "bad chain_height 0"),
        ("chain_height = [1.0]", "chain_height takes one value"),
        ('chain_anchored = "yes"', "bad chain_anchored 'yes'"),
        ("chain_strength = [5]", "unknown key"),
    ]:
        path.write_text(text + "\n")
        with pytest.raises(ValueError, match=match):
            load_design(path)


def test_chain_zero_keeps_the_key_and_a_chain_changes_it():
    plain = panel_key("2:1", "4:1", "running", 0.6, "associative")
    assert (
        panel_key("2:1", "4:1", "running", 0.6, "associative", chain=0.0, chain_y=690.0, chain_anchored=True) == plain
    )
    chained = {
        panel_key("2:1", "4:1", "running", 0.6, "associative", chain=c, chain_y=y, chain_anchored=a)
        for c, y, a in [(5.0, 690.0, False), (1.0, 690.0, False), (5.0, 390.0, False), (5.0, 690.0, True)]
    }
    assert len(chained) == 4 and plain not in chained
    with pytest.raises(ValueError, match="chain_y"):
        panel_key("2:1", "4:1", "running", 0.6, "associative", chain=5.0)


def test_level_zero_resumes_a_plain_study_and_chains_equal_direct_solves(tmp_path):
    plain = Design(panel_ratio=("2:1",), block_ratio=("4:1",), bond=("running", "stack"), friction=(0.6,))
    first = run_doe(tmp_path, design=plain, workers=1, progress=False)
    chained = Design(
        panel_ratio=("2:1",), block_ratio=("4:1",), bond=("running", "stack"), friction=(0.6,), chain=(0, 1)
    )
    both = run_doe(tmp_path, design=chained, workers=1, progress=False)
    lines = (tmp_path / "results.csv").read_text().splitlines()
    assert len(lines) == 1 + 4  # the chain-0 rows were not solved again
    zero = both[both["chain"] == 0].reset_index(drop=True)
    pd.testing.assert_frame_equal(zero[VALUES], first[VALUES])
    for r in both[both["chain"] == 1].itertuples():
        scene = with_chain(alma.paper_panel(r.bond, "2:1", "4:1", 0.6), 690.0, 1.0, name="chain")
        scene.validate()
        direct = alma.solve(scene)
        assert r.status == "optimal" and r.alpha_c == pytest.approx(direct.alpha, rel=1e-9, abs=1e-12)
    stack = both[both["bond"] == "stack"].set_index("chain")["alpha_c"]
    assert stack[1.0] > stack[0.0] + 0.05  # measured 0.4991 against 0.4191: the chain ties the columns
    nl = run_doe(
        tmp_path / "nl",
        design=Design(panel_ratio=("2:1",), block_ratio=("4:1",), bond=("stack",), friction=(0.6,), chain=(0.0, 1.0)),
        model="nonassociative",
        workers=1,
        progress=False,
    ).set_index("chain")
    assert set(nl["status"]) <= {"feasible", "optimal"}
    for strength in (0.0, 1.0):  # the search takes the tie: each row is the API's answer
        scene = alma.paper_panel("stack", "2:1", "4:1", 0.6)
        if strength:
            scene = with_chain(scene, 690.0, strength, name="chain")
            scene.validate()
        searched = alma.solve(scene, model="nonassociative")
        assert nl.loc[strength, "alpha_c"] == pytest.approx(searched.alpha, rel=1e-9, abs=1e-12)


def test_a_results_file_from_before_the_chain_factor_resumes(tmp_path):
    design = Design(panel_ratio=("2:1",), block_ratio=("4:1",), bond=("stack",), friction=(0.27, 0.6))
    before = run_doe(tmp_path, design=design, workers=1, progress=False)
    path = tmp_path / "results.csv"
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    with open(path, "w", newline="") as fh:  # the file as the study wrote it before the chain column
        # no chain, no compressive strength, no checksum
        csv.writer(fh, lineterminator="\n").writerows(r[:-3] for r in rows)
    assert "chain" not in path.read_text().splitlines()[0]
    assert list(read_results(path)["chain"]) == [0.0, 0.0]
    again = run_doe(tmp_path, design=design, workers=1, progress=False)
    text = path.read_text().splitlines()
    assert text[0] == ",".join(COLUMNS) and len(text) == 3  # the header gained the column; nothing solved
    pd.testing.assert_frame_equal(again[VALUES], before[VALUES])


def test_doe_and_anova_commands_with_a_chain(tmp_path, capsys):
    design = tmp_path / "chain.toml"
    design.write_text(FACTORS_TOML + "chain = [0, 1]\n")
    out = tmp_path / "doe"
    assert cli(["doe", "--out", str(out), "--design", str(design), "--workers", "2", "--quiet"]) == 0
    assert "32 results in" in capsys.readouterr().out
    size = (out / "results.csv").stat().st_size
    assert cli(["doe", "--out", str(out), "--design", str(design), "--workers", "2", "--quiet"]) == 0
    assert (out / "results.csv").stat().st_size == size  # resumed: nothing solved again
    capsys.readouterr()
    assert cli(["anova", str(out / "results.csv"), "--json"]) == 0
    rows = {r["source"]: r for r in json.loads(capsys.readouterr().out)["rows"]}
    for source in ("Chain", "Panel*Chain", "Block*Chain", "Bond*Chain", "Friction*Chain"):
        assert rows[source]["dof"] == 1 and rows[source]["adj_ss"] >= 0.0, source
    assert rows["Linear"]["dof"] == 5 and rows["Two-Way Interactions"]["dof"] == 10
    assert rows["Error"]["dof"] == 31 - 15 and rows["Chain"]["p_value"] < 0.05  # measured p = 0.001
    # The chain-0 half alone: the four-factor table, the Chain rows gone.
    df = read_results(out / "results.csv")
    zero = anova(df[df["chain"] == 0])
    assert "Chain" not in {r.source for r in zero.rows} and zero.row("Model").dof == 10


def test_anova_of_table5_is_unchanged_by_a_single_chain_level(tmp_path):
    t5 = load_results(TABLE5)
    path = tmp_path / "t5.csv"
    t5.assign(chain=0.0).to_csv(path, index=False)
    with_column = load_results(path)
    assert anova(with_column).to_dict() == anova(t5).to_dict()
    path.write_text(TABLE5.read_text().replace("\n", ",x\n").replace("alpha_c,x", "alpha_c,chain", 1))
    with pytest.raises(ValueError, match="bad level 'x' in column 'chain'"):
        load_results(path)
