"""The "thorough" search's seven fixed starts lose nothing the sixteen of before found.

``SearchSettings.gilbert_thorough``, ``gilbert_thorough_rows`` and ``tilt_degrees`` keep the
fixed starts that reached the lowest state of 271 measured searches (docs/decisions.md). Here the
former plan (seven Gilbert starts, turned tables at 10° and 20°, then every start with slope
steps and every turned table again with the yield conditions as rows) searches the scenes where
one kept start alone reached the lowest state, and must find nothing lower than the plan does.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import alma
from alma.nonassociative.policy import plan, start_name
from alma.settings import SearchSettings, Settings
from benchmarks.bench_friction import FRICTION, WALLS

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

#: The former plan's thorough starts, as settings.
FORMER = SearchSettings(
    gilbert_thorough=(
        (0.0, 1.0, 1),
        (1.0, 0.5, 0),
        (0.0, 1.0, 4),
        (1.0, 0.5, 4),
        (0.5, 0.5, 1),
        (2.0, 1.0, 1),
        (1.0, 1.0, 0),
    ),
    gilbert_thorough_rows=((0.0, 1.0, 1), (0.0, 1.0, 4), (1.0, 0.5, 4), (0.5, 0.5, 1), (2.0, 1.0, 1)),
    tilt_degrees=(10.0, 20.0),
    tilt_degrees_rows=(10.0, 20.0),
)


def _wall(k: int) -> alma.Scene:
    return alma.coursed_wall(WALLS[k], 400.0, 175.0, friction=FRICTION, thickness=1000.0, unit_weight=10.0)


def test_the_thorough_plan_is_the_measured_one():
    names = [start_name(kind, SearchSettings(), "thorough") for kind in plan(SearchSettings(), "thorough")]
    fixed = [n for n in names if n.startswith(("gilbert(", "tilt(")) and "±" not in n]
    assert fixed == [
        "gilbert(N̄=0·N_LP, r=1, steps=1)",
        "gilbert(N̄=1·N_LP, r=0.5, steps=0)",
        "gilbert(N̄=2·N_LP, r=1, steps=1)",
        "tilt(10°)",
        "gilbert(N̄=1·N_LP, r=0.5, steps=4, rows)",
        "gilbert(N̄=0.5·N_LP, r=0.5, steps=1, rows)",
        "gilbert(N̄=2·N_LP, r=1, steps=1, rows)",
    ]


@pytest.mark.slow  # the former plan takes 2-9 s a scene
@pytest.mark.parametrize(
    "scene",
    [
        pytest.param(lambda: _wall(2), id="F&TL wall 2"),  # gilbert(0, 1, 1) alone
        pytest.param(lambda: _wall(6), id="F&TL wall 6"),  # tilt(10°) alone
        pytest.param(lambda: alma.load_scene(EXAMPLES / "stack_cohesion.json"), id="stack_cohesion"),
    ],
)
def test_the_former_thorough_plan_finds_nothing_lower(scene):
    s = scene()
    now = alma.solve(s, model="nonassociative", effort="thorough")
    former = alma.solve(s, model="nonassociative", effort="thorough", settings=Settings(search=FORMER))
    assert now.status == former.status == "feasible", (now.status, former.status)
    assert len(former.starts) > len(now.starts)
    assert now.alpha <= former.alpha * (1 + 1e-9), (now.alpha, former.alpha)
