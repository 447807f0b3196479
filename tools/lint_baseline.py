"""Count what the lint baseline hides: the ruff findings and mypy errors in the files and modules
that pyproject.toml marks "owned by another change this round; to be cleared".

`make lint` checks every other file in full and exits non-zero on any finding; this script runs
the same ruff and mypy without the baseline and counts, per baseline entry, what is left to clear.
Run from the top of a clone: ``python tools/lint_baseline.py`` (``make lint-baseline``).
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
import tomllib
from collections import Counter
from fnmatch import fnmatch
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MARK = "owned by another change this round"
PATHS = ["alma", "tests", "verification", "benchmarks", "studies", "tools"]


def baseline(text: str) -> tuple[list[str], list[str]]:
    """(ruff path globs, mypy module patterns) on the lines that carry the baseline's mark."""
    marked = [line for line in text.splitlines() if MARK in line]
    globs = [m.group(1) for line in marked if (m := re.match(r'\s*"([^"]+)"\s*=', line))]
    modules = [m.group(1) for line in marked if (m := re.match(r'\s*"([^"]+)",', line))]
    return globs, modules


def _toml_list(values: list[str]) -> str:
    return "[" + ", ".join(json.dumps(v) for v in values) + "]"


def ruff_counts(config: dict, globs: list[str]) -> Counter[str]:
    """Findings per baseline glob, with the baseline's per-file ignores taken out."""
    kept = {k: v for k, v in config["tool"]["ruff"]["lint"].get("per-file-ignores", {}).items() if k not in globs}
    entries = ", ".join(f"{json.dumps(k)} = {_toml_list(v)}" for k, v in kept.items())
    inline = "lint.per-file-ignores = {" + entries + "}"
    out = subprocess.run([sys.executable, "-m", "ruff", "check", *PATHS, "--output-format", "json", "--config", inline],
                         cwd=ROOT, capture_output=True, text=True)
    counts: Counter[str] = Counter()
    for finding in json.loads(out.stdout or "[]"):
        path = Path(finding["filename"]).resolve().relative_to(ROOT).as_posix()
        counts.update(g for g in globs if fnmatch(path, g.replace("/**", "/*")) or path == g)
    return counts


def mypy_counts(config: dict, modules: list[str]) -> Counter[str]:
    """Errors per baseline module pattern, with mypy's configuration minus the baseline override."""
    mypy = config["tool"]["mypy"]
    lines = ["[mypy]"] + [f"{k} = {', '.join(v) if isinstance(v, list) else v}" for k, v in mypy.items()
                          if k != "overrides"]
    for override in mypy.get("overrides", []):
        names = override["module"] if isinstance(override["module"], list) else [override["module"]]
        if set(names) <= set(modules):
            continue
        options = {k: v for k, v in override.items() if k != "module"}
        lines += [f"[mypy-{','.join(names)}]"] + [f"{k} = {v}" for k, v in options.items()]
    with tempfile.NamedTemporaryFile("w", suffix=".ini", delete=False) as fh:
        fh.write("\n".join(lines) + "\n")
    out = subprocess.run([sys.executable, "-m", "mypy", "--config-file", fh.name], cwd=ROOT, capture_output=True,
                         text=True)
    Path(fh.name).unlink()
    counts: Counter[str] = Counter()
    for line in out.stdout.splitlines():
        m = re.match(r"(\S+)\.py:\d+: error:", line)
        if m:
            module = m.group(1).replace("/", ".").removesuffix(".__init__")
            counts.update(p for p in modules if module == p or (p.endswith(".*") and
                                                                (module + ".").startswith(p[:-1])))
    return counts


def main() -> int:
    text = (ROOT / "pyproject.toml").read_text()
    config = tomllib.loads(text)
    globs, modules = baseline(text)
    ruff, mypy = ruff_counts(config, globs), mypy_counts(config, modules)
    for name, counts, keys in (("ruff findings", ruff, globs), ("mypy errors", mypy, modules)):
        print(f"{name} in the baseline: {sum(counts.values())}")
        for key in keys:
            print(f"  {counts[key]:4d}  {key}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
