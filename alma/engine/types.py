"""Settings and result of alma's interior point for Eq. 10 (plain data, no alma internals)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: The interior point's sparse factorisations ("auto": the fastest importable; alma.engine.cholesky).
FACTORISATIONS = ("auto", "pardiso", "feral", "qdldl")


@dataclass(frozen=True)
class IPMSettings:
    """Tuned numbers of the interior point (dimensionless: forces per mean block weight).

    Every limit is an iteration count or a tolerance, never a time: the answer of a given
    problem does not depend on the machine or its load.
    """

    #: Iteration budget: the 108 paper panels and the walls up to 20,000 blocks need 8-56 ...
    max_iter: int = 120
    #: ... up to this many rows of u (20,000 blocks), and × √(rows / budget_rows) beyond: the
    #: iterations grow about as √size on the walls (56 at 20,000 blocks, 130 at 100,000).
    budget_rows: int = 60_000
    #: Relative complementarity gap sᵀμ / (N max(1, |α|)) at which the iteration stops: alma's
    #: certificate closes at a relative gap of 1e-7, which it measured equal to this measure; on
    #: the 108 paper panels it never failed below 1e-8 (10× margin; docs/engine.md).
    tol_gap: float = 1e-8
    #: Relative primal residual (flow rule Hᵀu = s, normalisation f_Lᵀu = N) at the stop.
    tol_feas: float = 1e-10
    #: Static residual ‖Hμ + f₀ + αf_L‖∞ (per mean block weight) at the stop: alma's certificate
    #: projects the field onto equilibrium, so only the gap and the support of μ must be sharp.
    tol_static: float = 1e-8
    #: Fraction of the step to the boundary of μ ≥ 0, s ≥ 0 (keeps the iterates interior).
    step_fraction: float = 0.99
    #: Mehrotra's centring exponent σ = (τ_aff / τ)^exponent.
    centring_exponent: float = 3.0
    #: Gondzio centrality correctors per iteration (one bordered solve each, no factorisation).
    correctors: int = 1
    #: A corrector aims at the step reach·α + 0.1 (α: the current step to the boundary).
    corrector_reach: float = 1.0
    #: ... and pushes the trial products s∘μ into this box, in units of σ τ.
    corrector_box: tuple = (0.1, 10.0)
    #: A corrector is kept while it lengthens the shorter step by at least gain·0.1.
    corrector_gain: float = 0.1
    #: Diagonal regularisation δ of K = H D Hᵀ + δ I, relative to the largest diagonal entry of K.
    regularisation: float = 1e-17
    #: Iterative-refinement steps of the Newton direction taken, on the static equation.
    refinement_steps: int = 3
    #: ... and up to this many more while the error still falls, when after them it would
    #: trigger a δ boost: at 100,000 blocks a boosted δ late in the run derails the static field,
    #: where more refinement keeps it on track (docs/engine.md).
    refinement_rescue: int = 5
    #: Refinement stops when the static equation's error is below this × max(‖r_d‖∞, floor):
    #: the step then reduces the static residual as the Newton step intends.
    refinement_target: float = 1e-1
    #: ... floor (per mean block weight): below it the certificate's projection does the rest.
    refinement_floor: float = 1e-9
    #: A direction whose static-equation error stays above this × the refinement target after
    #: refinement is recomputed with δ multiplied by 100 (from then on) ...
    #: (10 let δ run away on flemish 1:2 1:1 f = 0.27, where errors of 1e-9 are harmless)
    refinement_failure: float = 1e3
    #: ... at most this many times per iteration (QDLDL, without pivoting, needs it on some walls),
    boost_attempts: int = 3
    #: ... and δ at most this × its base value.
    boost_limit: float = 1e6
    #: D = μ / s is clipped to [1/cap, cap] in K only (refinement uses the same clipped D).
    scaling_cap: float = 1e14
    #: |u| / N, |α| or ‖μ‖∞ beyond this: the iterates diverge (an infeasible problem).
    blowup: float = 1e10
    #: Factorisation backend: "auto" (fastest importable) or a name of alma.engine.cholesky.
    backend: str = "auto"
    #: "auto" takes QDLDL instead of feral for K of fewer rows than this (3,000 free blocks): the
    #: interior point with QDLDL is 20-30 % faster on the largest paper panel, plain or with
    #: cohesion and ties, equal at 3,000 blocks and 1.4x slower at 5,000 (docs/engine.md, third pass).
    qdldl_max_rows: int = 9_000

    def __post_init__(self) -> None:
        if self.backend not in FACTORISATIONS:
            raise ValueError(
                f"IPMSettings.backend must be one of {', '.join(map(repr, FACTORISATIONS))}, got {self.backend!r}"
            )


@dataclass(frozen=True)
class IPMResult:
    """The interior point's answer for Eq. 10 (kinematic u, static μ and α).

    ``status`` is ``optimal`` (tolerances met), ``max_iterations``, ``diverged`` (iterates blow
    up: no mechanism or no static field, for Clarabel's infeasibility certificates to decide),
    or ``numerical_error``.  Only alma's certificate turns ``optimal`` into a proven answer.
    """

    status: str
    u: np.ndarray  # (3 n_free,) mechanism, f_Lᵀu = N
    mu: np.ndarray  # (k,) generator multipliers, μ ≥ 0
    alpha: float  # load multiplier of the static field H μ + f_0 + α f_L ≈ 0
    iterations: int
    gap: float  # relative duality gap at the end
    primal_residual: float  # relative ‖Hᵀu − s‖∞ and |f_Lᵀu − N| / N, the larger
    dual_residual: float  # ‖H μ + f_0 + α f_L‖∞ / max(1, ‖f_0‖∞)
    backend: str
    timings: dict = field(default_factory=dict)  # seconds per phase: pattern, factor, solve, total
    #: The normal-equations pattern used (alma.engine.normal), for another friction of the geometry.
    pattern: Any = field(default=None, repr=False, compare=False)
