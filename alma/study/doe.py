"""The paper's full-factorial design of experiments (Table 1): ``alma doe``.

3 panel ratios x 3 block ratios x 4 bonds x 3 frictions = 108 panels, solved with the chosen
contact model(s); a design may add a retrofitting chain across the top course as one more
factor (``chain`` strengths in kN; level 0 is the panel as it is), and a finite compressive
strength of the blocks as another (``compressive_strength`` in MPa; level 0: infinitely strong).
The study is built for long, interruptible runs:

- **one task = one geometry** (panel ratio x block ratio x bond) at one compressive strength
  and all its chains, frictions and models: the joints and the model are built once, each friction re-uses them through
  :meth:`alma.Model.with_friction`;
- **append-only results**: every finished panel is appended to ``OUT/results.csv`` at once
  (one line, flushed and fsync'ed), so a killed study loses only the panels being solved;
- **resumable**: each row carries a ``key``, a hash of the panel's factors, the contact model,
  the alma version, a hash of alma's source code and the solver settings; a panel whose key is
  already in the file is not solved again (a changed parameter or code is a new key);
- **checked**: each row ends with a checksum of its content and key; a damaged or inconsistent
  line (a partial last line left by a kill, a hand edit, garbage, a row whose factors are not
  its key's) is reported, moved to ``quarantine.txt`` and its panel solved again;
- **locked**: one run per folder (``.alma.lock``, released by the system when a run dies); a
  second run on the same folder is refused (:class:`StudyBusy`);
- **parallel**: local processes (``workers``, default all cores) or an existing Dask
  distributed cluster (``scheduler="tcp://host:8786"``; alma must be importable on the
  workers).

Factor levels come from a :class:`Design`; the default is the paper's, a TOML or JSON file can
change it (:func:`load_design`)::

    panel_ratio = ["2:1", "1:1"]
    block_ratio = ["4:1"]
    bond = ["running", "stack"]
    friction = [0.27, 0.6]
    chain = [0, 0.25, 1, 5]
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, cast

import pandas as pd

from alma.settings import EFFORTS, Effort, SearchSettings, Settings
from alma.study.design import PAPER_DESIGN, Design, load_design
from alma.study.keys import _alma_version, key_settings, panel_key
from alma.study.lock import StudyBusy, study_lock
from alma.study.progress import _Progress
from alma.study.runners import _run_dask, _run_local
from alma.study.store import COLUMNS, PICTURE, RESULTS_FILE, _ResultsFile, frame, picture_path, read_results
from alma.study.tasks import _solve_task, _Task

__all__ = [
    "COLUMNS",
    "MODELS",
    "PAPER_DESIGN",
    "RESULTS_FILE",
    "Design",
    "StudyBusy",
    "key_settings",
    "load_design",
    "panel_key",
    "picture_path",
    "read_results",
    "run_doe",
]

#: Contact models a study can run; ``both`` runs the two in turn on each panel.
MODELS = ("associative", "nonassociative")
_MODEL_CHOICES = (*MODELS, "both")


def _models(model: str) -> tuple[str, ...]:
    if model not in _MODEL_CHOICES:
        raise ValueError(f"model must be one of {', '.join(_MODEL_CHOICES)}, got {model!r}")
    return MODELS if model == "both" else (model,)


def run_doe(
    out_dir: str | os.PathLike[str],
    model: str = "associative",
    workers: int | None = None,
    scheduler: Any = None,
    design: Design | str | os.PathLike[str] | None = None,
    progress: bool = True,
    retry_errors: bool = False,
    effort: str | None = None,
    time_limit: float | None = None,
) -> pd.DataFrame:
    """Run (or resume) the full-factorial study and return its rows in Table 5 order.

    ``out_dir/results.csv`` receives one line per finished panel and model. Panels whose key
    is already there are skipped (with ``retry_errors=True``, rows with status ``error`` are
    solved again and the new row, appended later, wins). ``workers`` local processes
    (default ``os.cpu_count()``; 1 solves in this process), or the Dask cluster at
    ``scheduler`` (an address or a ``distributed.Client``). Ctrl-C stops the workers; every
    row finished before it is on disk, and ``KeyboardInterrupt`` is raised again.

    ``effort`` ("auto", "fast" or "thorough") is passed to :func:`alma.solve` for the
    non-associative model and is part of those rows' keys (``None``: ``alma.solve``'s default,
    the same key as "auto"); associative rows do not depend on it.  ``time_limit`` (s) is a
    wall-clock cap per panel and friction (default none), likewise part of those keys.  Every
    key hashes the package version and the settings (:class:`alma.settings.Settings`), so a
    changed setting or release never reuses an old row.

    The returned frame has the columns :data:`COLUMNS`, one row per panel of ``design`` and
    model, ``friction`` and the α columns as floats.
    """
    models = _models(model)
    design, n_workers = _check(design, workers, effort, time_limit)
    if any(s > 0 for s in design.compressive_strength) and "nonassociative" in models:
        raise ValueError(
            "the non-associative model (Eq. 9) takes no finite compressive strength: "
            "run the compressive_strength levels with --model associative"
        )
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    # effort: checked against EFFORTS by _check above.
    settings = Settings(search=SearchSettings(effort=cast(Effort, effort or "auto")), time_limit=time_limit)
    with study_lock(out):  # one run per folder: a second is refused, no panel is solved twice
        results = _ResultsFile(out / RESULTS_FILE)
        try:
            wanted, tasks = _plan(design, models, settings, results, retry_errors)
            sink = _Sink(out, results, tasks, len(wanted), progress)
            _execute(tasks, sink, scheduler, n_workers, results)
        finally:
            results.close()
    if sink.lost_rows:
        raise RuntimeError(
            f"{len(sink.lost_rows)} panel(s) were not solved ({sink.lost_rows[0]}); the other results are in "
            f"{results.path}; run again to retry them"
        )
    df = frame([results.rows[k] for k in dict.fromkeys(wanted) if k in results.rows])
    order = {k: i for i, k in enumerate(wanted)}
    df = df.assign(_order=df["key"].map(order)).sort_values("_order").drop(columns="_order")
    return df.reset_index(drop=True)


def _check(
    design: Design | str | os.PathLike[str] | None, workers: int | None, effort: str | None, time_limit: float | None
) -> tuple[Design, int]:
    """The design and the number of local workers, every option checked before any work."""
    if effort is not None and effort not in EFFORTS:
        raise ValueError(f"effort must be auto, fast or thorough, got {effort!r}")
    if time_limit is not None and not (math.isfinite(time_limit) and time_limit > 0):
        raise ValueError(f"time_limit must be a number of seconds > 0, got {time_limit!r}")
    if design is None:
        design = PAPER_DESIGN
    elif not isinstance(design, Design):
        design = load_design(design)
    if workers is not None and int(workers) < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    return design, int(workers) if workers is not None else (os.cpu_count() or 1)


def _plan(
    design: Design, models: tuple[str, ...], settings: Settings, results: _ResultsFile, retry_errors: bool
) -> tuple[list[str], list[_Task]]:
    """Every wanted row's key (Table 5 order), and the tasks of those not yet in the file,
    largest first (better load balance)."""
    version = _alma_version()
    wanted: list[str] = []
    todo: dict[tuple[str, str, str, float], list[tuple[float, float, str, str]]] = {}
    runs = [(*run, m) for run in design.runs() for m in models]
    keys = [
        panel_key(
            p,
            b,
            bond,
            friction,
            m,
            version=version,
            settings=settings,
            chain=chain,
            chain_y=design.chain_y(p),
            chain_anchored=design.chain_anchored,
            compressive_strength=sigma,
        )
        for p, b, bond, friction, chain, sigma, m in runs
    ]
    results.set_aside(
        {
            key: why
            for key, run in zip(keys, runs, strict=True)
            if key in results.rows and (why := _mismatch(results.rows[key], *run))
        }
    )
    for (p, b, bond, friction, chain, sigma, m), key in zip(runs, keys, strict=True):
        wanted.append(key)
        done = results.rows.get(key)
        if done is not None and not (retry_errors and done["status"] == "error"):
            continue
        todo.setdefault((p, b, bond, sigma), []).append((chain, friction, m, key))
    tasks = [
        _Task(
            p,
            b,
            bond,
            tuple(items),
            version,
            settings,
            chain_y=design.chain_y(p),
            chain_anchored=design.chain_anchored,
            compressive_strength=sigma,
        )
        for (p, b, bond, sigma), items in todo.items()
    ]
    tasks.sort(key=lambda task: task.size, reverse=True)
    return wanted, tasks


def _mismatch(
    row: dict[str, str],
    panel_ratio: str,
    block_ratio: str,
    bond: str,
    friction: float,
    chain: float,
    compressive_strength: float,
    model: str,
) -> str:
    """Why a stored row is not the run its key names (factors swapped or edited), or ''."""
    expected = {"panel_ratio": panel_ratio, "block_ratio": block_ratio, "bond": bond, "model": model}
    wrong = [c for c, v in expected.items() if row.get(c) != v]
    for column, value in (("friction", friction), ("chain", chain), ("compressive_strength", compressive_strength)):
        try:
            if float(row.get(column) or "nan") != float(value):
                wrong.append(column)
        except ValueError:
            wrong.append(column)
    return f"its factors ({', '.join(wrong)}) are not those of its key" if wrong else ""


class _Sink:
    """Where finished rows go: their picture, then the results file, then the progress line."""

    def __init__(self, out: Path, results: _ResultsFile, tasks: list[_Task], n_wanted: int, progress: bool):
        self.out, self.results = out, results
        self.weight = {item[-1]: task.size / len(task.items) for task in tasks for item in task.items}
        remaining = sum(len(task.items) for task in tasks)
        self.bar = _Progress(
            total=n_wanted, resumed=n_wanted - remaining, enabled=progress, work=sum(self.weight.values())
        )
        self.written: set[str] = set()
        self.lost_rows: list[str] = []

    def record(self, row: dict[str, Any]) -> None:
        key = str(row["key"])
        if key in self.written:
            return
        self.written.add(key)
        picture = row.pop(PICTURE, None)
        if picture is not None:
            try:  # before the row: a row on disk has its picture
                picture.save(picture_path(self.out, key))
            except Exception:  # the report solves the panel again to draw it
                picture_path(self.out, key).unlink(missing_ok=True)
        self.results.append(row)
        self.bar.update(failed=row["status"] == "error", work=self.weight.get(key, 0.0))

    def lost(self, task: _Task, message: str) -> None:
        for *_, key in task.items:
            if key not in self.written:
                self.lost_rows.append(message)
                self.bar.update(failed=True, work=self.weight.get(key, 0.0))


def _execute(tasks: list[_Task], sink: _Sink, scheduler: Any, n_workers: int, results: _ResultsFile) -> None:
    """Run the tasks here, in a local pool or on a Dask cluster; Ctrl-C leaves what is done on disk."""
    bar = sink.bar
    bar.show(force=True)
    try:
        if not tasks:
            pass
        elif scheduler is not None:
            _run_dask(tasks, scheduler, sink.record, sink.lost)
        elif n_workers == 1 or len(tasks) == 1:
            for task in tasks:
                _solve_task(task, emit=sink.record)
        else:
            _run_local(tasks, min(n_workers, len(tasks)), sink.record, sink.lost)
    except KeyboardInterrupt:
        bar.close(
            f"interrupted: {bar.done} of {bar.total} results are in {results.path}; "
            "run the same command again to resume"
        )
        raise
    bar.close(f"{bar.failed} failed" if bar.failed else "")
