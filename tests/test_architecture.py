"""The layers of docs/architecture.md: alma imports its own modules at module level only, and
the module-level imports form no cycle.

A function-local ``import alma…`` hides an edge of the import graph (the usual reason is to
dodge a cycle); imports under ``if TYPE_CHECKING:`` are annotations only and do not count.
"""

from __future__ import annotations

import ast
import dataclasses
import pickle
from pathlib import Path

import alma
from alma.engine import PatternCache

ALMA = Path(__file__).resolve().parents[1] / "alma"

#: Function-local imports kept on purpose, per module, with the reason.  The study commands'
#: handlers import their layer when run: at module level they would import pandas, statsmodels,
#: scipy.stats and matplotlib for every command (``import alma.cli.main`` 1.6 s → 4.3 s,
#: measured); the modules they import do not import ``alma.cli``, so no cycle hides here.
LAZY = {
    "alma/cli/study.py": {
        "alma.study.doe",
        "alma.stats.anova",
        "alma.study.store",
        "alma.paper.tables",
        "alma.study.compare",
    }
}


def _modules(root: Path = ALMA) -> dict[str, Path]:
    return {_module_name(p, root): p for p in sorted(root.rglob("*.py"))}


def _type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = set(_modules())


def _imported(node: ast.Import | ast.ImportFrom, module: str, package: bool) -> list[str]:
    """The alma modules one import statement names (relative imports resolved against ``module``)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] == "alma"]
    base = node.module or ""
    if node.level:
        parent = module.split(".")[: len(module.split(".")) - node.level + (1 if package else 0)]
        base = ".".join([*parent, base] if base else parent)
    if base.split(".")[0] != "alma":
        return []
    # `from alma.x import y` depends on the submodule alma.x.y if there is one, else on alma.x
    # (whose package __init__ Python runs first either way: no edge of its own).
    return sorted({f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base for a in node.names})


def imports(path: Path, root: Path = ALMA) -> tuple[set[str], list[tuple[int, str]]]:
    """(alma modules imported at module level, [(line, module)] imported inside a function or
    class body), both outside ``if TYPE_CHECKING:`` blocks."""
    module = _module_name(path, root)
    package = path.name == "__init__.py"
    top: set[str] = set()
    local: list[tuple[int, str]] = []

    def walk(node: ast.AST, nested: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _type_checking(child):
                for other in child.orelse:  # the else branch runs
                    walk(ast.Module(body=[other], type_ignores=[]), nested)
                continue
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                names = _imported(child, module, package)
                if nested:
                    local.extend((child.lineno, name) for name in names)
                else:
                    top.update(names)
            walk(child, nested or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)))

    walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path)), False)
    return top, local


def test_alma_modules_are_imported_at_module_level():
    offenders = {}
    for name, path in _modules().items():
        rel = str(path.relative_to(ALMA.parent))
        _, local = imports(path)
        left = [f"{line}: {mod}" for line, mod in local if mod not in LAZY.get(rel, set())]
        if left:
            offenders[rel] = left
    assert offenders == {}


def test_the_lazy_list_holds_only_what_is_still_lazy():
    """An entry of LAZY that the module no longer imports lazily is removed from the list."""
    for rel, allowed in LAZY.items():
        _, local = imports(ALMA.parent / rel)
        assert allowed == {mod for _, mod in local}, rel


def _cycle(graph: dict[str, set[str]]) -> list[str]:
    """One cycle of ``graph`` (a list of nodes, the first repeated at the end), or []."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str]:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return [*stack[stack.index(nxt) :], nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        stack.pop()
        state[node] = 2
        return []

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return []


def _graph() -> dict[str, set[str]]:
    """Module-level import edges between alma's modules (a package's ``__init__`` re-exports are
    edges of the package; ``alma/__init__.py`` itself, the public facade, is left out)."""
    modules = _modules()
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        if name == "alma":
            continue
        top, _ = imports(path)
        graph[name] = {m for m in top if m in modules and m not in (name, "alma")}
    return graph


def test_the_module_level_imports_form_no_cycle():
    assert _cycle(_graph()) == []


def test_the_checks_see_what_they_look_for(tmp_path):
    """The checks themselves: a function-local import is found, one under TYPE_CHECKING is not;
    relative imports resolve; a cycle is found."""
    root = tmp_path / "alma"
    (root / "geometry").mkdir(parents=True)
    (root / "__init__.py").write_text("")
    (root / "geometry" / "__init__.py").write_text("")
    module = root / "geometry" / "m.py"
    module.write_text(
        "from typing import TYPE_CHECKING\n"
        "import numpy\n"
        "from alma.status import Status\n"
        "from . import edges\n"
        "if TYPE_CHECKING:\n    from alma.geometry.scene import Scene\n"
        "def f():\n    import numpy\n    from alma.mechanics import model\n"
        "    if TYPE_CHECKING:\n        import alma.results\n"
        "class C:\n    def g(self):\n        from ..solve import solve\n        import alma.tilt\n"
    )
    top, local = imports(module, root)
    assert top == {"alma.status", "alma.geometry.edges"}
    assert local == [(9, "alma.mechanics.model"), (14, "alma.solve"), (15, "alma.tilt")]
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set(), "c": {"a", "b"}}) == []


def test_a_solve_writes_nothing_into_its_model():
    """No write into a caller's object: after both models (the LP, the friction search, its
    canonical drawing, the f = 0 bound) every field of the model and its H are as they were."""
    model = alma.build_model(alma.paper_panel("stack", "2:1", "4:1", 0.6))

    def state() -> bytes:
        return pickle.dumps(
            [
                *(getattr(model, f.name) for f in dataclasses.fields(model)),
                model.equilibrium,
                model.equilibrium.indices,
                model.contact_points,
            ]
        )

    before = state()
    patterns = PatternCache()
    first = alma.solve(model, model="both", patterns=patterns)
    assert state() == before
    again = alma.solve(model, model="both", patterns=patterns)
    assert first.to_dict()["ratio"] == again.to_dict()["ratio"]
    assert first.nonassociative.alpha == again.nonassociative.alpha
