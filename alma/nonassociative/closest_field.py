"""Among the static fields that carry a given α, the one closest to N̄ (Eqs. 3 and 5): the
projection step of :func:`alma.nonassociative.gilbert.projected_gilbert`."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from alma.backends.clarabel_backend import UpdatableQP, solve_conic_lp
from alma.backends.termination import SolverResult
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model


class ClosestField:
    """Among the static fields that carry a given α, the one closest to N̄ (Eqs. 3 and 5).

        min ½ ‖N − N̄‖²   s.t.  normal N + tangent T + G τ + f_0 + α f_L = 0,   N ≥ 0,   |T| ≤ cap,
                          0 ≤ τ ≤ capacity   (the bounded forces, when the model has them)

    The capped LP's optimal face is large on big panels, and a simplex vertex jumps across it
    from one Gilbert iteration to the next; the projection moves N̄ as little as the face
    allows, so the iteration settles.  Given the LP's ``face`` (its mechanism's open points and
    slip signs), the QP is written on that face alone: every optimal field is complementary to
    the LP's mechanism, so N = 0 where it opens and T = −sign(γ) cap where it slips (T = 0 where
    the cap is 0) are fixed and only the other forces are unknowns; without these fixings the
    fields at α (the LP's optimum less a hair) form a sliver around the face, with slabs of no
    width where caps are 0, where Clarabel needs 50–170 iterations instead of 31–60 on average.  When that
    QP does not solve, or without a face, one Clarabel QP over every force, kept between calls
    (only q (N̄) and b (α, caps) change), decides.
    """

    def __init__(self, model: Model, points: ContactPoints, *, tolerance: float = 1e-10, max_iter: int = 200) -> None:
        self.model = model
        self.points = points
        self._normal, self._tangent = points.normal.tocsc(), points.tangent.tocsc()
        self._P = points.count
        self._tolerance, self._max_iter = float(tolerance), int(max_iter)
        self._full: UpdatableQP | None = None
        self._n_eq = model.dead.shape[0]

    def _full_qp(self) -> UpdatableQP:
        """The QP over every force, built on first use (Clarabel's default iterative refinement;
        presolve off: the data are updated)."""
        if self._full is None:
            every = np.ones(self._P, dtype=bool)
            quadratic, A = self._matrices(every, every)
            self._full = UpdatableQP(
                quadratic,
                np.zeros(A.shape[1]),
                A,
                self._rhs(0.0, np.zeros(self._P), every, every, np.zeros(self._P)),
                self._n_eq,
                A.shape[0] - self._n_eq,
                tolerance=self._tolerance,
                max_iter=self._max_iter,
                refine=True,
            )
        return self._full

    def _matrices(self, keep: np.ndarray, free: np.ndarray) -> tuple[sp.csc_matrix, sp.csc_matrix]:
        """(quadratic, A) of the QP over x = (N[keep], T[free], τ): A's rows are the equilibrium,
        −N ≤ 0, T ≤ cap, −T ≤ cap, and for τ −τ ≤ 0 and τ ≤ capacity."""
        k = self.model.n_bounded
        n, t = int(keep.sum()), int(free.sum())
        columns = [self._normal[:, keep], self._tangent[:, free], *([self.model.bounded] if k else [])]
        eye_n, eye_t, eye_k = (sp.identity(m, format="csc") for m in (n, t, k))
        rows = [
            sp.hstack(columns),
            sp.hstack([-eye_n, sp.csc_matrix((n, t + k))]),
            sp.hstack([sp.csc_matrix((t, n)), eye_t, sp.csc_matrix((t, k))]),
            sp.hstack([sp.csc_matrix((t, n)), -eye_t, sp.csc_matrix((t, k))]),
        ]
        if k:
            rows += [sp.hstack([sp.csc_matrix((k, n + t)), -eye_k]), sp.hstack([sp.csc_matrix((k, n + t)), eye_k])]
        quadratic = sp.block_diag([eye_n, sp.csc_matrix((t + k, t + k))], format="csc")
        return quadratic, sp.vstack(rows).tocsc()

    def _rhs(self, alpha: float, cap: np.ndarray, keep: np.ndarray, free: np.ndarray, shear: np.ndarray) -> np.ndarray:
        """b of :meth:`_matrices`' rows, the shear fixed at ``shear`` where not ``free``."""
        k, fixed = self.model.n_bounded, ~free
        equilibrium = -self.model.dead - alpha * self.model.live
        if fixed.any():
            equilibrium = equilibrium - self._tangent[:, fixed] @ shear[fixed]
        bounds = [np.zeros(k), self.model.capacity] if k else []
        return np.concatenate([equilibrium, np.zeros(int(keep.sum())), cap[free], cap[free], *bounds])

    def solve(
        self, alpha: float, cap: np.ndarray, target: np.ndarray, face: tuple[np.ndarray, np.ndarray] | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(N, T, τ) of the closest field (τ empty without bounded forces), or None when the QP
        does not solve.  ``face``: the capped LP's mechanism's (open points, slip signs)."""
        if face is not None:
            nearest = self._on_face(alpha, cap, target, *face)
            if nearest is not None:
                return nearest
        every = np.ones(self._P, dtype=bool)
        b = self._rhs(alpha, cap, every, every, np.zeros(self._P))
        q = np.concatenate([-target, np.zeros(self._P + self.model.n_bounded)])
        return self._unpacked(self._full_qp().solve(q, b), self._P)

    def _unpacked(self, solution: SolverResult, n_normal: int) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(N, T, τ) of a solved QP whose x is (N, T, τ) with ``n_normal`` normal forces."""
        if not solution.termination.solved:
            return None
        x, k = solution.x, self.model.n_bounded
        normal, rest = np.maximum(x[:n_normal], 0.0), x[n_normal:]
        tau = np.clip(rest[rest.size - k :], 0.0, self.model.capacity) if k else np.zeros(0)
        return normal, rest[: rest.size - k].copy(), tau

    def _on_face(
        self, alpha: float, cap: np.ndarray, target: np.ndarray, open_points: np.ndarray, slip_sign: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The closest field with N = 0 where the face opens and T = −sign(γ) cap where it slips
        (0 where cap = 0): a QP over the other N and T (and τ), built anew (the unknowns change)."""
        keep, free = ~open_points, (slip_sign == 0) & (cap > 0)
        shear = np.where(cap > 0, -slip_sign * cap, 0.0)
        quadratic, A = self._matrices(keep, free)
        n = int(keep.sum())
        solution = solve_conic_lp(
            np.concatenate([-target[keep], np.zeros(A.shape[1] - n)]),
            A,
            self._rhs(alpha, cap, keep, free, shear),
            self._n_eq,
            A.shape[0] - self._n_eq,
            tolerance=self._tolerance,
            max_iter=self._max_iter,
            refine=True,
            quadratic=quadratic,
            form="static",
        )
        unpacked = self._unpacked(solution, n)
        if unpacked is None:
            return None
        normal = np.zeros(self._P)
        normal[keep], shear[free] = unpacked[0], unpacked[1]
        return normal, shear, unpacked[2]
