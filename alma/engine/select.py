"""Which engine solves Eq. 10, and the engine's answer in the form alma's certificate takes.

``engine="clarabel"`` is alma's Clarabel path; ``"ipm"`` this package's interior point;
``"auto"`` the interior point from :attr:`alma.settings.AssociativeSettings.auto_min_blocks`
free blocks on when a fast
factorisation backend (see :mod:`alma.engine.cholesky`) is importable, Clarabel otherwise.
The choice depends on the problem's size and the installed libraries only, never on the clock.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .cholesky import available_backends
from .ipm import solve_eq10
from .normal import NormalPattern
from .types import IPMResult, IPMSettings

#: The engines of Eq. 10 (as :data:`alma.settings.ENGINES`).
ENGINES = ("clarabel", "ipm", "auto")

#: Backends for which ``auto`` prefers the interior point (qdldl alone is not faster than
#: Clarabel's own QDLDL path by enough to switch: docs/engine.md).
FAST_BACKENDS = ("pardiso", "feral")

_warned = False


@dataclass(frozen=True)
class EngineAnswer:
    """The interior point's pair as alma's Clarabel path would pass it to the certificate."""

    status: str  # the interior point's own word (IPMResult.status): "optimal" when it met its tolerances
    x: np.ndarray  # mechanism u
    duals: np.ndarray  # (−α, μ): the dual of (f_Lᵀu = N, Hᵀu ≥ 0) as Clarabel orders it
    iterations: int
    label: str  # e.g. "alma-ipm/pardiso", for messages
    result: IPMResult


def choose(engine: str, n_free: int, bounded: bool = False, *, min_blocks: int, min_blocks_bounded: int) -> str:
    """``clarabel`` or ``ipm`` for a problem with ``n_free`` free blocks (``bounded``: with
    cohesion or ties); ``auto`` takes the interior point from ``min_blocks`` free blocks on
    (``min_blocks_bounded`` when bounded): :attr:`alma.settings.AssociativeSettings.auto_min_blocks`."""
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    if engine != "auto":
        return engine
    if n_free < (min_blocks_bounded if bounded else min_blocks):
        return "clarabel"
    if not any(b in FAST_BACKENDS for b in available_backends()):
        _warn_once(
            "alma: no fast sparse factorisation (pypardiso with MKL, or feral-solver) is installed; "
            "the associative LP is solved by Clarabel"
        )
        return "clarabel"
    return "ipm"


def _warn_once(message: str) -> None:
    global _warned
    if not _warned:
        warnings.warn(message, RuntimeWarning, stacklevel=3)
        _warned = True


def solve_with_engine(
    H: sp.csc_matrix,
    dead: np.ndarray,
    live: np.ndarray,
    norm_value: float,
    settings: IPMSettings | None = None,
    n_primary: int | None = None,
    pattern: NormalPattern | None = None,
) -> EngineAnswer:
    """Run the interior point on Eq. 10; ``status`` is "optimal" only when it converged.

    ``n_primary``: rows of u in H, the rest being bounded forces' dissipation variables;
    ``pattern``: the normal-equations pattern of this geometry from an earlier solve, if any
    (``result.pattern`` is the one used).
    """
    result = solve_eq10(H, dead, live, norm_value, settings, n_primary=n_primary, pattern=pattern)
    duals = np.concatenate([[-result.alpha], result.mu])
    return EngineAnswer(
        status=result.status,
        x=result.u,
        duals=duals,
        iterations=result.iterations,
        label=f"alma-ipm/{result.backend}",
        result=result,
    )
