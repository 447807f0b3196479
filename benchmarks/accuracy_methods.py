"""The methods that ``bench_accuracy`` times on the associative LP (Eq. 10 and its static dual).

Each is ``run(model, time_limit) -> (α, status)`` (α dimensionless, the time limit in s): alma
at each tolerance, Clarabel plain, HiGHS's interior point (with and without crossover) and dual
simplex through scipy's ``linprog`` on the static LP, and the kinematic LP written in cvxpy.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import scipy.sparse as sp
from scipy.optimize import OptimizeWarning, linprog

import alma
from benchmarks.bench_lp import plain_clarabel

DEFAULT_TOLERANCE = 1e-11
TOLERANCES = (1e-6, 1e-8, 1e-10, 1e-11)


def alma_method(tol: float):
    def run(model, time_limit):
        r = alma.solve(model, tolerance=tol)
        return r.alpha, r.status

    return run


def _static_arrays(model):
    H = model.equilibrium
    k = H.shape[1]
    A = sp.hstack([H, sp.csc_matrix(model.live.reshape(-1, 1))]).tocsc()
    c = np.zeros(k + 1)
    c[-1] = -1.0
    bounds = [(0, None)] * k + [(None, None)]
    return c, A, bounds


def highs_static(method: str, crossover: bool = True):
    def run(model, time_limit):
        c, A, bounds = _static_arrays(model)
        options: dict[str, float | str] = {"time_limit": float(time_limit)}
        if not crossover:
            options["run_crossover"] = "off"  # passed to HiGHS verbatim by SciPy
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", OptimizeWarning)
            res = linprog(c, A_eq=A, b_eq=-model.dead, bounds=bounds, method=method, options=options)
        if res.status != 0:
            return math.nan, f"status {res.status}: {res.message[:40]}"
        return float(res.x[-1]), "optimal"

    return run


def cvxpy_kinematic(solver: str):
    def run(model, time_limit):
        import cvxpy as cp

        H = model.equilibrium
        u = cp.Variable(H.shape[0])
        problem = cp.Problem(cp.Minimize(-model.dead @ u), [model.live @ u == 1, H.T @ u >= 0])
        kwargs = {"time_limit": float(time_limit)}
        try:
            with warnings.catch_warnings():  # "Solution may be inaccurate": reported via the status
                warnings.simplefilter("ignore", UserWarning)
                problem.solve(solver=solver, **kwargs)
        except cp.error.SolverError as exc:  # pragma: no cover - reported, not raised
            return math.nan, f"error: {exc}"[:50]
        if problem.status != cp.OPTIMAL:
            return (float(problem.value) if problem.value is not None else math.nan), str(problem.status)
        return float(problem.value), "optimal"

    return run


def method_table():
    methods = {}
    for tol in TOLERANCES:
        name = f"alma tol={tol:.0e}" + (" (default)" if tol == DEFAULT_TOLERANCE else "")
        methods[name] = alma_method(tol)
    methods["clarabel plain"] = plain_clarabel
    methods["highs-ipm"] = highs_static("highs-ipm")
    methods["highs-ipm no crossover"] = highs_static("highs-ipm", crossover=False)
    methods["highs-ds"] = highs_static("highs-ds")
    methods["cvxpy CLARABEL"] = cvxpy_kinematic("CLARABEL")
    methods["cvxpy HIGHS"] = cvxpy_kinematic("HIGHS")
    return methods


DEFAULT_NAME = f"alma tol={DEFAULT_TOLERANCE:.0e} (default)"
