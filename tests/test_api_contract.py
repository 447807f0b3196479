"""The API's contract: one status vocabulary, typed results, ``both`` whole, checks before work,
study keys that follow every setting."""

from __future__ import annotations

import dataclasses
import importlib
import json

import numpy as np
import pytest

import alma
from alma.settings import SearchSettings, Settings
from alma.status import Status
from alma.study.doe import panel_key


def _stack(block_ratio: str) -> alma.Scene:
    return alma.paper_panel(bond="stack", panel_ratio="2:1", block_ratio=block_ratio, friction=0.6)


def test_statuses_are_one_vocabulary():
    assert {str(s) for s in Status} == {
        "optimal",
        "feasible",
        "no_collapse",
        "no_equilibrium",
        "not_converged",
        "limit_reached",
        "invalid_input",
    }
    assert Status.OPTIMAL == "optimal" and json.dumps(Status.FEASIBLE) == '"feasible"'


def test_a_verified_state_without_proof_is_feasible_not_optimal():
    result = alma.solve(_stack("2:1"), model="nonassociative", effort="fast")
    assert isinstance(result, alma.NonAssociativeResult)
    assert result.status == Status.FEASIBLE and not result.success
    assert result.bounds.lower == pytest.approx(0.0, abs=1e-9)  # Radenkovic: the panel at f = 0 carries no push
    assert result.bounds.lower < result.bounds.upper == result.alpha
    assert result.to_dict()["status"] == "feasible"


def test_both_keeps_the_associative_certificate_whole():
    scene = _stack("4:1")
    assoc = alma.solve(scene)
    both = alma.solve(scene, model="both", effort="fast")
    assert isinstance(both, alma.Comparison)
    assert both.associative.bounds == assoc.bounds and both.associative.iterations == assoc.iterations > 0
    assert both.associative.status == Status.OPTIMAL
    assert both.ratio == pytest.approx(both.nonassociative.alpha / assoc.alpha, rel=1e-15)
    out = both.to_dict()
    assert out["model"] == "both" and out["alpha"] == both.nonassociative.alpha
    assert out["associative"]["bounds"]["lower"] == assoc.bounds.lower
    assert out["associative"]["iterations"] == assoc.iterations
    assert out["nonassociative"]["status"] == str(both.nonassociative.status)
    assert out["alpha_associative"] == assoc.alpha and out["ratio"] == both.ratio


def test_joint_forces_have_one_physical_form():
    result = alma.solve(alma.paper_panel(bond="running", panel_ratio="2:1", block_ratio="4:1", friction=0.6))
    for joint in result.joints:
        (n0, t0), (n1, t1) = joint.points
        assert joint.N == pytest.approx(n0 + n1, abs=1e-12) and joint.T == pytest.approx(t0 + t1, abs=1e-12)
    assert set(result.timings) <= {"joints_s", "build_s", "solve_s", "certify_s"}


def test_options_are_checked_before_any_work(monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("the LP ran before the options were checked")

    monkeypatch.setattr(importlib.import_module("alma.solve"), "solve_lp", boom)
    scene = _stack("4:1")
    with pytest.raises(ValueError, match="effort"):
        alma.solve(scene, model="nonassociative", effort="quick")
    with pytest.raises(ValueError, match="model"):
        alma.solve(scene, model="dilatant")
    with pytest.raises(ValueError, match="certify"):
        alma.solve(scene, certify=True)
    with pytest.raises(ValueError, match="time_limit"):
        alma.solve(scene, time_limit=0)


def test_a_scene_built_by_hand_is_validated_before_it_is_solved():
    ground = alma.Block("ground", np.array([[-100, -50], [400, -50], [400, 0], [-100, 0]], float), fixed=True)
    a = alma.Block("a", np.array([[0, 0], [200, 0], [200, 100], [0, 100]], float))
    b = alma.Block("b", np.array([[100, 50], [300, 50], [300, 150], [100, 150]], float))  # overlaps a
    with pytest.raises(alma.SceneError, match="overlap"):
        alma.solve(alma.Scene(blocks=(ground, a, b)))
    ok = alma.Scene(blocks=(ground, a))
    assert alma.solve(ok).status == Status.OPTIMAL


def test_changing_a_setting_changes_the_study_key():
    base = Settings()
    key = panel_key("2:1", "4:1", "running", 0.6, "nonassociative", version="1", settings=base)
    other_search = dataclasses.replace(base, search=SearchSettings(effort="fast"))
    other_lp = dataclasses.replace(base, associative=dataclasses.replace(base.associative, tolerance=1e-9))
    assert panel_key("2:1", "4:1", "running", 0.6, "nonassociative", version="1", settings=other_search) != key
    assert panel_key("2:1", "4:1", "running", 0.6, "nonassociative", version="1", settings=other_lp) != key
    assert panel_key("2:1", "4:1", "running", 0.6, "nonassociative", version="2", settings=base) != key
    # The associative rows depend on the LP's settings only: fast and thorough studies share them.
    assoc = panel_key("2:1", "4:1", "running", 0.6, "associative", version="1", settings=base)
    assert panel_key("2:1", "4:1", "running", 0.6, "associative", version="1", settings=other_search) == assoc
    assert panel_key("2:1", "4:1", "running", 0.6, "associative", version="1", settings=other_lp) != assoc
