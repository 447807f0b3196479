"""Non-associative friction (Eq. 9): analytic and prototype cases, certification, Radenkovic.

The default search (``alma.solve(model="nonassociative")``) must reach the global optimum
that the MILP certifies on small scenes, and never exceed the associative LP value.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, assume, given, settings, strategies as st

import alma

from helpers import assemblies, single_block_scene


def side_by_side(k: int, f: float, b: float = 1.0, h: float = 2.0) -> alma.Scene:
    """k blocks b × h side by side on the ground (the prototype's trap cases)."""
    blocks = [{"id": "g", "vertices": [[-b, -1], [(k + 1) * b, -1], [(k + 1) * b, 0], [-b, 0]], "fixed": True}]
    blocks += [
        {"id": f"b{i}", "vertices": [[i * b, 0], [(i + 1) * b, 0], [(i + 1) * b, h], [i * b, h]]} for i in range(k)
    ]
    return alma.Scene.from_dict({"friction": f, "blocks": blocks})


@pytest.mark.slow  # 10–15 s: CI runs it with the slow part
@given(b=st.floats(20, 1000), h=st.floats(20, 1000), f=st.floats(0.05, 2.0))
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_single_block_both_models(b, h, f):
    assume(abs(f - b / h) > 1e-3 * max(f, b / h))
    result = alma.solve(single_block_scene(b, h, f), model="both")
    expected = min(f, b / h)
    assert result.status == "feasible"  # a verified state; nothing proves it is the minimum
    assert result.alpha == pytest.approx(expected, rel=1e-7)
    assert result.alpha_associative == pytest.approx(expected, rel=1e-7)
    assert result.extra["ratio"] == pytest.approx(1.0, rel=1e-7)


@pytest.mark.parametrize(
    "k,f,associative,nonassociative",
    [
        (2, 1.0, 1.0, 0.5),  # each block rocks alone; the head joint slips with no normal force
        (2, 0.6, 0.5319148936, 0.5),
        (3, 1.0, 1.0, 0.5),  # the trap: LP start, penalty and a single Gilbert run stay at 1.0
    ],
)
def test_blocks_side_by_side(k, f, associative, nonassociative):
    result = alma.solve(side_by_side(k, f), model="nonassociative")
    assert result.status == "feasible"
    assert result.alpha_associative == pytest.approx(associative, rel=1e-7)
    assert result.alpha == pytest.approx(nonassociative, rel=1e-7)
    assert all(v <= 1e-7 for k_, v in result.residuals.items() if k_ != "live_load_work")


def test_stack_panel_rocks_at_b_over_H():
    result = alma.solve(alma.paper_panel("stack", "2:1", "2:1", 0.6), model="both")
    assert result.alpha_associative == pytest.approx(0.2245, abs=1e-4)
    assert result.alpha == pytest.approx(120 / 720, rel=1e-7)  # columns rock: b/H


@pytest.mark.parametrize("k,f", [(2, 1.0), (3, 1.0), (4, 0.6)])
def test_certificate_matches_search(k, f):
    scene = side_by_side(k, f)
    result = alma.solve(scene, model="nonassociative", certify=True)
    cert = result.extra["certificate"]
    assert cert["status"] == "proven"
    assert not cert["velocity_bound_active"]
    assert result.bounds.lower == pytest.approx(result.alpha, abs=1e-6)


@pytest.mark.slow  # 8–16 s: `make test` keeps to 5 minutes; `make test-slow` (CI) runs it
@given(data=assemblies(max_courses=2, max_per_course=3))
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_default_search_reaches_certified_optimum(data):
    """On small random assemblies the default α equals the MILP's proven optimum to 1e-6."""
    scene = alma.Scene.from_dict(data)
    assume(alma.solve(scene).status == "optimal")  # the assembly stands under its own weight
    result = alma.solve(scene, model="nonassociative", certify=True)
    cert = result.extra.get("certificate")
    assume(cert is not None and cert["status"] == "proven" and not cert["velocity_bound_active"])
    assert cert is not None  # for the type checker: assume() has already ruled None out
    assert result.status in ("feasible", "optimal")  # "optimal" once the certificate closes the bounds
    assert result.alpha == pytest.approx(cert["lower"], abs=1e-6), (result.alpha, cert, result.extra["candidates"])
    assert result.alpha <= result.alpha_associative + 1e-7


@pytest.mark.parametrize("bond", ["running", "stack", "english", "flemish"])
@pytest.mark.parametrize("friction", [0.27, 0.6, 1.0])
def test_radenkovic_on_small_paper_panels(bond, friction):
    """α_NLNCP ≤ α_LP + 1e-7 (Radenkovic's first theorem), every reported state verified."""
    result = alma.solve(alma.paper_panel(bond, "2:1", "4:1", friction), model="nonassociative", effort="fast")
    assert result.status == "feasible"
    assert result.alpha <= result.alpha_associative + 1e-7
    assert math.isfinite(result.alpha)
    candidates = result.extra["candidates"]
    assert any(c["verified"] and c["alpha"] == pytest.approx(result.alpha, abs=1e-12) for c in candidates)


def test_rocking_without_sliding_models_agree():
    """When the LP mechanism has no sliding joint (a slender column rocks), both models agree."""
    scene = single_block_scene(100, 400, 1.0)
    lp = alma.solve(scene)
    assert lp.mechanism_class == "rocking"
    result = alma.solve(scene, model="nonassociative", certify=True)
    assert result.alpha == pytest.approx(lp.alpha, rel=1e-7)
    assert result.bounds.lower == pytest.approx(lp.alpha, rel=1e-6)


def test_structure_that_cannot_stand_is_no_equilibrium_in_both_models():
    """A block held only by friction against a wall: α_LP < 0, hence α_NL ≤ α_LP < 0 (Radenkovic)."""
    leaning = alma.Scene.from_dict(
        {
            "blocks": [
                {"id": "wall", "vertices": [[-10, 0], [0, 0], [0, 100], [-10, 100]], "fixed": True},
                {"id": "b", "vertices": [[0, 10], [20, 10], [20, 30], [0, 30]]},
            ]
        }
    )
    result = alma.solve(leaning, model="both")
    assert result.status == "no_equilibrium"
    assert result.bounds.upper < 0 and result.bounds.lower <= result.bounds.upper


def test_gilbert_interior_point_path_gives_verified_states():
    """Large scenes iterate the caps with Clarabel, small ones re-solve a warm HiGHS model.

    The two paths follow different iterates (interior against vertex solutions), so they may end
    in different collapse states; both must be verified and below the associative α (Radenkovic).
    """
    from alma.associative.lp import solve_lp
    from alma.mechanics.contact_points import ContactPoints
    from alma.mechanics.model import build_model
    from alma.nonassociative.gilbert import gilbert

    model = build_model(alma.paper_panel("stack", "2:1", "2:1", 0.6))
    points = ContactPoints.from_model(model)
    lp = solve_lp(model)
    start = lp.multipliers.reshape(-1, 2).sum(axis=1)
    simplex, _ = gilbert(model, points, start, ipm_above=10**9)
    ipm, _ = gilbert(model, points, start, ipm_above=0)
    assert simplex is not None and ipm is not None
    assert simplex.verified and ipm.verified
    # 1/6 = b/H is the certified optimum (whole-panel rocking): no verified state lies below it.
    for state in (simplex, ipm):
        assert 120 / 720 - 1e-9 <= state.alpha <= lp.alpha + 1e-7


@pytest.mark.xfail(
    strict=False,
    reason="measured 2026-11-23: since the Gilbert LP keeps its caps as column "
    "bounds (alma/cap_lp.py) its vertices differ and this single start ends at 0.181818 (a "
    "verified state) instead of 1/6; the default search still returns 1/6 "
    "(test_stack_panel_rocks_at_b_over_H)",
)
def test_gilbert_simplex_path_reaches_b_over_H():
    """The warm-simplex Gilbert start (N̄ = N_LP, r = 0.5, 4 slope steps) on the stack panel 2:1 2:1, f = 0.6."""
    from alma.associative.lp import solve_lp
    from alma.mechanics.contact_points import ContactPoints
    from alma.mechanics.model import build_model
    from alma.nonassociative.gilbert import gilbert

    model = build_model(alma.paper_panel("stack", "2:1", "2:1", 0.6))
    lp = solve_lp(model)
    simplex, _ = gilbert(
        model, ContactPoints.from_model(model), lp.multipliers.reshape(-1, 2).sum(axis=1), ipm_above=10**9
    )
    assert simplex is not None and simplex.verified
    assert simplex.alpha == pytest.approx(120 / 720, rel=1e-9)


def test_associative_mechanism_read_as_slips_gives_the_sliding_state():
    """A panel that slides in the LP (α = f) slides without dilatancy too: the 'lp' start verifies at f."""
    from alma.associative.lp import solve_lp
    from alma.mechanics.contact_points import ContactPoints
    from alma.mechanics.model import build_model
    from alma.nonassociative.exact_states import exact_state

    model = build_model(alma.paper_panel("running", "2:1", "4:1", 0.27))
    lp = solve_lp(model)
    assert lp.alpha == pytest.approx(0.27, abs=1e-7)
    state = exact_state(model, ContactPoints.from_model(model), lp.mechanism, "lp", dilatant=True)
    assert state is not None and state.verified
    assert state.alpha == pytest.approx(0.27, rel=1e-9)
    assert state.residuals["interpenetration"] <= 1e-9 and state.residuals["open_with_force"] <= 1e-9


def test_kinematic_lp_meets_the_prescribed_active_set():
    import numpy as np

    from alma.mechanics.contact_points import ContactPoints
    from alma.mechanics.model import build_model
    from alma.nonassociative.states import active_set
    from alma.nonassociative.static_lps import kinematic_lp

    model = build_model(side_by_side(2, 1.0))
    points = ContactPoints.from_model(model)
    # Both blocks slide together to the right: the base points slip, the head joint sticks.
    together = np.zeros(model.dead.shape[0])
    together[[0, 3]] = 1.0
    open_points, slip_sign = active_set(model, points, together)
    assert not open_points.any() and np.count_nonzero(slip_sign) == 4
    u, _ = kinematic_lp(model, points, open_points, slip_sign)
    assert u is not None
    assert model.live @ u == pytest.approx(model.n_free)
    scale = np.abs(u).max()
    assert np.abs(points.normal.T @ u).max() <= 1e-9 * scale  # every point stays closed
    slip = points.tangent.T @ u
    assert np.all(slip[slip_sign == 0] == pytest.approx(0.0, abs=1e-9 * scale))
    assert np.all(slip_sign[slip_sign != 0] * slip[slip_sign != 0] > 0)
    # The right block alone cannot slide right with the head joint closed: no such mechanism.
    alone = np.zeros(model.dead.shape[0])
    alone[3] = 1.0
    _, alone_slips = active_set(model, points, alone)
    assert kinematic_lp(model, points, np.zeros(points.count, dtype=bool), alone_slips)[0] is None


@pytest.mark.slow  # runs the search to its time limit: 40 s here
def test_time_limit_stops_the_search_and_says_what_was_skipped():
    """A time limit that has passed before the first start: nothing runs, the solution says the
    cap stopped it and names every start it skipped."""
    import time

    from alma.associative.lp import solve_lp
    from alma.nonassociative.search import solve_nonassociative

    model = alma.build_model(alma.paper_panel("english", "2:1", "2:1", 1.0))
    lp = solve_lp(model)
    start = time.perf_counter()
    solution = solve_nonassociative(
        model, lp.mechanism, lp.multipliers, effort="thorough", time_limit=0.0, associative_alpha=lp.alpha
    )
    assert time.perf_counter() - start < 10.0
    assert solution.stopped_by_limit and solution.status == "not_converged" and not solution.starts
    assert solution.skipped[:3] == ("lp", "rocking", "gilbert(N̄=0·N_LP, r=1, steps=1)")
    assert "gilbert-projected" in solution.skipped
    plain = solve_nonassociative(model, lp.mechanism, lp.multipliers, effort="thorough", associative_alpha=lp.alpha)
    assert not plain.stopped_by_limit and plain.skipped == () and plain.status == "feasible"


@pytest.mark.parametrize(
    "bond, panel, block, friction, whole_search",
    [
        pytest.param("english", "1:1", "4:1", 1.0, True, marks=pytest.mark.slow),  # the whole search: 40 s here
        ("english", "1:1", "2:1", 0.27, False),
    ],
)
def test_projected_iteration_settles_on_large_panels(bond, panel, block, friction, whole_search):
    """Two panels (228 and 444 blocks) where no fixed start of the 108-panel run of 2026-11-21
    gave a verified state (their vertex iterates jump across the capped LPs' optimal faces):
    the projected iteration settles on a verified state below the associative α (Radenkovic),
    and the default search (effort "fast" above 200 blocks) reports a verified state below the
    associative α too (checked on the smaller panel only).  Measured with the work budgets (the
    same on every machine): on english 1:1 4:1 f = 1 the projected iteration (60,000 / free
    blocks iterations) settles at 0.7124146; the default search reports gilbert(1, 0.5, 0)'s
    0.7141536, since effort "fast" runs the projected iteration only when no fixed start has
    verified a state (docs/decisions.md).  Under the wall-clock shares this case was a
    strict xfail that passed or failed with the machine's load (issue 15)."""
    from alma.associative.lp import solve_lp
    from alma.mechanics.contact_points import ContactPoints
    from alma.mechanics.model import build_model
    from alma.nonassociative.gilbert import projected_gilbert

    model = build_model(alma.paper_panel(bond, panel, block, friction))
    points = ContactPoints.from_model(model)
    lp = solve_lp(model)
    state, _iterations = projected_gilbert(model, points, lp.multipliers.reshape(-1, 2).sum(axis=1))
    assert state is not None and state.verified, state and state.residuals
    assert state.alpha <= lp.alpha + 1e-7
    if whole_search:
        result = alma.solve(model, "nonassociative")
        assert result.status == "feasible" and result.alpha <= lp.alpha + 1e-7


def test_warm_highs_model_iteration_limit_is_per_solve():
    """The simplex iteration cap of the persistent HiGHS model applies to each re-solve, not to
    their sum: a cap above every single solve's count but far below the total never stops one."""
    import numpy as np

    from alma.associative.lp import solve_lp
    from alma.mechanics.contact_points import ContactPoints
    from alma.mechanics.model import build_model
    from alma.nonassociative.cap_lp import CapLP

    model = build_model(alma.paper_panel("running", "2:1", "4:1", 0.6))
    points = ContactPoints.from_model(model)
    n_lp = solve_lp(model).multipliers.reshape(-1, 2).sum(axis=1)
    caps = [points.friction * n_lp * factor for factor in np.random.default_rng(3).uniform(0.5, 1.5, 30)]
    warm = CapLP(model, points)
    free = [warm.solve(np.zeros(points.count), cap) for cap in caps]
    assert {lp.status for lp in free} == {"optimal"}
    largest = max(lp.pivots for lp in free)
    assert sum(lp.pivots for lp in free) > 3 * largest
    capped = CapLP(model, points, max_pivots=largest)
    again = [capped.solve(np.zeros(points.count), cap) for cap in caps]
    assert [lp.status for lp in again] == ["optimal"] * len(caps)
    assert [lp.alpha for lp in again] == [lp.alpha for lp in free]
    stalled = CapLP(model, points, max_pivots=1).solve(np.zeros(points.count), caps[0])
    assert stalled.status == "error"  # the first solve needs more than one iteration


def test_ipopt_polish_spends_iterations_not_seconds():
    """IPOPT's relaxed solves are bounded by iterations: with one iteration none converges and no
    candidate comes back; with the default it does (three blocks side by side).  A passed time
    limit starts no solve."""
    from alma.associative.lp import solve_lp
    from alma.mechanics.contact_points import ContactPoints
    from alma.mechanics.model import build_model
    from alma.nonassociative.limits import Cap
    from alma.nonassociative.nlp import ipopt_polish

    model = build_model(side_by_side(3, 0.6))
    points = ContactPoints.from_model(model)
    mechanism = solve_lp(model).mechanism
    assert ipopt_polish(model, points, mechanism, cap=Cap(0.0)) is None
    assert ipopt_polish(model, points, mechanism, max_iter=1) is None
    state = ipopt_polish(model, points, mechanism)
    assert state is not None and state.verified


@pytest.mark.parametrize("lp_verifies", [True, False])
def test_fast_fixed_starts_get_the_verified_budget_after_a_verified_state(monkeypatch, lp_verifies):
    """effort "fast": a fixed Gilbert start may spend ``gilbert_pivots`` simplex iterations, and
    only ``gilbert_pivots_verified`` once an earlier start has verified a state."""
    import alma.nonassociative.starts as starts
    from alma.associative.lp import solve_lp
    from alma.mechanics.model import build_model
    from alma.nonassociative.search import solve_nonassociative
    from alma.settings import SearchSettings

    model = build_model(single_block_scene(1.0, 2.0, 0.6))
    lp = solve_lp(model)
    budgets: list[int | None] = []

    def gilbert_spy(model, points, initial_normal, *, work, **kwargs):
        budgets.append(work.pivots)
        return None, 0

    monkeypatch.setattr(starts, "gilbert", gilbert_spy)
    monkeypatch.setattr(starts, "rocking_start", lambda *args, **kwargs: (None, 0))
    settings = SearchSettings(gilbert_pivots=5000, gilbert_pivots_verified=700)
    solution = solve_nonassociative(
        model,
        lp.mechanism if lp_verifies else None,
        lp.multipliers,
        effort="fast",
        settings=settings,
        associative_alpha=lp.alpha,
    )
    assert len(budgets) == len(settings.gilbert_fast)
    assert any(r.verified for r in solution.starts if r.start in ("lp", "rocking")) == lp_verifies
    assert budgets == [700 if lp_verifies else 5000] * len(settings.gilbert_fast)
