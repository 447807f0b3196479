"""The joints of a result are columns read as JointResult objects (alma.results.joint_table)."""

import json

import numpy as np
import pytest

import alma
from alma.results.joint_table import JointTable
from alma.results.types import JointResult, _joint_records


@pytest.fixture(scope="module")
def result():
    scene = alma.paper_panel(bond="running", panel_ratio="2:1", block_ratio="4:1", friction=0.6)
    return alma.solve(scene)


def test_joints_are_a_table_read_as_joint_results(result):
    joints = result.joints
    assert isinstance(joints, JointTable)
    assert len(joints) == result.n_joints > 0
    first, last = joints[0], joints[-1]
    assert isinstance(first, JointResult) and last == joints[len(joints) - 1]
    assert isinstance(first.N, float) and isinstance(first.blocks[0], str)
    assert joints[1:3] == (joints[1], joints[2])
    assert list(joints) == [joints[i] for i in range(len(joints))]
    with pytest.raises(IndexError):
        joints[len(joints)]


def test_a_table_equals_the_tuple_of_its_joints(result):
    joints = result.joints
    as_tuple = tuple(joints)
    assert joints == as_tuple
    changed = (*as_tuple[:-1], JointResult(**{**as_tuple[-1].__dict__, "N": as_tuple[-1].N + 1.0}))
    assert joints != changed
    assert joints != as_tuple[:-1]


def test_the_json_of_the_columns_is_the_json_of_the_joints(result):
    joints = result.joints
    by_columns = json.dumps(joints.records())
    by_objects = json.dumps(_joint_records(tuple(joints)))
    assert by_columns == by_objects
    moving = [j for j in joints if j.state != "rest"]
    assert moving and all(j.state in ("hinging", "sliding", "separating") for j in moving)
    # the forces of the columns are the forces each joint reports
    assert np.allclose([j.N for j in joints], joints.N) and np.allclose([j.M for j in joints], joints.M)
