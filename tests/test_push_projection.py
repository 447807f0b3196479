"""The unilateral step of a mechanism no closure can follow (alma.push.projection.projected_step).

The linkages of tests/test_push_release.py: a four-bar linkage whose hinges lie on one line, and
the same with its middle link resting on the ground at two more points, which no single opened
hinge frees.  With every contact unilateral both move: the step is the motion nearest the
mechanism's predictor that carries no contact point into its neighbour.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from alma.push.motion import Bodies, Contacts, MotionError, _moved
from alma.push.projection import projected_step
from alma.settings import PushSettings

SETTINGS = PushSettings()
TARGET = 0.01  # mm of the control point (the middle link's centre), along +x
ENTERING = 1e-6  # mm a contact point may enter its neighbour


def _linkage(resting: bool, order: np.ndarray | None = None) -> tuple[Bodies, Contacts]:
    """Ground (block 0) hinged at (0, 0) and (4, 0) to links A (1) and C (3), hinged at (1, 0)
    and (3, 0) to the middle link B (2); ``resting``: B also on the ground at (2, 0) and
    (2.5, 0).  The contacts listed in ``order``."""
    bodies = Bodies(
        np.array([-1, 0, 1, 2]), np.array([[0.5, 0.5], [2.0, 0.5], [3.5, 0.5]]), np.zeros(3), np.zeros((3, 2))
    )
    a, b = [0, 1, 2, 3], [1, 2, 3, 0]
    point = [[0.0, 0.0], [1.0, 0.0], [3.0, 0.0], [4.0, 0.0]]
    normal = [[0.0, 1.0], [1.0, 0.0], [1.0, 0.0], [0.0, -1.0]]
    if resting:
        a, b = [*a, 0, 0], [*b, 2, 2]
        point, normal = [*point, [2.0, 0.0], [2.5, 0.0]], [*normal, [0.0, 1.0], [0.0, 1.0]]
    n = len(a)
    k = np.arange(n) if order is None else order
    contacts = Contacts(
        np.array(a)[k],
        np.array(b)[k],
        np.array(point, dtype=float)[k],
        np.array(normal, dtype=float)[k],
        np.ones(n, bool),
        np.zeros(n, bool),
        np.full(n, 0.6),
        np.zeros(n, bool),
    )
    return bodies, contacts


def _step(bodies: Bodies, contacts: Contacts) -> np.ndarray:
    start = np.zeros((bodies.count, 3))
    return projected_step(bodies, contacts, start, (2, np.array([2.0, 0.5])), TARGET, 1.0, SETTINGS, ENTERING)


def _normal_gaps(bodies: Bodies, contacts: Contacts, z: np.ndarray) -> np.ndarray:
    """Per contact point, how far block b's copy lies from block a's along the normal (mm; the
    steps here turn no body, so the normal stays as drawn)."""
    gap = _moved(bodies, z, contacts.b, contacts.point) - _moved(bodies, z, contacts.a, contacts.point)
    return (gap * contacts.normal).sum(axis=1)


@pytest.mark.parametrize("resting", [False, True])
def test_the_control_point_moves_by_the_target_and_no_contact_enters(resting: bool) -> None:
    bodies, contacts = _linkage(resting)
    z = _step(bodies, contacts)
    moved = _moved(bodies, z, np.array([2]), np.array([[2.0, 0.5]]))[0]
    assert moved[0] - 2.0 == pytest.approx(TARGET, abs=1e-9)
    assert _normal_gaps(bodies, contacts, z).min() >= -ENTERING


def test_the_resting_link_slides_turning_as_little_as_it_must() -> None:
    # By hand, to first order (the objective weighs angle × L and shifts alike, L = 1 mm): B's
    # centre moves 0.01 to the right; B's right hinge pushes C's left end, xc + θc/2 ≥ 0.01 + θb/2;
    # B turning by θb = −2u lowers that by u but lifts its ground point at (2, 0) by −θb/2 (yb ≥ u).
    # C meets r = 0.01 − u least with xc = 0.8 r, θc = 0.4 r (cost 0.8 r²), B costs 5u², so
    # u = 0.016/11.6.  A stays.  The second-order gaps open, so the first round stands.
    bodies, contacts = _linkage(resting=True)
    z = _step(bodies, contacts)
    u = 0.016 / 11.6
    r = TARGET - u
    expected = np.array([[0.0, 0.0, 0.0], [-2 * u, TARGET, u], [0.4 * r, 0.8 * r, 0.0]])
    assert np.allclose(z, expected, rtol=0.0, atol=1e-8)


@given(st.permutations(list(range(6))))
@settings(max_examples=10, deadline=None)
def test_the_step_does_not_depend_on_the_contacts_order(order: list[int]) -> None:
    bodies, contacts = _linkage(resting=True)
    z = _step(bodies, contacts)
    bodies2, contacts2 = _linkage(True, np.array(order))
    assert np.allclose(_step(bodies2, contacts2), z, rtol=0.0, atol=1e-9)


def test_a_step_no_motion_allows_is_an_error_that_says_so() -> None:
    bodies, contacts = _linkage(resting=True)
    # a wall against B's right end, at (3, 0) and (3, 1) (normal from the wall into B along −x):
    # B can neither move nor turn its centre to the right
    walled = dataclasses.replace(
        contacts,
        a=np.concatenate([contacts.a, [0, 0]]),
        b=np.concatenate([contacts.b, [2, 2]]),
        point=np.concatenate([contacts.point, [[3.0, 0.0], [3.0, 1.0]]]),
        normal=np.concatenate([contacts.normal, [[-1.0, 0.0], [-1.0, 0.0]]]),
        hinge=np.ones(8, bool),
        sliding=np.zeros(8, bool),
        friction=np.full(8, 0.6),
        crushing=np.zeros(8, bool),
    )
    with pytest.raises(MotionError, match="no motion of the step"):
        _step(bodies, walled)


@given(scale=st.floats(0.01, 100.0), dx=st.floats(-1e4, 1e4), dy=st.floats(-1e4, 1e4))
@settings(max_examples=15, deadline=None)
def test_the_step_does_not_depend_on_the_units_or_the_origin(scale: float, dx: float, dy: float) -> None:
    # the linkage drawn in other units (lengths × scale) and elsewhere: the same turns, shifts × scale
    bodies, contacts = _linkage(resting=True)
    z = _step(bodies, contacts)
    shift = np.array([dx, dy])
    moved = Bodies(bodies.of_block, bodies.centre * scale + shift, bodies.omega, bodies.velocity * scale)
    placed = dataclasses.replace(contacts, point=contacts.point * scale + shift)
    where = np.array([2.0, 0.5]) * scale + shift
    z2 = projected_step(moved, placed, np.zeros((3, 3)), (2, where), TARGET * scale, scale, SETTINGS, ENTERING * scale)
    assert np.allclose(z2[:, 0], z[:, 0], rtol=0.0, atol=1e-9)
    assert np.allclose(z2[:, 1:] / scale, z[:, 1:], rtol=0.0, atol=1e-9)
