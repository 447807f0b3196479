"""Contact-point form of the model: normal and tangential force columns per point.

Every joint has two contact points (its end points).  At point p the force on
block b is ``N_p n + T_p t`` (and its opposite on block a).  The columns of
``normal`` and ``tangent`` are the corresponding equilibrium contributions, so
that Eq. 3 reads ``normal N + tangent T + f_0 + α f_L = 0``, and their
transposes give the relative velocities at the points:
``opening = normalᵀ u`` (ξ of Eq. 2, ≥ 0: no interpenetration) and
``slip = tangentᵀ u`` (γ of Eq. 2).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

if TYPE_CHECKING:
    from alma.mechanics.model import Model


@dataclass(frozen=True)
class ContactPoints:
    normal: sp.csc_matrix  # (3 n_free, P)
    tangent: sp.csc_matrix  # (3 n_free, P)
    friction: np.ndarray  # (P,)
    joint: np.ndarray  # (P,) joint index of each point

    @property
    def count(self) -> int:
        return int(self.friction.shape[0])

    def relative_velocities(self, u: np.ndarray) -> np.ndarray:
        """(m, 2, 2) array [joint, end point, (opening ξ, slip γ)] of a mechanism u (Eq. 2)."""
        return np.stack([self.normal.T @ u, self.tangent.T @ u], axis=1).reshape(-1, 2, 2)

    def static_constraints(self, model: Model, slope: np.ndarray) -> tuple[sp.csr_matrix, np.ndarray, sp.csr_matrix]:
        """Rows over x = (α, N, T): equilibrium A_eq x = b_eq (Eq. 3) and the yield rows
        A_ub x ≤ cap of |T| ≤ slope N + cap (first T − sN, then −T − sN; Eq. 5 with cap = 0)."""
        P = self.count
        A_eq = sp.hstack([sp.csc_matrix(model.live[:, None]), self.normal, self.tangent]).tocsr()
        eye = sp.identity(P, format="csr")
        zero = sp.csr_matrix((P, 1))
        A_ub = sp.vstack([sp.hstack([zero, -sp.diags(slope), eye]), sp.hstack([zero, -sp.diags(slope), -eye])]).tocsr()
        return A_eq, -model.dead, A_ub

    @classmethod
    def from_model(cls, model: Model) -> ContactPoints:
        """The contact points of ``model``: its :attr:`~alma.mechanics.model.Model.contact_points`,
        built once per model by :meth:`build`."""
        return model.contact_points

    @classmethod
    def build(cls, model: Model) -> ContactPoints:
        """The contact points of ``model`` from its generator columns."""
        # Generator columns are ordered (joint, point, ±); the "+" columns carry n and +t.
        return cls(
            normal=model.normal_part[:, 0::2].tocsc(),
            tangent=model.tangent_part[:, 0::2].tocsc(),
            friction=np.repeat(model.friction, 2),
            joint=np.repeat(np.arange(model.n_joints), 2),
        )
