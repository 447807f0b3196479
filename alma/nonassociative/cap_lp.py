"""The static LP of the Gilbert iteration as persistent HiGHS models, re-solved warm.

    max α   s.t.  normal N + tangent T + f_0 + α f_L = 0   (Eq. 3)
                  N ≥ 0,   T − s N ≤ c,   −T − s N ≤ c       (Eq. 5 with slope s, cap c)

and, with cohesion and ties, their forces G τ in the equilibrium with 0 ≤ τ ≤ capacity: the
fictitious cohesion c = (f − s) N̄ of Gilbert's iteration adds to the real one.

Between Gilbert iterations only the caps c = (f − s) N̄ change and, during the first steps, the
slopes s.  The models keep the equilibrium rows only, every yield condition a column bound
(except the sloped model's ``yield_rows`` form):
at s = 0 |T| ≤ c bounds T itself; at s > 0 the force is written on the generators of its
yield domain, (N, T) = λ⁺ (1, s) + λ⁻ (1, −s) + (0, κ) with λ± ≥ 0 and |κ| ≤ c (every
(N, T) with N ≥ 0 and |T| ≤ s N + c is one: κ = clip(T, ±c)), so a new slope changes the λ±
columns' coefficients and a new cap κ's bounds.  HiGHS keeps its basis, so each re-solve is a
dual-simplex run from the previous vertex instead of a cold solve, and the cold first solve is
a third of the time it takes with the yield conditions as 2 rows per contact point.  The
mechanism u is read from the equilibrium rows' duals; a third model, the slope-zero one at α's
cost Σ|f_L|, cleans a vertex's mechanism (:meth:`CapLP.clean_mechanism`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from alma.backends.highs_backend import INF, lp_model
from alma.backends.highs_warm import WarmLP
from alma.backends.termination import SolverResult, Termination
from alma.floats import dot
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.static_lps import StaticLP, failed

#: Feasibility tolerances of the warm-started HiGHS model (absolute, dimensionless units).
DUAL_TOLERANCE = 1e-10


def live_total(model: Model) -> float:
    """The live load's total force Σ|f_L| over the blocks' force components (not their moments).

    α's cost in :meth:`CapLP.clean_mechanism`.  The capped LP's duals y are the mechanism up to
    scale, u = y n_free / (f_Lᵀy), and f_Lᵀy is α's cost, so HiGHS's absolute dual feasibility δ
    leaves openings down to −δ n_free / cost; a mechanism normalised so, moving its blocks by about
    n_free / Σ|f_L|, then interpenetrates by δ Σ|f_L| / cost of its own velocities: δ at this cost,
    whatever the scene's size and units (with cost 1, 1.25e-7 on a 1,560-block panel: over the
    verification's 1e-7).
    """
    forces = np.abs(model.live.reshape(-1, 3)[:, :2]).ravel()
    return max(float(forces.sum()), 1e-300)


def _caps(cap: np.ndarray) -> np.ndarray:
    """Caps as the bounds −c ≤ T ≤ c take them: never below zero.  A cap f N̄ from a normal force
    that HiGHS returned a round-off below zero (−1e-15 × its scale) would give T the inconsistent
    bounds [|c|, −|c|]."""
    return np.maximum(np.asarray(cap, dtype=float), 0.0)


class CapLP:
    """Persistent HiGHS models of the capped static LP (see module docstring).

    Three models, each built on first use and then re-solved warm: on the yield domain's
    generators (λ⁺, λ⁻, κ) while the slope is positive (the first Gilbert steps), and on
    (N, T) with −c ≤ T ≤ c at slope zero, which has a column per point fewer.  ``yield_rows``:
    the sloped model keeps the yield conditions as rows instead (the same LP; other vertices).
    :meth:`clean_mechanism` re-optimises the last slope-zero vertex at α's cost :func:`live_total`
    on a third, for a mechanism feasible to ``DUAL_TOLERANCE`` of its own velocities.
    """

    def __init__(
        self,
        model: Model,
        points: ContactPoints,
        *,
        max_pivots: int = 200_000,
        yield_rows: bool = False,
        alpha_floor: float = -INF,
    ) -> None:
        self.model = model
        self.alpha_floor = float(alpha_floor)
        self.yield_rows = yield_rows
        self.points = points
        self._n = model.dead.shape[0]
        self._max_pivots = int(max_pivots)
        self._slope = np.zeros(points.count)
        self._sloped: WarmLP | None = None
        self._bounded: WarmLP | None = None
        self._clean: WarmLP | None = None
        P = points.count
        self._shear_cols = np.arange(1 + P, 1 + 2 * P, dtype=np.int32)
        self._kappa_cols = np.arange(1 + 2 * P, 1 + 3 * P, dtype=np.int32)
        # The entries of the λ± columns: normal ± s · tangent on the union of both patterns.
        pattern = (abs(points.normal) + abs(points.tangent)).tocoo()
        self._entry_rows, self._entry_points = pattern.row, pattern.col
        self._entry_normal = np.asarray(points.normal.tocsr()[pattern.row, pattern.col]).ravel()
        self._entry_tangent = np.asarray(points.tangent.tocsr()[pattern.row, pattern.col]).ravel()

    def _warm(
        self,
        cost: np.ndarray,
        lower: np.ndarray,
        upper: np.ndarray,
        A_eq: sp.spmatrix,
        A_ub: sp.spmatrix | None = None,
        alpha_cost: float = 1.0,
    ) -> WarmLP:
        """A persistent HiGHS model of ``max α`` on the equilibrium rows (and ``A_ub x ≤ 0``),
        the bounded forces' columns appended, cold-solved first by interior point with crossover
        (about twice as fast as simplex here; a basis for the warm re-solves), every later solve
        dual simplex (a caller may set another solver before the first run, as
        :meth:`clean_mechanism` does).  α's cost (``cost[0]``) is set here: −``alpha_cost``."""
        cost = np.concatenate([[-alpha_cost], cost[1:]])
        b_eq = -self.model.dead
        m = 0 if A_ub is None else A_ub.shape[0]
        A = A_eq if A_ub is None else sp.vstack([A_eq, A_ub])
        if self.model.n_bounded:
            A = sp.hstack([A, sp.vstack([self.model.bounded, sp.csr_matrix((m, self.model.n_bounded))])])
            zeros = np.zeros(self.model.n_bounded)
            cost, lower = np.concatenate([cost, zeros]), np.concatenate([lower, zeros])
            upper = np.concatenate([upper, self.model.capacity])
        row_lower, row_upper = np.concatenate([b_eq, np.full(m, -INF)]), np.concatenate([b_eq, np.zeros(m)])
        # The mechanism is read from the duals: HiGHS's default dual feasibility (1e-7, absolute)
        # leaves interpenetrations of ~1e-5 of the largest velocity on large panels, more than
        # the verification accepts.
        # The dual simplex stops once its objective (−α × α's cost, of a dual feasible point) proves α below
        # ``alpha_floor``, where the search gives its iterate up: on a displaced linkage such
        # runs can take seconds a pivot (numerically singular bases).
        h = WarmLP(
            lp_model(cost, lower, upper, A, row_lower, row_upper),
            dual_feasibility_tolerance=DUAL_TOLERANCE,
            primal_feasibility_tolerance=DUAL_TOLERANCE,
            objective_bound=-alpha_cost * self.alpha_floor if np.isfinite(self.alpha_floor) else INF,
        )
        h.set_option("solver", "ipm")
        return h

    def _new_bounded(self, alpha_cost: float = 1.0) -> WarmLP:
        """x = (α, N, T[, τ]): N ≥ 0, T free until the caps are set."""
        P = self.points.count
        live = sp.csc_matrix(self.model.live[:, None])
        cost = np.zeros(1 + 2 * P)
        lower = np.concatenate([[-INF], np.zeros(P), np.full(P, -INF)])
        A_eq = sp.hstack([live, self.points.normal, self.points.tangent])
        return self._warm(cost, lower, np.full(1 + 2 * P, INF), A_eq, alpha_cost=alpha_cost)

    def _generator_columns(self, slope: np.ndarray, sign: float) -> sp.csc_matrix:
        """normal + sign · s · tangent on the fixed pattern (explicit zeros kept)."""
        values = self._entry_normal + sign * slope[self._entry_points] * self._entry_tangent
        shape = (self._n, self.points.count)
        return sp.csc_matrix((values, (self._entry_rows, self._entry_points)), shape=shape)

    def _new_generators(self, slope: np.ndarray) -> WarmLP:
        """x = (α, λ⁺, λ⁻, κ[, τ]): λ± ≥ 0, κ free until the caps are set."""
        P = self.points.count
        live = sp.csc_matrix(self.model.live[:, None])
        A_eq = sp.hstack(
            [live, self._generator_columns(slope, 1.0), self._generator_columns(slope, -1.0), self.points.tangent]
        )
        cost = np.zeros(1 + 3 * P)
        lower = np.concatenate([[-INF], np.zeros(2 * P), np.full(P, -INF)])
        return self._warm(cost, lower, np.full(1 + 3 * P, INF), A_eq)

    def _model_for(self, slope: np.ndarray, cap: np.ndarray) -> WarmLP:
        """The persistent model for this slope (built on first use), with the new caps set."""
        if not np.any(slope):
            if self._bounded is None:
                self._bounded = self._new_bounded()
            self._bounded.change_col_bounds(self._shear_cols, -cap, cap)
            return self._bounded
        if self.yield_rows:
            return self._rows_for(slope, cap)
        if self._sloped is None:
            self._sloped = self._new_generators(slope)
        else:
            self._set_slope(self._sloped, slope)
        self._slope = np.array(slope, dtype=float, copy=True)
        self._sloped.change_col_bounds(self._kappa_cols, -cap, cap)
        return self._sloped

    def _rows_for(self, slope: np.ndarray, cap: np.ndarray) -> WarmLP:
        """The sloped model with the yield conditions as rows, x = (α, N, T[, τ]): T − sN ≤ c and
        −T − sN ≤ c (``yield_rows``; its vertices differ from the generators' form)."""
        P, n = self.points.count, self._n
        if self._sloped is None:
            A_eq, _, A_ub = self.points.static_constraints(self.model, slope)
            cost = np.zeros(1 + 2 * P)
            lower = np.concatenate([[-INF], np.zeros(P), np.full(P, -INF)])
            self._sloped = self._warm(cost, lower, np.full(1 + 2 * P, INF), A_eq, A_ub)
        else:
            for p in np.flatnonzero(slope != self._slope):  # only during the first (slope > 0) steps
                self._sloped.change_coeff(n + p, 1 + p, -slope[p])
                self._sloped.change_coeff(n + P + p, 1 + p, -slope[p])
        self._slope = np.array(slope, dtype=float, copy=True)
        rows = np.arange(n, n + 2 * P, dtype=np.int32)
        self._sloped.change_row_bounds(rows, np.full(2 * P, -INF), np.concatenate([cap, cap]))
        return self._sloped

    def _set_slope(self, h: WarmLP, slope: np.ndarray) -> None:
        """The λ± columns' coefficients for a new slope (only during the first, slope > 0, steps)."""
        P = self.points.count
        changed = np.flatnonzero(slope[self._entry_points] != self._slope[self._entry_points])
        rows, cols = self._entry_rows[changed], self._entry_points[changed]
        shift = slope[cols] * self._entry_tangent[changed]
        plus, minus = self._entry_normal[changed] + shift, self._entry_normal[changed] - shift
        for row, col, a, b in zip(rows, cols, plus, minus, strict=True):
            h.change_coeff(row, 1 + col, a)
            h.change_coeff(row, 1 + P + col, b)

    @staticmethod
    def _run(h: WarmLP, max_pivots: int, seconds: float) -> SolverResult:
        """One solve within ``max_pivots`` simplex (and interior-point) iterations and a user's
        ``seconds``; every later solve is dual simplex, warm."""
        return h.run(max_pivots, then="simplex", seconds=seconds)

    def solve(
        self, slope: np.ndarray, cap: np.ndarray, max_pivots: int | None = None, seconds: float = INF
    ) -> StaticLP:
        """Re-solve with new slopes and caps within ``max_pivots`` iterations (default: the constructor's)
        and what is left of a user's hard cap (``seconds``).  An α proven below ``alpha_floor`` is
        a failed solve."""
        P = self.points.count
        limit = self._max_pivots if max_pivots is None else max(1, int(max_pivots))
        h = self._model_for(slope, _caps(cap))
        sol = self._run(h, limit, seconds)
        pivots = sol.iterations
        if sol.termination is Termination.NUMERICAL:
            # The warm simplex can stop without a verdict (numerical trouble at the 1e-10
            # tolerances); a cold interior-point solve with crossover usually settles it.
            h.clear_solver()
            h.set_option("solver", "ipm")
            sol = self._run(h, limit, seconds)
            pivots += sol.iterations
        if sol.termination is Termination.UNBOUNDED:
            return failed(Termination.UNBOUNDED, P, pivots, np.inf)
        if sol.termination in (Termination.INFEASIBLE, Termination.INFEASIBLE_OR_UNBOUNDED):
            return failed(Termination.INFEASIBLE, P, pivots)
        if sol.termination is not Termination.OPTIMAL:
            return failed(Termination.ERROR, P, pivots)
        mechanism = self._mechanism(sol)
        normal, shear, tau = self._forces(sol.x, slope)
        bounded = np.clip(tau, 0.0, self.model.capacity)  # empty without cohesion and ties
        return StaticLP(Termination.OPTIMAL, float(sol.x[0]), normal, shear, mechanism, pivots, bounded)

    def clean_mechanism(self, cap: np.ndarray, max_pivots: int, seconds: float = INF) -> tuple[np.ndarray | None, int]:
        """The mechanism of the last slope-zero solve (at caps ``cap``) re-optimised at α's cost
        :func:`live_total`: a second model started from its basis, a few simplex pivots to the
        scaled cost's dual feasibility, so that its duals interpenetrate by at most
        ``DUAL_TOLERANCE`` of their own velocities; the first model and its path are untouched.
        Returns the mechanism (None when the re-solve does not end optimal) and its pivots."""
        if self._bounded is None:
            return None, 0
        if self._clean is None:
            self._clean = self._new_bounded(alpha_cost=live_total(self.model))
            self._clean.set_option("solver", "simplex")
        caps = _caps(cap)
        self._clean.change_col_bounds(self._shear_cols, -caps, caps)
        self._clean.set_basis(self._bounded.basis())
        sol = self._clean.run(max(1, int(max_pivots)), seconds=seconds)
        if sol.termination is not Termination.OPTIMAL:
            return None, sol.iterations
        return self._mechanism(sol), sol.iterations

    def _mechanism(self, sol: SolverResult) -> np.ndarray | None:
        """The mechanism u of an optimal solve, f_Lᵀu = n_free, from the equilibrium rows' duals
        (∂(−cost)/∂b, whose f_Lᵀy is α's cost); None when the live load does no work on them."""
        y = sol.duals[: self._n]
        work = dot(self.model.live, y)
        return y * (self.model.n_free / work) if work > 0 else None

    def _forces(self, x: np.ndarray, slope: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(N, T, τ) of a solution: read off at slope zero or with ``yield_rows``, from λ± and κ
        otherwise."""
        P = self.points.count
        if not np.any(slope) or self.yield_rows:
            return x[1 : 1 + P].copy(), x[1 + P : 1 + 2 * P].copy(), x[1 + 2 * P :]
        plus, minus, kappa = x[1 : 1 + P], x[1 + P : 1 + 2 * P], x[1 + 2 * P : 1 + 3 * P]
        return plus + minus, slope * (plus - minus) + kappa, x[1 + 3 * P :]
