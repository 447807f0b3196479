"""What bounds one run of the capped (Gilbert) LP: a floor on α, the simplex's bailout checks,
and the user's hard cap.

A displaced paper panel (english 1:1 2:1, f = 0.6, the first configuration of its friction push)
had warm dual simplex runs go on for seconds a pivot on numerically singular bases, one after
proving α below −2,000, another looping through 56,000 bailout checks in 6,300 iterations: 24
minutes without an answer.  The floor stops a run whose dual objective proves α below it; the
checks count against the iteration limit and stop a run where they outrun its iterations; the
user's cap reaches into the run as HiGHS's time limit.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import alma
from alma.associative.lp import solve_lp
from alma.backends import highs_warm
from alma.backends.termination import Termination
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import build_model
from alma.nonassociative.cap_lp import DUAL_TOLERANCE, CapLP, live_total
from alma.nonassociative.limits import Work
from alma.nonassociative.policy import _floored
from alma.nonassociative.tilted import turned


def _turned_panel() -> tuple:
    """A small panel on a table turned by 20°, its LP normal forces, and the caps' scales."""
    model = turned(build_model(alma.paper_panel("running", "2:1", "4:1", 0.6)), 20.0)
    points = ContactPoints.from_model(model)
    n_lp = solve_lp(model).multipliers.reshape(-1, 2).sum(axis=1)
    return model, points, points.friction * n_lp


def _two_solves(model, points, cap, **kwargs) -> tuple:
    """The first (cold) solve at the LP's caps, then a warm one at a hundredth of them."""
    lp = CapLP(model, points, **kwargs)
    first = lp.solve(np.zeros(points.count), cap)
    return first, lp.solve(np.zeros(points.count), 0.01 * cap)


def test_a_capped_lp_proven_below_its_floor_stops_failed():
    model, points, cap = _turned_panel()
    first, low = _two_solves(model, points, cap)
    assert first.status == low.status == "optimal"
    assert low.alpha < 0 < first.alpha  # a hundredth of the shear capacity: the turned weight must be pulled back
    margin = 0.01 * abs(low.alpha)
    above_floor = _two_solves(model, points, cap, alpha_floor=low.alpha - margin)
    assert [s.status for s in above_floor] == ["optimal", "optimal"]
    assert above_floor[1].alpha == pytest.approx(low.alpha, rel=1e-9)
    below_floor = _two_solves(model, points, cap, alpha_floor=low.alpha + margin)
    assert below_floor[0].alpha == pytest.approx(first.alpha, rel=1e-9)
    assert below_floor[1].status == "error" and below_floor[1].mechanism is None


def test_a_spent_user_cap_stops_the_run_and_a_free_one_does_not():
    model, points, cap = _turned_panel()
    lp = CapLP(model, points)
    assert lp.solve(np.zeros(points.count), cap, seconds=0.0).status == "error"
    again = lp.solve(np.zeros(points.count), cap, seconds=float("inf"))
    assert again.status == "optimal" and np.isfinite(again.alpha)


@pytest.mark.parametrize("alpha, floor", [(0.4, -100.0), (-3.0, -300.0), (250.0, -25_000.0), (None, -np.inf)])
def test_the_starts_floor_scales_with_the_associative_alpha(alpha, floor):
    """−capped_alpha_floor × max(1, |α_LP|); no floor without a finite α_LP."""
    ctx = SimpleNamespace(associative_alpha=alpha, settings=alma.Settings().search)
    assert _floored(Work(), ctx).alpha_floor == floor  # type: ignore[arg-type]


def test_the_bailout_checks_count_against_the_iteration_limit(monkeypatch):
    """With no check allowed, HiGHS's first bailout check interrupts the warm run: the callback is
    wired and its interrupt stops the simplex, reported as an iteration limit."""
    model, points, cap = _turned_panel()
    lp = CapLP(model, points)
    assert lp.solve(np.zeros(points.count), cap).status == "optimal"  # cold: interior point, no checks
    monkeypatch.setattr(highs_warm._Checks, "floor", 0)
    original = highs_warm._Checks.reset
    monkeypatch.setattr(highs_warm._Checks, "reset", lambda self, limit: original(self, 0))
    stopped = lp.solve(np.zeros(points.count), 0.5 * cap)
    assert stopped.status == "error" and stopped.mechanism is None
    assert lp._bounded is not None and lp._bounded.run(100_000).termination is Termination.ITERATION_LIMIT
    monkeypatch.undo()
    assert lp.solve(np.zeros(points.count), 0.5 * cap).status == "optimal"


def test_the_checks_read_the_runs_own_pivot_count(monkeypatch):
    """The stall rule compares the checks with HiGHS's pivots of the same run: in a real warm run
    the count the callback reads ends at the pivots the solve reports."""
    seen: list[int] = []
    original = highs_warm._Checks.count

    def count(self, event):
        seen.append(int(event.data_out.simplex_iteration_count))
        original(self, event)

    monkeypatch.setattr(highs_warm._Checks, "count", count)  # before the model subscribes it
    model, points, cap = _turned_panel()
    lp = CapLP(model, points)
    lp.solve(np.zeros(points.count), cap)
    seen.clear()
    warm = lp.solve(np.zeros(points.count), 0.5 * cap)
    assert warm.status == "optimal" and warm.pivots > 10
    assert seen and seen == sorted(seen) and warm.pivots - 2 <= seen[-1] <= warm.pivots


def test_checks_interrupt_only_past_their_limit():
    checks = highs_warm._Checks()
    checks.reset(2)  # below the floor: the floor
    assert checks.limit == checks.floor
    checks.reset(checks.floor + 2)
    event = _Event()
    for _ in range(checks.floor + 2):
        event.data_out.simplex_iteration_count += 1  # one check per pivot: a healthy run
        checks.count(event)
    assert not checks.spent and not event.interrupted
    checks.count(event)
    assert checks.spent and event.interrupted


def test_checks_that_stall_interrupt_before_the_limit():
    """Checks beyond the iterations, past the floor and a tenth of the iterations, stop the run."""
    checks = highs_warm._Checks()
    checks.reset(100_000)
    event = _Event()
    for _ in range(5_000):
        event.data_out.simplex_iteration_count += 1
        checks.count(event)
    allowed = checks.floor + checks.stall_share * 5_000
    for _ in range(int(allowed)):
        checks.count(event)  # rebuilds without a pivot
    assert not checks.spent and not event.interrupted
    checks.count(event)
    assert checks.spent and event.interrupted
    checks.reset(100_000)  # a new run starts its own count
    event.data_out.simplex_iteration_count = 0
    checks.count(event)
    assert not checks.spent and not event.interrupted


class _Event:
    """A stand-in for highspy's callback event: its interrupt flag and the run's iteration count."""

    def __init__(self) -> None:
        self.interrupted = False
        self.data_out = SimpleNamespace(simplex_iteration_count=0)

    def interrupt(self, value: bool = True) -> None:
        self.interrupted = value


def _panel_at_its_lp_caps(*panel) -> tuple:
    model = build_model(alma.paper_panel(*panel))
    points = ContactPoints.from_model(model)
    return model, points, points.friction * solve_lp(model).multipliers.reshape(-1, 2).sum(axis=1)


def _interpenetration(model, points, u) -> float:
    """The largest closing of a contact point per the mechanism's largest relative velocity."""
    assert float(model.live @ u) == pytest.approx(model.n_free)
    opening = points.normal.T @ u
    return float(np.maximum(-opening, 0).max()) / float(np.abs(np.concatenate([opening, points.tangent.T @ u])).max())


def test_the_clean_mechanism_is_exact_to_the_lps_tolerance():
    """At cost 1 a vertex's duals are dual feasible to δ = DUAL_TOLERANCE absolute, so its
    mechanism may close contacts by δ Σ|f_L| of its velocities: 2.0e-7 on this 1,560-block panel,
    over the verification's 1e-7.  Re-optimised at α's cost Σ|f_L| it closes none by more than δ."""
    model, points, cap = _panel_at_its_lp_caps("flemish", "1:2", "1:1", 0.27)
    assert live_total(model) == pytest.approx(float(np.abs(model.live).sum()))  # horizontal weights
    lp = CapLP(model, points)
    assert lp.solve(np.zeros(points.count), cap).status == "optimal"
    clean, pivots = lp.clean_mechanism(cap, max_pivots=10_000)
    assert clean is not None and pivots < 10_000
    assert _interpenetration(model, points, clean) <= 10 * DUAL_TOLERANCE


def test_cleaning_a_mechanism_leaves_the_iterations_path_alone():
    model, points, cap = _panel_at_its_lp_caps("running", "1:1", "2:1", 0.6)
    runs = []
    for clean in (False, True):
        lp = CapLP(model, points)
        lp.solve(np.zeros(points.count), cap)
        if clean:
            assert lp.clean_mechanism(cap, max_pivots=10_000)[0] is not None
        runs.append(lp.solve(np.zeros(points.count), 0.5 * cap))
    assert runs[0].alpha == runs[1].alpha and runs[0].pivots == runs[1].pivots
    plain, cleaned = runs[0].mechanism, runs[1].mechanism
    assert plain is not None and cleaned is not None
    assert np.array_equal(runs[0].normal, runs[1].normal) and np.array_equal(plain, cleaned)


def test_a_cap_a_round_off_below_zero_bounds_its_shear_to_zero(monkeypatch):
    """A cap f N̄ from a normal force HiGHS returned a round-off below zero: the shear's bounds go
    to HiGHS consistent (0 ≤ 0, not [1e-15, −1e-15]), and the solve is the one at cap zero."""
    model, points, cap = _turned_panel()
    negative = np.where(np.arange(points.count) % 3 == 0, -1e-15, cap)
    sent = []
    change = highs_warm.WarmLP.change_col_bounds

    def spy(self, cols, lower, upper):
        sent.append((np.array(lower), np.array(upper)))
        change(self, cols, lower, upper)

    monkeypatch.setattr(highs_warm.WarmLP, "change_col_bounds", spy)
    solved = CapLP(model, points).solve(np.zeros(points.count), negative)
    assert sent and all(np.all(lower <= upper) for lower, upper in sent)
    zeroed = CapLP(model, points).solve(np.zeros(points.count), np.maximum(negative, 0.0))
    assert solved.status == zeroed.status == "optimal"
    assert solved.alpha == zeroed.alpha
