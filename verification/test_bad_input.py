"""Bad input (SPEC §2) is refused with a SceneError naming the block or joint and the rule.

Every test starts from a valid scene (one 200 × 100 block on the ground) and breaks one rule.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import alma

from helpers import rect, single_block_dict


def base() -> dict:
    return single_block_dict(200.0, 100.0, 0.6)


def refused(data: dict, *fragments: str) -> str:
    with pytest.raises(alma.SceneError) as info:
        alma.Scene.from_dict(data)
    message = str(info.value)
    for fragment in fragments:
        assert fragment.lower() in message.lower(), (fragment, message)
    return message


def test_base_scene_is_valid():
    result = alma.solve(alma.Scene.from_dict(base()))
    assert result.status == "optimal"
    assert result.alpha == pytest.approx(0.6, rel=1e-7)  # min(f = 0.6, b/h = 2)


# ----------------------------------------------------------------------------- polygons
@pytest.mark.parametrize(
    "vertices,rule",
    [
        ([[0, 0], [200, 0], [100, 20], [200, 100], [0, 100]], "convex"),  # reflex corner
        ([[0, 0], [200, 0], [200, 100], [100, 60], [0, 100]], "convex"),  # dent in the top
        (
            [
                [100, 0],
                [130, 70],
                [200, 80],
                [140, 110],
                [160, 180],
                [100, 130],
                [40, 180],
                [60, 110],
                [0, 80],
                [70, 70],
            ],
            "convex",
        ),  # star
    ],
)
def test_non_convex_polygon(vertices, rule):
    data = base()
    data["blocks"][1]["vertices"] = vertices
    refused(data, "'b1'", rule)


def test_self_intersecting_pentagram():
    """All turns are left turns but the boundary winds twice."""
    angles = np.pi / 2 + np.arange(5) * 4 * np.pi / 5
    star = np.column_stack([100 + 50 * np.cos(angles), 60 + 50 * np.sin(angles)])
    data = base()
    data["blocks"][1]["vertices"] = star.tolist()
    refused(data, "'b1'", "convex")


@pytest.mark.parametrize(
    "vertices,rule",
    [
        ([[0, 0], [200, 0], [200, 0], [200, 100], [0, 100]], "degenerate"),  # repeated vertex
        ([[0, 0], [0, 0], [0, 0]], "degenerate"),  # a point
        ([[0, 0], [100, 0], [200, 0]], "degenerate"),  # zero area, collinear
        ([[0, 0], [200, 0], [200, 100], [200, 0]], "degenerate"),  # zero area, folded
        ([[0, 0], [200, 0]], "3 vertices"),
        ([[0, 0]], "3 vertices"),
    ],
)
def test_degenerate_polygon(vertices, rule):
    data = base()
    data["blocks"][1]["vertices"] = vertices
    refused(data, "'b1'", rule)


@pytest.mark.parametrize("vertices", [[], [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, "a"], [1, 0], [0, 1]], "square"])
def test_malformed_vertices(vertices):
    data = base()
    data["blocks"][1]["vertices"] = vertices
    refused(data, "'b1'", "vertices")


def test_clockwise_input_accepted_and_reordered():
    data = base()
    data["blocks"][1]["vertices"] = rect(0, 0, 200, 100)[::-1]  # clockwise
    scene = alma.Scene.from_dict(data)
    block = scene.blocks[1]
    x, y = block.vertices[:, 0], block.vertices[:, 1]
    signed_area = 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    assert signed_area == pytest.approx(200 * 100)  # counter-clockwise after reading
    assert {tuple(v) for v in block.vertices.tolist()} == {tuple(v) for v in rect(0, 0, 200, 100)}
    reference = alma.solve(alma.Scene.from_dict(base()))
    result = alma.solve(scene)
    assert result.alpha == pytest.approx(reference.alpha, rel=1e-9)
    assert result.status == reference.status
    assert len(result.joints) == 1


# ----------------------------------------------------------------------------- assemblies
@pytest.mark.parametrize(
    "other",
    [
        rect(150, 0, 300, 100),  # partial overlap
        rect(50, 20, 100, 60),  # inside b1
        rect(-50, -20, 300, 150),  # contains b1 (and cuts the ground)
    ],
)
def test_overlapping_blocks(other):
    data = base()
    data["blocks"].append({"id": "b2", "vertices": other})
    message = refused(data, "overlap")
    assert "'b2'" in message and ("'b1'" in message or "'ground'" in message), message


def test_overlapping_blocks_names_both():
    data = base()
    data["blocks"].append({"id": "b2", "vertices": rect(150, 0, 300, 100)})
    refused(data, "'b1'", "'b2'", "overlap")


def test_touching_blocks_are_not_overlapping():
    data = base()
    data["blocks"].append({"id": "b2", "vertices": rect(200, 0, 300, 100)})
    scene = alma.Scene.from_dict(data)
    assert alma.find_joints(scene).count == 3  # two on the ground, one between the blocks


@pytest.mark.parametrize(
    "other",
    [
        rect(500, 500, 600, 600),  # far away
        rect(200, 100, 300, 200),  # touches b1 at one corner only: no joint of positive length
        rect(0, 101, 200, 200),  # a gap of 1 mm above b1
    ],
)
def test_free_block_touching_nothing(other):
    data = base()
    data["blocks"].append({"id": "b2", "vertices": other})
    refused(data, "'b2'", "touches nothing")


def test_floating_cluster_is_not_carried():
    """Two free blocks that touch each other but no support: accepted (each has a joint) and
    reported as unable to carry its weight."""
    data = base()
    data["blocks"] += [
        {"id": "b2", "vertices": rect(500, 500, 600, 600)},
        {"id": "b3", "vertices": rect(500, 600, 600, 700)},
    ]
    try:
        scene = alma.Scene.from_dict(data)
    except alma.SceneError as exc:  # refusing it, naming a block, is also acceptable
        assert "'b2'" in str(exc) or "'b3'" in str(exc)
        return
    result = alma.solve(scene)
    assert result.status == "no_equilibrium"


def test_no_support():
    data = base()
    data["blocks"][0]["fixed"] = False
    refused(data, "no support", "fixed")


def test_only_fixed_blocks():
    data = base()
    data["blocks"][1]["fixed"] = True
    refused(data, "free block")


def test_duplicate_ids():
    data = base()
    data["blocks"][1]["id"] = "ground"
    refused(data, "'ground'", "duplicate")


@pytest.mark.parametrize("value", ["yes", 1, None])
def test_fixed_must_be_boolean(value):
    data = base()
    data["blocks"][1]["fixed"] = value
    refused(data, "'b1'", "fixed")


# ----------------------------------------------------------------------------- numbers
@pytest.mark.parametrize(
    "key,value,rule",
    [
        ("thickness", 0, "> 0"),
        ("thickness", -120, "> 0"),
        ("unit_weight", 0, "> 0"),
        ("unit_weight", -18, "> 0"),
        ("friction", -0.1, ">= 0"),
        ("friction", -1e-12, ">= 0"),
        ("cohesion", -1.0, ">= 0"),
    ],
)
def test_non_positive_material_numbers(key, value, rule):
    data = base()
    data[key] = value
    refused(data, key, rule)


@pytest.mark.parametrize("key", ["thickness", "unit_weight", "friction", "cohesion"])
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_non_finite_material_numbers(key, value):
    data = base()
    data[key] = value
    refused(data, key, "nan or inf")


@pytest.mark.parametrize("key", ["thickness", "friction"])
@pytest.mark.parametrize("value", ["120", True, [1]])
def test_material_numbers_must_be_numbers(key, value):
    data = base()
    data[key] = value
    refused(data, key, "number")


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("corner", [0, 2])
def test_non_finite_vertices(value, corner):
    data = base()
    data["blocks"][1]["vertices"][corner] = [value, 100.0]
    refused(data, "'b1'", "nan or inf")


@pytest.mark.parametrize("value", [math.nan, math.inf, -1.0])
def test_bad_block_weight(value):
    data = base()
    data["blocks"][1]["weight"] = value
    refused(data, "'b1'", "weight")


@pytest.mark.parametrize("key", ["gravity", "live_load"])
@pytest.mark.parametrize("vector,rule", [([0, 0], "non-zero"), ([math.nan, -1], "nan or inf"), ([1, 2, 3], "pair")])
def test_bad_directions(key, vector, rule):
    data = base()
    if key == "gravity":
        data["gravity"] = vector
    else:
        data["live_load"] = {"direction": vector}
    refused(data, key, rule)


# ----------------------------------------------------------------------------- files
def _write_with_literal(tmp_path, data: dict, literal: str):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data).replace('"@@"', literal))
    return path


@pytest.mark.parametrize("literal", ["NaN", "Infinity", "-Infinity", "1e999", "-1e999"])
def test_load_scene_refuses_non_finite_numbers(tmp_path, literal):
    data = base()
    data["blocks"][1]["vertices"][2] = ["@@", 100]
    with pytest.raises(alma.SceneError) as info:
        alma.load_scene(_write_with_literal(tmp_path, data, literal))
    message = str(info.value)
    assert "nan" in message.lower() or "inf" in message.lower(), message


@pytest.mark.parametrize("literal", ["1e999", "-1e999"])
def test_load_scene_names_block_of_overflowing_vertex(tmp_path, literal):
    data = base()
    data["blocks"][1]["vertices"][2] = ["@@", 100]
    with pytest.raises(alma.SceneError, match="'b1'"):
        alma.load_scene(_write_with_literal(tmp_path, data, literal))


@pytest.mark.parametrize("literal", ["NaN", "Infinity"])
def test_load_scene_names_block_of_nan_vertex(tmp_path, literal):
    data = base()
    data["blocks"][1]["vertices"][2] = ["@@", 100]
    with pytest.raises(alma.SceneError, match="'b1'"):
        alma.load_scene(_write_with_literal(tmp_path, data, literal))


def test_load_scene_refuses_nan_thickness(tmp_path):
    data = base()
    data["thickness"] = "@@"
    with pytest.raises(alma.SceneError, match=r"(?i)nan"):
        alma.load_scene(_write_with_literal(tmp_path, data, "NaN"))


def test_load_scene_reads_a_valid_file(tmp_path):
    path = tmp_path / "ok.json"
    path.write_text(json.dumps(base()))
    assert alma.solve(alma.load_scene(path)).status == "optimal"


@pytest.mark.parametrize("text", ["{", "[1, 2]", '{"blocks": 3}'])
def test_load_scene_refuses_malformed_files(tmp_path, text):
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(alma.SceneError):
        alma.load_scene(path)


def test_load_scene_missing_file(tmp_path):
    with pytest.raises(alma.SceneError, match="cannot be read"):
        alma.load_scene(tmp_path / "missing.json")


# ----------------------------------------------------------------------------- unknown keys
def test_unknown_top_level_key():
    data = base()
    data["colour"] = "red"
    refused(data, "unknown", "colour")


def test_unknown_block_key():
    data = base()
    data["blocks"][1]["colour"] = "red"
    refused(data, "'b1'", "unknown", "colour")


def test_unknown_live_load_key():
    data = base()
    data["live_load"]["magnitude"] = 2.0
    refused(data, "live_load", "unknown", "magnitude")


def test_missing_blocks():
    data = base()
    del data["blocks"]
    refused(data, "blocks")


# ----------------------------------------------------------------------------- joints
def test_joint_override_unknown_block():
    data = base()
    data["joints"] = [{"blocks": ["ground", "bX"], "friction": 0.3}]
    refused(data, "joint", "'bX'", "unknown")


@pytest.mark.parametrize(
    "key,value,rule", [("friction", -0.5, ">= 0"), ("cohesion", -1.0, ">= 0"), ("friction", math.nan, "nan or inf")]
)
def test_joint_override_bad_numbers(key, value, rule):
    data = base()
    data["joints"] = [{"blocks": ["ground", "b1"], key: value}]
    refused(data, "joint", "ground", "b1", key, rule)


def test_joint_override_unknown_key():
    data = base()
    data["joints"] = [{"blocks": ["ground", "b1"], "friction": 0.3, "colour": "red"}]
    refused(data, "joint", "unknown", "colour")


def test_joint_override_applies():
    data = base()
    data["joints"] = [{"blocks": ["ground", "b1"], "friction": 0.3}]
    assert alma.solve(alma.Scene.from_dict(data)).alpha == pytest.approx(0.3, rel=1e-7)


def test_joint_override_between_blocks_that_do_not_touch():
    data = base()
    data["blocks"].append({"id": "b2", "vertices": rect(300, 0, 400, 100)})
    data["joints"] = [{"blocks": ["b1", "b2"], "friction": 0.3}]
    refused(data, "joint", "'b1'", "'b2'", "touch")
