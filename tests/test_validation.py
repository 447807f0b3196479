"""Scene validation is pure (alma.geometry.validation): ``Scene.validate`` returns the validated
scene and changes nothing; a hand-built scene's joints are found once on the way to its model."""

from __future__ import annotations

import dataclasses
import importlib
import json

import numpy as np
import pytest

import alma
import alma.geometry.validation as validation_module
from alma.geometry.validation import check_scene, validated
from alma.status import Status

#: The module alma.solve (the package's attribute of that name is the function).
solve_module = importlib.import_module("alma.solve")


def _scene(**overrides) -> alma.Scene:
    ground = alma.Block("ground", np.array([[-100, -50], [400, -50], [400, 0], [-100, 0]], float), fixed=True)
    a = alma.Block("a", np.array([[0, 0], [200, 0], [200, 100], [0, 100]], float))
    b = alma.Block("b", np.array([[0, 100], [200, 100], [200, 200], [0, 200]], float))
    return alma.Scene(blocks=(ground, a, b), **overrides)


def test_validate_returns_the_validated_scene_and_changes_nothing():
    scene = _scene()
    before = json.dumps(scene.to_dict())
    checked = scene.validate()
    assert checked.validated and not scene.validated
    assert checked is not scene and json.dumps(checked.to_dict()) == before
    assert checked.validate() is checked  # a validated scene is returned as it is, checked again


def test_a_bad_scene_is_refused_and_left_as_it_was():
    scene = _scene(thickness=-1.0)
    with pytest.raises(alma.SceneError, match="thickness"):
        scene.validate()
    assert not scene.validated
    with pytest.raises(alma.SceneError, match="thickness"):
        dataclasses.replace(scene, validated=True).validate()  # the mark does not skip the checks


def test_loaders_return_validated_scenes(tmp_path):
    data = _scene().to_dict()
    assert alma.Scene.from_dict(data).validated
    assert not alma.Scene.from_dict(data, validate=False).validated
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    assert alma.load_scene(path).validated


def test_validated_gives_the_joints_it_found():
    scene = _scene()
    checked, joints = validated(scene)
    found = alma.find_joints(scene)
    assert checked.validated and joints.count == found.count == 2
    assert np.array_equal(joints.block_a, found.block_a) and np.array_equal(joints.start, found.start)
    assert check_scene(checked).count == joints.count


def _count_joint_detection(monkeypatch) -> list[str]:
    calls: list[str] = []
    for module in (validation_module, solve_module):
        original = module.find_joints

        def counted(scene, *args, _original=original, _name=module.__name__, **kwargs):
            calls.append(_name)
            return _original(scene, *args, **kwargs)

        monkeypatch.setattr(module, "find_joints", counted)
    return calls


def test_solve_finds_a_hand_built_scenes_joints_once(monkeypatch):
    """The joints validation needs (a free block must touch something) serve the model."""
    calls = _count_joint_detection(monkeypatch)
    result = alma.solve(_scene())
    assert result.status == Status.OPTIMAL
    assert calls == ["alma.geometry.validation"]


def test_solve_does_not_validate_a_validated_scene_again(monkeypatch):
    scene = _scene().validate()
    calls = _count_joint_detection(monkeypatch)
    alma.solve(scene)
    assert calls == ["alma.solve"]


def test_the_answer_does_not_depend_on_who_validated():
    by_hand, loaded = alma.solve(_scene()), alma.solve(_scene().validate())
    assert by_hand.status == loaded.status == Status.OPTIMAL
    assert (by_hand.alpha, by_hand.bounds) == (loaded.alpha, loaded.bounds)
    assert by_hand.blocks == loaded.blocks
