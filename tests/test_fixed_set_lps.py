"""The search's store of fixed-set LPs: a repeat gets the stored solve only where a new solve
would run the same iterations (:class:`alma.nonassociative.fixed_set_lps.FixedSetLPs`)."""

from __future__ import annotations

import numpy as np
import pytest

import alma
from alma.backends.linprog_backend import LPMethod
from alma.backends.termination import Termination
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import build_model
from alma.nonassociative.exact_states import exact_state
from alma.nonassociative.fixed_set_lps import FixedSetLPs


def _scene(width: float = 1.0) -> alma.Scene:
    return alma.Scene.from_dict(
        {
            "friction": 0.6,
            "blocks": [
                {"id": "g", "vertices": [[-1, -1], [4, -1], [4, 0], [-1, 0]], "fixed": True},
                {"id": "a", "vertices": [[0, 0], [width, 0], [width, 2], [0, 2]]},
                {"id": "b", "vertices": [[width, 0], [2, 0], [2, 2], [width, 2]]},
                {"id": "c", "vertices": [[0, 2], [2, 2], [2, 3], [0, 3]]},
            ],
        }
    )


@pytest.fixture
def store() -> FixedSetLPs:
    model = build_model(_scene())
    return FixedSetLPs(model, ContactPoints.from_model(model))


def _sticking(store: FixedSetLPs) -> tuple[np.ndarray, np.ndarray]:
    count = store.points.count
    return np.zeros(count, dtype=bool), np.zeros(count)


def test_a_repeat_is_served_read_only(store):
    open_points, slip = _sticking(store)
    first = store.static(open_points, slip, max_pivots=10_000, method=LPMethod.SIMPLEX)
    again = store.static(open_points.copy(), slip.copy(), max_pivots=10_000, method=LPMethod.SIMPLEX)
    assert first.status is Termination.OPTIMAL and again is first and store.hits == 1
    assert not first.normal.flags.writeable
    mechanism, pivots = store.kinematic(open_points, slip, max_pivots=10_000)
    assert store.kinematic(open_points, slip, max_pivots=10_000) == (mechanism, pivots) and store.hits == 2
    store.static(open_points, slip, max_pivots=10_000, method=LPMethod.IPM)  # another method: solved anew
    assert store.hits == 2


def test_a_solve_stopped_by_its_cap_serves_no_larger_cap(store):
    open_points, slip = _sticking(store)
    full = store.static(open_points, slip, max_pivots=10_000, method=LPMethod.SIMPLEX)
    assert full.pivots >= 2, "the LP must take more than one iteration for this test"
    cut = store.static(open_points, slip, max_pivots=1, method=LPMethod.SIMPLEX)
    assert cut.status is not Termination.OPTIMAL and store.hits == 0  # p < 1 fails: solved under the cap
    again = store.static(open_points, slip, max_pivots=10_000, method=LPMethod.SIMPLEX)
    assert again.status is Termination.OPTIMAL and store.hits == 0  # the cut solve stopped at its cap
    assert again.alpha == full.alpha
    assert store.static(open_points, slip, max_pivots=again.pivots + 1, method=LPMethod.SIMPLEX) is again
    assert store.hits == 1


def test_the_store_of_another_model_is_refused(store):
    other = build_model(_scene(width=0.9))
    points = ContactPoints.from_model(other)
    mechanism = np.zeros(other.dead.shape[0])
    mechanism[0] = 1.0
    with pytest.raises(ValueError, match="another model"):
        exact_state(other, points, mechanism, "test", lps=store)
