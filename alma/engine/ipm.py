"""Primal–dual Mehrotra predictor–corrector interior point for the associative LP, Eq. 10.

Kinematic problem (primal) and static problem (dual), dimensionless::

    min  −f₀ᵀu   s.t.  f_Lᵀu = N,  Hᵀu − s = 0,  s ≥ 0        (u free: block velocities)
    max  N α     s.t.  H μ + f₀ + α f_L = 0,  μ ≥ 0            (α free: load multiplier)

With D = μ / s, one Newton step reduces to the bordered normal equations::

    [ H D Hᵀ   −f_L ] [Δu]   [ r_d − H (S⁻¹ r_c + D r_p) ]
    [ f_Lᵀ      0   ] [Δα] = [ −r_a                      ]

K = H D Hᵀ (3 rows per free block) is factorised once per iteration on a fixed pattern
(:mod:`alma.engine.normal`); the dense row f_L is never added to K: the backend eliminates it
by its Schur complement f_Lᵀ K⁻¹ f_L, or factorises the bordered matrix [K f_L; f_Lᵀ 0] with
f_L last (feral).  The direction taken (not the predictor nor the trial correctors) is refined
against K without the regularisation δ I.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from .auxiliary import Auxiliary, auxiliary_rows
from .cholesky import FactorisationError, Factoriser, dot as _dot, make_factoriser
from .normal import NormalPattern, canonical, normal_pattern
from .types import IPMResult, IPMSettings


class _Newton:
    """The factorised normal matrix of one iteration and the bordered solves with it."""

    def __init__(
        self,
        H: sp.csc_matrix,
        live: np.ndarray,
        pattern: NormalPattern,
        factoriser: Factoriser,
        settings: IPMSettings,
        auxiliary: Auxiliary | None = None,
    ):
        self.H, self.HT = H, H.T.tocsr()
        self.live = live
        self.pattern, self.factoriser, self.settings = pattern, factoriser, settings
        self.auxiliary = auxiliary  # v rows eliminated from K (bounded forces), or None
        self.d = np.ones(H.shape[1])
        self.c = self.s_aux = np.ones(0)  # C = V D Vᵀ and S of the auxiliary rows
        self.factor_time = self.solve_time = 0.0
        self.factorisations = 0
        self.boost = 1.0  # multiplies δ after a direction the refinement could not make accurate
        self.last_error = 0.0

    def factor(self, d: np.ndarray) -> None:
        """Factorise K = H D Hᵀ + δ I (D clipped to [1/cap, cap]); δ grows 100× on failure."""
        cap = self.settings.scaling_cap
        self.d = np.clip(d, 1.0 / cap, cap)
        t0 = time.perf_counter()
        weights = self.d
        if self.auxiliary is not None:
            self.c, self.s_aux, weights = self.auxiliary.weights(self.d)
        values = self.pattern.values(weights)
        top = float(values[self.pattern.diagonal].max(initial=1.0))
        shift = self.settings.regularisation * self.boost * max(top, 1.0)
        for attempt in range(4):
            try:
                values[self.pattern.diagonal] += shift
                self.factoriser.factor(values)
                break
            except FactorisationError:
                if attempt == 3:
                    raise
                values[self.pattern.diagonal] -= shift
                shift *= 100.0
        self.factorisations += 1
        self.factor_time += time.perf_counter() - t0

    @property
    def solves(self) -> int:
        """Right-hand sides solved with the factors so far."""
        return self.factoriser.columns

    def bordered(self, g: np.ndarray, h: float) -> tuple[np.ndarray, float]:
        """Solve K Δu − f_L Δα = g, f_Lᵀ Δu = h (the backend's bordered solve, border f_L)."""
        t0 = time.perf_counter()
        aux = self.auxiliary
        if aux is None:
            du, neg_da = self.factoriser.solve_bordered(g, h)
        else:  # f_L is zero on the v rows: the border stays on u
            du, neg_da = self.factoriser.solve_bordered(aux.reduce(g, self.c, self.s_aux), h)
            du = aux.expand(du, g, self.c, self.s_aux)
        self.solve_time += time.perf_counter() - t0
        return du, -neg_da

    def direction(self, state: _State, rc: np.ndarray, res: _Residuals) -> tuple:
        """Newton direction (Δu, Δs, Δμ, Δα) for the complementarity target r_c = s∘μ − target,
        from one bordered solve (not refined)."""
        g = res.dual - self.H @ (rc / state.s + self.d * res.primal)
        du, da = self.bordered(g, -res.norm)
        ds = self.HT @ du + res.primal
        dmu = -rc / state.s - self.d * ds  # the same (clipped) D as in K
        return du, ds, dmu, da

    def refine(self, res: _Residuals, step: tuple) -> tuple:
        """Iterative refinement of a Newton direction on the static equation.

        The reduced solve loses accuracy where D spans many orders of magnitude; the static
        equation H Δμ + f_L Δα = −r_d (terms of the size of μ) is then refined in the full
        system, each correction being one more bordered solve with the same factors.  Only the
        direction the step takes is refined: the predictor and the trial correctors only decide
        step lengths and the centring.
        """
        du, ds, dmu, da = step
        target = self.settings.refinement_target * max(
            float(np.abs(res.dual).max(initial=0.0)), self.settings.refinement_floor
        )
        e_static = self.H @ dmu + self.live * da + res.dual
        error = float(np.abs(e_static).max(initial=0.0))
        s_ = self.settings
        for step_count in range(s_.refinement_steps + s_.refinement_rescue):
            if error <= target or (step_count >= s_.refinement_steps and error <= s_.refinement_failure * target):
                break
            cu, ca = self.bordered(e_static, -(_dot(self.live, du) + res.norm))
            cs = self.HT @ cu
            new = (du + cu, ds + cs, dmu - self.d * cs, da + ca)
            e_new = self.H @ new[2] + self.live * new[3] + res.dual
            error_new = float(np.abs(e_new).max(initial=0.0))
            if step_count >= s_.refinement_steps and error_new >= error:
                break  # a rescue step that does not help is not taken
            (du, ds, dmu, da), e_static, error = new, e_new, error_new
        self.last_error = error / target
        return du, ds, dmu, da


class _State:
    """Iterate (u, s, μ, α) of the primal–dual pair."""

    def __init__(self, u: np.ndarray, s: np.ndarray, mu: np.ndarray, alpha: float):
        self.u, self.s, self.mu, self.alpha = u, s, mu, alpha


class _Residuals:
    """r_p = Hᵀu − s, r_a = f_Lᵀu − N, r_d = H μ + f₀ + α f_L and the duality measure τ."""

    def __init__(self, H, HT, dead, live, norm_value: float, state: _State):
        self.primal = HT @ state.u - state.s
        self.norm = _dot(live, state.u) - norm_value
        self.dual = H @ state.mu + dead + state.alpha * live
        self.tau = _dot(state.s, state.mu) / max(state.s.size, 1)


def _max_step(x: np.ndarray, dx: np.ndarray) -> float:
    """Largest a ≤ 1 with x + a dx ≥ 0."""
    neg = dx < 0
    if not neg.any():
        return 1.0
    return float(min(1.0, np.min(-x[neg] / dx[neg])))


def _start(newton: _Newton, dead: np.ndarray, live: np.ndarray, norm_value: float) -> _State:
    """Mehrotra's starting point: least-norm fields with D = I, shifted into the interior."""
    newton.factor(np.ones(newton.H.shape[1]))
    # static: min ‖μ‖ s.t. H μ + f₀ + α f_L = 0  ->  μ = Hᵀy, [HHᵀ −f_L; f_Lᵀ 0] [y; −α] = [−f₀; 0]
    y, neg_alpha = newton.bordered(-dead, 0.0)
    mu = newton.HT @ y
    alpha = -neg_alpha
    # kinematic: min ‖Hᵀu‖ s.t. f_Lᵀu = N  ->  u ∝ (HHᵀ)⁻¹ f_L
    u, _ = newton.bordered(np.zeros(newton.H.shape[0]), norm_value)
    s = newton.HT @ u
    s = s + max(-1.5 * float(s.min(initial=0.0)), 0.0)
    mu = mu + max(-1.5 * float(mu.min(initial=0.0)), 0.0)
    s = np.maximum(s, 1e-8 * max(float(s.max(initial=1.0)), 1.0))
    mu = np.maximum(mu, 1e-8 * max(float(mu.max(initial=1.0)), 1.0))
    product = _dot(s, mu)
    s = s + 0.5 * product / float(mu.sum())
    mu = mu + 0.5 * product / float(s.sum())
    return _State(u, s, mu, alpha)


def _measures(res: _Residuals, state: _State, dead: np.ndarray, norm_value: float) -> tuple[float, float, float]:
    """(relative complementarity gap sᵀμ / (N max(1, |α|)), relative primal residual, dual residual).

    sᵀμ is the duality gap of the pair up to the residual terms; those are judged separately
    (the static residual is what alma's certificate repairs by projection, so it is held to a
    looser tolerance than the gap).
    """
    scale = max(norm_value, 1.0) * max(1.0, abs(state.alpha))
    gap = _dot(state.s, state.mu) / scale
    primal = max(
        float(np.abs(res.primal).max(initial=0.0)) / max(float(state.s.max(initial=0.0)), norm_value, 1.0),
        abs(res.norm) / max(norm_value, 1.0),
    )
    dual = float(np.abs(res.dual).max(initial=0.0)) / max(1.0, float(np.abs(dead).max(initial=0.0)))
    return gap, primal, dual


def _diverged(state: _State, norm_value: float, settings: IPMSettings) -> bool:
    values = (state.u, state.s, state.mu, np.array([state.alpha]))
    if not all(np.all(np.isfinite(v)) for v in values):
        return True
    big = settings.blowup
    return (
        float(np.abs(state.u).max(initial=0.0)) > big * max(norm_value, 1.0)
        or abs(state.alpha) > big
        or float(state.mu.max(initial=0.0)) > big
    )


def solve_eq10(
    H: sp.csc_matrix,
    dead: np.ndarray,
    live: np.ndarray,
    norm_value: float,
    settings: IPMSettings | None = None,
    *,
    pattern: NormalPattern | None = None,
    n_primary: int | None = None,
) -> IPMResult:
    """Solve Eq. 10 and its static dual by the Mehrotra predictor–corrector interior point.

    Parameters
    ----------
    H : scipy.sparse.csc_matrix
        Equilibrium matrix of Eq. 3 on cone generators, (3 n_free, k), dimensionless.
    dead, live : numpy.ndarray
        f₀ and f_L, (3 n_free,), forces per mean block weight.
    norm_value : float
        N of the normalisation f_Lᵀu = N (α is unaffected; u scales with N).
    settings : IPMSettings, optional
    pattern : NormalPattern, optional
        The pattern of H D Hᵀ (of its first ``n_primary`` rows) built for this geometry at
        another friction: reused, with its map rebuilt from this H's values, when H has the same
        structure (the result's ``pattern`` is the one used).
    n_primary : int, optional
        Rows of u; the rows after them are the dissipation variables of bounded forces
        (:mod:`alma.engine.auxiliary`), eliminated from K.  Default: every row is u.
    """
    s_ = settings or IPMSettings()
    t_start = time.perf_counter()
    H = sp.csc_matrix(H)
    live = np.asarray(live, float)
    aux = auxiliary_rows(H, n_primary) if n_primary is not None and n_primary < H.shape[0] else None
    primary = canonical(H if aux is None else aux.U)
    reuse = pattern is not None and pattern.fits(primary)
    pattern = pattern.with_values(primary) if pattern is not None and reuse else normal_pattern(primary)
    factoriser = make_factoriser(pattern, s_.backend, border=live[: primary.shape[0]], qdldl_max_rows=s_.qdldl_max_rows)
    t_pattern = time.perf_counter() - t_start
    newton = _Newton(H, live, pattern, factoriser, s_, aux)
    dead = np.asarray(dead, float)
    try:
        state = _start(newton, dead, newton.live, norm_value)
        status, iterations, measures = _iterate(newton, state, dead, norm_value, s_, _budget(s_, primary.shape[0]))
    except FactorisationError:
        status, iterations, measures = "numerical_error", 0, (np.inf, np.inf, np.inf)
        state = _State(np.zeros(H.shape[0]), np.ones(H.shape[1]), np.zeros(H.shape[1]), 0.0)
    finally:
        factoriser.close()
    timings = dict(
        pattern_s=t_pattern,
        factor_s=newton.factor_time,
        solve_s=newton.solve_time,
        total_s=time.perf_counter() - t_start,
        factorisations=newton.factorisations,
        solves=newton.solves,
        boost=newton.boost,
    )
    return IPMResult(
        status=status,
        u=state.u,
        mu=state.mu,
        alpha=float(state.alpha),
        iterations=iterations,
        gap=measures[0],
        primal_residual=measures[1],
        dual_residual=measures[2],
        backend=factoriser.name,
        timings=timings,
        pattern=pattern,
    )


def _budget(settings: IPMSettings, rows: int) -> int:
    """The iteration budget: ``max_iter``, growing as √size beyond ``budget_rows`` rows of u."""
    return int(np.ceil(settings.max_iter * max(1.0, np.sqrt(rows / settings.budget_rows))))


def _iterate(
    newton: _Newton, state: _State, dead: np.ndarray, norm_value: float, settings: IPMSettings, budget: int
) -> tuple[str, int, tuple[float, float, float]]:
    """The predictor–corrector loop (at most ``budget`` iterations); updates ``state`` in place."""
    H, HT, live = newton.H, newton.HT, newton.live
    eta = settings.step_fraction
    for iteration in range(budget + 1):
        res = _Residuals(H, HT, dead, live, norm_value, state)
        measures = _measures(res, state, dead, norm_value)
        if measures[0] <= settings.tol_gap and measures[1] <= settings.tol_feas and measures[2] <= settings.tol_static:
            return "optimal", iteration, measures
        if _diverged(state, norm_value, settings):
            return "diverged", iteration, measures
        if iteration == budget:
            break
        du, ds, dmu, da = _accurate_direction(newton, state, res, settings)
        ap = min(1.0, eta * _max_step(state.s, ds))
        ad = min(1.0, eta * _max_step(state.mu, dmu))
        state.u = state.u + ap * du
        state.s = state.s + ap * ds
        state.mu = state.mu + ad * dmu
        state.alpha = state.alpha + ad * da
    return "max_iterations", budget, measures


def _accurate_direction(newton: _Newton, state: _State, res: _Residuals, settings: IPMSettings) -> tuple:
    """The direction, recomputed with δ 100× larger while its refined static-equation error stays
    above ``refinement_failure``; a boost that does not lower the error is taken back (at 100,000
    blocks a boosted δ late in the run derails the static field: docs/engine.md)."""
    best = _direction(newton, state, res, settings)
    best_error, best_boost = newton.last_error, newton.boost
    for _ in range(settings.boost_attempts):
        if best_error <= settings.refinement_failure or newton.boost >= settings.boost_limit:
            break
        newton.boost *= 100.0  # the factors were too inaccurate for this D: regularise more
        step = _direction(newton, state, res, settings)
        if newton.last_error >= best_error:
            break
        best, best_error, best_boost = step, newton.last_error, newton.boost
    newton.boost, newton.last_error = best_boost, best_error
    return best


def _direction(newton: _Newton, state: _State, res: _Residuals, settings: IPMSettings) -> tuple:
    """Factorise at the current D and return the predictor–corrector(–centrality) direction."""
    newton.factor(state.mu / state.s)
    # predictor (affine scaling): target s∘μ = 0
    _du, ds, dmu, _da = newton.direction(state, state.s * state.mu, res)
    ap, ad = _max_step(state.s, ds), _max_step(state.mu, dmu)
    tau_aff = _dot(state.s + ap * ds, state.mu + ad * dmu) / state.s.size
    sigma = min(1.0, (tau_aff / max(res.tau, 1e-300)) ** settings.centring_exponent)
    # corrector: second-order term and centring
    rc = state.s * state.mu + ds * dmu - sigma * res.tau
    step = newton.direction(state, rc, res)
    step = _centrality_correctors(newton, state, res, rc, step, sigma * res.tau, settings)
    return newton.refine(res, step)


def _centrality_correctors(
    newton: _Newton, state: _State, res: _Residuals, rc: np.ndarray, step: tuple, target: float, settings: IPMSettings
) -> tuple:
    """Gondzio's multiple centrality correctors: push the products s∘μ of a longer trial step
    back into [β_min, β_max]·target, as long as each correction lengthens the step enough."""
    ap, ad = _max_step(state.s, step[1]), _max_step(state.mu, step[2])
    for _ in range(settings.correctors):
        trial_p = min(1.0, settings.corrector_reach * ap + 0.1)
        trial_d = min(1.0, settings.corrector_reach * ad + 0.1)
        v = (state.s + trial_p * step[1]) * (state.mu + trial_d * step[2])
        lo, hi = settings.corrector_box[0] * target, settings.corrector_box[1] * target
        t = np.clip(v, lo, hi) - v
        t = np.maximum(t, -hi)
        new_rc = rc - t
        candidate = newton.direction(state, new_rc, res)
        cp, cd = _max_step(state.s, candidate[1]), _max_step(state.mu, candidate[2])
        if min(cp, cd) < min(ap, ad) + settings.corrector_gain * 0.1:
            if cp + cd > ap + ad:
                step, ap, ad = candidate, cp, cd
            break
        step, ap, ad, rc = candidate, cp, cd, new_rc
    return step
