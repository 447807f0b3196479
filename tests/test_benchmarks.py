"""The benchmarks' harness, and every benchmark and study importable as a module of the clone
(no ``sys.path`` edits), each make target naming one that exists."""

from __future__ import annotations

import importlib
import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from benchmarks import harness

ROOT = Path(__file__).resolve().parents[1]
MODULES = sorted(
    f"{p.parent.name}.{p.stem}"
    for folder in ("benchmarks", "studies")
    for p in (ROOT / folder).glob("*.py")
    if p.stem != "__init__"
)
# Every bench target the Makefile had before its pattern rule, still a name that works.
TARGETS = (
    "bench",
    "bench-assoc",
    "bench-accuracy",
    "bench-scaling",
    "bench-joints",
    "bench-nonassociative",
    "bench-certify",
    "bench-ipopt",
    "bench-floor",
    "bench-bounded",
    "bench-engine",
    "bench-crisp",
    "bench-crisp-floor",
    "bench-first-order",
)


def test_timed_takes_medians_and_keeps_the_last_value():
    calls = []

    def counted() -> int:
        calls.append(1)
        return len(calls)

    timing, value = harness.timed(counted, 3)
    assert value == 3 and timing.repeat == 3 and len(calls) == 3
    assert timing.best <= timing.median <= max(timing.times)
    timing, word = harness.timed(lambda: "once", 0)  # at least one run
    assert timing.repeat == 1 and word == "once"
    median, value = harness.median_time(lambda: 7, 2)
    assert median >= 0 and value == 7


def test_table_aligns_columns_and_rounds_floats():
    text = harness.table([{"case": "panel", "s": 0.123456}, {"case": "wall 20k", "s": 14.6}], digits=3)
    lines = text.splitlines()
    assert lines[0].split() == ["case", "s"] and len({len(line) for line in lines}) == 1
    assert "0.123" in lines[1] and "14.6" in lines[2]


def test_write_json_records_the_machine(tmp_path):
    path = harness.write_json(tmp_path / "out" / "run.json", [{"a": 1.5}], command="bench_lp")
    data = json.loads(path.read_text())
    assert data["rows"] == [{"a": 1.5}] and data["command"] == "bench_lp"
    assert {"cpus", "load_average_1_5_15", "alma"} <= set(data["machine"])


def test_table5_is_the_108_panels():
    rows = harness.table5()
    assert len(rows) == 108 and len({r[:4] for r in rows}) == 108


@pytest.mark.parametrize("module", MODULES)
def test_module_imports_without_path_edits(module):
    source = (ROOT / (module.replace(".", "/") + ".py")).read_text()
    assert "sys.path" not in source, module
    importlib.import_module(module)


@pytest.mark.skipif(shutil.which("make") is None, reason="needs make")
def test_every_bench_target_runs_an_existing_module():
    # `-o` holds the venv's stamp as up to date: a dry run must install nothing.  (Overriding STAMP
    # with the Makefile's own name made make remake the Makefile, which it does even under -n: a
    # pip install in the middle of the suite, which changed the installed version and with it the
    # study keys of tests running beside it.)
    done = subprocess.run(
        ["make", "-n", "-o", ".venv/.installed", *TARGETS], cwd=ROOT, capture_output=True, text=True, check=True
    )
    modules = re.findall(r"python -m ((?:benchmarks|studies)\.\S+)", done.stdout)
    assert len(modules) == len(TARGETS), done.stdout
    assert set(modules) <= set(MODULES), set(modules) - set(MODULES)
