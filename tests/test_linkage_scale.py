"""The velocity scale of a collapse state's active set and verification (a linkage's included)."""

from __future__ import annotations

import numpy as np
import pytest

from alma.nonassociative.states import velocity_scale
from alma.settings import StateTolerances


def test_a_mechanism_that_moves_its_contacts_is_measured_by_them():
    mechanism = np.array([2.0, 0.0, 0.5, -1.0, 3.0, 0.0])  # centroids move at up to 3
    opening, slip = np.array([0.0, 0.4, -0.1]), np.array([0.02, -0.3])
    assert velocity_scale(mechanism, opening, slip) == 0.4


def test_a_linkage_is_measured_by_its_blocks():
    # relative velocities of round-off (a linkage of point hinges moves no contact): no share of
    # them means anything, the centroids' velocity is the scale
    mechanism = np.array([2.0, 0.0, 0.5, -1.0, 3.0, 0.0])
    noise = np.array([3e-9, -1e-16])
    assert velocity_scale(mechanism, noise) == 3.0
    assert velocity_scale(mechanism, noise, linkage=1e-10) == 3e-9  # above that share: not a linkage


def test_the_scale_does_not_depend_on_units():
    mechanism, noise = np.array([2.0, 0.0, 0.5, -1.0, 3.0, 0.0]), np.array([3e-9])
    for unit in (1e-3, 25.4, 1e3):  # lengths and translations scale, rotations do not
        scaled = mechanism * np.tile([unit, unit, 1.0], 2)
        assert velocity_scale(scaled, noise * unit) == pytest.approx(3.0 * unit)


def test_the_default_share_is_the_settings():
    assert StateTolerances().linkage == 1e-6
