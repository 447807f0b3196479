"""``alma panel --chain HEIGHT:STRENGTH [--anchored]``: chains across a panel."""

from __future__ import annotations

import json

import pytest

import alma
from alma.cli.main import main
from alma.geometry.chains import parse_chain, with_chain


def test_a_chain_ties_the_two_end_blocks_of_its_course():
    panel = alma.paper_panel("running", "2:1", "4:1", 0.6)
    chained = with_chain(panel, 690.0, 5.0)
    (tie,) = chained.ties
    assert tie.from_point == (0.0, 690.0) and tie.to_point == (1440.0, 690.0) and tie.strength == 5.0
    chained.validate()  # both plates lie on their blocks
    assert alma.solve(chained).alpha >= alma.solve(panel).alpha - 1e-9


def test_an_anchored_chain_ties_each_end_to_a_fixed_anchor():
    panel = alma.paper_panel("running", "1:2", "4:1", 0.6)
    chained = with_chain(panel, 2850.0, 5.0, anchored=True)
    chained.validate()
    anchors = [b for b in chained.blocks if b.id.endswith(("anchor-left", "anchor-right"))]
    assert len(anchors) == 2 and all(b.fixed for b in anchors)
    assert len(alma.find_joints(chained).block_a) == len(alma.find_joints(panel).block_a)  # anchors touch nothing
    assert alma.solve(chained).alpha > alma.solve(panel).alpha + 1e-4  # measured: 0.43111 against 0.42731


def test_chain_errors_name_the_chain():
    panel = alma.paper_panel("running", "2:1", "4:1", 0.6)
    with pytest.raises(alma.SceneError, match="no block of the wall spans"):
        with_chain(panel, 5000.0, 1.0)
    with pytest.raises(alma.SceneError, match="strength must be >= 0"):
        with_chain(panel, 300.0, -1.0)
    with pytest.raises(alma.SceneError, match="HEIGHT:STRENGTH"):
        parse_chain("690")


def test_panel_command_takes_chains(capsys):
    assert (
        main(
            [
                "panel",
                "--bond",
                "running",
                "--panel-ratio",
                "1:2",
                "--block-ratio",
                "4:1",
                "--friction",
                "0.6",
                "--chain",
                "1410:5",
                "--chain",
                "2850:5",
                "--json",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert [t["id"] for t in out["ties"]] == ["chain1", "chain2"] and out["status"] == "optimal"
    assert (
        main(
            [
                "panel",
                "--bond",
                "running",
                "--panel-ratio",
                "1:2",
                "--block-ratio",
                "4:1",
                "--friction",
                "0.6",
                "--chain",
                "oops",
                "--json",
            ]
        )
        == 2
    )
