"""One result type for every solver call, and the one place where solvers' statuses are read.

Each adapter (:mod:`alma.backends.clarabel_backend`, :mod:`~alma.backends.highs_backend`,
:mod:`~alma.backends.linprog_backend`, :mod:`~alma.backends.ipopt_backend`, and alma's own
interior point) returns a :class:`SolverResult`: the solver's raw status, kept verbatim, read
through this module's tables into a :class:`Termination` — what the solver says happened, the
same words for every solver (as cvxpy's ``*_conif.py`` maps or linopy's
``TerminationCondition``).

What a termination *means* for limit analysis depends on the form of the problem solved:
:data:`KINEMATIC_MEANING` (a mechanism with f_Lᵀu fixed, as Eq. 10: infeasible means no
mechanism, unbounded no static field) and :data:`STATIC_MEANING` (max α over stress fields: the
other way round).  A solver's ``optimal`` is only a candidate; alma's certificates decide.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Literal

import numpy as np

from alma.status import Status


class Termination(StrEnum):
    """Why a solver stopped, in one vocabulary for every solver."""

    #: The solver's optimality tolerances were met.
    OPTIMAL = "optimal"
    #: Optimal to reduced accuracy (Clarabel's "AlmostSolved").
    OPTIMAL_INACCURATE = "optimal_inaccurate"
    #: The problem has no feasible point (a certificate of infeasibility).
    INFEASIBLE = "infeasible"
    #: Infeasible to reduced accuracy.
    INFEASIBLE_INACCURATE = "infeasible_inaccurate"
    #: The objective is unbounded (a certificate: the dual is infeasible).
    UNBOUNDED = "unbounded"
    #: Unbounded to reduced accuracy.
    UNBOUNDED_INACCURATE = "unbounded_inaccurate"
    #: Infeasible or unbounded, the solver did not say which.
    INFEASIBLE_OR_UNBOUNDED = "infeasible_or_unbounded"
    #: The iteration (or node) budget was spent.
    ITERATION_LIMIT = "iteration_limit"
    #: Another work limit stopped it (solution count, objective bound or target).
    OTHER_LIMIT = "other_limit"
    #: The user's wall-clock cap stopped it.
    TIME_LIMIT = "time_limit"
    #: A callback or an interrupt stopped it.
    INTERRUPTED = "interrupted"
    #: Numerical trouble: the solver stopped without a verdict.
    NUMERICAL = "numerical"
    #: The solver failed (bad model, internal error, unknown status).
    ERROR = "error"

    @property
    def solved(self) -> bool:
        """Optimal, to full or reduced accuracy: a candidate solution is there."""
        return self in (Termination.OPTIMAL, Termination.OPTIMAL_INACCURATE)


#: Clarabel's ``SolverStatus`` names.
CLARABEL: dict[str, Termination] = {
    "Solved": Termination.OPTIMAL,
    "AlmostSolved": Termination.OPTIMAL_INACCURATE,
    "PrimalInfeasible": Termination.INFEASIBLE,
    "AlmostPrimalInfeasible": Termination.INFEASIBLE_INACCURATE,
    "DualInfeasible": Termination.UNBOUNDED,
    "AlmostDualInfeasible": Termination.UNBOUNDED_INACCURATE,
    "MaxIterations": Termination.ITERATION_LIMIT,
    "MaxTime": Termination.TIME_LIMIT,
    "NumericalError": Termination.NUMERICAL,
    "InsufficientProgress": Termination.NUMERICAL,
    "CallbackTerminated": Termination.INTERRUPTED,
    "Unsolved": Termination.ERROR,
}

#: HiGHS's ``HighsModelStatus`` names (``kUnknown``: the simplex ended without a verdict).
HIGHS: dict[str, Termination] = {
    "kOptimal": Termination.OPTIMAL,
    "kInfeasible": Termination.INFEASIBLE,
    "kUnbounded": Termination.UNBOUNDED,
    "kUnboundedOrInfeasible": Termination.INFEASIBLE_OR_UNBOUNDED,
    "kIterationLimit": Termination.ITERATION_LIMIT,
    "kSolutionLimit": Termination.OTHER_LIMIT,
    "kObjectiveBound": Termination.OTHER_LIMIT,
    "kObjectiveTarget": Termination.OTHER_LIMIT,
    "kTimeLimit": Termination.TIME_LIMIT,
    "kInterrupt": Termination.INTERRUPTED,
    "kHighsInterrupt": Termination.INTERRUPTED,
    "kUnknown": Termination.NUMERICAL,
}

#: ``scipy.optimize.linprog``'s integer status (its HiGHS methods): 4 is "numerical difficulties".
LINPROG: dict[int, Termination] = {
    0: Termination.OPTIMAL,
    1: Termination.ITERATION_LIMIT,
    2: Termination.INFEASIBLE,
    3: Termination.UNBOUNDED,
    4: Termination.NUMERICAL,
}

#: alma's interior point (:class:`alma.engine.types.IPMResult` statuses); "diverged" means the
#: iterates blew up (no mechanism or no static field), for an infeasibility certificate to decide.
ENGINE: dict[str, Termination] = {
    "optimal": Termination.OPTIMAL,
    "max_iterations": Termination.ITERATION_LIMIT,
    "diverged": Termination.INFEASIBLE_OR_UNBOUNDED,
    "numerical_error": Termination.NUMERICAL,
}

#: IPOPT's ``return_status`` names (through CasADi's ``stats()``).
IPOPT: dict[str, Termination] = {
    "Solve_Succeeded": Termination.OPTIMAL,
    "Solved_To_Acceptable_Level": Termination.OPTIMAL_INACCURATE,
    "Infeasible_Problem_Detected": Termination.INFEASIBLE,
    "Diverging_Iterates": Termination.UNBOUNDED,
    "Maximum_Iterations_Exceeded": Termination.ITERATION_LIMIT,
    "Maximum_CpuTime_Exceeded": Termination.TIME_LIMIT,
    "Maximum_WallTime_Exceeded": Termination.TIME_LIMIT,
    "User_Requested_Stop": Termination.INTERRUPTED,
    "Restoration_Failed": Termination.NUMERICAL,
    "Error_In_Step_Computation": Termination.NUMERICAL,
    "Search_Direction_Becomes_Too_Small": Termination.NUMERICAL,
}

#: Every solver's table, by the adapter's name for it.
TABLES: dict[str, dict] = {"clarabel": CLARABEL, "highs": HIGHS, "linprog": LINPROG, "engine": ENGINE, "ipopt": IPOPT}


def termination(solver: str, raw: object) -> Termination:
    """``raw`` (a status of ``solver``: a key of :data:`TABLES`) as a :class:`Termination`;
    ``ERROR`` for a status the table does not know."""
    return TABLES[solver].get(raw, Termination.ERROR)


#: A problem's form: ``kinematic`` (a mechanism, f_Lᵀu fixed, as Eq. 10) or ``static`` (max α).
Form = Literal["kinematic", "static"]

#: What each termination says about the structure for a problem in kinematic form.  ``optimal``
#: is only a candidate: the certificate decides.
KINEMATIC_MEANING: dict[Termination, Status] = {
    Termination.OPTIMAL: Status.OPTIMAL,
    Termination.OPTIMAL_INACCURATE: Status.OPTIMAL,
    Termination.INFEASIBLE: Status.NO_COLLAPSE,
    Termination.INFEASIBLE_INACCURATE: Status.NO_COLLAPSE,
    Termination.UNBOUNDED: Status.NO_EQUILIBRIUM,
    Termination.UNBOUNDED_INACCURATE: Status.NO_EQUILIBRIUM,
    Termination.INFEASIBLE_OR_UNBOUNDED: Status.NOT_CONVERGED,
    Termination.ITERATION_LIMIT: Status.NOT_CONVERGED,
    Termination.OTHER_LIMIT: Status.NOT_CONVERGED,
    Termination.TIME_LIMIT: Status.LIMIT_REACHED,
    Termination.INTERRUPTED: Status.LIMIT_REACHED,
    Termination.NUMERICAL: Status.NOT_CONVERGED,
    Termination.ERROR: Status.NOT_CONVERGED,
}

#: ... and for a problem in static form (max α): an infeasible one has no admissible stress field
#: (no equilibrium), an unbounded one carries any α (no collapse).  HiGHS's "unbounded or
#: infeasible" of a static LP is read as no equilibrium (its presolve says so when no field exists).
STATIC_MEANING: dict[Termination, Status] = {
    **KINEMATIC_MEANING,
    Termination.INFEASIBLE: Status.NO_EQUILIBRIUM,
    Termination.INFEASIBLE_INACCURATE: Status.NO_EQUILIBRIUM,
    Termination.UNBOUNDED: Status.NO_COLLAPSE,
    Termination.UNBOUNDED_INACCURATE: Status.NO_COLLAPSE,
    Termination.INFEASIBLE_OR_UNBOUNDED: Status.NO_EQUILIBRIUM,
}


def meaning(term: Termination, form: Form) -> Status:
    """What ``term`` says about the structure for a problem in ``form``."""
    if form not in ("kinematic", "static"):
        raise ValueError(f"form must be 'kinematic' or 'static', got {form!r}")
    return (KINEMATIC_MEANING if form == "kinematic" else STATIC_MEANING)[term]


@dataclass(frozen=True)
class SolverResult:
    """One solver call's answer, whatever the solver.

    ``duals`` follow the conic convention of ``min qᵀx s.t. A x + s = b``: q + Aᵀ duals = 0 at
    the optimum (duals = −∂ objective / ∂ b), one per row the adapter names; ``iterations`` are
    the solver's own work units (interior-point, simplex, crossover iterations); ``solve_time``
    (s) is reported, never decided on.
    """

    termination: Termination
    raw_status: str  # the solver's own word, verbatim
    x: np.ndarray
    duals: np.ndarray
    iterations: int
    solve_time: float
    solver: str  # e.g. "Clarabel", "HiGHS simplex", "alma-ipm/feral"
    form: Form = "kinematic"

    @property
    def status(self) -> Status:
        """The termination's meaning for the structure (:func:`meaning` of the result's form)."""
        return meaning(self.termination, self.form)
