"""Invariances of the collapse multiplier (property-based).

α_c is a ratio of works: it cannot depend on the unit of length, the unit weight, where the
structure stands or how it is turned (gravity and live load turned with it), on a mirror image
with the live load reversed, nor on how blocks and vertices are numbered.  It never decreases
when friction grows, and a structure on a horizontal ground cannot resist more than f (it can
always slide as a whole on the ground).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma

from helpers import CERTIFICATE, assemblies, panel_geometry, panel_id, rect, scene_dict, solve_panel, table5

REL = 1e-7


def same_alpha(a: alma.Result, b: alma.Result) -> None:
    assert a.status == b.status, (a.status, b.status, a.alpha, b.alpha)
    if math.isfinite(a.alpha) or math.isfinite(b.alpha):
        assert b.alpha == pytest.approx(a.alpha, rel=REL, abs=REL), (a.alpha, b.alpha)
    else:
        assert a.alpha == b.alpha


def solve_dict(data: dict) -> alma.Result:
    return alma.solve(alma.Scene.from_dict(data))


def map_vertices(data: dict, fn) -> dict:
    out = dict(data)
    out["blocks"] = [
        dict(b, vertices=[list(map(float, fn(np.array(v, dtype=float)))) for v in b["vertices"]])
        for b in data["blocks"]
    ]
    return out


def panel_dict(bond="stack", panel_ratio="2:1", block_ratio="4:1", friction=0.6) -> dict:
    data = alma.paper_panel(bond, panel_ratio, block_ratio, friction).to_dict()
    return data


PANEL = panel_dict()
PANEL_ALPHA = solve_dict(PANEL)


def test_panel_reference_value():
    # stack bond, 2:1 panel, 4:1 blocks, f = 0.6 (Table 5: 0.4191)
    assert PANEL_ALPHA.status == "optimal"
    assert abs(PANEL_ALPHA.alpha - 0.4191) <= 1e-4


# ----------------------------------------------------------------------------- scaling
def scaled(data: dict, length: float, weight: float = 1.0) -> dict:
    out = map_vertices(data, lambda v: v * length)
    out["thickness"] = data["thickness"] * length
    out["unit_weight"] = data["unit_weight"] * weight
    return out


@pytest.mark.parametrize("length", [1e-3, 1e3, 1e6])
@pytest.mark.parametrize("weight", [1.0, 1e-3, 250.0])
def test_panel_scaling(length, weight):
    same_alpha(PANEL_ALPHA, solve_dict(scaled(PANEL, length, weight)))


@settings(max_examples=20, deadline=None)
@given(data=assemblies(), length=st.sampled_from([1e-3, 1e3, 1e6]), weight=st.sampled_from([1e-2, 1.0, 1e3]))
def test_random_scaling(data, length, weight):
    same_alpha(solve_dict(data), solve_dict(scaled(data, length, weight)))


# ----------------------------------------------------------------------------- rigid motions
def rotation(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def rotated_dict(data: dict, angle: float, offset=(0.0, 0.0)) -> dict:
    """Rotation + translation written on the JSON scene, independently of Scene.transformed."""
    R = rotation(angle)
    out = map_vertices(data, lambda v: R @ v + np.asarray(offset))
    out["gravity"] = list(R @ np.asarray(data.get("gravity", [0.0, -1.0]), dtype=float))
    out["live_load"] = {"direction": list(R @ np.asarray(data["live_load"]["direction"], dtype=float))}
    return out


#: ±π/2 and 3π/2 turn bed joints into lines whose outward-normal angle rounds to exactly π; before
#: e3edc6c ("canonical line direction from the angle") find_joints lost such joints (stack-2:1-4:1
#: turned by π/2: 124 joints instead of 132, 'no_equilibrium' instead of 0.41912).
@pytest.mark.parametrize("angle", [0.3, 2.0, math.pi, -1.1, -math.pi / 2, math.pi / 2, 3 * math.pi / 2])
def test_panel_rotation(angle):
    scene = alma.Scene.from_dict(PANEL)
    assert alma.find_joints(scene.transformed(rotation(angle))).count == alma.find_joints(scene).count
    same_alpha(PANEL_ALPHA, alma.solve(scene.transformed(rotation(angle))))
    same_alpha(PANEL_ALPHA, solve_dict(rotated_dict(PANEL, angle)))


@pytest.mark.parametrize("offset", [(1e4, -3e3), (-250.5, 77.25), (0.0, 1e5)])
def test_panel_translation(offset):
    scene = alma.Scene.from_dict(PANEL)
    same_alpha(PANEL_ALPHA, alma.solve(scene.transformed(np.eye(2), offset)))


@settings(max_examples=20, deadline=None)
@given(data=assemblies(), angle=st.floats(-math.pi, math.pi), dx=st.floats(-5e3, 5e3), dy=st.floats(-5e3, 5e3))
def test_random_rigid_motion(data, angle, dx, dy):
    reference = solve_dict(data)
    same_alpha(reference, solve_dict(rotated_dict(data, angle, (dx, dy))))
    scene = alma.Scene.from_dict(data)
    same_alpha(reference, alma.solve(scene.transformed(rotation(angle), (dx, dy))))


# ----------------------------------------------------------------------------- mirror
def mirrored(data: dict) -> dict:
    out = map_vertices(data, lambda v: np.array([-v[0], v[1]]))  # now clockwise: alma reorders
    d = data["live_load"]["direction"]
    out["live_load"] = {"direction": [-d[0], d[1]]}
    return out


def test_panel_mirror():
    same_alpha(PANEL_ALPHA, solve_dict(mirrored(PANEL)))
    scene = alma.Scene.from_dict(PANEL)
    same_alpha(PANEL_ALPHA, alma.solve(scene.transformed(np.diag([-1.0, 1.0]))))


@settings(max_examples=20, deadline=None)
@given(data=assemblies())
def test_random_mirror(data):
    same_alpha(solve_dict(data), solve_dict(mirrored(data)))


# ----------------------------------------------------------------------------- numbering
def renumbered(data: dict, perm, shifts, reverse) -> dict:
    out = dict(data)
    blocks = []
    for new, old in enumerate(perm):
        b = dict(data["blocks"][old])
        v = list(b["vertices"])
        k = shifts[old] % len(v)
        v = v[k:] + v[:k]
        if reverse[old]:
            v = v[::-1]  # clockwise input
        b["vertices"] = v
        b["id"] = f"renamed{len(perm) - new}"
        blocks.append(b)
    out["blocks"] = blocks
    return out


@settings(max_examples=20, deadline=None)
@given(data=assemblies(), seed=st.integers(0, 2**32 - 1))
def test_random_renumbering(data, seed):
    rng = np.random.default_rng(seed)
    n = len(data["blocks"])
    other = renumbered(data, rng.permutation(n), rng.integers(0, 4, n), rng.integers(0, 2, n).astype(bool))
    same_alpha(solve_dict(data), solve_dict(other))


def test_panel_renumbering():
    rng = np.random.default_rng(7)
    n = len(PANEL["blocks"])
    other = renumbered(PANEL, rng.permutation(n), rng.integers(0, 4, n), rng.integers(0, 2, n).astype(bool))
    result = solve_dict(other)
    same_alpha(PANEL_ALPHA, result)
    assert {b.id for b in result.blocks} == {b["id"] for b in other["blocks"] if not b.get("fixed")}
    assert len(result.joints) == len(PANEL_ALPHA.joints)


# ----------------------------------------------------------------------------- friction
FRICTIONS = [0.001, 0.1, 0.2, 0.27, 0.4, 0.6, 0.8, 1.0, 1.5, 3.0]
#: bounds of two solves are compared up to the accuracy of alma's certificates (see conftest)


@pytest.mark.parametrize(
    "geometry",
    [("stack", "2:1", "4:1"), ("running", "2:1", "2:1"), ("english", "2:1", "4:1"), ("flemish", "2:1", "4:1")],
    ids=lambda g: "-".join(g),
)
def test_panel_alpha_non_decreasing_in_friction(geometry):
    model = panel_geometry(*geometry)
    results = [alma.solve(model.with_friction(f)) for f in FRICTIONS]
    for f, r in zip(FRICTIONS, results, strict=True):
        assert r.status == "optimal", (f, r.status, r.message)
        assert r.bounds.lower <= f + 1e-9  # (α itself: test_panel_alpha_at_most_friction)
    for (f0, r0), (f1, r1) in itertools.pairwise(zip(FRICTIONS, results, strict=True)):
        # proven: α_c(f1) ≥ lower(f1) and α_c(f0) ≤ upper(f0); monotonicity needs upper(f1) ≥ lower(f0)
        assert r1.bounds.upper >= r0.bounds.lower - CERTIFICATE, (f0, r0.alpha, f1, r1.alpha)
        assert r1.alpha >= r0.alpha - 1e-7 * max(1.0, abs(r0.alpha)), (f0, r0.alpha, f1, r1.alpha)


@settings(max_examples=15, deadline=None)
@given(data=assemblies(friction=0.6))
def test_random_alpha_non_decreasing_in_friction(data):
    scene = alma.Scene.from_dict(data)
    model = alma.build_model(scene)
    previous = None
    for f in [0.05, 0.2, 0.4, 0.6, 0.9, 1.4, 2.5]:
        result = alma.solve(model.with_friction(f))
        assert result.status in ("optimal", "no_equilibrium"), (f, result.status)
        # on the ground the whole assembly can slide: α ≤ f
        assert result.alpha <= f + 1e-9, (f, result.alpha)
        if previous is not None:
            assert (
                result.alpha >= previous.alpha - 1e-7 * max(1.0, abs(previous.alpha)) or previous.alpha == -math.inf
            ), (f, previous.alpha, result.alpha)
            if math.isfinite(previous.bounds.lower):
                assert result.bounds.upper >= previous.bounds.lower - CERTIFICATE
        previous = result


@pytest.mark.parametrize("geometry", [("stack", "2:1", "4:1"), ("running", "2:1", "2:1")])
def test_frictionless_panel_carries_its_dead_load(geometry):
    """With f = 0 nothing resists a horizontal push (α_c = 0) but the dead load stands."""
    result = alma.solve(panel_geometry(*geometry).with_friction(0.0))
    assert abs(result.alpha) <= 1e-9
    assert result.bounds.lower >= -1e-9
    assert result.status == "optimal", (result.status, result.bounds)
    assert result.mechanism_class == "sliding"


# ----------------------------------------------------------------------------- α ≤ f
#: Panels where alma's α exceeds f by more than 1e-9 (measured; the certified lower bound is
#: below f), as strict xfails.  None since alma.associative.NORMALISATION = 1000 (also at 100); with the
#: normalisation f_Lᵀu = n_free they were stack-2:1-4:1-1 (α = 1.0000000033342067) and
#: flemish-2:1-4:1-1 (1.0000000016129584): Clarabel stopped 'AlmostSolved' with relative gap
#: ~1e-8 although 1e-11 was requested.
ABOVE_F: dict[str, float] = {}


def _alpha_le_f_params():
    for row in table5():
        key = panel_id(*row[:4])
        marks = []
        if key in ABOVE_F:
            marks.append(
                pytest.mark.xfail(
                    strict=True,
                    reason=(
                        f"alma reports α = {ABOVE_F[key]!r} > f = {row[3]} (+{ABOVE_F[key] - row[3]:.1e}); "
                        "the solve is accepted 'AlmostSolved' with relative gap ~1e-8 although the "
                        "requested tolerance is 1e-11"
                    ),
                )
            )
        yield pytest.param(*row[:4], id=key, marks=marks)


ALPHA_LE_F_PARAMS = list(_alpha_le_f_params())


@pytest.mark.parametrize("bond,panel_ratio,block_ratio,friction", ALPHA_LE_F_PARAMS)
def test_panel_alpha_at_most_friction(bond, panel_ratio, block_ratio, friction):
    result = solve_panel(bond, panel_ratio, block_ratio, friction)
    assert result.bounds.lower <= friction + 1e-9
    assert result.alpha <= friction + 1e-9, result.alpha - friction


# ----------------------------------------------------------------------------- transformed()
def test_transformed_scene_round_trips():
    data = scene_dict(
        [
            {"id": "ground", "vertices": rect(-100, -50, 300, 0), "fixed": True},
            {"id": "b1", "vertices": rect(0, 0, 200, 100)},
        ],
        friction=0.6,
    )
    scene = alma.Scene.from_dict(data).transformed(np.diag([1.0, 2.0]))
    assert math.hypot(*scene.gravity) == pytest.approx(1.0)
    assert math.hypot(*scene.live_load_direction) == pytest.approx(1.0)
    same_alpha(alma.solve(alma.Scene.from_dict(scene.to_dict())), alma.solve(scene))


# ----------------------------------------------------------------------------- joint detection
def test_near_vertical_joint_is_found():
    """Regression (fixed in e3edc6c): the wall face is tilted by 1.1e-16 rad, far within the 1e-9
    tolerances, and its outward-normal angle rounds to exactly π.  find_joints used to wrap that
    angle to 0 without flipping the line's sign, found 1 joint instead of 2 and let the block rock
    away through the wall at α = 0.1 instead of 'no_collapse'."""
    data = scene_dict(
        [
            {"id": "ground", "vertices": rect(0, -50, 2000, 0), "fixed": True},
            {"id": "wall", "vertices": rect(900, 0, 1000, 1000), "fixed": True},
            {"id": "b1", "vertices": [[1000, 0], [1100, 0], [1100, 1000], [1000.0000000000001, 1000]]},
        ],
        friction=0.6,
        live=(-1.0, 0.0),
    )
    scene = alma.Scene.from_dict(data)
    assert alma.find_joints(scene).count == 2
    assert alma.solve(scene).status == "no_collapse"


def test_exactly_vertical_joint_is_found():
    """Control for the test above: with the corner exactly at x = 1000 both joints are found."""
    data = scene_dict(
        [
            {"id": "ground", "vertices": rect(0, -50, 2000, 0), "fixed": True},
            {"id": "wall", "vertices": rect(900, 0, 1000, 1000), "fixed": True},
            {"id": "b1", "vertices": rect(1000, 0, 1100, 1000)},
        ],
        friction=0.6,
        live=(-1.0, 0.0),
    )
    scene = alma.Scene.from_dict(data)
    assert alma.find_joints(scene).count == 2
    assert alma.solve(scene).status == "no_collapse"
