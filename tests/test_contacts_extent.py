"""Joint detection's memory depends on the number of edges, not on the drawing's extent.

A wall plus one support far away (1e7 mm) must cost what the wall alone costs: the candidate
search once paired every edge of a course with every other (its slack grew with the distance
from the drawing's centre), so that 40,000 blocks and one far block needed > 17 GB.  Memory is
measured with tracemalloc (numpy's buffers are traced), not with the clock.
"""
from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import alma
from alma.geometry.contacts import find_joints
from alma.geometry.scene import Scene


def _wall(far: float | None) -> Scene:
    data = alma.wall("running", 240.0 * 25, 60.0 * 40, 240.0).to_dict()
    if far is not None:
        data["blocks"].append({"id": "far", "fixed": True,
                               "vertices": [[far, 0], [far + 240, 0], [far + 240, 60], [far, 60]]})
    return Scene.from_dict(data)


def _peak_bytes(scene: Scene) -> tuple[int, object]:
    tracemalloc.start()
    try:
        joints = find_joints(scene)
        return tracemalloc.get_traced_memory()[1], joints
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("far", [1e5, 1e7, -3e8])
def test_far_block_costs_no_memory(far):
    near_peak, near = _peak_bytes(_wall(None))
    far_peak, distant = _peak_bytes(_wall(far))
    assert far_peak <= 1.25 * near_peak, (far_peak, near_peak)
    # The same joints: the far block touches nothing.
    assert distant.count == near.count
    for field in ("block_a", "block_b", "start", "end", "normal"):
        assert np.array_equal(getattr(distant, field), getattr(near, field)), field
