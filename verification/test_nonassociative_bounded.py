"""Cohesion and ties in the non-associative model (Eq. 9 with bounded forces).

Analytic single blocks (property-based), Radenkovic's bounds on random small cohesive and tied
scenes, the limit c → 0 on a paper panel, and a cohesive paper panel between its bounds.
Every state counted here passed :func:`alma.nonassociative.states.verify` with the bounded
forces' equilibrium, bounds, flow rule and dissipation.
"""

from __future__ import annotations

import dataclasses
import math

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st
from test_cohesion_ties_loads import THICKNESS, _tied_block, _weight, block_scene

import alma
from alma.settings import StateTolerances
from alma.status import Status

from helpers import assemblies

KINEMATIC_TOLERANCE = StateTolerances().kinematic
YIELD_TOLERANCE = StateTolerances().yield_violation

VERIFIED = (Status.OPTIMAL, Status.FEASIBLE)


def _nonassociative(scene: alma.Scene, **kwargs) -> alma.NonAssociativeResult:
    result = alma.solve(scene, model="nonassociative", **kwargs)
    assert result.status in VERIFIED, result.message
    assert result.residuals.get("bounded_not_mobilised", 0.0) <= KINEMATIC_TOLERANCE
    assert result.residuals["yield"] <= YIELD_TOLERANCE
    return result


@pytest.mark.slow  # 10–15 s: CI runs it with the slow part
@settings(max_examples=15, deadline=None)
@given(b=st.floats(60, 400), h=st.floats(40, 600), f=st.floats(0.1, 1.5), c=st.floats(0.5, 20.0))
def test_single_block_with_base_cohesion(b, h, f, c):
    """α = min(f + c b t / W, b / h): sliding against friction and cohesion, or rocking (neither
    dilates, so the associative value is also the non-associative one)."""
    result = _nonassociative(block_scene(b, h, f, cohesion=c))
    expected = min(f + c * b * THICKNESS * 1e-6 / _weight(b, h), b / h)
    assert result.alpha == pytest.approx(expected, rel=1e-8)


@pytest.mark.slow  # 8–16 s: `make test` keeps to 5 minutes; `make test-slow` (CI) runs it
@settings(max_examples=15, deadline=None)
@given(
    b=st.floats(60, 300),
    h=st.floats(100, 600),
    f=st.floats(1.0, 3.0),
    y_frac=st.floats(0.3, 0.95),
    share=st.floats(0.0, 1.0),
)
def test_single_block_with_a_tie_to_a_windward_anchor(b, h, f, y_frac, share):
    """The tied block of the associative test (tie at height y to a windward anchor, F = share · W):
    α = min(f + F/W, b/h + 2 F y / (W h)) in the non-associative model too, the tie at its strength."""
    y, W = y_frac * h, _weight(b, h)
    strength = share * W
    result = _nonassociative(_tied_block(b, h, f, y, strength))
    assert result.alpha == pytest.approx(min(f + strength / W, b / h + 2 * strength * y / (W * h)), rel=1e-8)
    (chain,) = result.to_dict()["ties"]
    assert chain["force"] == pytest.approx(strength, rel=1e-7, abs=1e-12)


@st.composite
def cohesive_tied_scenes(draw) -> alma.Scene:
    """A random small assembly with base and bed cohesion and, half the time, a tie from its last
    block's centre to the ground on the windward side."""
    data = draw(assemblies(max_courses=3, max_per_course=3))
    data["cohesion"] = draw(st.floats(0.5, 20.0))
    if draw(st.booleans()):
        ground, last = data["blocks"][0]["vertices"], data["blocks"][-1]["vertices"]
        x = 0.75 * ground[0][0] + 0.25 * ground[1][0]
        centre = [0.5 * (last[0][0] + last[2][0]), 0.5 * (last[0][1] + last[2][1])]
        data["ties"] = [
            {
                "id": "t",
                "from": {"block": data["blocks"][-1]["id"], "point": centre},
                "to": {"block": "ground", "point": [x, 0.5 * ground[0][1]]},
                "strength": draw(st.floats(0.0, 0.2)),
            }
        ]
    return alma.Scene.from_dict(data)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene=cohesive_tied_scenes())
def test_radenkovic_bounds_hold_on_random_cohesive_and_tied_scenes(scene):
    """Radenkovic's lower bound (associative, friction 0) ≤ every verified collapse state, and the
    lowest verified state ≤ the associative α (his upper bound: the minimum of Eq. 9 lies below
    α_LP; a single state other than the lowest may lie above it)."""
    both = alma.solve(scene, model="both", effort="fast")
    nl, lp = both.nonassociative, both.associative
    verified = [c["alpha"] for c in nl.candidates if c["verified"]]
    if not verified:
        # Random stacks with overhangs often cannot stand (both models: no_equilibrium); about
        # half of the examples give verified states.
        assert nl.status in (Status.NO_EQUILIBRIUM, Status.NOT_CONVERGED) or lp.status == Status.NO_COLLAPSE
        return
    # Candidates hold α on the search's canonical model (data rounded, canonical_bits); the answer is
    # the lowest one made exact on the scene itself.
    assert min(verified) == pytest.approx(nl.alpha, rel=1e-6)
    lower = nl.search["radenkovic_lower_bound"]
    tol = 1e-7 * max(1.0, abs(nl.alpha))
    if lower is not None:
        assert all(alpha >= lower - tol for alpha in verified)
    if lp.status in (Status.OPTIMAL, Status.NO_EQUILIBRIUM) and math.isfinite(lp.alpha):
        assert nl.alpha <= lp.alpha + tol


def _with_cohesion(bond: str, panel: str, block: str, f: float, c: float) -> alma.Scene:
    return dataclasses.replace(alma.paper_panel(bond, panel, block, f), cohesion=c)


@pytest.mark.parametrize("bond,panel,block,f", [("running", "2:1", "4:1", 0.27), ("stack", "2:1", "2:1", 0.6)])
def test_cohesion_to_zero_recovers_the_cohesionless_search(bond, panel, block, f):
    """c = 10⁻⁶ kPa: the same α as without cohesion within what that cohesion can dissipate
    (running 2:1 4:1, f = 0.27: 0.27 sliding, 0.2700000770 with c; stack 2:1 2:1: 1/6 rocking)."""
    base = alma.solve(alma.paper_panel(bond, panel, block, f), model="nonassociative", effort="fast")
    small = _nonassociative(_with_cohesion(bond, panel, block, f, 1e-6), effort="fast")
    assert base.status in VERIFIED
    assert small.alpha == pytest.approx(base.alpha, rel=1e-6)


@pytest.mark.slow  # 8–16 s: `make test` keeps to 5 minutes; `make test-slow` (CI) runs it
@pytest.mark.xfail(
    strict=True,
    reason="measured: c = 1e-9 kPa gives 0.422791 against 0.421139 without cohesion "
    "(both gilbert(N̄=0·N_LP, r=1, steps=1)); the extra columns change the simplex's "
    "path on the degenerate faces and the first Gilbert start ends on another state",
)
def test_cohesion_to_zero_on_the_running_panel_1_1_2_1():
    """Running 1:1 2:1, f = 0.6: the search is not continuous in c on this panel."""
    base = alma.solve(alma.paper_panel("running", "1:1", "2:1", 0.6), model="nonassociative")
    small = _nonassociative(_with_cohesion("running", "1:1", "2:1", 0.6, 1e-9))
    assert small.alpha == pytest.approx(base.alpha, rel=1e-6)


@pytest.mark.slow  # 8–16 s: `make test` keeps to 5 minutes; `make test-slow` (CI) runs it
@pytest.mark.xfail(
    strict=True,
    reason="the search on the canonical drawing (issue 30) lands at 0.769868 "
    "> 0.765467: a higher local minimum of the non-convex search (docs/decisions.md)",
)
def test_cohesive_running_panel_between_radenkovic_and_the_associative_bound():
    """Running 1:1 2:1, f = 0.6, c = 5 kPa (300 blocks, effort "fast"): Radenkovic's bound
    0.192901 and the associative α 0.792870 (LP optima: pinned); the lowest verified
    non-associative state is the search's (a heuristic on degenerate faces, whose path follows the
    platform's round-off): 0.765467 (start gilbert(N̄=0·N_LP, r=1, steps=1)) on the CI machine of
    2026-11-25, 0.765260 (gilbert(N̄=1·N_LP, r=0.5, steps=0)) on an AVX-512 machine the same
    day; it must not rise above the first.  Without cohesion the panel gave 0.420710 and
    0.435172 then (0.421139 here on 2026-11-26)."""
    both = alma.solve(_with_cohesion("running", "1:1", "2:1", 0.6, 5.0), model="both")
    nl, lp = both.nonassociative, both.associative
    assert lp.status == Status.OPTIMAL and nl.status == Status.FEASIBLE
    assert nl.residuals["bounded_not_mobilised"] <= KINEMATIC_TOLERANCE
    assert nl.bounds.lower == pytest.approx(0.192901, abs=1e-6)
    assert nl.bounds.lower < nl.alpha < lp.alpha
    assert lp.alpha == pytest.approx(0.792870, abs=1e-6)
    assert nl.alpha <= 0.765467 + 1e-6


def _ipopt_state(scene: alma.Scene):
    """IPOPT's polish alone, from the associative mechanism (no seed forces), turned into an
    exact state and verified like every other candidate."""
    from alma.associative.lp import solve_lp
    from alma.mechanics.contact_points import ContactPoints
    from alma.nonassociative.nlp import ipopt_polish

    model = alma.build_model(scene)
    state = ipopt_polish(model, ContactPoints.from_model(model), solve_lp(model).mechanism)
    assert state is not None and state.verified, state
    assert state.bounded.shape == (model.n_bounded,)
    return model, state


@settings(max_examples=8, deadline=None)
@given(b=st.floats(60, 400), h=st.floats(40, 600), f=st.floats(0.1, 1.5), c=st.floats(0.5, 20.0))
def test_ipopt_takes_cohesion_on_a_single_block(b, h, f, c):
    """The IPOPT polish with cohesion: α = min(f + c b t / W, b / h)."""
    _, state = _ipopt_state(block_scene(b, h, f, cohesion=c))
    assert state.alpha == pytest.approx(min(f + c * b * THICKNESS * 1e-6 / _weight(b, h), b / h), rel=1e-8)


@settings(max_examples=8, deadline=None)
@given(
    b=st.floats(60, 300),
    h=st.floats(100, 600),
    f=st.floats(1.0, 3.0),
    y_frac=st.floats(0.3, 0.95),
    share=st.floats(0.05, 1.0),
)
def test_ipopt_takes_a_tie_on_a_single_block(b, h, f, y_frac, share):
    """The IPOPT polish with a tie to a windward anchor: α = min(f + F/W, b/h + 2 F y / (W h))."""
    y, W = y_frac * h, _weight(b, h)
    model, state = _ipopt_state(_tied_block(b, h, f, y, share * W))
    assert state.alpha == pytest.approx(min(f + share, b / h + 2 * share * y / h), rel=1e-8)
    assert state.bounded[0] == pytest.approx(model.capacity[0], rel=1e-7)


@pytest.mark.slow  # IPOPT on a cohesive tied wall: 25-145 s each here
@pytest.mark.parametrize("c,tie", [(2.0, 0.0), (0.5, 0.2), (0.0, 0.5)])
def test_ipopt_on_a_cohesive_tied_wall_lies_between_the_bounds(c, tie):
    """A small running-bond wall (3 courses of 240 × 60 mm, f = 0.6) with cohesion and a tie
    across its top course: the IPOPT state is verified and lies between Radenkovic's lower bound
    and the associative α."""
    data = alma.wall("running", 720.0, 180.0, 240.0).with_friction(0.6).to_dict()
    free = [b for b in data["blocks"] if not b.get("fixed")]
    top = max(v[1] for b in free for v in b["vertices"])
    course = [b for b in free if max(v[1] for v in b["vertices"]) == top]
    left = min(course, key=lambda b: min(v[0] for v in b["vertices"]))
    right = max(course, key=lambda b: max(v[0] for v in b["vertices"]))
    ties = (
        [
            {
                "id": "chain",
                "from": {"block": left["id"], "point": [min(v[0] for v in left["vertices"]), top - 30]},
                "to": {"block": right["id"], "point": [max(v[0] for v in right["vertices"]), top - 30]},
                "strength": tie,
            }
        ]
        if tie
        else []
    )
    scene = alma.Scene.from_dict({**data, "cohesion": c, "ties": ties})
    _, state = _ipopt_state(scene)
    result = alma.solve(scene, model="nonassociative")
    assert result.bounds.lower - 1e-9 <= state.alpha <= result.alpha_associative + 1e-9


def test_ipopt_finds_a_cohesive_state_below_the_associative_one():
    """A 480 × 480 mm running-bond wall of 240 × 60 mm blocks, f = 0.6, c = 1 kPa (20 free
    blocks): IPOPT's verified state lies strictly below the associative α (measured 0.708557
    against 0.715741) and above Radenkovic's bound (0.115741), and it is as low as the search's."""
    data = alma.wall("running", 480.0, 480.0, 240.0).with_friction(0.6).to_dict()
    scene = alma.Scene.from_dict({**data, "cohesion": 1.0})
    _, state = _ipopt_state(scene)
    result = alma.solve(scene, model="nonassociative")
    assert result.bounds.lower - 1e-9 <= state.alpha <= result.alpha_associative - 1e-3
    assert state.alpha <= result.alpha + 1e-7
