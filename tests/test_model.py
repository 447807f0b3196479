"""The sparse model (Eqs. 1–8) and the LP result object."""

from __future__ import annotations

import numpy as np
import pytest

import alma
from alma.mechanics.model import build_model


def test_single_block_matrices():
    scene = alma.Scene.from_dict(
        {
            "friction": 0.5,
            "blocks": [
                {"id": "g", "vertices": [[-1, -1], [3, -1], [3, 0], [-1, 0]], "fixed": True},
                {"id": "b", "vertices": [[0, 0], [2, 0], [2, 1], [0, 1]]},
            ],
        }
    )
    m = build_model(scene)
    H = m.equilibrium.toarray()
    assert H.shape == (3, 4)
    # generator n ± f t on block b: vertical component 1, horizontal ±0.5
    assert sorted(H[1]) == pytest.approx([1, 1, 1, 1])
    assert sorted(H[0]) == pytest.approx([-0.5, -0.5, 0.5, 0.5])
    assert m.dead == pytest.approx([0, -1, 0])  # one block: its weight is the unit
    assert m.live == pytest.approx([1, 0, 0])


def test_with_friction_matches_rebuild():
    panel = alma.paper_panel("flemish", "2:1", "2:1", 0.27)
    m = build_model(panel)
    again = build_model(panel.with_friction(1.0))
    assert abs(m.with_friction(1.0).equilibrium - again.equilibrium).max() == 0


def test_result_to_dict_is_json():
    import json

    r = alma.solve(alma.paper_panel("stack", "2:1", "4:1", 0.6))
    d = r.to_dict()
    json.dumps(d)
    assert d["model"] == "associative" and d["status"] == "optimal"
    assert d["alpha_associative"] == d["alpha"]
    assert {j["state"] for j in d["joints"]} <= {"rest", "hinging", "sliding", "separating"}


def test_no_equilibrium_and_no_collapse():
    # A block leaning on nothing but a vertical wall to its left cannot stand.
    leaning = alma.Scene.from_dict(
        {
            "blocks": [
                {"id": "wall", "vertices": [[-10, 0], [0, 0], [0, 100], [-10, 100]], "fixed": True},
                {"id": "b", "vertices": [[0, 10], [20, 10], [20, 30], [0, 30]]},
            ]
        }
    )
    assert alma.solve(leaning).status == "no_equilibrium"
    # A block in a tight slot under a fixed lid cannot move in +x: the live load does no work.
    boxed = alma.Scene.from_dict(
        {
            "friction": 0.5,
            "blocks": [
                {"id": "floor", "vertices": [[-10, -10], [30, -10], [30, 0], [-10, 0]], "fixed": True},
                {"id": "right", "vertices": [[20, 0], [30, 0], [30, 20], [20, 20]], "fixed": True},
                {"id": "b", "vertices": [[0, 0], [20, 0], [20, 20], [0, 20]]},
            ],
        }
    )
    assert alma.solve(boxed).status == "no_collapse"


def test_cohesion_solved_by_both_models_and_certified():
    scene = alma.Scene.from_dict(
        {
            "cohesion": 0.1,
            "blocks": [
                {"id": "g", "vertices": [[-1, -1], [3, -1], [3, 0], [-1, 0]], "fixed": True},
                {"id": "b", "vertices": [[0, 0], [2, 0], [2, 1], [0, 1]]},
            ],
        }
    )
    assert alma.solve(scene).status == "optimal"
    polish = alma.Settings(search=alma.SearchSettings(ipopt_blocks=60))  # the IPOPT start, asked for
    result = alma.solve(scene, model="nonassociative", effort="thorough", certify=True, settings=polish)
    assert result.status == "optimal" and result.alpha == pytest.approx(2.0, rel=1e-9)
    assert result.extra["certificate"]["status"] == "proven" and "not_run" not in result.search
    milp = [s for s in result.extra["starts"] if s["start"] == "milp"]  # the MILP start takes cohesion
    assert milp, result.extra["starts"]
    # IPOPT takes cohesion.  A start's record holds α on the search's canonical model, whose data
    # are rounded to canonical_bits (alma.mechanics.canonical); only the kept state is exact on the scene.
    ipopt = [s for s in result.extra["starts"] if s["start"] == "ipopt"]
    assert ipopt and ipopt[0]["verified"] and ipopt[0]["alpha"] == pytest.approx(2.0, rel=1e-6), ipopt


def test_large_wall_builds():
    wall = alma.wall("running", 240.0 * 100, 60.0 * 100, 240.0)
    m = build_model(wall)
    assert m.n_free == 100 * 100 + 50  # odd courses have one extra piece
    assert np.isfinite(m.equilibrium.data).all()


def test_h_and_contact_points_are_built_once_per_model():
    from alma.mechanics.contact_points import ContactPoints

    model = alma.build_model(alma.paper_panel("running", "2:1", "4:1", 0.6))
    assert model.equilibrium is model.equilibrium
    assert ContactPoints.from_model(model) is ContactPoints.from_model(model)
    other = model.with_friction(0.3)  # a new model: its own H and points, with the new friction
    assert ContactPoints.from_model(other).friction.max() == 0.3
    assert abs(other.equilibrium - model.equilibrium).max() > 0


def test_a_joint_open_at_both_ends_is_separating_even_when_it_slips():
    from alma.results.joints import joint_states

    scene = alma.Scene.from_dict(
        {
            "blocks": [
                {"id": "ground", "vertices": [[-100, -50], [400, -50], [400, 0], [-100, 0]], "fixed": True},
                {"id": "b", "vertices": [[0, 0], [240, 0], [240, 60], [0, 60]]},
            ]
        }
    )
    model = alma.build_model(scene)
    lift_and_slide = np.array([1.0, 0.5, 0.0])  # up and sideways: both ends open, and it slips
    states, rel = joint_states(model, lift_and_slide)
    assert (rel[0, :, 0] > 0).all() and abs(rel[0, :, 1]).max() > 0
    assert list(states) == ["separating"]
    assert list(joint_states(model, np.array([1.0, 0.0, 0.0]))[0]) == ["sliding"]
