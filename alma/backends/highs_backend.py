"""HiGHS adapter (highspy): a silenced solver instance and one status map.

HiGHS writes its banner and log to standard output unless told otherwise before its first
run; alma's ``--json`` output must be the only thing on standard output, so every instance is
created here with output switched off at the source.
"""
from __future__ import annotations

import highspy

from alma.status import Status

#: HiGHS model statuses as alma's vocabulary, for a problem in static form (maximise α): an
#: unbounded static problem carries any load (no collapse), an infeasible one has no field.
STATIC_STATUS: dict[str, Status] = {
    "kOptimal": Status.OPTIMAL,
    "kUnbounded": Status.NO_COLLAPSE,
    "kInfeasible": Status.NO_EQUILIBRIUM,
    "kUnboundedOrInfeasible": Status.NO_EQUILIBRIUM,
    "kIterationLimit": Status.NOT_CONVERGED,
    "kSolutionLimit": Status.NOT_CONVERGED,
    "kObjectiveBound": Status.NOT_CONVERGED,
    "kObjectiveTarget": Status.NOT_CONVERGED,
    "kTimeLimit": Status.LIMIT_REACHED,
    "kInterrupt": Status.LIMIT_REACHED,
}


def quiet_highs(**options: object) -> highspy.Highs:
    """A ``highspy.Highs`` that prints nothing, with ``options`` set (HiGHS option names)."""
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("log_to_console", False)
    for name, value in options.items():
        h.setOptionValue(name, value)
    return h


def static_status(h: highspy.Highs) -> Status:
    """The model status of ``h`` in alma's words (:data:`STATIC_STATUS`)."""
    name = str(h.getModelStatus()).rsplit(".", 1)[-1]
    return STATIC_STATUS.get(name, Status.NOT_CONVERGED)
