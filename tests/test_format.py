"""`ruff format` is enforced (`make lint`, pre-commit) and every module stays under the house's
400 lines (docs/decisions.md, "Lint": the formatter's growth was met by splitting modules)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: The house's limit on a module's length (issue 15: modules by concept, none over 400 lines).
MAX_LINES = 400
FOLDERS = ("alma", "tests", "verification", "benchmarks", "studies", "tools", "paper_tables")


def _python_files() -> list[Path]:
    files = [ROOT / "conftest.py"]
    for folder in FOLDERS:
        files += sorted((ROOT / folder).rglob("*.py"))
    return files


def test_every_module_is_at_most_400_lines():
    long = {}
    for path in _python_files():
        n = len(path.read_text(encoding="utf-8").splitlines())
        if n > MAX_LINES:
            long[str(path.relative_to(ROOT))] = n
    assert long == {}


def test_the_formatter_is_configured_and_enforced():
    fmt = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["ruff"]["format"]
    assert fmt["quote-style"] == "double" and fmt["skip-magic-trailing-comma"] is True
    makefile = (ROOT / "Makefile").read_text()
    recipe = re.search(r"^lint:.*?\n((?:\t.*\n)+)", makefile, re.M)
    assert recipe is not None and "$(BIN)/ruff format --check $(LINT_PATHS)" in recipe.group(1)
    hooks = (ROOT / ".pre-commit-config.yaml").read_text()
    assert "entry: ruff format" in hooks
