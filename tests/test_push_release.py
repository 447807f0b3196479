"""The push corrector with one hinge opened (alma.push.corrector.one_hinge_opened).

A four-bar linkage whose four hinges lie on one line moves infinitesimally (its middle hinges
rise) but locks over any finite step: the three links span exactly the distance between the
ground hinges. One hinge must open; the corrector keeps the release that opens least without
the released corners overlapping.
"""

from __future__ import annotations

import dataclasses
import importlib
from types import SimpleNamespace

import numpy as np
import pytest

from alma.push.corrector import corrected, one_hinge_opened
from alma.push.motion import Bodies, Contacts, MotionError, _moved
from alma.settings import PushSettings

SETTINGS = PushSettings()
step_module = importlib.import_module("alma.push.step")
TARGET = 0.01  # mm of the control point (the middle link's centre), along +x


def _linkage(order: np.ndarray | None = None) -> tuple[Bodies, Contacts]:
    """Ground (block 0) hinged at (0, 0) and (4, 0) to links A (1) and C (3), hinged at (1, 0)
    and (3, 0) to the middle link B (2); the contacts listed in ``order``."""
    bodies = Bodies(
        np.array([-1, 0, 1, 2]), np.array([[0.5, 0.5], [2.0, 0.5], [3.5, 0.5]]), np.zeros(3), np.zeros((3, 2))
    )
    a, b = np.array([0, 1, 2, 3]), np.array([1, 2, 3, 0])
    point = np.array([[0.0, 0.0], [1.0, 0.0], [3.0, 0.0], [4.0, 0.0]])
    normal = np.array([[0.0, 1.0], [1.0, 0.0], [1.0, 0.0], [0.0, -1.0]])
    k = np.arange(4) if order is None else order
    contacts = Contacts(
        a[k], b[k], point[k], normal[k], np.ones(4, bool), np.zeros(4, bool), np.full(4, 0.6), np.zeros(4, bool)
    )
    return bodies, contacts


def _args(bodies: Bodies) -> tuple:
    return (np.zeros((bodies.count, 3)), (2, np.array([2.0, 0.5])), TARGET, 1.0, SETTINGS)


def _gap(bodies: Bodies, contacts: Contacts, z: np.ndarray, k: int) -> np.ndarray:
    """Where block b's copy of contact point k lies from block a's after the increments z (mm)."""
    pick = slice(k, k + 1)
    return (
        _moved(bodies, z, contacts.b[pick], contacts.point[pick])
        - _moved(bodies, z, contacts.a[pick], contacts.point[pick])
    )[0]


def test_the_collinear_linkage_locks_with_every_hinge_closed() -> None:
    bodies, contacts = _linkage()
    with pytest.raises(MotionError, match="cannot stay closed"):
        corrected(bodies, contacts, *_args(bodies))


def test_one_hinge_opens_the_rest_stay_closed_and_the_control_point_moves_by_the_target() -> None:
    bodies, contacts = _linkage()
    z = one_hinge_opened(bodies, contacts, *_args(bodies))
    gaps = np.array([np.hypot(*_gap(bodies, contacts, z, k)) for k in range(4)])
    assert np.sum(gaps > 1e-6) == 1  # one hinge open, by far more than the corrector's round-off
    assert np.sort(gaps)[:3].max() <= 1e-9
    opened = int(np.argmax(gaps))
    assert _gap(bodies, contacts, z, opened) @ contacts.normal[opened] >= 0.0
    moved = _moved(bodies, z, np.array([2]), np.array([[2.0, 0.5]]))[0]
    assert moved[0] - 2.0 == pytest.approx(TARGET, abs=1e-12)


def test_the_release_that_opens_least_without_overlap_is_kept() -> None:
    bodies, contacts = _linkage()
    z = one_hinge_opened(bodies, contacts, *_args(bodies))
    openings = {}
    for k in range(4):
        kept = dataclasses.replace(contacts, hinge=np.arange(4) != k)
        zk = corrected(bodies, kept, *_args(bodies))
        gap = _gap(bodies, contacts, zk, k)
        openings[k] = (float(np.hypot(*gap)), float(gap @ contacts.normal[k]), zk)
    admissible = {k: v for k, v in openings.items() if v[1] >= 0.0}
    assert len(admissible) < 4  # a release that would press the corners into each other is refused
    least = min(admissible, key=lambda k: admissible[k][0])
    assert np.array_equal(z, admissible[least][2])


@pytest.mark.parametrize("order", [np.array([3, 1, 0, 2]), np.array([2, 3, 1, 0])])
def test_the_opened_hinge_does_not_depend_on_the_contacts_order(order: np.ndarray) -> None:
    bodies, contacts = _linkage()
    z = one_hinge_opened(bodies, contacts, *_args(bodies))
    bodies2, contacts2 = _linkage(order)
    z2 = one_hinge_opened(bodies2, contacts2, *_args(bodies2))
    assert np.allclose(z2, z, rtol=0.0, atol=1e-12)


def test_a_linkage_no_single_release_frees_is_an_error_that_says_so() -> None:
    bodies, contacts = _linkage()
    # with the middle link's hinges on both ground points as well, one release leaves it locked
    extra = dataclasses.replace(
        contacts,
        a=np.concatenate([contacts.a, [0, 0]]),
        b=np.concatenate([contacts.b, [2, 2]]),
        point=np.concatenate([contacts.point, [[2.0, 0.0], [2.5, 0.0]]]),
        normal=np.concatenate([contacts.normal, [[0.0, 1.0], [0.0, 1.0]]]),
        hinge=np.ones(6, bool),
        sliding=np.zeros(6, bool),
        friction=np.full(6, 0.6),
        crushing=np.zeros(6, bool),
    )
    with pytest.raises(MotionError, match="nor with any one of its 6 hinges opened"):
        one_hinge_opened(bodies, extra, *_args(bodies))


def _stand_ins(bodies: Bodies, contacts: Contacts) -> tuple[SimpleNamespace, SimpleNamespace]:
    """The run and state :func:`alma.push.step.increment` reads, for the linkage pushed by its
    middle link's centre from d = 0."""
    run = SimpleNamespace(push=SETTINGS, control=2, length=1.0, sense=1.0)
    return run, SimpleNamespace(bodies=bodies, contacts=contacts, d=0.0)


def test_a_step_whose_hinges_lock_opens_one_of_them() -> None:
    bodies, contacts = _linkage()
    run, state = _stand_ins(bodies, contacts)
    z = step_module.increment(run, state, TARGET, 1.0, np.array([2.0, 0.5]), np.full(4, 1e-3))
    assert np.array_equal(z, one_hinge_opened(bodies, contacts, *_args(bodies)))


def test_a_step_whose_hinges_close_but_whose_held_points_do_not_opens_none(monkeypatch) -> None:
    # measured on flemish 1:2 1:1 f = 0.27: the hinges closed and only the re-solves holding the
    # points a step drove into their neighbours stalled, yet every step released each of its
    # 159 hinges in turn (77 of 127 s); the motion found without the held points stands, and
    # the landing shortens the step to where they touch
    bodies, contacts = _linkage()
    run, state = _stand_ins(bodies, contacts)
    found = [np.full((3, 3), 1.0), np.full((3, 3), 2.0)]

    def held_apart(solve, bodies, contacts, tolerance, rounds, unheld):
        unheld.append(found[len(unheld)])
        raise MotionError("a held point stalls the corrector")

    def no_release(*args):
        pytest.fail("no hinge locks: none is released")

    monkeypatch.setattr(step_module, "_held_apart", held_apart)
    monkeypatch.setattr(step_module, "one_hinge_opened", no_release)
    z = step_module.increment(run, state, TARGET, 1.0, np.array([2.0, 0.5]), np.full(4, 1e-3))
    assert z is found[0]
