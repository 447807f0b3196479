"""One crisp mechanism out of the optimal face of Eq. 10.

Where several mechanisms attain α_c (common in the dilatant model: a panel that slides at
α = f may slide on any set of courses), the interior point returns a blend of them, the centre
of the optimal face: joints of blocks that barely move show as sliding.  After the certified
solve a second LP picks the sparsest mechanism among those that attain the certified α::

    min  1ᵀ Hᵀu     s.t.  f_Lᵀu = 1,  Hᵀu ≥ 0,  and  (Hᵀu)_S = 0   or   −f_0ᵀu ≤ α (1 + δ)

1ᵀHᵀu sums the power of every cone generator, twice the opening of every contact point: the
L1 norm of the joints' relative motion under the flow rule (Eq. 6).  The optimal face is given
by complementary slackness (no power in the generators S that carry the certified stress
field), which HiGHS's presolve removes, or, when the interior point's partition does not
define it, by the cap on the dead load's work.  HiGHS's interior point with crossover returns a
vertex, which moves as few joints as the face allows.  The certified α and its bounds stay
those of the main solve; the crisp mechanism's own α must meet them within δ, or the interior
point's mechanism is kept.  Dimensionless, as :mod:`alma.mechanics.model`.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from alma.backends.highs_backend import solve_conic_form
from alma.floats import dot
from alma.mechanics.model import Model
from alma.status import Status

#: f_Lᵀu per free block in the crisp LP: the scale at which HiGHS certifies (see
#: ``SIMPLEX_NORMALISATIONS`` in :mod:`alma.associative.lp`).
CRISP_NORMALISATION = 10.0
#: A generator is held without power when its relative multiplier exceeds this multiple of its
#: relative power: the interior point's two sides differ by orders of magnitude there.
SUPPORT = 1e3


def crisp_mechanism(
    model: Model,
    alpha: float,
    slack: float,
    multipliers: np.ndarray,
    mechanism: np.ndarray,
    *,
    max_blocks_capped: int,
    time_limit: float | None = None,
    keep: tuple[np.ndarray, float] | None = None,
) -> tuple[np.ndarray | None, str]:
    """The sparsest mechanism (f_Lᵀu = 1) of the optimal face of the certified ``alpha``, from
    the interior point's pair (``multipliers``, ``mechanism``); (None, why) when none is found.

    The capped form (no complementarity) runs only up to ``max_blocks_capped`` free blocks: it
    costs tens of solves on the largest panels.  ``keep`` = (r, v): only mechanisms with
    rᵀu ≥ v (f_Lᵀu = 1), e.g. a control block's velocity at least the interior point's.
    """
    H = model.equilibrium
    power = np.maximum(H.T @ mechanism, 0.0)
    tight = multipliers / max(float(multipliers.max(initial=0.0)), 1e-300) > SUPPORT * power / max(
        float(power.max(initial=0.0)), 1e-300
    )
    u, why = _solve(model, alpha, slack, tight, time_limit, keep)
    if u is None and model.n_free <= max_blocks_capped:
        u, why = _solve(model, alpha, slack, np.zeros_like(tight), time_limit, keep)
    return u, why


def _solve(
    model: Model,
    alpha: float,
    slack: float,
    tight: np.ndarray,
    time_limit: float | None,
    keep: tuple[np.ndarray, float] | None = None,
) -> tuple[np.ndarray | None, str]:
    H = model.equilibrium
    scale = CRISP_NORMALISATION * model.n_free
    k = int(tight.sum())
    # With the equalities the face is fixed and the cap is redundant (and a round-off away from
    # making the LP infeasible); without them the cap on the dead load's work defines the face.
    cap = [] if k else [sp.csr_matrix(-model.dead)]
    kept = [] if keep is None else [sp.csr_matrix(-keep[0])]
    A = sp.vstack(
        [sp.csr_matrix(model.live), -H.T[np.flatnonzero(tight)], *cap, -H.T[np.flatnonzero(~tight)], *kept]
    ).tocsc()
    limit = (alpha + slack * max(1.0, abs(alpha))) * scale
    b = np.concatenate(
        [
            [scale],
            np.zeros(k),
            [] if k else [limit],
            np.zeros(int((~tight).sum())),
            [] if keep is None else [-keep[1] * scale],
        ]
    )
    cost = np.asarray(H @ np.ones(H.shape[1])).ravel()
    sol = solve_conic_form(cost, A, b, 1 + k, time_limit=time_limit, solver="ipm")
    form = "complementary" if k else "capped"
    if sol.status != Status.OPTIMAL:
        return None, f"crisp mechanism ({form}): {sol.solver} {sol.raw_status}"
    u = sol.x[: H.shape[0]] / scale
    why = _off_face(model, alpha, slack, u)
    if why:
        return None, f"crisp mechanism ({form}): {why}"
    return u / dot(model.live, u), f"crisp mechanism: a vertex of the optimal face ({form} form)"


def on_face(
    model: Model, alpha: float, slack: float, u: np.ndarray, keep: tuple[np.ndarray, float] | None = None
) -> np.ndarray | None:
    """``u`` normalised to f_Lᵀu = 1 where it is a mechanism of the optimal face of the certified
    ``alpha`` by the tests a crisp vertex meets (flow rule to 1e-9, its own α within 2 ``slack``)
    and keeps rᵀu ≥ v (``keep`` = (r, v), as :func:`crisp_mechanism`); None otherwise.

    A capacity curve's next configuration keeps its mechanism this way while that mechanism is
    still optimal there, and needs no crisp LP.
    """
    if not dot(model.live, u) > 0:
        return None
    u = u / dot(model.live, u)
    if _off_face(model, alpha, slack, u) or (keep is not None and float(keep[0] @ u) < keep[1]):
        return None
    return u


def _off_face(model: Model, alpha: float, slack: float, u: np.ndarray) -> str:
    """Why the mechanism ``u`` (f_Lᵀu > 0) is not on the optimal face of ``alpha``; "" if it is."""
    H = model.equilibrium
    size = float((abs(H.T) @ np.abs(u)).max(initial=0.0))
    if -float((H.T @ u).min(initial=0.0)) > 1e-9 * max(size, 1e-300):
        return "breaks the flow rule beyond 1e-9"
    own = -dot(model.dead, u) / dot(model.live, u)
    if abs(own - alpha) > 2 * slack * max(1.0, abs(alpha)):
        return f"α {own:.12g} off the certified {alpha:.12g}"
    return ""
