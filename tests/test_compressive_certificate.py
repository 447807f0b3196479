"""The certificate of finite compressive strength (issue 34): the anchored blend that puts the
stress field inside every cone, the mechanism counted with its exact crushing dissipation, and
the margins as settings.  The panels are paper panels the first version left ``not_converged``."""

from __future__ import annotations

import dataclasses
import types
from typing import cast

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma.associative.cone_field as cone_field_module
from alma.associative.cone_field import blend_theta
from alma.associative.crushing import cone_violation, crushing_dissipation, static_cone_form, uniform_margins
from alma.associative.lp import solve_lp
from alma.geometry.panels import paper_panel
from alma.mechanics.model import Model, build_model
from alma.settings import AssociativeSettings, CrushingSettings, Settings
from alma.status import Status


def panel_model(bond: str, panel: str, block: str, friction: float, sigma: float):
    return build_model(dataclasses.replace(paper_panel(bond, panel, block, friction), compressive_strength=sigma))


def fields_of(points: np.ndarray) -> np.ndarray:
    """Generator multipliers (4 per joint) whose point forces are ``points`` (j, 2): all of N_p on
    the first generator of each point."""
    mu = np.zeros(4 * points.shape[0])
    mu[0::2] = points.ravel()
    return mu


def cone_values(c: np.ndarray, points: np.ndarray) -> np.ndarray:
    return 2.0 * c[:, None] * points - points.sum(axis=1)[:, None] ** 2


point_pair = st.tuples(st.floats(0.0, 10.0), st.floats(0.0, 10.0))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.floats(1.0, 1e4), point_pair, point_pair), min_size=1, max_size=6))
def test_blend_is_the_smallest_theta_inside_every_cone(joints):
    """θ puts every point inside 2 c N_p ≥ N², and no smaller θ does (when an end is outside)."""
    c = np.array([j[0] for j in joints])
    mu1, mu0 = (np.array([j[i] for j in joints], dtype=float) for i in (1, 2))
    model = cast(Model, types.SimpleNamespace(crushing=c))  # blend_theta reads model.crushing only
    theta = blend_theta(model, fields_of(mu1), fields_of(mu0))
    g0, g1 = cone_values(c, mu1), cone_values(c, mu0)
    if np.any((g0 < 0) & (g1 < 0)):
        assert theta is None
        return
    if theta is None:  # each point is fine at one end, but no θ suits all of them
        grid = np.linspace(0.0, 1.0, 2001)
        assert not any((cone_values(c, (1 - t) * mu1 + t * mu0) >= 0).all() for t in grid)
        return
    scale = 2.0 * c[:, None] * (mu0 + mu1).max() + 1.0  # round-off of g: the blend sums in another order
    assert (cone_values(c, (1 - theta) * mu1 + theta * mu0) >= -1e-14 * scale).all()
    if theta == 0.0:
        assert (g0 >= 0.0).all()
    # minimal: a little less is outside (where the anchor is not on a cone's boundary, which
    # round-off decides)
    strict = (g1 > 1e-6 * scale).all()
    if theta > 1e-6 and strict:
        earlier = theta * (1.0 - 1e-6)
        assert (cone_values(c, (1 - earlier) * mu1 + earlier * mu0) < 0.0).any()


def test_blend_of_a_field_inside_is_zero():
    model = cast(Model, types.SimpleNamespace(crushing=np.array([10.0])))  # model.crushing only
    assert blend_theta(model, fields_of(np.array([[3.0, 1.0]])), fields_of(np.array([[0.0, 5.0]]))) == 0.0


def certified_field(model, lp) -> tuple[float, float]:
    """The lower bound's field checked here, independently of the certificate: its equilibrium
    residual |H μ + f₀ + α_lower f_L|∞ and its largest cone violation."""
    residual = model.equilibrium @ lp.multipliers + model.dead + lp.lower * model.live
    return float(np.abs(residual).max()), cone_violation(model, lp.multipliers)


def test_anchor_solve_certifies_a_field_left_outside_a_cone(monkeypatch):
    """english 1:1 4:1 f = 0.6 at 10 MPa: Clarabel's field (and both repairs of it) miss the
    cone of a joint carrying 0.005 block weights by 2.9e-9; the anchor's blend is admissible."""
    calls = []
    real = cone_field_module.solve_static_crushing

    def counted(*a, **k):
        calls.append(1)
        return real(*a, **k)

    monkeypatch.setattr(cone_field_module, "solve_static_crushing", counted)
    model = panel_model("english", "1:1", "4:1", 0.6, 10.0)
    lp = solve_lp(model)
    assert lp.status == Status.OPTIMAL and "anchor solve, blend" in lp.message and len(calls) == 1
    equilibrium, cone = certified_field(model, lp)
    assert equilibrium <= 1e-9 and cone <= 1e-9
    assert lp.lower <= lp.upper and (lp.upper - lp.lower) / lp.upper <= 1e-7


def test_no_anchor_solve_when_the_field_is_inside(monkeypatch):
    monkeypatch.setattr(
        cone_field_module, "solve_static_crushing", lambda *a, **k: pytest.fail("anchor solve on an admissible field")
    )
    lp = solve_lp(panel_model("running", "2:1", "4:1", 0.6, 2.0))
    assert lp.status == Status.OPTIMAL and "anchor" not in lp.message


def test_exact_dissipation_mechanism_certifies():
    """english 1:2 2:1 f = 1 at 2 MPa: holding the joints at rest to the flow rule costs the upper
    bound 1.2e-7 (not certified); the solver's own mechanism with every joint's exact crushing
    dissipation closes the gap.  The bound is recomputed here from the returned mechanism."""
    model = panel_model("english", "1:2", "2:1", 1.0, 2.0)
    lp = solve_lp(model)
    assert lp.status == Status.OPTIMAL
    u = lp.mechanism
    upper = (-model.dead @ u + crushing_dissipation(model, model.equilibrium.T @ u)) / (model.live @ u)
    assert upper == pytest.approx(lp.upper, rel=1e-12)
    equilibrium, cone = certified_field(model, lp)
    assert equilibrium <= 1e-9 and cone <= 1e-9 and lp.lower <= lp.upper


def test_margins_are_settings_and_enter_the_digest():
    model = panel_model("running", "2:1", "4:1", 0.6, 2.0)
    wide = CrushingSettings(cone_margin=1e-3)
    _, _, b, _, _, _ = static_cone_form(model, model.equilibrium, margins=uniform_margins(model, wide))
    root = np.sqrt(model.crushing[np.isfinite(model.crushing)])
    assert np.allclose(b[-3 * 2 * root.size :: 3], np.repeat(root, 2) * (1.0 - 1e-3), rtol=1e-15)
    base = Settings()
    other = Settings(associative=AssociativeSettings(crushing=wide))
    assert base.digest() != other.digest()
    assert "crushing" in base.to_dict()["associative"]
