"""The fixed-set LPs of one search, each solved once (Eqs. 2, 3 and 5 with the active set fixed).

The starts of a search often reach an active set that an earlier start (or an earlier iteration
of the same start) already made exact: on the Ferris & Tin-Loi walls about half of the
fixed-set static and kinematic LPs repeat one solved before.  :class:`FixedSetLPs` keeps each
solve of one model under its active set and hands a repeat the stored solution.  HiGHS and
Clarabel are deterministic, so that is the solution a new solve would give; the search's answer
does not depend on whether an LP came from the store.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from alma.backends.linprog_backend import LPMethod
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.static_lps import StaticLP, fixed_set_static_interior, kinematic_lp, static_lp


@dataclass(frozen=True)
class _Solved:
    """One stored solve: what it returned, its iterations and the cap it ran under."""

    result: Any
    iterations: int
    cap: int


def _key(kind: str, *parts: Any) -> tuple[Any, ...]:
    """A hashable key of an LP's data: arrays by dtype, shape and bytes, anything else as is."""
    return (kind, *((p.dtype.str, p.shape, p.tobytes()) if isinstance(p, np.ndarray) else p for p in parts))


def _frozen(array: np.ndarray | None) -> np.ndarray | None:
    """The stored array, read-only: a repeat hands out the same object."""
    if array is not None:
        array.flags.writeable = False
    return array


class FixedSetLPs:
    """The fixed-set static and kinematic LPs of one ``model`` and its contact ``points``.

    A stored solve that stopped after p iterations under a cap c stands for a call with cap c'
    when c' = c, or when p < c and p < c' (it stopped on its own, and a cap above p is never
    reached: the solvers run the same iterations).  Otherwise the LP is solved again and stored.
    The caller counts the stored solve's iterations as its own, so that a start's work budget
    runs out at the same point whether an LP came from the store or not.  ``hits`` counts the
    repeats served.
    """

    def __init__(self, model: Model, points: ContactPoints) -> None:
        self.model = model
        self.points = points
        self.hits = 0
        self._store: dict[tuple[Any, ...], _Solved] = {}

    def serves(self, model: Model, points: ContactPoints) -> bool:
        """Whether this store belongs to ``model`` and ``points`` (the same objects)."""
        return model is self.model and points is self.points

    def _stored(self, key: tuple[Any, ...], cap: int) -> _Solved | None:
        solved = self._store.get(key)
        if solved is None:
            return None
        if solved.cap == cap or (solved.iterations < solved.cap and solved.iterations < cap):
            self.hits += 1
            return solved
        return None

    def _once(self, key: tuple[Any, ...], cap: int, solve: Callable[[], Any]) -> Any:
        """The stored result of ``key`` that stands for a call with ``cap``, else ``solve()``'s (a
        :class:`StaticLP`, or a kinematic LP's (mechanism, iterations)), stored with its arrays
        read-only."""
        solved = self._stored(key, cap)
        if solved is None:
            result = solve()
            arrays: tuple[np.ndarray | None, ...]
            if isinstance(result, StaticLP):
                arrays, iterations = (result.normal, result.shear, result.bounded), result.pivots
            else:
                arrays, iterations = (result[0],), result[1]
            for array in arrays:
                _frozen(array)
            solved = _Solved(result, iterations, cap)
            self._store[key] = solved
        return solved.result

    def static(
        self,
        open_points: np.ndarray,
        slip_sign: np.ndarray,
        *,
        max_pivots: int,
        method: LPMethod,
        bounded_signs: np.ndarray | None = None,
    ) -> StaticLP:
        """:func:`~alma.nonassociative.static_lps.static_lp` of this model, solved once per set and method."""
        extra = {} if bounded_signs is None else {"bounded_signs": bounded_signs}
        return self._once(
            _key("static", method.value, open_points, slip_sign, bounded_signs),
            max_pivots,
            lambda: static_lp(
                self.model, self.points, open_points, slip_sign, max_pivots=max_pivots, method=method, **extra
            ),
        )

    def interior(self, open_points: np.ndarray, slip_sign: np.ndarray, *, max_iter: int) -> StaticLP:
        """:func:`~alma.nonassociative.static_lps.fixed_set_static_interior` of this model, solved once per set."""
        return self._once(
            _key("interior", open_points, slip_sign),
            max_iter,
            lambda: fixed_set_static_interior(self.model, self.points, open_points, slip_sign, max_iter=max_iter),
        )

    def kinematic(
        self,
        open_points: np.ndarray,
        slip_sign: np.ndarray,
        *,
        max_pivots: int,
        free_slip: np.ndarray | None = None,
        bounded_allowed: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray | None, int]:
        """:func:`~alma.nonassociative.static_lps.kinematic_lp` of this model, solved once per set."""
        allowed = (None, None) if bounded_allowed is None else bounded_allowed
        return self._once(
            _key("kinematic", open_points, slip_sign, free_slip, *allowed),
            max_pivots,
            lambda: kinematic_lp(
                self.model,
                self.points,
                open_points,
                slip_sign,
                max_pivots=max_pivots,
                free_slip=free_slip,
                bounded_allowed=bounded_allowed,
            ),
        )
