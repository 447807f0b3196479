"""The falling mode as a certificate that Eq. 10 has no field at any α (alma.associative.falling)."""

from __future__ import annotations

import numpy as np
import pytest

import alma
from alma.associative.falling import FallingRay, falling_ray
from alma.geometry.contacts import find_joints
from alma.mechanics.model import build_model


def _wedged(friction: float):
    """A block held only by two fixed walls at its sides: it stands by friction on them, or falls."""
    scene = alma.Scene.from_dict(
        {
            "thickness": 100,
            "unit_weight": 20,
            "friction": friction,
            "blocks": [
                {"id": "left", "vertices": [[-100, 0], [0, 0], [0, 500], [-100, 500]], "fixed": True},
                {"id": "right", "vertices": [[300, 0], [400, 0], [400, 500], [300, 500]], "fixed": True},
                {"id": "b", "vertices": [[0, 100], [300, 100], [300, 400], [0, 400]]},
            ],
        }
    ).validate()
    return build_model(scene, find_joints(scene))


def test_a_block_between_frictionless_walls_has_a_falling_mode_that_proves_it():
    model = _wedged(0.0)
    ray = falling_ray(model)
    assert ray is not None and ray.proves(model.n_free, 1e6)
    u = ray.u.reshape(-1, 3)[0]
    # it falls straight down (the weights' work), the live load (horizontal) does none
    assert u[1] == pytest.approx(-1.0) and abs(u[0]) < 1e-12 and abs(u[2]) < 1e-12
    assert (model.equilibrium.T @ ray.u).min() >= -1e-12 and abs(model.live @ ray.u) < 1e-12


def test_a_block_held_by_friction_has_none():
    assert falling_ray(_wedged(0.5)) is None


def test_a_ray_whose_breach_is_not_far_below_its_work_proves_nothing():
    u = np.zeros(3)
    assert FallingRay(u, 1e-3, 1e-12).proves(10, 1e6)
    assert not FallingRay(u, 1e-3, 1e-9).proves(10, 1e6)  # a field of 1e6 block weights could stand
    assert not FallingRay(u, 0.0, 0.0).proves(1, 1e6)
