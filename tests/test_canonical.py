"""The canonical drawing (alma.geometry.canonical) and model (alma.mechanics.canonical): the data
the friction search sees are the same, bit for bit, however one structure is written."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.geometry.canonical import canonical_scene
from alma.geometry.contacts import Joints, find_joints
from alma.mechanics.canonical import field_to_drawing, mechanism_to_drawing, snapped
from alma.mechanics.model import build_model


def _panel() -> dict:
    data = alma.paper_panel("english", "2:1", "2:1", 0.6).to_dict()
    data["cohesion"] = 2.0
    data["loads"] = [{"block": data["blocks"][5]["id"], "dead": [0.0, -1.0], "live": [0.3, 0.0]}]
    return data


def _rewrite(
    data: dict, angle: float, mirror: bool, shift: tuple[float, float], length: float, force: float, seed: int
) -> dict:
    """Turned by ``angle`` (mirrored first), moved by ``shift`` mm, in units of ``length`` mm, forces
    × ``force``, blocks shuffled and polygons started elsewhere (``seed``)."""
    c, s = math.cos(angle), math.sin(angle)
    matrix = np.array([[c, -s], [s, c]]) @ (np.diag([-1.0, 1.0]) if mirror else np.eye(2))
    out = json.loads(json.dumps(data))
    rng = np.random.default_rng(seed)

    def move(p):
        return list(map(float, length * (matrix @ np.asarray(p, dtype=float) + np.asarray(shift))))

    for b in out["blocks"]:
        v = [move(p) for p in b["vertices"]]
        k = int(rng.integers(len(v)))
        b["vertices"] = v[k:] + v[:k]
    out["blocks"] = [out["blocks"][i] for i in rng.permutation(len(out["blocks"]))]
    for load in out.get("loads", []):
        for key in ("dead", "live"):
            load[key] = list(map(float, force * (matrix @ np.asarray(load[key]))))
    out["gravity"] = list(map(float, matrix @ np.array([0.0, -1.0])))
    out["live_load"] = {"direction": list(map(float, matrix @ np.array([1.0, 0.0])))}
    out["thickness"] *= length
    out["unit_weight"] *= force / length**3
    out["cohesion"] *= force / length**2
    return out


def _canonical(data: dict):
    scene, frame = canonical_scene(alma.Scene.from_dict(data))
    return scene, frame, snapped(build_model(scene), alma.SearchSettings().canonical_bits)


REFERENCE = _canonical(_panel())


@settings(max_examples=15, deadline=None, derandomize=True)
@given(
    angle=st.floats(-math.pi, math.pi),
    mirror=st.booleans(),
    shift=st.tuples(st.floats(-1e5, 1e5), st.floats(-1e5, 1e5)),  # a site frame 100 m away
    length=st.sampled_from([1.0, 1e-3, 25.4]),
    force=st.sampled_from([1.0, 1e-2, 9.81]),
    seed=st.integers(0, 2**31 - 1),
)
def test_the_search_sees_the_same_model(angle, mirror, shift, length, force, seed):
    scene, _, model = _canonical(_rewrite(_panel(), angle, mirror, shift, length, force, seed))
    ref_scene, _, ref = REFERENCE
    assert [b.id for b in scene.blocks] == [b.id for b in ref_scene.blocks]
    for a, b in zip(scene.blocks, ref_scene.blocks, strict=True):  # the same polygons, to round-off
        np.testing.assert_allclose(a.vertices, b.vertices, rtol=0, atol=1e-11)
    for name in ("normal_part", "tangent_part", "bounded"):
        x, y = getattr(model, name), getattr(ref, name)
        assert (x != y).nnz == 0, name
    for name in ("dead", "live", "capacity", "friction"):
        np.testing.assert_array_equal(getattr(model, name), getattr(ref, name), err_msg=name)


def test_redundant_vertices_are_dropped_and_polygons_start_low_left():
    data = {
        "blocks": [
            {"id": "g", "fixed": True, "vertices": [[0, 0], [5, 0], [10, 0], [10, 0.5], [10, 1], [0, 1]]},
            {"id": "b", "vertices": [[4, 3], [2, 3], [2, 1], [3, 1], [4, 1]]},
        ]
    }
    scene, frame = canonical_scene(alma.Scene.from_dict(data))
    assert [b.id for b in scene.blocks] == ["g", "b"]
    assert [len(b.vertices) for b in scene.blocks] == [4, 4]  # the collinear ones gone
    for b in scene.blocks:  # counter-clockwise from the lowest, then leftmost vertex
        assert tuple(b.vertices[0]) == min(map(tuple, b.vertices), key=lambda p: (p[1], p[0]))
    assert frame.unit == pytest.approx(2.0)


def test_a_mechanism_comes_back_to_the_drawings_frame():
    """A rigid rotation of every free block, written in the canonical frame, read in the drawing's."""
    data = _rewrite(_panel(), 0.4, True, (100.0, -50.0), 1.0, 1.0, 3)
    drawing = build_model(alma.Scene.from_dict(data))
    _scene, frame, canonical = _canonical(data)
    omega, pivot = 0.01, np.array([0.3, -0.2])  # canonical model units
    c = canonical.centroid
    u = np.column_stack([-omega * (c[:, 1] - pivot[1]), omega * (c[:, 0] - pivot[0]), np.full(len(c), omega)])
    back = mechanism_to_drawing(u.ravel(), canonical, frame, drawing).reshape(-1, 3)
    assert np.allclose(back[:, 2], -omega)  # a mirror turns the sense of rotation
    # the drawing's velocities are one rigid rotation about one point (the pivot's image)
    x, w = drawing.centroid, back[:, 2]
    pivot_x, pivot_y = x[:, 0] - back[:, 1] / w, x[:, 1] + back[:, 0] / w
    assert np.ptp(pivot_x) < 1e-9 and np.ptp(pivot_y) < 1e-9


@settings(max_examples=8, deadline=None, derandomize=True)
@given(
    angle=st.floats(-math.pi, math.pi),
    mirror=st.booleans(),
    shift=st.tuples(st.floats(-1e5, 1e5), st.floats(-1e5, 1e5)),
    length=st.sampled_from([1.0, 1e-3, 25.4]),
    force=st.sampled_from([1.0, 1e-2, 9.81]),
    seed=st.integers(0, 2**31 - 1),
)
def test_a_static_field_comes_back_to_the_drawings_joints(angle, mirror, shift, length, force, seed):
    """Any field of contact and cohesive forces on the canonical joints pushes each block in the
    drawing as in the canonical frame: the same resultant, turned back, in the drawing's force unit."""
    data = _rewrite(_panel(), angle, mirror, shift, length, force, seed)
    drawing = build_model(alma.Scene.from_dict(data))
    _scene, frame, canonical = _canonical(data)
    rng = np.random.default_rng(seed)
    count, q = canonical.contact_points.count, canonical.n_bounded
    normal, shear, tau = rng.uniform(0.0, 1.0, count), rng.uniform(-1.0, 1.0, count), rng.uniform(0.0, 1.0, q)
    carried = field_to_drawing(normal, shear, canonical, frame, drawing, tau)
    assert carried is not None and q > 0
    n_d, t_d, tau_d = carried
    cp, dp = canonical.contact_points, drawing.contact_points
    resultant_c = (cp.normal @ normal + cp.tangent @ shear + canonical.bounded @ tau).reshape(-1, 3)
    resultant_d = (dp.normal @ n_d + dp.tangent @ t_d + drawing.bounded @ tau_d).reshape(-1, 3)
    target = drawing.free_index[frame.order[canonical.free_blocks]]
    expected = resultant_c[:, :2] @ frame.matrix * (canonical.force_scale / drawing.force_scale)
    np.testing.assert_allclose(resultant_d[target, :2], expected, rtol=0, atol=1e-9 * np.abs(expected).max())


def test_joints_split_differently_carry_no_field():
    """A support edge split at a block corner makes two drawn joints of one canonical joint: the
    field is not carried (the mechanism still is)."""
    data = {
        "blocks": [
            {"id": "g", "fixed": True, "vertices": [[0, -1], [10, -1], [10, 0], [5, 0], [0, 0]]},
            {"id": "b", "vertices": [[2, 0], [8, 0], [8, 1], [2, 1]]},
        ]
    }
    plain = json.loads(json.dumps(data))
    plain["blocks"][0]["vertices"] = [[0, -1], [10, -1], [10, 0], [0, 0]]
    drawing = build_model(alma.Scene.from_dict(data))
    _scene, frame, canonical = _canonical(plain)
    count = canonical.contact_points.count
    assert drawing.joints.count == canonical.joints.count + 1
    assert field_to_drawing(np.ones(count), np.zeros(count), canonical, frame, drawing) is None


def _pair() -> dict:
    """A slender block (100 × 600) beside a stout one (400 × 600) on a fixed base, f = 5 (no sliding)."""
    return {
        "friction": 5.0,
        "thickness": 100.0,
        "unit_weight": 20.0,
        "cohesion": 0.0,
        "blocks": [
            {"id": "base", "vertices": [[-100, -100], [500, -100], [500, 0], [-100, 0]], "fixed": True},
            {"id": "a", "vertices": [[0, 0], [100, 0], [100, 600], [0, 600]]},
            {"id": "b", "vertices": [[100, 0], [500, 0], [500, 600], [100, 600]]},
        ],
    }


@settings(max_examples=6, deadline=None, derandomize=True)
@given(
    angle=st.floats(-math.pi, math.pi),
    mirror=st.booleans(),
    shift=st.tuples(st.floats(-1e4, 1e4), st.floats(-1e4, 1e4)),
    seed=st.integers(0, 2**31 - 1),
)
def test_the_friction_search_keeps_a_models_own_joints(angle, mirror, shift, seed):
    """A model built with given joints (the two blocks' shared joint left out, as a displaced
    configuration of ``alma.push`` keeps its own contacts) is searched on those joints, in any
    frame and block order: the slender block rocks alone (α = b/h = 1/6), where with the
    drawing's own joints it leans on its neighbour.  The search used to find the joints again on the
    drawing and answer for the pair."""
    scene = alma.Scene.from_dict(_rewrite(_pair(), angle, mirror, shift, 1.0, 1.0, seed)).validate()
    joints = find_joints(scene)
    ids = np.array([b.id for b in scene.blocks])
    shared = np.isin(ids[joints.block_a], ["a", "b"]) & np.isin(ids[joints.block_b], ["a", "b"])
    keep = ~shared
    assert shared.sum() == 1
    own = Joints(joints.block_a[keep], joints.block_b[keep], joints.start[keep], joints.end[keep], joints.normal[keep])
    alone = alma.solve(build_model(scene, own), "nonassociative")
    pair = alma.solve(build_model(scene), "nonassociative")
    assert alone.status == "feasible" and abs(alone.alpha - 1 / 6) <= 1e-9
    assert pair.alpha > 1 / 6 + 1e-3
