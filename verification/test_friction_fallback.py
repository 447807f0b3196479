"""The canonical model's precision (``SearchSettings.canonical_bits``) and the optional second run
at full precision (``SearchSettings.fallback_bits``).

Rounded to 24 bits, the canonical model of nine of the 108 paper panels gave states that verified
there but not on the drawing's own model, and the search ended ``not_converged``; rounded to 28
bits (the default), eight of them verify (docs/decisions.md, "The canonical model at 28 bits").
English bond 1:1 2:1 at f = 0.27 is one of them: its state from the recorded run
(docs/runs/compare-2026-11-25-tilt.csv, α_NL = 0.26704441069143087) is the reference.
"""

from __future__ import annotations

import pytest

import alma
from alma.settings import SearchSettings, Settings

RECORDED = 0.26704441069143087  # docs/runs/compare-2026-11-25-tilt.csv, english 1:1 2:1 f = 0.27


def _panel() -> alma.Scene:
    return alma.paper_panel(bond="english", panel_ratio="1:1", block_ratio="2:1", friction=0.27)


@pytest.mark.slow
def test_the_default_precision_carries_the_state_back():
    scene = _panel()
    result = alma.solve(scene, model="nonassociative")
    assert result.status == "feasible"
    assert result.alpha <= RECORDED * (1 + 1e-9)
    assert result.alpha <= alma.solve(scene).alpha


@pytest.mark.slow
def test_the_unrounded_second_run_finds_a_verified_state():
    scene = _panel()
    coarse = SearchSettings(canonical_bits=24)
    without = alma.solve(scene, model="nonassociative", settings=Settings(search=coarse))
    assert without.status == "not_converged"
    fallback = SearchSettings(canonical_bits=24, fallback_bits=52)
    result = alma.solve(scene, model="nonassociative", settings=Settings(search=fallback))
    assert result.status == "feasible"
    assert result.alpha <= RECORDED * (1 + 1e-9)
    assert result.alpha <= alma.solve(scene).alpha
