"""alma's interior point with cohesion and ties (bounded forces as eliminated auxiliary rows).

The same checks as for the Clarabel path (``test_cohesion_ties_loads.py``), run through
``solve_lp(engine="ipm")``: the analytic single-block values, an independent static LP with
HiGHS, cohesive and tied panels against Clarabel (overlapping certified intervals), and random
assemblies with random cohesion and ties (same status, overlapping intervals).  Every answer
must come from the interior point itself, certified, with no fallback to Clarabel.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st
from test_cohesion_ties_loads import THICKNESS, _tied_block, _weight, block_scene, independent_static
from test_engine_crosscheck import _directed, _overlap, engines_agree

import alma
from alma.associative.lp import solve_lp
from alma.geometry.chains import with_chain
from alma.status import Status

from helpers import assemblies


def _ipm(model: alma.Model):
    result = solve_lp(model, engine="ipm")
    assert "alma-ipm" in result.message and "Clarabel used" not in result.message, result.message
    return result


def _brackets(result, value: float) -> bool:
    tol = 1e-7 * max(1.0, abs(value))
    return result.lower <= value + tol and value <= result.upper + tol


@settings(max_examples=20, deadline=None)
@given(b=st.floats(60, 400), h=st.floats(40, 600), f=st.floats(0.1, 1.5), c=st.floats(0.0, 20.0))
def test_single_block_with_base_cohesion(b, h, f, c):
    """α = min(f + c b t / W, b / h) through the interior point."""
    result = _ipm(alma.build_model(block_scene(b, h, f, cohesion=c)))
    expected = min(f + c * b * THICKNESS * 1e-6 / _weight(b, h), b / h)
    assert result.status == Status.OPTIMAL
    assert result.alpha == pytest.approx(expected, rel=1e-8)


@settings(max_examples=20, deadline=None)
@given(
    b=st.floats(60, 300),
    h=st.floats(100, 600),
    f=st.floats(1.0, 3.0),
    y_frac=st.floats(0.3, 0.95),
    share=st.floats(0.0, 1.0),
)
def test_single_block_with_a_tie_to_a_windward_anchor(b, h, f, y_frac, share):
    """α = min(f + F/W, b/h + 2 F y / (W h)) through the interior point (the range of the
    Clarabel-path test, where these two mechanisms are the lowest)."""
    W = _weight(b, h)
    model = alma.build_model(_tied_block(b, h, f, y_frac * h, share * W))
    result = _ipm(model)
    expected = min(f + share, b / h + 2 * share * W * y_frac * h / (W * h))
    assert result.status == Status.OPTIMAL
    assert result.alpha == pytest.approx(expected, rel=1e-8)
    # τ within [0, capacity] (dimensionless, as the model's capacity)
    assert result.bounded_forces.min() >= -1e-9
    assert result.bounded_forces.max() <= model.capacity.max() * (1 + 1e-9) + 1e-12


def _largest(cohesion: float = 0.0, chains: int = 0) -> alma.Scene:
    panel = alma.paper_panel("english", "1:2", "1:1", 0.6)
    for height in (690.0, 1410.0, 2130.0, 2850.0)[:chains]:
        panel = with_chain(panel, height, 5.0)
    return alma.Scene.from_dict({**panel.to_dict(), "cohesion": cohesion})


#: Small enough for the independent static LP (HiGHS's dual simplex takes ~50 s on the largest).
CASES = {
    "running 2:1 4:1 c=2": lambda: alma.Scene.from_dict(
        {**alma.paper_panel("running", "2:1", "4:1", 0.6).to_dict(), "cohesion": 2.0}
    ),
    "stack 2:1 2:1 c=5": lambda: alma.Scene.from_dict(
        {**alma.paper_panel("stack", "2:1", "2:1", 0.6).to_dict(), "cohesion": 5.0}
    ),
    "english 1:1 2:1 c=1": lambda: alma.Scene.from_dict(
        {**alma.paper_panel("english", "1:1", "2:1", 0.6).to_dict(), "cohesion": 1.0}
    ),
}
#: The largest paper panel (1,752 blocks), against Clarabel.
LARGEST = {
    "english 1:2 1:1 c=5": lambda: _largest(5.0),
    "english 1:2 1:1 c=1e-6": lambda: _largest(1e-6),  # capacities ~1e-6: the rows C stay tiny
    "english 1:2 1:1 4 chains": lambda: _largest(0.0, 4),
    "english 1:2 1:1 c=5 + 4 chains": lambda: _largest(5.0, 4),
}


def _against_clarabel(model: alma.Model):
    ipm = _ipm(model)
    clarabel = solve_lp(model, engine="clarabel")
    assert ipm.status == clarabel.status == Status.OPTIMAL, (ipm.message, clarabel.message)
    assert (ipm.upper - ipm.lower) / max(1.0, abs(ipm.upper)) <= 1e-7
    assert _overlap(ipm, clarabel), (ipm.lower, ipm.upper, clarabel.lower, clarabel.upper)
    return ipm


@pytest.mark.parametrize("name", list(CASES))
def test_cohesive_and_tied_panels_against_clarabel_and_an_independent_lp(name):
    model = alma.build_model(CASES[name]())
    ipm = _against_clarabel(model)
    assert _brackets(ipm, independent_static(model)), (ipm.lower, ipm.upper)


@pytest.mark.parametrize("name", list(LARGEST))
def test_the_largest_panel_with_cohesion_and_chains_against_clarabel(name):
    _against_clarabel(alma.build_model(LARGEST[name]()))


@st.composite
def _bounded_assemblies(draw):
    data = draw(assemblies())
    data["cohesion"] = draw(st.sampled_from([0.0, 0.01, 0.5, 5.0, 50.0]))
    free = [b for b in data["blocks"] if not b.get("fixed")]
    if draw(st.booleans()):
        a, b = draw(st.sampled_from(free)), draw(st.sampled_from(data["blocks"]))
        pa, pb = a["vertices"][draw(st.integers(0, 3))], b["vertices"][draw(st.integers(0, 3))]
        if a["id"] != b["id"] and pa != pb:
            data["ties"] = [
                {
                    "id": "t",
                    "from": {"block": a["id"], "point": pa},
                    "to": {"block": b["id"], "point": pb},
                    "strength": draw(st.sampled_from([0.0, 0.01, 0.2, 2.0])),
                }
            ]
    return data


@settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(data=_bounded_assemblies(), gravity=st.floats(0.0, 2 * math.pi), live=st.floats(0.0, 2 * math.pi))
def test_random_bounded_scenes_same_status_and_overlapping_bounds(data, gravity, live):
    engines_agree(alma.build_model(_directed(data, gravity, live)))
