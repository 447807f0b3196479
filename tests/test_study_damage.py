"""Damaged study files and concurrent runs (issue 32, items 3 and 4).

A tiny design (one panel ratio, one block ratio, two bonds, two frictions: 4 panels of ~20 ms)
is solved once; its ``results.csv`` is then damaged in each of the ways a file is damaged in
practice — an unbalanced quote, a line cut and followed by good rows, binary garbage, an edited
α, a lower bound above α, factors swapped under a key — and the next ``doe`` must report the
damage (count and line numbers on stderr), move the lines to ``quarantine.txt``, solve those
panels again and end with the clean run's rows.  Two runs on one folder: the second is refused
while the first holds the lock, and a lock left by a killed run does not block.
"""

from __future__ import annotations

import csv
import io
import os
import shutil
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

from alma.study.doe import COLUMNS, Design, panel_key, read_results, run_doe
from alma.study.integrity import row_checksum
from alma.study.keys import code_revision
from alma.study.lock import StudyBusy, study_lock
from alma.study.store import QUARANTINE_FILE

ROOT = Path(__file__).resolve().parents[1]
TINY = Design(panel_ratio=("2:1",), block_ratio=("4:1",), bond=("running", "english"), friction=(0.27, 0.60))
VALUES = [
    "panel_ratio",
    "block_ratio",
    "bond",
    "friction",
    "model",
    "status",
    "alpha_c",
    "alpha_lower",
    "alpha_upper",
    "mechanism_class",
    "key",
]


@pytest.fixture(scope="module")
def clean(tmp_path_factory) -> tuple[bytes, pd.DataFrame]:
    out = tmp_path_factory.mktemp("clean")
    df = run_doe(out, workers=1, design=TINY, progress=False)
    return (out / "results.csv").read_bytes(), df


def _rows(data: bytes) -> list[list[str]]:
    return list(csv.reader(io.StringIO(data.decode("utf-8"))))


def _write(rows: list[list[str]], resign: bool) -> bytes:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    for k, r in enumerate(rows):
        writer.writerow([*r[:-1], row_checksum(r[:-1])] if resign and k > 0 else r)
    return buf.getvalue().encode("utf-8")


def _lines(data: bytes) -> list[bytes]:
    return data.split(b"\n")[:-1]


def _unbalanced_quote(data: bytes) -> tuple[bytes, list[int]]:
    lines = _lines(data)
    lines[2] = b'"' + lines[2]
    return b"\n".join(lines) + b"\n", [3]


def _cut_line(data: bytes) -> tuple[bytes, list[int]]:
    lines = _lines(data)
    lines[1] = lines[1][:40]  # cut, and the good rows follow on their own lines
    return b"\n".join(lines) + b"\n", [2]


def _cut_and_merged(data: bytes) -> tuple[bytes, list[int]]:
    lines = _lines(data)
    merged = lines[1][:40] + lines[2]  # a cut line continued by the next row
    return b"\n".join([lines[0], merged, *lines[3:]]) + b"\n", [2]


def _garbage(data: bytes) -> tuple[bytes, list[int]]:
    lines = _lines(data)
    noise = bytes(range(256)) * 3
    return b"\n".join([*lines[:3], noise.replace(b"\n", b""), *lines[3:]]) + b"\n", [4]


def _alpha_changed(data: bytes) -> tuple[bytes, list[int]]:
    rows = _rows(data)
    rows[3][COLUMNS.index("alpha_c")] = repr(float(rows[3][COLUMNS.index("alpha_c")]) * 1.5)
    return _write(rows, resign=False), [4]


def _lower_above_alpha(data: bytes) -> tuple[bytes, list[int]]:
    rows = _rows(data)  # re-signed: the checksum holds, the values do not
    rows[2][COLUMNS.index("alpha_lower")] = repr(float(rows[2][COLUMNS.index("alpha_c")]) + 0.1)
    return _write(rows, resign=True), [3]


def _factors_swapped(data: bytes) -> tuple[bytes, list[int]]:
    rows = _rows(data)  # re-signed: only the key betrays them
    bond = COLUMNS.index("bond")
    rows[1][bond], rows[3][bond] = rows[3][bond], rows[1][bond]
    return _write(rows, resign=True), [2, 4]


DAMAGES = [
    _unbalanced_quote,
    _cut_line,
    _cut_and_merged,
    _garbage,
    _alpha_changed,
    _lower_above_alpha,
    _factors_swapped,
]


@pytest.mark.parametrize("damage", DAMAGES, ids=lambda f: f.__name__.strip("_"))
def test_damaged_rows_are_reported_quarantined_and_solved_again(damage, clean, tmp_path, capfd):
    data, good = clean
    damaged, line_numbers = damage(data)
    path = tmp_path / "results.csv"
    path.write_bytes(damaged)
    capfd.readouterr()
    if damage is not _factors_swapped:  # a plain read leaves the damage out, and says so
        rows = read_results(path)
        err = capfd.readouterr().err
        assert f"{len(line_numbers)} damaged or inconsistent row(s) (lines {', '.join(map(str, line_numbers))})" in err
        assert set(rows["key"]) <= set(good["key"]) and len(rows) >= len(good) - 2
    df = run_doe(tmp_path, workers=1, design=TINY, progress=False)
    err = capfd.readouterr().err
    assert f"{len(line_numbers)} damaged or inconsistent row(s) (lines {', '.join(map(str, line_numbers))})" in err
    assert "set aside" in err and QUARANTINE_FILE in err
    pd.testing.assert_frame_equal(df[VALUES], good[VALUES])
    quarantine = (tmp_path / QUARANTINE_FILE).read_bytes()
    assert quarantine.count(b"# results.csv line ") == len(line_numbers)
    # The file is sound again: one header, one line per panel, every checksum right, nothing to report.
    assert len(_lines(path.read_bytes())) == 1 + len(good)
    stored = read_results(path).set_index("key").loc[good["key"]].reset_index()
    pd.testing.assert_frame_equal(stored[VALUES], good[VALUES])
    assert capfd.readouterr().err == ""
    before = path.read_bytes()
    run_doe(tmp_path, workers=1, design=TINY, progress=False)  # nothing left to solve
    assert path.read_bytes() == before


def test_anova_of_a_damaged_file_leaves_the_row_out_without_a_pandas_error(clean, tmp_path, capfd):
    from alma.cli.main import main

    damaged, _ = _unbalanced_quote(clean[0])
    path = tmp_path / "results.csv"
    path.write_bytes(damaged)
    code = main(["anova", str(path), "--order", "1"])
    err = capfd.readouterr().err
    assert "line 3" in err and "Traceback" not in err and "Error tokenizing" not in err
    assert code in (0, 2)  # 3 rows may be too few for the model: then a clear error, exit 2


def test_the_doe_command_on_a_damaged_file_reports_and_resumes(clean, tmp_path, capfd):
    from alma.cli.main import main

    out = tmp_path / "study"
    out.mkdir()
    damaged, _ = _garbage(_unbalanced_quote(clean[0])[0])
    (out / "results.csv").write_bytes(damaged)
    design = tmp_path / "tiny.toml"
    design.write_text(
        'panel_ratio = ["2:1"]\nblock_ratio = ["4:1"]\nbond = ["running", "english"]\nfriction = [0.27, 0.6]\n'
    )
    capfd.readouterr()
    assert main(["doe", "--out", str(out), "--design", str(design), "--workers", "1", "--quiet"]) == 0
    captured = capfd.readouterr()
    assert "2 damaged or inconsistent row(s) (lines 3, 4)" in captured.err and "Traceback" not in captured.err
    assert "4 results in" in captured.out


def test_keys_hash_the_code_revision(tmp_path):
    base = panel_key("2:1", "4:1", "running", 0.27, "associative")
    assert base == panel_key("2:1", "4:1", "running", 0.27, "associative", revision=code_revision())
    assert base != panel_key("2:1", "4:1", "running", 0.27, "associative", revision="another")
    # A copy of the package (no git) with one changed source file has another revision.
    copy = tmp_path / "copy"
    shutil.copytree(ROOT / "alma", copy / "alma", ignore=shutil.ignore_patterns("__pycache__"))
    probe = "from alma.study.keys import code_revision; print(code_revision())"
    env = dict(os.environ, PYTHONPATH=str(copy))
    same = subprocess.run(
        [sys.executable, "-c", probe], env=env, cwd=tmp_path, capture_output=True, text=True, check=True
    )
    assert same.stdout.strip() == code_revision()
    with open(copy / "alma" / "settle.py", "a") as fh:
        fh.write("\n# a change\n")
    changed = subprocess.run(
        [sys.executable, "-c", probe], env=env, cwd=tmp_path, capture_output=True, text=True, check=True
    )
    assert changed.stdout.strip() != code_revision()


_HOLDER = textwrap.dedent("""
    import sys, time
    from alma.study.lock import study_lock
    with study_lock(sys.argv[1]):
        print("locked", flush=True)
        time.sleep(120)
""")


def test_a_second_run_on_one_folder_is_refused_and_a_killed_holder_does_not_block(tmp_path):
    out = tmp_path / "study"
    out.mkdir()
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    holder = subprocess.Popen([sys.executable, "-c", _HOLDER, str(out)], env=env, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout is not None  # stdout=PIPE
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(StudyBusy, match=f"pid {holder.pid}"):
            run_doe(out, workers=1, design=TINY, progress=False)
        assert not (out / "results.csv").exists()  # refused before any work
        design = out.parent / "tiny.toml"
        design.write_text('panel_ratio = ["2:1"]\nblock_ratio = ["4:1"]\nbond = ["running"]\nfriction = [0.6]\n')
        cli = subprocess.run(
            [
                sys.executable,
                "-m",
                "alma.cli",
                "doe",
                "--out",
                str(out),
                "--design",
                str(design),
                "--workers",
                "1",
                "--quiet",
            ],
            env=env,
            capture_output=True,
            text=True,
        )
        assert cli.returncode == 1 and "another alma run" in cli.stderr and "Traceback" not in cli.stderr
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    assert (out / ".alma.lock").exists()  # the killed run's lock file is left behind ...
    df = run_doe(out, workers=1, design=TINY, progress=False)  # ... and does not block
    assert len(df) == 4


def test_the_lock_is_held_for_the_whole_run(tmp_path, monkeypatch):
    """While a run solves, its folder is locked (checked from inside the solve)."""
    import alma.study.doe as doe

    seen = []
    real = doe._execute

    def spy(*args, **kwargs):
        try:
            with study_lock(tmp_path):
                seen.append("free")
        except StudyBusy:
            seen.append("busy")
        return real(*args, **kwargs)

    monkeypatch.setattr(doe, "_execute", spy)
    run_doe(tmp_path, workers=1, design=TINY, progress=False)
    assert seen == ["busy"]
