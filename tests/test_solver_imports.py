"""Every solver call goes through ``alma/backends/`` (one adapter per solver, SPEC house rules).

Fails when a module outside ``alma/backends/`` imports a solver package (HiGHS, Clarabel, QDLDL,
CasADi/IPOPT, SCIP, scipy's ``linprog``/``milp``).  ``alma/engine/`` is alma's own interior point
with its factorisation backends (QDLDL, feral), which are the product, not an adapter.
"""

from __future__ import annotations

import ast
from pathlib import Path

ALMA = Path(__file__).resolve().parents[1] / "alma"
SOLVERS = ("highspy", "clarabel", "qdldl", "casadi", "pyscipopt", "cvxpy")
SCIPY_SOLVERS = ("linprog", "milp")
EXEMPT = ("backends", "engine")


def solver_imports(path: Path) -> list[str]:
    """The solver imports of one module (any depth: function-local imports count too)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.split(".")[0] in SOLVERS]
        elif isinstance(node, ast.ImportFrom) and node.module:
            if node.module.split(".")[0] in SOLVERS:
                found.append(node.module)
            elif node.module.startswith("scipy.optimize"):
                found += [f"{node.module}.{a.name}" for a in node.names if a.name in SCIPY_SOLVERS]
    return found


def test_no_solver_import_outside_backends():
    offenders = {
        str(p.relative_to(ALMA.parent)): solver_imports(p)
        for p in sorted(ALMA.rglob("*.py"))
        if p.relative_to(ALMA).parts[0] not in EXEMPT
    }
    assert {k: v for k, v in offenders.items() if v} == {}


def test_the_check_sees_solver_imports(tmp_path):
    """The check itself: top-level, aliased, function-local and scipy imports are all found."""
    module = tmp_path / "m.py"
    module.write_text(
        "import highspy\nimport casadi as ca\nfrom scipy.optimize import linprog, minimize\n"
        "def f():\n    import clarabel\n    from qdldl import Solver\n"
    )
    assert solver_imports(module) == ["highspy", "casadi", "scipy.optimize.linprog", "clarabel", "qdldl"]
