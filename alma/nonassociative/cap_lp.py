"""The static LP of the Gilbert iteration as persistent HiGHS models, re-solved warm.

    max α   s.t.  normal N + tangent T + f_0 + α f_L = 0   (Eq. 3)
                  N ≥ 0,   T − s N ≤ c,   −T − s N ≤ c       (Eq. 5 with slope s, cap c)

and, with cohesion and ties, their forces G τ in the equilibrium with 0 ≤ τ ≤ capacity: the
fictitious cohesion c = (f − s) N̄ of Gilbert's iteration adds to the real one.

Between Gilbert iterations only the caps c = (f − s) N̄ change (row bounds; at
s = 0, where |T| ≤ c is a pair of column bounds, the model has no yield rows) and,
during the first steps, the slopes s (one coefficient per row).  HiGHS keeps
its basis, so each re-solve is a short dual-simplex run from the previous
vertex instead of a cold solve: on a 444-block panel 0.03–0.3 s per iteration
against 1–2 s cold.  The mechanism u is read from the equilibrium rows' duals.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from alma.backends.clarabel_backend import UpdatableQP
from alma.backends.highs_backend import INF, WarmLP, lp_model
from alma.backends.termination import SolverResult, Termination
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.static_lps import StaticLP, failed, with_bounded_columns

#: Feasibility tolerances of the warm-started HiGHS model (absolute, dimensionless units).
DUAL_TOLERANCE = 1e-10


class CapLP:
    """Persistent HiGHS models of the capped static LP (see module docstring).

    Two models, each built on first use and then re-solved warm: with a slope (the first
    Gilbert steps) the yield conditions are rows; at slope zero they are the column bounds
    −c ≤ T ≤ c, and the model keeps only the equilibrium rows (3 per block instead of 3 per
    block plus 2 per contact point), which the dual simplex re-solves in about half the time.
    """

    def __init__(self, model: Model, points: ContactPoints, *, max_pivots: int = 200_000) -> None:
        self.model = model
        self.points = points
        self._n = model.dead.shape[0]
        self._max_pivots = int(max_pivots)
        self._slope = np.zeros(points.count)
        self._rows: WarmLP | None = None
        self._bounded: WarmLP | None = None
        P = points.count
        self._cap_rows = np.arange(self._n, self._n + 2 * P, dtype=np.int32)
        self._shear_cols = np.arange(1 + P, 1 + 2 * P, dtype=np.int32)
        # Slopes enter the yield rows as −s in the N columns (x = (α, N, T)): rows n+p and n+P+p, column 1+p.
        self._slope_rows = (self._n + np.arange(P), self._n + P + np.arange(P))

    def _new_highs(self, with_yield_rows: bool) -> WarmLP:
        P, q = self.points.count, self.model.n_bounded
        A_eq, b_eq, A_ub = self.points.static_constraints(self.model, self._slope)
        if q:
            A_eq, A_ub = with_bounded_columns(self.model, A_eq, A_ub)
        width = 1 + 2 * P + q
        cost = np.zeros(width)
        cost[0] = -1.0
        col_lower = np.concatenate([[-INF], np.zeros(P), np.full(P, -INF), np.zeros(q)])
        col_upper = np.concatenate([np.full(1 + 2 * P, INF), self.model.capacity])
        if with_yield_rows:
            lp = lp_model(
                cost,
                col_lower,
                col_upper,
                sp.vstack([A_eq, A_ub]),
                np.concatenate([b_eq, np.full(2 * P, -INF)]),
                np.concatenate([b_eq, np.zeros(2 * P)]),
            )
        else:
            lp = lp_model(cost, col_lower, col_upper, A_eq, b_eq, b_eq)
        # The mechanism is read from the duals: HiGHS's default dual feasibility (1e-7, absolute)
        # leaves interpenetrations of ~1e-5 of the largest velocity on large panels, more than
        # the verification accepts.
        h = WarmLP(lp, dual_feasibility_tolerance=DUAL_TOLERANCE, primal_feasibility_tolerance=DUAL_TOLERANCE)
        # The cold first solve: interior point with crossover (a basis for the warm re-solves) is
        # about twice as fast as simplex here; every later solve is dual simplex from that basis.
        h.set_option("solver", "ipm")
        return h

    def _model_for(self, slope: np.ndarray, cap: np.ndarray) -> WarmLP:
        """The persistent model for this slope (built on first use), with the new caps set."""
        P = self.points.count
        if not np.any(slope):
            if self._bounded is None:
                self._bounded = self._new_highs(with_yield_rows=False)
            self._bounded.change_col_bounds(self._shear_cols, -cap, cap)
            return self._bounded
        if self._rows is None:
            self._rows = self._new_highs(with_yield_rows=True)
        h = self._rows
        for p in np.flatnonzero(slope != self._slope):  # only during the first (slope > 0) steps
            h.change_coeff(self._slope_rows[0][p], 1 + p, -slope[p])
            h.change_coeff(self._slope_rows[1][p], 1 + p, -slope[p])
        self._slope = np.array(slope, dtype=float, copy=True)
        h.change_row_bounds(self._cap_rows, np.full(2 * P, -INF), np.concatenate([cap, cap]))
        return h

    @staticmethod
    def _run(h: WarmLP, max_pivots: int) -> SolverResult:
        """One solve within ``max_pivots`` simplex (and interior-point) iterations; every later
        solve is dual simplex, warm."""
        return h.run(max_pivots, then="simplex")

    def solve(self, slope: np.ndarray, cap: np.ndarray, max_pivots: int | None = None) -> StaticLP:
        """Re-solve with new slopes and caps within ``max_pivots`` iterations (default: the model's)."""
        P = self.points.count
        limit = self._max_pivots if max_pivots is None else max(1, int(max_pivots))
        h = self._model_for(slope, np.asarray(cap, dtype=float))
        sol = self._run(h, limit)
        pivots = sol.iterations
        if sol.termination is Termination.NUMERICAL:
            # The warm simplex can stop without a verdict (numerical trouble at the 1e-10
            # tolerances); a cold interior-point solve with crossover usually settles it.
            h.clear_solver()
            h.set_option("solver", "ipm")
            sol = self._run(h, limit)
            pivots += sol.iterations
        if sol.termination is Termination.UNBOUNDED:
            return failed(Termination.UNBOUNDED, P, pivots, np.inf)
        if sol.termination in (Termination.INFEASIBLE, Termination.INFEASIBLE_OR_UNBOUNDED):
            return failed(Termination.INFEASIBLE, P, pivots)
        if sol.termination is not Termination.OPTIMAL:
            return failed(Termination.ERROR, P, pivots)
        x = sol.x
        y = sol.duals[: self._n]  # ∂(−α)/∂b of the equilibrium rows: u with f_Lᵀu = 1
        work = float(self.model.live @ y)
        mechanism = y * (self.model.n_free / work) if work > 0 else None
        if self.model.n_bounded:
            return StaticLP(
                Termination.OPTIMAL,
                float(x[0]),
                x[1 : 1 + P].copy(),
                x[1 + P : 1 + 2 * P].copy(),
                mechanism,
                pivots,
                np.clip(x[1 + 2 * P :], 0.0, self.model.capacity),
            )
        return StaticLP(Termination.OPTIMAL, float(x[0]), x[1 : 1 + P].copy(), x[1 + P :].copy(), mechanism, pivots)


class ClosestField:
    """Among the static fields that carry a given α, the one closest to N̄ (Eqs. 3 and 5).

        min ½ ‖N − N̄‖²   s.t.  normal N + tangent T + G τ + f_0 + α f_L = 0,   N ≥ 0,   |T| ≤ cap,
                          0 ≤ τ ≤ capacity   (the bounded forces, when the model has them)

    The capped LP's optimal face is large on big panels, and a simplex vertex jumps across it
    from one Gilbert iteration to the next; the projection moves N̄ as little as the face
    allows, so the iteration settles.  One Clarabel QP, kept between calls: only q (N̄) and b
    (α, caps) change.
    """

    def __init__(self, model: Model, points: ContactPoints, *, tolerance: float = 1e-10, max_iter: int = 200) -> None:
        P, k = points.count, model.n_bounded
        self.model = model
        self._P = P
        equilibrium = sp.hstack([points.normal, points.tangent]).tocsc()
        eye, zero = sp.identity(P, format="csc"), sp.csc_matrix((P, P))
        rows = [equilibrium, sp.hstack([-eye, zero]), sp.hstack([zero, eye]), sp.hstack([zero, -eye])]
        if k:  # τ beside (N, T): G in the equilibrium, then −τ ≤ 0 and τ ≤ capacity
            rows = [
                sp.hstack([row, model.bounded if i == 0 else sp.csc_matrix((row.shape[0], k))])
                for i, row in enumerate(rows)
            ]
            eye_k = sp.identity(k, format="csc")
            rows += [sp.hstack([sp.csc_matrix((k, 2 * P)), -eye_k]), sp.hstack([sp.csc_matrix((k, 2 * P)), eye_k])]
        A = sp.vstack(rows).tocsc()
        quadratic = sp.block_diag([sp.identity(P), sp.csc_matrix((P + k, P + k))], format="csc")
        self._n_eq = equilibrium.shape[0]
        # Clarabel's default iterative refinement; presolve off (the data are updated).
        self._solver = UpdatableQP(
            quadratic,
            np.zeros(2 * P + k),
            A,
            self._rhs(0.0, np.zeros(P)),
            self._n_eq,
            3 * P + 2 * k,
            tolerance=tolerance,
            max_iter=max_iter,
            refine=True,
        )

    def _rhs(self, alpha: float, cap: np.ndarray) -> np.ndarray:
        k = self.model.n_bounded
        bounds = [np.zeros(k), self.model.capacity] if k else []
        return np.concatenate([-self.model.dead - alpha * self.model.live, np.zeros(self._P), cap, cap, *bounds])

    def solve(
        self, alpha: float, cap: np.ndarray, target: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(N, T, τ) of the closest field (τ empty without bounded forces), or None when the QP
        does not solve."""
        k = self.model.n_bounded
        solution = self._solver.solve(np.concatenate([-target, np.zeros(self._P + k)]), self._rhs(alpha, cap))
        if not solution.termination.solved:
            return None
        x = solution.x
        if k:
            return (
                np.maximum(x[: self._P], 0.0),
                x[self._P : 2 * self._P].copy(),
                np.clip(x[2 * self._P :], 0.0, self.model.capacity),
            )
        return np.maximum(x[: self._P], 0.0), x[self._P :].copy(), np.zeros(0)
