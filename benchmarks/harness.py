"""The benchmarks' shared harness: timing by medians, the paper's panels, tables, JSON records.

Every benchmark runs as a module from the top of a clone (``python -m benchmarks.bench_lp``,
which ``make bench-lp`` does), imports alma as installed and this harness as
``benchmarks.harness``; the one-off experiments of ``studies/`` use it the same way.

Times are medians of ``repeat`` runs (``time.perf_counter``, seconds).  On a shared machine only
ratios taken within one run are meaningful; ``machine()`` records the load beside the figures.
"""

from __future__ import annotations

import csv
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from functools import cache, lru_cache
from pathlib import Path
from typing import Any, TypeVar

import alma

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
TABLE5 = ROOT / "verification" / "data" / "table5_collapse_multipliers.csv"

T = TypeVar("T")


@dataclass(frozen=True)
class Timing:
    """The times of ``repeat`` runs of one call (s), their median and minimum."""

    times: tuple[float, ...]

    @property
    def median(self) -> float:
        return statistics.median(self.times)

    @property
    def best(self) -> float:
        return min(self.times)

    @property
    def repeat(self) -> int:
        return len(self.times)


def timed(fn: Callable[[], T], repeat: int) -> tuple[Timing, T]:
    """Run ``fn`` ``repeat`` times (at least once); its timings and its last value."""
    times, value = [], None
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        value = fn()
        times.append(time.perf_counter() - t0)
    return Timing(tuple(times)), value  # type: ignore[return-value]


def median_time(fn: Callable[[], T], repeat: int) -> tuple[float, T]:
    """The median time of ``repeat`` runs of ``fn`` (s) and its last value."""
    timing, value = timed(fn, repeat)
    return timing.median, value


# ----------------------------------------------------------------------------- the paper's panels
@lru_cache(maxsize=1)
def table5() -> tuple[tuple[str, str, str, float, float], ...]:
    """Rows (bond, panel_ratio, block_ratio, friction, alpha_c) of the paper's Table 5 (the
    108 panels; the published α is read from verification/data, never from alma)."""
    with open(TABLE5, newline="") as handle:
        return tuple(
            (r["bond"], str(r["panel_ratio"]), str(r["block_ratio"]), float(r["friction"]), float(r["alpha_c"]))
            for r in csv.DictReader(handle)
        )


@cache
def panel_geometry(bond: str, panel_ratio: str, block_ratio: str) -> alma.Model:
    """The model of a paper panel at friction 0.6, built once per geometry (``.with_friction``)."""
    return alma.build_model(alma.paper_panel(bond, panel_ratio, block_ratio, 0.6))


# ----------------------------------------------------------------------------- output
def table(rows: Sequence[Mapping[str, Any]], columns: Sequence[str] | None = None, digits: int = 4) -> str:
    """A plain-text table of ``rows`` (numbers to ``digits`` significant digits), one line each."""
    columns = list(columns or (rows[0].keys() if rows else ()))

    def cell(v: Any) -> str:
        return f"{v:.{digits}g}" if isinstance(v, float) else str(v)

    cells = [[cell(r.get(c, "")) for c in columns] for r in rows]
    widths = [max([len(c)] + [len(line[i]) for line in cells]) for i, c in enumerate(columns)]
    lines = ["  ".join(c.rjust(w) for c, w in zip(columns, widths, strict=True))]
    lines += ["  ".join(v.rjust(w) for v, w in zip(line, widths, strict=True)) for line in cells]
    return "\n".join(lines)


def print_table(rows: Sequence[Mapping[str, Any]], columns: Sequence[str] | None = None, digits: int = 4) -> None:
    print(table(rows, columns, digits), flush=True)


def machine() -> dict[str, Any]:
    """Where and under what load the figures were taken."""
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    return {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpus": os.cpu_count(),
        "load_average_1_5_15": list(load),
        "alma": str(alma.__version__),
    }


def write_json(path: str | os.PathLike[str], rows: Sequence[Mapping[str, Any]], **extra: Any) -> Path:
    """Write ``{"machine": ..., "rows": rows, **extra}`` to ``path`` (folders made); the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    payload = {"machine": machine(), **extra, "rows": [dict(r) for r in rows]}
    path.write_text(json.dumps(payload, indent=1, default=_plain) + "\n")
    return path


def _plain(value: Any) -> Any:
    """JSON for numpy scalars, dataclasses and paths."""
    if hasattr(value, "item"):
        return value.item()
    if hasattr(value, "__dataclass_fields__"):
        return asdict(value)
    return str(value)


# ----------------------------------------------------------------------------- subprocess workers
def run_worker(
    module: str, args: Sequence[str], env: Mapping[str, str] | None = None, cwd: str | os.PathLike[str] = ROOT
) -> dict[str, Any]:
    """Run ``python -m module args`` in a fresh process (its peak memory its own) and read the
    JSON object on the last line of its stdout; ``{"error": stderr}`` when it fails."""
    proc = subprocess.run(
        [sys.executable, "-m", module, *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=None if env is None else dict(env),
    )
    if proc.returncode != 0:
        return {"error": f"exit {proc.returncode}: {proc.stderr[-1500:]}"}
    return json.loads(proc.stdout.strip().splitlines()[-1])
