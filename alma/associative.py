"""The associative (dilatant) limit-analysis LP, Eq. 10, and its static dual.

Kinematic form (Eq. 10, written on contact-point generators)::

    α_c = min  -f_0ᵀ u      s.t.  f_Lᵀ u = 1,   Hᵀ u ≥ 0      (flow rule, Eq. 6)

Static form (its dual)::

    α_c = max  α            s.t.  H μ + f_0 + α f_L = 0,  μ ≥ 0  (Eqs. 3–5)

Clarabel solves the kinematic form as a primal–dual pair: ``x`` is the
mechanism u and the dual ``z`` gives (−α, μ).  After the interior-point solve
both fields are repaired to admissibility (a minimum-norm projection on their
active sets), which turns them into an upper bound (the mechanism) and a lower
bound (the stress field) that certify each other.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import clarabel
import numpy as np
import qdldl
import scipy.sparse as sp

from .engine.select import choose as choose_engine, solve_with_engine
from .model import Model


#: Certified results have relative gap and admissibility residuals below these.
GAP_TOLERANCE = 1e-7
RESIDUAL_TOLERANCE = 1e-9

#: Eq. 10's normalisation f_Lᵀu = 1 is passed to Clarabel as f_Lᵀu = NORMALISATION · n_free
#: (loads are per mean block weight, so block velocities are of order NORMALISATION).  The
#: scale only changes how Clarabel balances its primal and dual residuals, and with it the
#: iterations and the accuracy of the mechanism.  Measured on the 108 panels (tolerance 1e-11,
#: no iterative refinement), factor 1 / 10 / 100 / 1000: the 1,752-block panel takes 109 / 42 /
#: 42 / 42 iterations and the 2,997-block wall 63 / 41 / 37 / 41; at 1000 all 108 are certified
#: in 2,525 iterations with largest gap 3.0e-9 and flow-rule residual 2e-11 (factor 1 with
#: refinement: 2,822, 1.3e-8, 8.6e-10) and no α exceeds its friction bound f by 1e-9.  (100 is
#: as good on these figures, but with its LP mechanism HiGHS's MILP fails with a solve error in
#: the "classic" certification of three blocks side by side, verification/test_certify.py; that
#: formulation fails on 7 of 20 perturbations by 1e-10 of the inputs at factor 1 too.)
NORMALISATION = 1000.0


@dataclass(frozen=True)
class LPSolution:
    """Raw dimensionless solution of the associative LP (see ``alma.result``)."""

    status: str  # optimal | no_collapse | no_equilibrium | not_converged
    message: str
    alpha: float
    lower: float
    upper: float
    mechanism: np.ndarray  # (3 n_free,) u, v, θ per free block, f_Lᵀu = 1
    multipliers: np.ndarray  # (4 m,) μ ≥ 0
    static_residual: float  # ‖H μ + f_0 + α_lower f_L‖_∞, loads per mean block weight
    kinematic_residual: float  # max(0, −min Hᵀu) / max(|Hᵀ| |u|): relative flow-rule violation
    iterations: int
    solve_time: float
    certify_time: float


def solve_lp(model: Model, *, tolerance: float = 1e-11, max_iter: int = 200,
             equilibrium: sp.csc_matrix | None = None, engine: str = "auto") -> LPSolution:
    """Solve Eq. 10 and certify the value from both sides.

    ``engine``: "clarabel", "ipm" (alma.engine, Clarabel if it does not converge) or "auto"
    (the interior point from alma.engine.select.AUTO_MIN_BLOCKS free blocks on, when a fast
    factorisation backend is installed; Clarabel otherwise).
    """
    H = model.equilibrium if equilibrium is None else equilibrium
    n, k = H.shape
    start = time.perf_counter()
    if k == 0:
        # No joint: any motion is free, no load can be carried.
        return _trivial(model, "no_equilibrium", "no joint carries the free blocks")
    ran, solver_name, note = None, "Clarabel", ""
    if choose_engine(engine, model.n_free) == "ipm":  # alma's interior point; Clarabel if it fails
        ran = solve_with_engine(H, model.dead, model.live, NORMALISATION * float(model.n_free))
        solver_name = ran.label
        if ran.raw_status != "Solved":
            note = f"; {ran.label}: {ran.raw_status} after {ran.iterations} iterations, Clarabel used"
            ran, solver_name = None, "Clarabel"
    if ran is not None:
        solve_time, status, iterations = time.perf_counter() - start, ran.raw_status, ran.iterations
        sol_x, sol_z = ran.x, ran.z
    else:
        solve_time, status, iterations, sol_x, sol_z = _clarabel(model, H, tolerance, max_iter, start)
    return _certified(model, H, status, iterations, sol_x, sol_z, solve_time, solver_name, note)


def _clarabel(model: Model, H: sp.csc_matrix, tolerance: float, max_iter: int, start: float) -> tuple:
    """Clarabel's solve of Eq. 10: (solve time, status, iterations, x, z)."""
    n, k = H.shape
    P = sp.csc_matrix((n, n))
    A = sp.vstack([sp.csr_matrix(model.live), -H.T]).tocsc()
    b = np.zeros(1 + k)
    b[0] = NORMALISATION * float(model.n_free)
    cones = [clarabel.ZeroConeT(1), clarabel.NonnegativeConeT(k)]
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = tolerance
    settings.tol_gap_rel = tolerance
    settings.tol_feas = tolerance
    settings.max_iter = max_iter
    # QDLDL named explicitly: Clarabel's "auto" switches to faer when the factor's flops per
    # nonzero pass 40 (running-bond walls from ~3,000 blocks), 3-5x slower per iteration here.
    settings.direct_solve_method = "qdldl"
    # No iterative refinement of the KKT solves: the certificate below, not Clarabel's residuals,
    # decides, and on the 108 panels (normalisation 10) the refined solves cost ~30 % of the time
    # for the same iterations (2,527 refined, 2,551 not), the same certified set, α within 1e-9.
    settings.iterative_refinement_enable = False
    solver = clarabel.DefaultSolver(P, -model.dead, A, b, cones, settings)
    sol = solver.solve()
    return time.perf_counter() - start, str(sol.status), int(sol.iterations), sol.x, sol.z


def _certified(model: Model, H: sp.csc_matrix, status: str, iterations: int, sol_x, sol_z,
               solve_time: float, solver_name: str = "Clarabel", note: str = "") -> LPSolution:
    """The certificate's verdict on a solver's primal–dual pair (the solver's flag does not decide)."""
    if status == "PrimalInfeasible":  # no mechanism lets the live load do positive work
        return _trivial(model, "no_collapse", "no kinematically admissible mechanism with positive live-load work" + note,
                        iterations=iterations, solve_time=solve_time)
    if status == "DualInfeasible":  # dead-load work unbounded below: no equilibrium for any α
        return _trivial(model, "no_equilibrium", "no statically admissible stress field for any load multiplier" + note,
                        iterations=iterations, solve_time=solve_time)

    t0 = time.perf_counter()
    u = np.asarray(sol_x, dtype=float)
    z = np.asarray(sol_z, dtype=float)
    u, mu, alpha_static, static_residual, kinematic_residual = _certify(H, model, u, z[1:].copy(), -z[0])
    # A mechanism that breaks the flow rule by v_j only proves α ≤ (−f_0ᵀu + Σ v_j μ*_j) / f_Lᵀu:
    # the violation work is charged with the certified stress field's multipliers.
    violation_work = float(np.maximum(-(H.T @ u), 0.0) @ mu)
    upper = float((-model.dead @ u + violation_work) / (model.live @ u))
    lower = alpha_static
    certify_time = time.perf_counter() - t0

    # The certificate, not the solver's flag, decides: both fields admissible and the bounds close.
    gap = (upper - lower) / max(1.0, abs(upper))
    static_ok = static_residual <= RESIDUAL_TOLERANCE
    kinematic_ok = kinematic_residual <= RESIDUAL_TOLERANCE
    if not static_ok:
        lower = -float("inf")  # the stress field proves nothing
    if not kinematic_ok:
        upper = float("inf")  # the mechanism proves nothing
    zero = GAP_TOLERANCE * max(1.0, abs(upper) if np.isfinite(upper) else 1.0)
    if kinematic_ok and upper < -zero:
        # An admissible mechanism in which the dead load alone does positive work: α_c < 0.
        result_status, message = "no_equilibrium", "the structure cannot carry its dead load (α_c < 0)"
    elif static_ok and kinematic_ok and gap <= GAP_TOLERANCE and status in ("Solved", "AlmostSolved"):
        result_status = "optimal"
        message = f"certified: relative gap {gap:.1e} ({solver_name}: {status}){note}"
    else:
        result_status = "not_converged"
        message = (f"{solver_name} status {status}; relative gap {gap:.2e}, residuals static "
                   f"{static_residual:.1e}, kinematic {kinematic_residual:.1e}{note}")
    alpha = upper if np.isfinite(upper) else float(-model.dead @ u / (model.live @ u))
    return LPSolution(status=result_status, message=message, alpha=alpha, lower=lower, upper=upper,
                      mechanism=u, multipliers=mu, static_residual=static_residual,
                      kinematic_residual=kinematic_residual, iterations=iterations,
                      solve_time=solve_time, certify_time=certify_time)


def _certify(H: sp.csc_matrix, model: Model, u: np.ndarray, mu: np.ndarray,
             alpha: float) -> tuple[np.ndarray, np.ndarray, float, float, float]:
    """Repair the interior-point pair into admissible fields (the two bounds).

    Both repairs are minimum-norm corrections solved with a sparse factorisation:

    - static: on the support S of μ and on α, (μ_S, α) += [H_S f_L]ᵀ y with
      (H_S H_Sᵀ + f_L f_Lᵀ) y = −r removes the equilibrium residual
      r = H μ + f_0 + α f_L (the rank-one term by Sherman–Morrison); μ stays ≥ 0
      because the step is far below the support threshold, and α moves by the
      matching amount;
    - kinematic: the flow-rule rows V that the interior point violates
      (Hᵀu < 0, by round-off) are closed by u += H_V w with (H_Vᵀ H_V) w = −H_Vᵀu
      (solved in velocity space) while nearly active rows are held; the first step that
      does not reduce the largest violation ends the repair; finally f_Lᵀu is restored
      by scaling.

    Returns (u, μ, α_lower, static residual, kinematic residual).
    """
    live = model.live
    HT = H.T.tocsr()
    norm = float(model.n_free)
    u = u * (norm / (live @ u))
    violated = np.zeros(HT.shape[0], dtype=bool)

    abs_HT = abs(HT)

    def violation(x: np.ndarray) -> float:
        """Largest flow-rule violation relative to the size of its terms, max(0, −Hᵀu) / (|Hᵀ| |u|)."""
        power = HT @ x
        size = float((abs_HT @ np.abs(x)).max(initial=0.0))
        return max(0.0, -float(power.min(initial=0.0))) / max(size, 1e-300)

    best = violation(u)
    for _ in range(4):
        if best <= 0.1 * RESIDUAL_TOLERANCE:
            break
        power = HT @ u
        # Violated rows are closed; nearly active rows are held where they are (target 0 change).
        violated |= power < 1e-8 * float(np.abs(power).max(initial=0.0))
        rows = np.flatnonzero(violated)
        HV = HT[rows]
        # The minimum-norm step H_V w, (H_Vᵀ H_V + ε I) w = t, is computed in velocity space as
        # (H_V H_Vᵀ + ε I)⁻¹ H_V t (the same vector): that Gram matrix has the size of u (3 per
        # block) instead of one row per held generator, which is 3x larger and much denser.
        eps = 1e-12 * max(float(np.max(np.asarray(HV.multiply(HV).sum(axis=1)), initial=1.0)), 1.0)
        solve_u = _regularised_solver(HV.T @ HV, eps)
        candidate = u.copy()
        for _ in range(3):
            target = np.maximum(-(HV @ candidate), 0.0)
            candidate = candidate + solve_u(HV.T @ target)
        candidate = candidate * (norm / (live @ candidate))
        value = violation(candidate)
        if value >= best:
            # Rejected: u and hence the next round's row set and step would be the same again.
            break
        u, best = candidate, value
    # Static side. Two correction spaces: the plain support of μ, then an affine-scaled one
    # (column j moves in proportion to μ_j, so every positive multiplier can take part and μ
    # stays ≥ 0) -- the second only when the first is not admissible or leaves a gap near the
    # tolerance, since it costs another factorisation.
    mu = np.maximum(mu, 0.0)
    u_final = u / norm
    upper_estimate = float(-model.dead @ u_final / (live @ u_final))
    best_static = None
    top = max(float(mu.max(initial=0.0)), 1e-300)
    for affine in (False, True):
        if affine:
            ok = best_static[2] <= 0.1 * RESIDUAL_TOLERANCE
            gap = (upper_estimate - best_static[1]) / max(1.0, abs(upper_estimate))
            if ok and gap <= 0.1 * GAP_TOLERANCE:
                break
            support = np.flatnonzero(mu > 1e-14 * top)
            weight = np.sqrt(mu[support] / top)
        else:
            support = np.flatnonzero(mu > 1e-9 * top)
            weight = np.ones(support.size)
        trial = _static_correction(H, model, mu.copy(), alpha, support, weight)
        if best_static is None or _better(trial, best_static):
            best_static = trial
    mu, alpha, static_residual = best_static
    return u / norm, mu, float(alpha), static_residual, best


def _better(trial: tuple, best: tuple) -> bool:
    """Prefer an admissible field (residual below tolerance) with the larger α, else the smaller residual."""
    ok_t, ok_b = trial[2] <= 0.1 * RESIDUAL_TOLERANCE, best[2] <= 0.1 * RESIDUAL_TOLERANCE
    if ok_t and ok_b:
        return trial[1] > best[1]
    return ok_t or (not ok_b and trial[2] < best[2])


def _static_correction(H: sp.csc_matrix, model: Model, mu: np.ndarray, alpha: float,
                       support: np.ndarray, weight: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Minimum-norm correction of (μ_S, α) removing the equilibrium residual (Eq. 3)."""
    live = model.live
    HS = H[:, support] @ sp.diags(weight)
    solve_g = _regularised_solver(HS @ HS.T)
    g_live = solve_g(live)
    # α takes part with a small weight first: the correction goes to the stresses, and α only
    # absorbs what they cannot (the "matching reduction" of the multiplier) when the weight grows.
    for alpha_weight in (1e-6, 1e-3, 1.0):
        denom = 1.0 / alpha_weight**2 + live @ g_live
        for _ in range(4):  # iterative refinement of the regularised solve
            residual = H @ mu + model.dead + alpha * live
            if np.abs(residual).max(initial=0.0) <= 1e-15:
                break
            x = solve_g(-residual)
            y = x - g_live * (live @ x) / denom  # (G + w² f_L f_Lᵀ)⁻¹(−r), Sherman–Morrison
            candidate = mu.copy()
            candidate[support] += weight * (HS.T @ y)
            np.maximum(candidate, 0.0, out=candidate)
            new_alpha = alpha + float(live @ y) * alpha_weight**2
            if np.abs(H @ candidate + model.dead + new_alpha * live).max() >= np.abs(residual).max():
                break
            mu, alpha = candidate, new_alpha
        if np.abs(H @ mu + model.dead + alpha * live).max(initial=0.0) <= 1e-13:
            break
    residual = H @ mu + model.dead + alpha * live
    return mu, float(alpha), float(np.abs(residual).max(initial=0.0))


def _regularised_solver(gram: sp.spmatrix, eps: float | None = None):
    """A solver for (G + ε I) x = b, G a Gram matrix; ε only guards against rank deficiency.

    ``eps`` defaults to 1e-12 max(1, max diag G); a zero diagonal entry (a variable G does not
    touch) gets 1 instead, so that variable's solution component is 0.

    G + ε I is symmetric positive definite, so an LDLᵀ factorisation without pivoting after an
    approximate-minimum-degree ordering (QDLDL, the factorisation inside Clarabel) is stable and
    keeps the factor small (measured on the 1,752-block panel's 5,256 × 5,256 Gram matrix: 0.035 s,
    SuperLU's symmetric-mode LU 0.045 s).
    """
    gram = sp.csc_matrix(gram)
    diag = gram.diagonal()
    if eps is None:
        eps = 1e-12 * max(float(diag.max(initial=1.0)), 1.0)
    gram = (gram + sp.diags(np.where(diag > 0, eps, 1.0))).tocsc()
    return qdldl.Solver(gram).solve


def _trivial(model: Model, status: str, message: str, iterations: int = 0, solve_time: float = 0.0) -> LPSolution:
    k = 4 * model.n_joints
    nan = float("nan")
    if status == "no_collapse":
        lower, upper = float("inf"), float("inf")
    else:
        lower, upper = -float("inf"), -float("inf")
    return LPSolution(status=status, message=message, alpha=upper, lower=lower, upper=upper,
                      mechanism=np.zeros(3 * model.n_free), multipliers=np.zeros(k),
                      static_residual=nan, kinematic_residual=nan, iterations=iterations,
                      solve_time=solve_time, certify_time=0.0)
