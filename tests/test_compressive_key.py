"""``compressive_strength`` (SPEC §2, issue 34): the key, its overrides, the CLI option, refusals,
the crushing state, and a scene without it solved exactly as before."""

from __future__ import annotations

import copy
import json
import types
from typing import cast

import numpy as np
import pytest
from hypothesis import example, given, settings, strategies as st

import alma
import alma.associative.lp_crushing as lp_crushing_module
from alma.associative.crushing import crushing_dissipation
from alma.cli.main import main
from alma.geometry.scene import SceneError
from alma.mechanics.model import Model, build_model
from alma.status import Status

B, H, T = 240.0, 600.0, 120.0
W = B * H * T * 18.0 * 1e-9  # kN


def block(sigma: float | None = None, **extra) -> dict:
    data = {
        "thickness": T,
        "unit_weight": 18.0,
        "friction": 10.0,
        "blocks": [
            {"id": "g", "vertices": [[-300, -100], [540, -100], [540, 0], [-300, 0]], "fixed": True},
            {"id": "b1", "vertices": [[0, 0], [B, 0], [B, H], [0, H]]},
        ],
        **extra,
    }
    if sigma is not None:
        data["compressive_strength"] = sigma
    return data


def stack(sigma: float | None = None, override: float | None = None) -> dict:
    data = block(sigma)
    data["blocks"].append({"id": "b2", "vertices": [[0, H], [B, H], [B, 2 * H], [0, 2 * H]]})
    if override is not None:
        data["joints"] = [{"blocks": ["b1", "b2"], "compressive_strength": override}]
    return data


def test_key_round_trip_and_override():
    scene = alma.Scene.from_dict(stack(2.0, override=0.5))
    assert scene.compressive_strength == 2.0 and scene.joint_overrides[0].compressive_strength == 0.5
    again = alma.Scene.from_dict(scene.to_dict())
    assert again.to_dict() == scene.to_dict()
    model = build_model(scene)
    # σ_c l t in mean block weights: 2 MPa on the ground joint, 0.5 on the joint between the blocks
    assert np.allclose(model.crushing * model.force_scale, [2.0 * 1e-3 * B * T, 0.5 * 1e-3 * B * T])
    assert "compressive_strength" not in alma.Scene.from_dict(block()).to_dict()


def test_override_alone_gives_one_crushing_joint():
    model = build_model(alma.Scene.from_dict(stack(None, override=0.5)))
    assert np.isinf(model.crushing[0]) and np.isfinite(model.crushing[1]) and model.crushes


@pytest.mark.parametrize("value", [0, -1.0, "2", float("nan")])
def test_bad_strength_is_refused(value):
    with pytest.raises(SceneError, match="compressive_strength"):
        alma.Scene.from_dict(block(value))
    data = stack(None)
    data["joints"] = [{"blocks": ["b1", "b2"], "compressive_strength": value}]
    with pytest.raises(SceneError, match="compressive_strength"):
        alma.Scene.from_dict(data)


def test_absent_key_takes_the_rigid_path(monkeypatch):
    """Without the key the model has no crushing data, the cone program is never called and the
    joints carry no new fields: the result is the rigid model's (byte-identical JSON apart from
    timings; measured against the commit before this feature in docs/compressive.md)."""

    def refuse(*args, **kwargs):
        raise AssertionError("the cone program ran on a scene without compressive_strength")

    monkeypatch.setattr(lp_crushing_module, "solve_static_crushing", refuse)
    scene = alma.Scene.from_dict(stack())
    assert build_model(scene).crushing.size == 0
    out = alma.solve(scene).to_dict()
    assert out["status"] == "optimal" and out["alpha"] == pytest.approx(B / (2 * H), rel=1e-9)
    assert all("capacity" not in j and "stress_block" not in j for j in out["joints"])


def test_pure_crushing_state():
    """A live load pushing the block down: α W + W = σ_c b t, the base crushes over its length."""
    sigma = 0.05
    data = block(sigma, live_load={"direction": [0.0, -1.0]})
    result = alma.solve(alma.Scene.from_dict(data))
    capacity = sigma * 1e-3 * B * T
    assert result.status == Status.OPTIMAL
    assert result.alpha == pytest.approx((capacity - W) / W, rel=1e-9)
    joint = result.joints[0]
    # the static field keeps the solver's cone margin (crushing.CONE_RELATIVE_MARGIN = 5e-8)
    assert joint.state == "crushing" and joint.N == pytest.approx(capacity, rel=1e-7)
    assert joint.stress_block is not None
    (x0, _), (x1, _) = joint.stress_block
    assert abs(x1 - x0) == pytest.approx(B, rel=1e-7)


def test_friction_model_refuses():
    scene = alma.Scene.from_dict(block(1.0))
    for model in ("nonassociative", "both"):
        with pytest.raises(SceneError, match="non-associative model"):
            alma.solve(scene, model=model)


def test_settle_refuses():
    data = block(1.0)
    data["blocks"][0]["settlement"] = {"translation": [0.0, -1.0]}
    with pytest.raises(SceneError, match="compressive_strength"):
        alma.settle(alma.Scene.from_dict(data))


def test_cli_option(tmp_path, capsys):
    path = tmp_path / "block.json"
    path.write_text(json.dumps(block()))
    assert main(["solve", str(path), "--compressive-strength", "0.05", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["alpha"] == pytest.approx((B - W / (0.05 * 1e-3 * T)) / H, rel=1e-9)
    assert out["joints"][0]["stress_block"]["extent"] == pytest.approx(W / (0.05 * 1e-3 * T), rel=1e-7)
    for args in (["--compressive-strength", "0"], ["--compressive-strength", "0.05", "--model", "both"]):
        assert main(["solve", str(path), *args, "--json"]) == 2
        captured = capsys.readouterr()
        assert json.loads(captured.out)["status"] == "invalid_input"
        assert "compressive" in captured.err and "Traceback" not in captured.err


def test_cli_panel_option(tmp_path, capsys):
    path = tmp_path / "panel.json"
    assert (
        main(
            [
                "panel",
                "--bond",
                "stack",
                "--panel-ratio",
                "2:1",
                "--block-ratio",
                "4:1",
                "--friction",
                "0.6",
                "--compressive-strength",
                "2",
                "--export-scene",
                str(path),
                "--json",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "optimal" and "capacity" in out["joints"][0]
    assert json.loads(path.read_text())["compressive_strength"] == 2.0


@settings(max_examples=8, deadline=None)
@given(dx=st.floats(-1e5, 1e5), dy=st.floats(-1e5, 1e5), reverse=st.booleans())
def test_origin_and_block_order_do_not_matter(dx, dy, reverse):
    base = alma.solve(alma.Scene.from_dict(stack(0.05, override=0.02))).alpha
    data = copy.deepcopy(stack(0.05, override=0.02))
    for blk in data["blocks"]:
        blk["vertices"] = [[x + dx, y + dy] for x, y in blk["vertices"]]
    if reverse:
        data["blocks"].reverse()
    assert alma.solve(alma.Scene.from_dict(data)).alpha == pytest.approx(base, rel=1e-8)


@settings(max_examples=20, deadline=None, derandomize=True)
@given(g=st.lists(st.floats(-2.0, 2.0), min_size=4, max_size=4), c=st.floats(0.1, 100.0))
@example(g=[0.0, 0.0, 0.0, -1.192092896e-07], c=10.0)  # Clarabel's default gap was 4e-7 off here
@example(g=[0.0, 0.0, 0.0, -1.0], c=89.0)  # unscaled, Clarabel stopped 'optimal_inaccurate' 1.1e-4 off
def test_closed_form_dissipation_is_the_sup(g, c):
    """crushing_dissipation = max over the joint's yield set of −μᵀg (a small cvxpy program).

    The sup is homogeneous of degree 1 in c (μ = c ν), so the reference solves the c = 1 program,
    which Clarabel closes to 'optimal' at 1e-9 on every case tried (worst error 1.4e-9 c); unscaled,
    it stops 'optimal_inaccurate' on some."""
    cp = pytest.importorskip("cvxpy")
    model = cast(Model, types.SimpleNamespace(crushing=np.array([c])))  # only model.crushing is read
    nu = cp.Variable(4, nonneg=True)
    N = cp.sum(nu)
    problem = cp.Problem(
        cp.Maximize(-np.array(g) @ nu), [cp.square(N) <= 2 * (nu[0] + nu[1]), cp.square(N) <= 2 * (nu[2] + nu[3])]
    )
    problem.solve(solver=cp.CLARABEL, tol_gap_abs=1e-9, tol_gap_rel=1e-9, tol_feas=1e-9)
    assert problem.status == "optimal"
    assert crushing_dissipation(model, np.array(g)) == pytest.approx(c * problem.value, rel=1e-7, abs=1e-8 * c)
