"""The kinematic LP's probe: a dual-simplex run past
:data:`~alma.nonassociative.static_lps.KINEMATIC_PROBE_PIVOTS` asks HiGHS's interior point whether
the LP is feasible; an infeasible one ends there, a feasible one gets the simplex's own vertex."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from alma.backends.linprog_backend import LPMethod
from alma.backends.termination import Termination
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


def _probed(monkeypatch: pytest.MonkeyPatch) -> list[LPMethod]:
    """The methods of the kinematic LP's solves from now on, its first simplex run stopped at the
    probe's iteration limit (these small LPs are solved by HiGHS's presolve, in no iteration)."""
    used: list[LPMethod] = []
    solve = static_lps.solve_lp

    def probed(*args, **kwargs):
        used.append(kwargs["method"])
        result = solve(*args, **kwargs)
        if len(used) == 1:
            assert kwargs["max_iterations"] == static_lps.KINEMATIC_PROBE_PIVOTS
            return dataclasses.replace(result, termination=Termination.ITERATION_LIMIT, x=np.zeros(0))
        return result

    monkeypatch.setattr(static_lps, "solve_lp", probed)
    return used


def test_a_feasible_lp_past_the_probe_gives_the_simplex_vertex(panel, monkeypatch):
    model, points, mechanism = panel
    open_points, slip_sign = active_set(model, points, mechanism)
    plain, _ = static_lps.kinematic_lp(model, points, open_points, slip_sign)
    assert plain is not None
    used = _probed(monkeypatch)
    probed, _ = static_lps.kinematic_lp(model, points, open_points, slip_sign)
    assert used == [LPMethod.SIMPLEX, LPMethod.IPM, LPMethod.SIMPLEX]
    assert probed is not None and np.array_equal(probed, plain)


def test_an_infeasible_lp_past_the_probe_ends_at_the_interior_point(panel, monkeypatch):
    model, points, _ = panel
    # Every point closed and sticking: the panel is locked, no mechanism does work.
    locked = np.zeros(points.count, dtype=bool), np.zeros(points.count)
    assert static_lps.kinematic_lp(model, points, *locked)[0] is None
    used = _probed(monkeypatch)
    assert static_lps.kinematic_lp(model, points, *locked)[0] is None
    assert used == [LPMethod.SIMPLEX, LPMethod.IPM]


def test_the_probe_is_not_asked_below_its_pivots(panel, monkeypatch):
    model, points, mechanism = panel
    used: list[LPMethod] = []
    solve = static_lps.solve_lp

    def counted(*args, **kwargs):
        used.append(kwargs["method"])
        return solve(*args, **kwargs)

    monkeypatch.setattr(static_lps, "solve_lp", counted)
    static_lps.kinematic_lp(model, points, *active_set(model, points, mechanism))
    assert used == [LPMethod.SIMPLEX]
