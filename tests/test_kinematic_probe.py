"""The kinematic LP's probe: a dual-simplex run past
:data:`~alma.nonassociative.static_lps.KINEMATIC_PROBE_PIVOTS` goes to HiGHS's interior point with
crossover, whose vertex (a mechanism with the set) or proof of infeasibility is the answer."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from alma.backends.linprog_backend import LPMethod
from alma.backends.termination import Termination
from alma.floats import dot
from alma.geometry.panels import paper_panel
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import build_model
from alma.nonassociative import static_lps
from alma.nonassociative.states import active_set


@pytest.fixture(scope="module")
def panel() -> tuple:
    """A paper panel and a mechanism of it: the whole panel sliding to the right on its base."""
    model = build_model(paper_panel("running", "2:1", "4:1", 0.6))
    sliding = np.zeros(model.dead.shape[0])
    sliding[0::3] = 1.0
    return model, ContactPoints.from_model(model), sliding


def _methods(monkeypatch: pytest.MonkeyPatch, *, stop_first: bool = True) -> list[LPMethod]:
    """The methods of the kinematic LP's solves from now on; ``stop_first``: its first simplex run
    stopped at the probe's iteration limit (these small LPs are solved by HiGHS's presolve, in no
    iteration)."""
    used: list[LPMethod] = []
    solve = static_lps.solve_lp

    def logged(*args, **kwargs):
        used.append(kwargs["method"])
        result = solve(*args, **kwargs)
        if stop_first and len(used) == 1:
            assert kwargs["max_iterations"] == static_lps.KINEMATIC_PROBE_PIVOTS
            return dataclasses.replace(result, termination=Termination.ITERATION_LIMIT, x=np.zeros(0))
        return result

    monkeypatch.setattr(static_lps, "solve_lp", logged)
    return used


def test_a_feasible_lp_past_the_probe_gives_the_interior_point_vertex(panel, monkeypatch):
    model, points, mechanism = panel
    open_points, slip_sign = active_set(model, points, mechanism)
    used = _methods(monkeypatch)
    u, _ = static_lps.kinematic_lp(model, points, open_points, slip_sign)
    assert used == [LPMethod.SIMPLEX, LPMethod.IPM]
    assert u is not None
    # A mechanism with exactly the prescribed set: closed points stay closed, sticking ones do
    # not slip, slipping ones slip their way, and the live load does n_free of work.
    assert dot(model.live, u) == pytest.approx(model.n_free, rel=1e-9)
    scale = float(np.abs(u).max())
    assert np.abs(points.normal.T @ u).max() <= 1e-9 * scale
    slip = points.tangent.T @ u
    assert np.abs(slip[slip_sign == 0]).max(initial=0.0) <= 1e-9 * scale
    assert np.all(slip_sign[slip_sign != 0] * slip[slip_sign != 0] > 0)


def test_an_infeasible_lp_past_the_probe_ends_at_the_interior_point(panel, monkeypatch):
    model, points, _ = panel
    # Every point closed and sticking: the panel is locked, no mechanism does work.
    locked = np.zeros(points.count, dtype=bool), np.zeros(points.count)
    assert static_lps.kinematic_lp(model, points, *locked)[0] is None
    used = _methods(monkeypatch)
    assert static_lps.kinematic_lp(model, points, *locked)[0] is None
    assert used == [LPMethod.SIMPLEX, LPMethod.IPM]


def test_the_probe_is_not_asked_below_its_pivots(panel, monkeypatch):
    model, points, mechanism = panel
    used = _methods(monkeypatch, stop_first=False)
    static_lps.kinematic_lp(model, points, *active_set(model, points, mechanism))
    assert used == [LPMethod.SIMPLEX]
