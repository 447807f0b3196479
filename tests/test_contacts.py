"""Joint detection: collinear, facing, overlapping edges in any orientation."""

from __future__ import annotations

import numpy as np
import pytest

import alma
from alma.geometry.contacts import find_joints
from alma.geometry.scene import Block, Scene


def _scene(*polys, fixed=(0,)):
    blocks = tuple(Block(id=f"b{i}", vertices=np.array(p, float), fixed=i in fixed) for i, p in enumerate(polys))
    return Scene(blocks=blocks)


def test_partial_overlap_gives_segment():
    s = _scene([[0, -10], [100, -10], [100, 0], [0, 0]], [[60, 0], [160, 0], [160, 20], [60, 20]])
    j = find_joints(s)
    assert j.count == 1
    assert sorted([j.start[0, 0], j.end[0, 0]]) == pytest.approx([60, 100])
    assert j.normal[0] == pytest.approx([0, 1])  # from block a (ground) into block b


def test_touching_at_a_point_is_no_joint():
    s = _scene([[0, -10], [100, -10], [100, 0], [0, 0]], [[100, 0], [200, 0], [200, 20], [100, 20]])
    assert find_joints(s).count == 0


@pytest.mark.parametrize("angle", [0.0, 0.3, np.pi / 2, np.pi, 2.0, -0.7, np.pi - 1e-12])
def test_rotated_pair_found(angle):
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    a = np.array([[0, -10], [100, -10], [100, 0], [0, 0]], float) @ R.T
    b = np.array([[20, 0], [80, 0], [80, 30], [20, 30]], float) @ R.T
    j = find_joints(_scene(a, b))
    assert j.count == 1
    assert j.length[0] == pytest.approx(60)
    assert j.normal[0] == pytest.approx(R @ [0, 1], abs=1e-12)


def test_parallel_but_separated_edges_are_no_joint():
    """1 mm apart on blocks of √area 45 mm: beyond the near-miss band (1e-2 of 45 mm), silent."""
    s = _scene([[0, -10], [100, -10], [100, 0], [0, 0]], [[0, 1.0], [100, 1.0], [100, 20], [0, 20]])
    joints = find_joints(s)
    assert joints.count == 0 and joints.warnings == ()


@pytest.mark.parametrize("gap", [1e-3, -1e-3, 1e-9, -1e-9])
def test_gap_or_overlap_within_the_tolerance_is_snapped_midway(gap):
    """A gap or an overlap below the contact tolerance (1e-4 of √area = 4.5e-3 mm) is a joint
    lying halfway between the two edges."""
    s = _scene([[0, -10], [100, -10], [100, 0], [0, 0]], [[0, gap], [100, gap], [100, 20], [0, 20]])
    joints = find_joints(s)
    assert joints.count == 1 and joints.warnings == ()
    assert joints.length[0] == pytest.approx(100)
    assert joints.start[0, 1] == pytest.approx(gap / 2, abs=1e-15)
    assert joints.end[0, 1] == pytest.approx(gap / 2, abs=1e-15)


def test_near_miss_is_reported_naming_the_blocks():
    s = _scene([[0, -10], [100, -10], [100, 0], [0, 0]], [[0, 0.1], [100, 0.1], [100, 20], [0, 20]])
    joints = find_joints(s)
    assert joints.count == 0
    assert len(joints.warnings) == 1
    assert "'b0' and 'b1' nearly touch" in joints.warnings[0] and "0.1 mm" in joints.warnings[0]


def test_contact_tolerance_is_a_scene_setting():
    blocks = [
        {"id": "g", "fixed": True, "vertices": [[0, -10], [100, -10], [100, 0], [0, 0]]},
        {"id": "b", "vertices": [[0, 0.1], [100, 0.1], [100, 20], [0, 20]]},
    ]
    with pytest.raises(alma.SceneError, match="touches nothing"):
        alma.Scene.from_dict({"blocks": blocks})
    scene = alma.Scene.from_dict({"blocks": blocks, "contact_tolerance": 0.005})
    assert find_joints(scene).count == 1
    assert alma.Scene.from_dict(scene.to_dict()).contact_tolerance == 0.005
    with pytest.raises(alma.SceneError, match="contact_tolerance"):
        alma.Scene.from_dict({"blocks": blocks, "contact_tolerance": 0.5})


def test_overlap_deeper_than_the_tolerance_is_refused():
    blocks = [
        {"id": "g", "fixed": True, "vertices": [[0, -10], [100, -10], [100, 0], [0, 0]]},
        {"id": "b", "vertices": [[0, -0.1], [100, -0.1], [100, 20], [0, 20]]},
    ]
    with pytest.raises(alma.SceneError, match="'g' and 'b' overlap"):
        alma.Scene.from_dict({"blocks": blocks})


def test_wall_joint_count():
    panel = alma.paper_panel("running", "2:1", "4:1", 0.6)
    j = find_joints(panel)
    # 12 courses; even courses 6 blocks, odd 7 pieces: head joints 5*6 + 6*6, bed joints
    heads = 6 * 5 + 6 * 6
    beds = 6 + sum(6 + 6 for _ in range(11))  # ground–course 0, then every course boundary: 12 segments
    assert j.count == heads + beds


def test_triangles_and_hexagon():
    tri = [[0, 0], [10, 0], [5, 8]]
    ground = [[-5, -2], [15, -2], [15, 0], [-5, 0]]
    j = find_joints(_scene(ground, tri))
    assert j.count == 1 and j.length[0] == pytest.approx(10)
