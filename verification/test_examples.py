"""The scenes of ``examples/`` solve as the README says, and agree with independent LPs."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from test_cohesion_ties_loads import independent_static

import alma

from helpers import check_against_independent

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
NAMES = sorted(p.stem for p in EXAMPLES.glob("*.json"))


def test_the_examples_are_there():
    assert {"single_block", "wall_with_window", "arch", "portal"} <= set(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_example_is_certified_and_independently_checked(name):
    scene = alma.load_scene(EXAMPLES / f"{name}.json")
    result = alma.solve(scene)
    assert result.status == "optimal", result.message
    model = alma.build_model(scene)
    if model.n_bounded:  # cohesion or ties: bounded columns, which only this static LP takes
        reference = independent_static(model)
        assert result.bounds.lower <= reference + 1e-7 * max(1, abs(reference))
        assert result.bounds.upper >= reference - 1e-7 * max(1, abs(reference))
    else:
        check_against_independent(result, model)
    json.dumps(result.to_dict())  # the JSON of SPEC §3


def test_single_block_slides_at_f():
    """240 × 60 block, f = 0.6: sliding at α = f (rocking would need b / h = 4)."""
    result = alma.solve(alma.load_scene(EXAMPLES / "single_block.json"))
    assert result.alpha == pytest.approx(0.6, abs=1e-9) and result.mechanism_class == "sliding"


@pytest.mark.parametrize("name", ["arch", "portal"])
def test_example_nonassociative_state_is_verified_below_the_lp(name):
    scene = alma.load_scene(EXAMPLES / f"{name}.json")
    both = alma.solve(scene, model="both", effort="fast")
    assert both.nonassociative.status in ("feasible", "optimal")
    assert both.nonassociative.alpha <= both.associative.bounds.upper + 1e-9


def test_the_dxf_example_is_the_generated_facade():
    """``examples/facade.dxf`` was written by ``alma wall --bond english --width 2400 --height 1800
    --block 240x60 --opening 720,600,720,720 --export-scene examples/facade.dxf``: read back, it
    gives the generator's α."""
    drawn = alma.load_scene(EXAMPLES / "facade.dxf", thickness=120.0, friction=0.6)
    built = alma.wall("english", 2400.0, 1800.0, 240.0, 60.0, openings=[(720, 600, 720, 720)])
    a, b = alma.solve(drawn), alma.solve(built)
    assert a.status == b.status == "optimal"
    assert a.alpha == pytest.approx(b.alpha, rel=1e-9)
    assert sum(blk.fixed for blk in drawn.blocks) == 1  # the ground, on layer "fixed"


def test_the_coursed_wall_example_is_ferris_and_tin_lois_wall_3(capsys):
    """``examples/ferris_tin_loi_wall3.txt`` through the command line is wall 3 of
    ``test_ferris_tin_loi.py`` (drawn top course first there, listed bottom first here)."""
    from test_ferris_tin_loi import wall

    from alma.cli import main

    assert (
        main(
            [
                "wall",
                "--courses",
                str(EXAMPLES / "ferris_tin_loi_wall3.txt"),
                "--block",
                "400x175",
                "--thickness",
                "1000",
                "--friction",
                "0.65",
                "--json",
            ]
        )
        == 0
    )
    alpha = json.loads(capsys.readouterr().out)["alpha"]
    assert alpha == pytest.approx(alma.solve(wall(3)).alpha, rel=1e-12)
