"""alma works from a wheel installed outside the repository (``alma paper`` included)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# Builds and installs a wheel, then runs `alma paper` on the 108 panels from it: minutes.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> tuple[Path, dict[str, str]]:
    """The wheel built from this checkout, installed (without dependencies, which the test venv
    has) into a folder of its own; the environment that imports alma from there."""
    tmp = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "-w", str(tmp / "dist"), str(ROOT)],
        check=True,
        cwd=tmp,
    )
    wheels = sorted((tmp / "dist").glob("alma-*.whl"))
    assert len(wheels) == 1, wheels
    site = tmp / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--target", str(site), str(wheels[0])],
        check=True,
        cwd=tmp,
    )
    env = dict(os.environ, PYTHONPATH=str(site))
    return site, env


def _alma(env: dict[str, str], cwd: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "alma.cli", *args], capture_output=True, text=True, env=env, cwd=cwd, timeout=600
    )


def test_the_wheel_is_the_alma_that_runs(installed, tmp_path):
    site, env = installed
    out = subprocess.run(
        [sys.executable, "-c", "import alma; print(alma.__file__)"],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        check=True,
    ).stdout.strip()
    assert Path(out).resolve().is_relative_to(site.resolve()), out
    assert not any(p.name == "data" for p in (site / "alma").rglob("*") if p.is_dir()), (
        "the package ships no published data"
    )


def test_alma_paper_runs_from_the_wheel(installed, tmp_path):
    _site, env = installed
    assert _alma(env, tmp_path, "paper", "--help").returncode == 0
    missing = _alma(env, tmp_path, "paper", "--out", str(tmp_path / "p"))
    assert missing.returncode == 2 and "--published" in missing.stderr
    done = _alma(
        env,
        tmp_path,
        "paper",
        "--out",
        str(tmp_path / "p"),
        "--workers",
        "2",
        "--published",
        str(ROOT / "paper_tables" / "data"),
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert re.search(r"Table 5: \d+/108 agree", done.stdout), done.stdout
    table5 = (tmp_path / "p" / "table5_comparison.csv").read_text().splitlines()
    assert len(table5) == 1 + 108
    assert (tmp_path / "p" / "comparison.md").is_file()


def test_the_code_revision_of_a_wheel_is_the_checkouts(installed, tmp_path):
    """Study keys hash alma's source (``code_revision``): from a wheel, without git, it is the
    same as from the checkout it was built from."""
    from alma.study.keys import code_revision

    site, env = installed
    probe = "import alma, alma.study.keys as k; print(alma.__file__); print(k.code_revision())"
    out = subprocess.run(
        [sys.executable, "-c", probe], env=env, cwd=tmp_path, capture_output=True, text=True, check=True
    ).stdout.split()
    assert out[0].startswith(str(site)) and out[1] == code_revision()
