"""A certificate that Eq. 10 has no statically admissible field at any load multiplier.

By Farkas' lemma ``H μ + f_0 + α f_L = 0, μ ≥ 0`` has no solution (μ, α) exactly when a
velocity field u exists with::

    Hᵀu ≥ 0,   f_Lᵀu = 0,   f_0ᵀu > 0

(every contact point opens or slides on its cone, Eq. 6; the live load does no work; the
weights do positive work): a *falling mode*, a ray of Eq. 10's kinematic form.  It is found as
a vertex of ``max f_0ᵀu s.t. f_Lᵀu = 0, Hᵀu ≥ 0, −1 ≤ u ≤ 1`` by HiGHS's interior point with
crossover (:mod:`alma.backends.highs_backend`).  With the vertex's round-off, Hᵀu ≥ −v and
|f_Lᵀu| ≤ v, an equilibrium would need forces with ‖μ‖₁ + |α| ≥ f_0ᵀu / v (in the model's force
unit, the mean weight of a free block): the mode proves that no field exists below
``margin`` × n_free of them.  Dimensionless, as :mod:`alma.mechanics.model`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from alma.backends.highs_backend import solve_conic_form
from alma.floats import dot
from alma.mechanics.model import Model
from alma.status import Status


@dataclass(frozen=True)
class FallingRay:
    """A falling mode of a model: its velocities (u, v, θ per free block, |u| ≤ 1), the work of
    the weights on it and the largest breach of its constraints (both dimensionless)."""

    u: np.ndarray
    dead_work: float
    breach: float

    def proves(self, n_free: int, margin: float) -> bool:
        """Whether no field with forces below ``margin`` × ``n_free`` block weights exists."""
        return self.dead_work > 0 and self.dead_work >= margin * max(1, n_free) * self.breach


def falling_ray(model: Model) -> FallingRay | None:
    """The falling mode of ``model`` (module docstring), or None when HiGHS finds none with
    positive work of the weights."""
    H = model.equilibrium
    n = H.shape[0]
    eye = sp.identity(n, format="csr")
    A = sp.vstack([sp.csr_matrix(model.live), -H.T, eye, -eye]).tocsc()
    b = np.concatenate([[0.0], np.zeros(H.shape[1]), np.ones(2 * n)])
    # HiGHS's interior point with crossover (a vertex): half its dual simplex's time on the panels.
    sol = solve_conic_form(-model.dead, A, b, 1, solver="ipm")
    if sol.status != Status.OPTIMAL:
        return None
    u = sol.x
    work = dot(model.dead, u)
    if not work > 0:
        return None
    breach = max(-float((H.T @ u).min(initial=0.0)), abs(dot(model.live, u)))
    return FallingRay(u, work, breach)
