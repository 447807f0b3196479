"""The friction search's optional second run at full precision (``SearchSettings.fallback_bits``).

The canonical search rounds the model's data to 24 bits; on nine of the 108 paper panels
(measured: `python -m benchmarks.bench_friction --panels`, docs/decisions.md) none of its
verified states then verified on the drawing's own model, and the search ended ``not_converged``.
English bond 1:1 2:1 at f = 0.27 is one of them: its state from the recorded run
(docs/runs/compare-2026-11-25-tilt.csv, α_NL = 0.26704441069143087) is the reference.
"""

from __future__ import annotations

import pytest

import alma
from alma.settings import SearchSettings, Settings

RECORDED = 0.26704441069143087  # docs/runs/compare-2026-11-25-tilt.csv, english 1:1 2:1 f = 0.27


@pytest.mark.slow
def test_the_unrounded_second_run_finds_a_verified_state():
    scene = alma.paper_panel(bond="english", panel_ratio="1:1", block_ratio="2:1", friction=0.27)
    without = alma.solve(scene, model="nonassociative")  # the default: no second run
    assert without.status == "not_converged"
    result = alma.solve(scene, model="nonassociative", settings=Settings(search=SearchSettings(fallback_bits=52)))
    assert result.status == "feasible"
    assert result.alpha <= RECORDED * (1 + 1e-9)
    assert result.alpha <= alma.solve(scene).alpha
