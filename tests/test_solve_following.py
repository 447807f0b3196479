"""The mechanism a capacity curve follows on a sliding wall (alma.solve.solve_following)."""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.geometry.contacts import find_joints
from alma.geometry.panels import paper_panel
from alma.mechanics.model import build_model
from alma.solve import solve_following

solve_module = importlib.import_module("alma.solve")


@pytest.fixture(scope="module")
def sliding():
    scene = paper_panel("running", "2:1", "2:1", 0.27).validate()
    return scene, build_model(scene, find_joints(scene))


def test_a_sliding_wall_moves_one_part_that_carries_the_control_block(sliding):
    # at α = f every part above a bed joint can slide: the interior point moves each of the 150
    # blocks at its own rate (150 macro-blocks); the followed vertex moves rigid parts (here
    # the control block sliding on the 149 others, which slide on the base)
    scene, built = sliding
    blend = alma.solve(built)
    control = scene.block_ids.index("b150")
    followed = solve_following(built, None, control, 1.0)
    assert followed.status == blend.status == alma.Status.OPTIMAL
    assert followed.alpha == blend.alpha and followed.bounds == blend.bounds
    assert len(blend.macro_blocks) == 150 and len(followed.macro_blocks) <= 2
    assert all(m.motion == "translation" for m in followed.macro_blocks)
    assert next(b for b in followed.blocks if b.id == "b150").u[0] > 0


def test_a_mechanism_still_on_the_face_is_kept_without_a_crisp_lp(sliding, monkeypatch):
    # a capacity curve's next configuration keeps the part that slides while it is optimal
    scene, built = sliding
    control = scene.block_ids.index("b150")
    followed = solve_following(built, None, control, 1.0)
    motions = np.array([b.u for b in followed.blocks])
    previous = np.zeros((len(scene.blocks), 3))
    previous[[scene.block_ids.index(b.id) for b in followed.blocks]] = 2.0 * motions  # any scale
    monkeypatch.setattr(solve_module, "crisp_mechanism", lambda *a, **k: pytest.fail("crisp LP solved"))
    kept = solve_following(built, None, control, 1.0, previous)
    assert "previous configuration's mechanism" in kept.message
    assert np.allclose([b.u for b in kept.blocks], motions, rtol=1e-9, atol=1e-12)
    monkeypatch.undo()
    # a mechanism off the face (every block also turning) takes the crisp LP
    previous[:, 2] = 1e-3
    turned = solve_following(built, None, control, 1.0, previous)
    assert "previous configuration's mechanism" not in turned.message
    assert [b.u for b in turned.blocks] == [b.u for b in followed.blocks]


def test_a_mechanism_that_turns_is_the_interior_points(sliding):
    # only translations are followed; a rocking or mixed mechanism is the solve's own
    scene = paper_panel("running", "1:1", "1:1", 0.6).validate()
    built = build_model(scene, find_joints(scene))
    plain = alma.solve(built)
    assert plain.mechanism_class != "sliding"
    moving = next(i for i, b in enumerate(scene.blocks) if not b.fixed)
    followed = solve_following(built, None, moving, 1.0)
    assert [b.u for b in followed.blocks] == [b.u for b in plain.blocks]


@settings(max_examples=3, deadline=None)
@given(
    scale=st.sampled_from([0.1, 1.0, 25.4]),
    shift=st.tuples(st.floats(-1e4, 1e4), st.floats(-1e4, 1e4)),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_followed_sliding_curve_does_not_depend_on_the_drawing(scale, shift, seed):
    # the vertex a degenerate face gives must not follow the order of blocks or vertices (the
    # panel's upper part slides on one bed joint, kept while it is optimal, until it tips off
    # the lower part: a loss of equilibrium)
    scene = paper_panel("running", "2:1", "4:1", 0.27)
    base = alma.push(scene, steps=20)
    rng = np.random.default_rng(seed)
    data = scene.to_dict()
    for block in data["blocks"]:
        block["vertices"] = (np.array(block["vertices"]) * scale + shift).tolist()
        k = int(rng.integers(len(block["vertices"])))
        block["vertices"] = block["vertices"][k:] + block["vertices"][:k]
    data["blocks"] = [data["blocks"][i] for i in rng.permutation(len(data["blocks"]))]
    data["unit_weight"] /= scale**3  # the same weights
    data["thickness"] *= scale
    other = alma.push(alma.Scene.from_dict(data), steps=20)
    assert other.end["reason"] == base.end["reason"] == "no_equilibrium" and other.control == base.control
    assert len(other.curve) == len(base.curve)
    assert np.allclose([p.alpha for p in other.curve], [p.alpha for p in base.curve], atol=1e-7)
    assert np.allclose([p.d / scale for p in other.curve], [p.d for p in base.curve], rtol=1e-6)
    assert np.array(other.end["bracket"]) / scale == pytest.approx(base.end["bracket"], rel=1e-6)
