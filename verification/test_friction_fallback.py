"""The canonical model's precision (``SearchSettings.canonical_bits``) and the optional second run
at full precision (``SearchSettings.fallback_bits``).

A canonical state reaches the drawing whole (its field and mechanism, verified on the drawing's
own model) or, failing that, made exact there. Rounded to 24 bits, the canonical model of nine of
the 108 paper panels once gave states that did neither, and the search ended ``not_converged``;
English bond 1:1 2:1 at f = 0.27 is one of them, and its state from the recorded run
(docs/runs/compare-2026-11-25-tilt.csv, α_NL = 0.26704441069143087) is the reference. Carried
whole, its 24-bit state now verifies; rounded to 16 bits (1.5e-5 relative, far above the
verification's 1e-7) no state does, and the second run at full precision is what finds one
(docs/decisions.md, "The canonical model at 28 bits" and "A canonical state carried whole").
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


@pytest.mark.slow
def test_a_24_bit_state_carried_whole_verifies():
    scene = _panel()
    result = alma.solve(scene, model="nonassociative", settings=Settings(search=SearchSettings(canonical_bits=24)))
    assert result.status == "feasible"
    assert result.alpha <= RECORDED * (1 + 1e-9)


@pytest.mark.slow
def test_the_unrounded_second_run_finds_a_verified_state():
    scene = _panel()
    coarse = SearchSettings(canonical_bits=16)
    without = alma.solve(scene, model="nonassociative", settings=Settings(search=coarse))
    assert without.status == "not_converged"
    fallback = SearchSettings(canonical_bits=16, fallback_bits=52)
    result = alma.solve(scene, model="nonassociative", settings=Settings(search=fallback))
    assert result.status == "feasible"
    assert result.alpha <= RECORDED * (1 + 1e-9)


@pytest.mark.slow
# Until 2026-11-28 this failed by 3.2e-11 (α_NL 0.26704441085254027 from HiGHS's capped LP against
# Clarabel's certified α_LP 0.2670444108439167); since the search's dense sums left BLAS
# (alma/floats.py) it holds on every CPU, but alma still does not make α_NL ≤ α_LP by
# construction (docs/decisions.md).
@pytest.mark.parametrize("search", [SearchSettings(), SearchSettings(canonical_bits=16, fallback_bits=52)])
def test_the_state_is_at_most_the_associative_alpha(search):
    scene = _panel()
    result = alma.solve(scene, model="nonassociative", settings=Settings(search=search))
    assert result.alpha <= alma.solve(scene).alpha
