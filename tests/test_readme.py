"""The README's commands run as written.

Every shell command in the README's ``sh`` code blocks (and the ``python`` blocks) runs from a
temporary folder that holds what a clone holds and the README names (``examples/``, the published
tables of ``paper_tables/data/``, ``verification/data/``), in the README's order, with ``alma``
the checkout under test, and exits 0.  Commands that take minutes, or that build the
environment this test already runs in, are listed in ``EXCLUDED`` with the reason.  ``make test``
runs the quick commands in one process through ``alma.cli.main``; ``make test-slow`` runs them
again as written, by bash, then the whole-study commands and the python blocks.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from alma.cli import main as cli_main

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"

# What a clone holds that the README's commands read (paths relative to the clone).
SHIPPED = ("examples", "paper_tables/data", "verification/data/table5_collapse_multipliers.csv")

_STUDY = "the 108 panels with both models (~10 min on 2 cores); `alma compare` runs here on examples/small.toml"
EXCLUDED: dict[str, str] = {
    "make demo": "builds .venv with pip (minutes, the network); CI's `make test` builds the same venv, and the "
    "command it then runs (`alma panel ... --plot`) runs here",
    ". .venv/bin/activate": "sources the venv that `make demo` built; here PATH leads to the alma under test",
    "make test": "this suite itself",
    "make compare": _STUDY,
    "alma compare --out cmp/ --workers 2": _STUDY,
    "alma compare --out cmp15/ --workers 2 --time-limit 15": _STUDY,
    "alma paper --out paper/ --nonassociative": "runs the 108-panel comparison of both models first: " + _STUDY,
}
# Whole studies (108 or 432 panels): a minute or more each on 2 cores, so in the slow test.
SLOW: frozenset[str] = frozenset(
    {
        "alma doe --out results/ --workers 2",
        "alma paper --out paper/",
        "alma doe --out chain_study/ --design examples/design_chain.toml --workers 2",
        "alma anova chain_study/results.csv",
    }
)


def _blocks(text: str, languages: tuple[str, ...]) -> list[str]:
    """The bodies of the fenced code blocks of the given languages, in order."""
    pattern = re.compile(r"^```([A-Za-z]*)[ \t]*\n(.*?)^```[ \t]*$", re.M | re.S)
    return [m.group(2) for m in pattern.finditer(text) if m.group(1) in languages]


def shell_commands(text: str) -> list[str]:
    """Every command of the ``sh`` blocks: continuation lines joined, comment lines dropped."""
    commands = []
    for body in _blocks(text, ("sh", "bash", "shell")):
        joined = re.sub(r"\\\n\s*", " ", body)
        commands += [line.strip() for line in joined.splitlines() if line.strip() and not line.strip().startswith("#")]
    return commands


def key(command: str) -> str:
    """The command's words without its trailing comment: the name it has in EXCLUDED and SLOW."""
    return " ".join(shlex.split(command, comments=True))


COMMANDS = shell_commands(README.read_text(encoding="utf-8"))
PYTHON_BLOCKS = _blocks(README.read_text(encoding="utf-8"), ("python",))


def test_the_readme_has_its_commands():
    keys = [key(c) for c in COMMANDS]
    assert len(keys) >= 25, keys
    assert "alma solve examples/small.json --model nonassociative --certify" in keys
    assert any(k.startswith("alma wall ") and k.endswith("--export-scene facade.dxf") for k in keys), keys


def test_every_exclusion_names_a_readme_command():
    """An exclusion or a slow command that the README no longer shows is stale."""
    keys = {key(c) for c in COMMANDS}
    assert set(EXCLUDED) <= keys, set(EXCLUDED) - keys
    assert SLOW <= keys, SLOW - keys
    assert not SLOW & set(EXCLUDED)


def test_the_files_the_readme_names_are_shipped():
    """Every path a command reads from the clone (examples/, verification/, paper_tables/) exists."""
    named = {
        word
        for c in COMMANDS
        for word in shlex.split(c, comments=True)
        if word.startswith(("examples/", "verification/", "paper_tables/"))
    }
    named |= set(re.findall(r"\"(examples/[^\"]+)\"", "\n".join(PYTHON_BLOCKS)))
    assert named, "the README names no shipped file"
    missing = sorted(p for p in named if not (ROOT / p).exists())
    assert not missing, missing


def _clone_like(tmp: Path) -> dict[str, str]:
    """``tmp`` filled with the shipped files; the environment whose ``alma`` and ``python`` are
    the interpreter running this test with the checkout first on its path."""
    for rel in SHIPPED:
        src, dst = ROOT / rel, tmp / rel
        dst.parent.mkdir(parents=True, exist_ok=True)
        (shutil.copytree if src.is_dir() else shutil.copy)(src, dst)
    shims = tmp / ".bin"
    shims.mkdir()
    (shims / "alma").write_text(f'#!/bin/sh\nexec "{sys.executable}" -m alma.cli "$@"\n')
    (shims / "python").write_text(f'#!/bin/sh\nexec "{sys.executable}" "$@"\n')
    for shim in shims.iterdir():
        shim.chmod(0o755)
    pythonpath = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p)
    return dict(
        os.environ, PATH=f"{shims}{os.pathsep}{os.environ.get('PATH', '')}", PYTHONPATH=pythonpath, MPLBACKEND="Agg"
    )


def _run_all(commands: list[str], tmp: Path, env: dict[str, str]) -> list[str]:
    """Run the commands in order in ``tmp``; the failures, each with the end of its stderr."""
    failures = []
    for command in commands:
        done = subprocess.run(
            ["bash", "-c", command],
            cwd=tmp,
            env=env,
            capture_output=True,
            text=True,
            timeout=900,
            stdin=subprocess.DEVNULL,
        )
        if done.returncode != 0:
            failures.append(f"exit {done.returncode}: {command}\n{done.stderr[-1500:]}")
    return failures


def test_the_readme_commands_exit_0(tmp_path, monkeypatch, capsys):
    """The commands that take seconds, in the README's order (later ones read what earlier ones
    wrote: flemish.json, facade.dxf), each through ``alma.cli.main`` with the README's words as
    its argv, in one process (the shell and the entry point are the slow test's)."""
    _clone_like(tmp_path)
    monkeypatch.chdir(tmp_path)
    run = [c for c in COMMANDS if key(c) not in EXCLUDED and key(c) not in SLOW]
    assert len(run) >= 15 and all(c.startswith("alma ") for c in run), run
    failures = []
    for command in run:
        code = cli_main(shlex.split(command, comments=True)[1:])
        if code != 0:
            failures.append(f"exit {code}: {command}\n{capsys.readouterr().err[-1500:]}")
    assert not failures, "\n\n".join(failures)
    assert (tmp_path / "out.png").is_file() and (tmp_path / "cohesion.png").is_file()


@pytest.mark.slow
def test_the_readme_commands_run_in_a_shell(tmp_path):
    """The same commands as written, each by bash with ``alma`` on the PATH."""
    env = _clone_like(tmp_path)
    failures = _run_all([c for c in COMMANDS if key(c) not in EXCLUDED and key(c) not in SLOW], tmp_path, env)
    assert not failures, "\n\n".join(failures)


@pytest.mark.slow
def test_the_readme_studies_and_python_run(tmp_path):
    """The whole-study commands, then every python block (the README's API tour)."""
    env = _clone_like(tmp_path)
    failures = _run_all([c for c in COMMANDS if key(c) in SLOW], tmp_path, env)
    assert (tmp_path / "results" / "results.csv").is_file()
    for body in PYTHON_BLOCKS:
        done = subprocess.run(
            [sys.executable, "-c", body],
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            timeout=900,
            stdin=subprocess.DEVNULL,
        )
        if done.returncode != 0:
            failures.append(f"exit {done.returncode}: python block\n{body}\n{done.stderr[-1500:]}")
    assert not failures, "\n\n".join(failures)
