"""The paper's full-factorial design of experiments (Table 1): ``alma doe``.

3 panel ratios x 3 block ratios x 4 bonds x 3 frictions = 108 panels, solved with the chosen
contact model(s). The study is built for long, interruptible runs:

- **one task = one geometry** (panel ratio x block ratio x bond) and all its frictions and
  models: the joints and the model are built once, each friction re-uses them through
  :meth:`alma.Model.with_friction`;
- **append-only results**: every finished panel is appended to ``OUT/results.csv`` at once
  (one line, flushed and fsync'ed), so a killed study loses only the panels being solved;
- **resumable**: each row carries a ``key``, a hash of the panel's factors, the contact model,
  the alma version and the solver settings; a panel whose key is already in the file is not
  solved again (a changed parameter is a new key). A partial last line left by a kill is
  dropped on restart;
- **parallel**: local processes (``workers``, default all cores) or an existing Dask
  distributed cluster (``scheduler="tcp://host:8786"``; alma must be importable on the
  workers).

Factor levels come from a :class:`Design`; the default is the paper's, a TOML or JSON file can
change it (:func:`load_design`)::

    panel_ratio = ["2:1", "1:1"]
    block_ratio = ["4:1"]
    bond = ["running", "stack"]
    friction = [0.27, 0.6]
"""
from __future__ import annotations

import csv
import dataclasses
import gc
import hashlib
import json
import math
import os
import queue as queue_mod
import signal
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import pandas as pd

from alma.settings import SearchSettings, Settings

__all__ = [
    "COLUMNS",
    "Design",
    "MODELS",
    "PAPER_DESIGN",
    "load_design",
    "panel_key",
    "read_results",
    "run_doe",
]

#: Contact models a study can run; ``both`` runs the two in turn on each panel.
MODELS = ("associative", "nonassociative")
_MODEL_CHOICES = (*MODELS, "both")

#: Columns of ``results.csv``, in order. The first five are those of Table 5 (``alma anova``).
COLUMNS: tuple[str, ...] = (
    "panel_ratio", "block_ratio", "bond", "friction", "alpha_c",
    "model", "status", "alpha_lower", "alpha_upper", "gap", "mechanism_class",
    "joints_s", "build_s", "solve_s", "certify_s", "message", "alma_version", "key",
    # Added for the model comparison (``alma compare``); older files are migrated on open.
    "alpha_associative", "ratio", "start", "alpha_lp_start", "lp_start_verified",
    "n_candidates", "n_verified", "nonassociative_s", "n_blocks", "effort",
    # Each start of the non-associative search, as JSON [[start, seconds, verified], ...].
    "starts",
)
#: The columns of results files written before the comparison columns were added.
_LEGACY_COLUMNS = COLUMNS[:18]
#: Numeric columns of ``results.csv``.
_NUMERIC = ("friction", "alpha_c", "alpha_lower", "alpha_upper", "gap", "joints_s", "build_s",
            "solve_s", "certify_s", "alpha_associative", "ratio", "alpha_lp_start",
            "n_candidates", "n_verified", "nonassociative_s", "n_blocks")
RESULTS_FILE = "results.csv"
#: Folder of ``out_dir`` with the mechanism of every solved row (:class:`alma.plot.MechanismPicture`).
PICTURES_FOLDER = "mechanisms"
PICTURE = "_picture"  # the row's picture, on its way from the worker to the results file


def picture_path(out_dir: str | os.PathLike[str], key: str) -> Path:
    """Where :func:`run_doe` keeps the mechanism of the row with ``key``."""
    return Path(out_dir) / PICTURES_FOLDER / f"{key}.npz"

_PANEL_RATIOS = ("2:1", "1:1", "1:2")
_BLOCK_RATIOS = ("4:1", "2:1", "1:1")
_BONDS = ("running", "stack", "english", "flemish")
# Geometry of Table 1 (mm), only used to order the tasks largest first.
_PANEL_HEIGHT = {"2:1": 720.0, "1:1": 1440.0, "1:2": 2880.0}
_BLOCK_LENGTH = {"4:1": 240.0, "2:1": 120.0, "1:1": 60.0}
_BOND_COST = {"running": 1.0, "stack": 0.6, "english": 1.6, "flemish": 1.3}


# ------------------------------------------------------------------------------------------
# Design
# ------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Design:
    """Factor levels of a full-factorial study (Table 1 of the paper by default).

    Panels are enumerated in the order of Table 5: friction slowest, then bond, block ratio,
    and panel ratio fastest.
    """

    panel_ratio: tuple[str, ...] = _PANEL_RATIOS
    block_ratio: tuple[str, ...] = _BLOCK_RATIOS
    bond: tuple[str, ...] = _BONDS
    friction: tuple[float, ...] = (0.27, 0.60, 1.00)

    def __post_init__(self) -> None:
        for name, allowed in (("panel_ratio", _PANEL_RATIOS), ("block_ratio", _BLOCK_RATIOS),
                              ("bond", _BONDS)):
            values = tuple(str(v).strip() for v in getattr(self, name))
            if name == "bond":
                values = tuple(v.lower() for v in values)
            if not values:
                raise ValueError(f"design: {name} needs at least one level")
            for v in values:
                if v not in allowed:
                    raise ValueError(f"design: bad {name} level {v!r}; allowed: {', '.join(allowed)}")
            if len(set(values)) != len(values):
                raise ValueError(f"design: repeated {name} level in {list(values)}")
            object.__setattr__(self, name, values)
        fr: list[float] = []
        for v in self.friction:
            if isinstance(v, bool):
                raise ValueError(f"design: bad friction level {v!r}")
            try:
                f = float(v)
            except (TypeError, ValueError):
                raise ValueError(f"design: bad friction level {v!r}; expected a number") from None
            if not (math.isfinite(f) and f >= 0):
                raise ValueError(f"design: bad friction level {v!r}; expected a finite number >= 0")
            fr.append(f)
        if not fr:
            raise ValueError("design: friction needs at least one level")
        if len(set(fr)) != len(fr):
            raise ValueError(f"design: repeated friction level in {fr}")
        object.__setattr__(self, "friction", tuple(fr))

    @property
    def geometries(self) -> list[tuple[str, str, str]]:
        """(panel_ratio, block_ratio, bond) of every geometry, Table 5 order."""
        return [(p, b, bond) for bond in self.bond for b in self.block_ratio for p in self.panel_ratio]

    def panels(self) -> list[tuple[str, str, str, float]]:
        """(panel_ratio, block_ratio, bond, friction) of every panel, Table 5 order."""
        return [(p, b, bond, f) for f in self.friction for bond in self.bond
                for b in self.block_ratio for p in self.panel_ratio]

    def __len__(self) -> int:
        return len(self.panel_ratio) * len(self.block_ratio) * len(self.bond) * len(self.friction)

    def to_dict(self) -> dict[str, list[Any]]:
        return {k: list(v) for k, v in dataclasses.asdict(self).items()}


PAPER_DESIGN = Design()

_DESIGN_KEYS = {
    "panel_ratio": "panel_ratio", "panel_ratios": "panel_ratio",
    "block_ratio": "block_ratio", "block_ratios": "block_ratio",
    "bond": "bond", "bonds": "bond",
    "friction": "friction", "frictions": "friction",
}


def load_design(path: str | os.PathLike[str]) -> Design:
    """Read factor levels from a TOML (``.toml``) or JSON file; missing factors keep the paper's.

    Keys: ``panel_ratio``, ``block_ratio``, ``bond``, ``friction`` (plural forms accepted),
    each a list of levels (a single value is a one-level list); they may also sit in a
    ``[design]`` table. Unknown keys and bad levels raise ``ValueError``.
    """
    p = Path(path)
    try:
        raw_text = p.read_bytes()
    except OSError as exc:
        raise ValueError(f"{p}: cannot read design file ({exc.strerror or exc})") from None
    if p.suffix.lower() == ".toml":
        import tomllib

        try:
            data = tomllib.loads(raw_text.decode("utf-8"))
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise ValueError(f"{p}: not valid TOML ({exc})") from None
    else:
        try:
            data = json.loads(raw_text)
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise ValueError(f"{p}: not valid JSON ({exc})") from None
    if isinstance(data, dict) and set(data) == {"design"} and isinstance(data["design"], dict):
        data = data["design"]
    if not isinstance(data, dict):
        raise ValueError(f"{p}: a design file holds one object/table of factor levels")
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        field = _DESIGN_KEYS.get(key)
        if field is None:
            raise ValueError(f"{p}: unknown key {key!r}; expected panel_ratio, block_ratio, bond, friction")
        if field in kwargs:
            raise ValueError(f"{p}: factor {field!r} given twice")
        values = value if isinstance(value, list) else [value]
        kwargs[field] = tuple(values)
    try:
        return Design(**kwargs)
    except ValueError as exc:
        raise ValueError(f"{p}: {exc}") from None


# ------------------------------------------------------------------------------------------
# Keys
# ------------------------------------------------------------------------------------------


def _alma_version() -> str:
    import alma

    return str(getattr(alma, "__version__", "unknown"))


def key_settings(settings: Settings, model: str) -> dict[str, Any]:
    """What of ``settings`` changes a row of ``model``: the associative LP's settings for the
    associative model (so fast and thorough runs share those rows), all of them otherwise."""
    data = settings.to_dict()
    return {"associative": data["associative"]} if model == "associative" else data


def _friction_text(f: float) -> str:
    return format(float(f), ".12g")


def panel_key(panel_ratio: str, block_ratio: str, bond: str, friction: float, model: str,
              *, version: str | None = None, settings: Settings | dict[str, Any] | None = None) -> str:
    """Stable key of one result row: hash of factors, model, alma version and every setting
    that changes the row (:func:`key_settings`; a dict is taken as it is)."""
    if not isinstance(settings, dict):
        settings = key_settings(settings if settings is not None else Settings(), model)
    payload = {
        "panel_ratio": panel_ratio, "block_ratio": block_ratio, "bond": bond,
        "friction": _friction_text(friction), "model": model,
        "alma": _alma_version() if version is None else version,
        "solver": settings,
    }
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:20]


# ------------------------------------------------------------------------------------------
# Worker side: one geometry, all its frictions and models
# ------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Task:
    panel_ratio: str
    block_ratio: str
    bond: str
    items: tuple[tuple[float, str, str], ...]  # (friction, model, key) still to do
    version: str
    settings: Settings = Settings()

    @property
    def size(self) -> float:
        """Rough relative cost (LP time grows faster than the block count; measured on Table 5)."""
        n_blocks = _PANEL_HEIGHT.get(self.panel_ratio, 1.0) / 60.0 * 1440.0 / _BLOCK_LENGTH.get(self.block_ratio, 1.0)
        return n_blocks ** 1.7 * _BOND_COST.get(self.bond, 1.0) * len(self.items)


def _num(x: Any) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return math.nan
    return v


def _row(task: _Task, friction: float, model: str, key: str, *, result: Any = None,
         error: str = "", timings: dict[str, float] | None = None) -> dict[str, Any]:
    row: dict[str, Any] = {
        "panel_ratio": task.panel_ratio, "block_ratio": task.block_ratio, "bond": task.bond,
        "friction": float(friction), "model": model, "alma_version": task.version, "key": key,
    }
    t = dict(timings or {})
    row["effort"] = "" if model == "associative" else task.settings.search.effort
    if result is not None:
        t.update({k: v for k, v in result.timings.items() if k in ("solve_s", "certify_s")})
        row.update({
            "alpha_c": _num(result.alpha), "status": str(result.status),
            "alpha_lower": _num(result.bounds.lower), "alpha_upper": _num(result.bounds.upper),
            "gap": _num(result.bounds.gap), "mechanism_class": str(result.mechanism_class or ""),
            "message": str(getattr(result, "message", "") or ""),
        })
        row.update(_comparison_fields(result, model))
        try:
            from alma.report.plot import MechanismPicture

            row[PICTURE] = MechanismPicture.from_result(result)
        except Exception:  # a picture is a convenience: it must not lose the result
            pass
    else:
        row.update({"alpha_c": math.nan, "status": "error", "alpha_lower": math.nan,
                    "alpha_upper": math.nan, "gap": math.nan, "mechanism_class": "",
                    "message": error})
    for name in ("joints_s", "build_s", "solve_s", "certify_s"):
        row[name] = float(t.get(name, 0.0))
    return row


def _comparison_fields(result: Any, model: str) -> dict[str, Any]:
    """Columns of the model comparison: the associative α beside the non-associative one,
    their ratio, the winning start, the α of the start from the LP mechanism ("lp"; NaN
    when the search has no such candidate), candidate counts and the search time."""
    extra = getattr(result, "extra", None) or {}
    alpha_lp = _num(getattr(result, "alpha_associative", math.nan))
    n_blocks = extra.get("n_blocks")
    out: dict[str, Any] = {"alpha_associative": alpha_lp,
                           "n_blocks": int(n_blocks) if isinstance(n_blocks, (int, float)) else math.nan}
    if model == "associative":
        return out
    alpha = _num(result.alpha)
    ratio = alpha / alpha_lp if math.isfinite(alpha) and math.isfinite(alpha_lp) and alpha_lp > 0 else math.nan
    candidates = [c for c in extra.get("candidates") or [] if isinstance(c, dict)]
    lp = [c for c in candidates if c.get("start") == "lp"]
    out.update({
        "ratio": ratio,
        "start": str(extra.get("start") or ""),
        "alpha_lp_start": _num(lp[0].get("alpha")) if lp else math.nan,
        "lp_start_verified": str(bool(lp[0].get("verified"))) if lp else "",
        "n_candidates": len(candidates),
        "n_verified": sum(bool(c.get("verified")) for c in candidates),
        "nonassociative_s": _num(result.timings.get("nonassociative_s", math.nan)),
        # [start, seconds, verified, α of its state (null if none)]
        "starts": json.dumps([[r.get("start"), round(float(r.get("time_s", math.nan)), 3), bool(r.get("verified")),
                               r.get("alpha")]  # already None when not finite (alma.result)
                              for r in extra.get("starts") or [] if isinstance(r, dict)], ensure_ascii=False),
    })
    return out


def _error_text(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}".replace("\n", " ").strip()


def _solve_task(task: _Task, emit: Callable[[dict[str, Any]], None] | None = None) -> list[dict[str, Any]]:
    """Build the geometry once and solve all (friction, model) items; rows are emitted as done.

    ``joints_s`` and ``build_s`` of the geometry are charged to the first row solved from it;
    the other rows carry the (small) cost of :meth:`Model.with_friction` as ``build_s``.
    Exceptions become rows with status ``error`` and the message; nothing is raised.
    """
    import alma
    from alma.geometry.contacts import find_joints

    rows: list[dict[str, Any]] = []

    def out(row: dict[str, Any]) -> None:
        rows.append(row)
        if emit is not None:
            emit(row)

    first = {"joints_s": 0.0, "build_s": 0.0}
    try:
        t0 = time.perf_counter()
        friction0 = task.items[0][0]
        scene = alma.paper_panel(task.bond, task.panel_ratio, task.block_ratio, friction0)
        joints = find_joints(scene)
        t1 = time.perf_counter()
        base = alma.build_model(scene, joints)
        t2 = time.perf_counter()
        first = {"joints_s": t1 - t0, "build_s": t2 - t1}
    except Exception as exc:  # geometry failed: every item of the task fails with it
        msg = _error_text(exc)
        for friction, model, key in task.items:
            out(_row(task, friction, model, key, error=msg, timings=first))
            first = {"joints_s": 0.0, "build_s": 0.0}
        return rows

    by_friction: dict[float, dict[str, str]] = {}
    for friction, model, key in task.items:
        by_friction.setdefault(friction, {})[model] = key
    for friction, keys in by_friction.items():
        timings = dict(first)
        try:
            t0 = time.perf_counter()
            built = base.with_friction(friction)
            timings["build_s"] += time.perf_counter() - t0
            results = _solve_models(built, tuple(keys), task.settings)
        except Exception as exc:
            for model, key in keys.items():
                out(_row(task, friction, model, key, error=_error_text(exc), timings=timings))
        else:
            for model, key in keys.items():
                out(_row(task, friction, model, key, result=results[model], timings=timings))
        first = {"joints_s": 0.0, "build_s": 0.0}
    return rows


def _solve_models(built: Any, models: tuple[str, ...], settings: Settings) -> dict[str, Any]:
    """Each model's result for one panel and friction, the associative LP solved once: with
    both models, one ``alma.solve(model="both")`` gives both rows."""
    import alma

    if set(models) == {"associative", "nonassociative"}:
        both = alma.solve(built, model="both", settings=settings)
        return {"associative": both.associative, "nonassociative": both.nonassociative}
    return {m: alma.solve(built, model=m, settings=settings) for m in models}


# Local process pool: rows stream back through a queue given to each worker at start-up.
_WORKER_QUEUE: Any = None


def _init_worker(q: Any) -> None:
    global _WORKER_QUEUE
    _WORKER_QUEUE = q
    # Ctrl-C is handled by the parent, which stops the workers itself.
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _solve_task_pooled(task: _Task) -> list[dict[str, Any]]:
    q = _WORKER_QUEUE
    return _solve_task(task, emit=None if q is None else q.put)


# ------------------------------------------------------------------------------------------
# Results file
# ------------------------------------------------------------------------------------------


def _format(value: Any) -> str:
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return str(value)


class _ResultsFile:
    """Append-only CSV: header once, one fsync'ed line per result."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.rows: dict[str, dict[str, str]] = {}
        self.dropped_partial = False
        self._prepare()
        self._fh = open(self.path, "a", newline="", encoding="utf-8")

    def _prepare(self) -> None:
        path = self.path
        header_line = ",".join(COLUMNS) + "\n"
        if not path.exists() or path.stat().st_size == 0:
            path.parent.mkdir(parents=True, exist_ok=True)
            with open(path, "w", encoding="utf-8", newline="") as fh:
                fh.write(header_line)
                fh.flush()
                os.fsync(fh.fileno())
            return
        data = path.read_bytes()
        if not data.endswith(b"\n"):
            # A kill in the middle of a write: drop the unfinished last line.
            cut = data.rfind(b"\n") + 1
            with open(path, "r+b") as fh:
                fh.truncate(cut)
                fh.flush()
                os.fsync(fh.fileno())
            self.dropped_partial = True
            data = data[:cut]
            if cut == 0:  # even the header was cut
                with open(path, "w", encoding="utf-8", newline="") as fh:
                    fh.write(header_line)
                    fh.flush()
                    os.fsync(fh.fileno())
                return
        text = data.decode("utf-8")
        reader = csv.reader(text.splitlines())
        header = next(reader, None)
        if header is not None and header != list(COLUMNS) and _is_legacy_header(header):
            text = self._migrate(text, header)
            reader = csv.reader(text.splitlines())
            header = next(reader, None)
        if header != list(COLUMNS):
            raise ValueError(
                f"{path}: not a results file of this alma version (columns {header}); "
                "choose another --out folder")
        for fields in reader:
            if len(fields) != len(COLUMNS):
                continue  # malformed line: ignored, its panel is solved again
            row = dict(zip(COLUMNS, fields))
            if row["key"]:
                self.rows[row["key"]] = row

    def _migrate(self, text: str, header: list[str]) -> str:
        """Rewrite a file of an older column set with the current header (new columns empty).

        Written to a temporary file and renamed over the old one, so a kill leaves either
        the old or the new file, never a mix.
        """
        buf = _LineBuffer()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(COLUMNS)
        for fields in csv.reader(text.splitlines()[1:]):
            if len(fields) == len(header):
                writer.writerow(fields + [""] * (len(COLUMNS) - len(header)))
        tmp = self.path.with_name(self.path.name + ".migrating")
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.write(buf.text)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, self.path)
        return buf.text

    def append(self, row: dict[str, Any]) -> None:
        buf = _LineBuffer()
        csv.writer(buf, lineterminator="\n").writerow([_format(row.get(c, "")) for c in COLUMNS])
        self._fh.write(buf.text)  # one write per line
        self._fh.flush()
        os.fsync(self._fh.fileno())
        self.rows[str(row["key"])] = {c: _format(row.get(c, "")) for c in COLUMNS}

    def close(self) -> None:
        self._fh.close()


def _is_legacy_header(header: list[str]) -> bool:
    """A header of an older alma: a proper prefix of :data:`COLUMNS`, at least the legacy ones."""
    n = len(header)
    return len(_LEGACY_COLUMNS) <= n < len(COLUMNS) and header == list(COLUMNS[:n])


class _LineBuffer:
    def __init__(self) -> None:
        self.text = ""

    def write(self, s: str) -> None:
        self.text += s


def read_results(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read a ``results.csv`` written by :func:`run_doe` (last row per key wins)."""
    text_columns = ("message", "mechanism_class", "start", "lp_start_verified", "effort", "starts")
    df = pd.read_csv(path, dtype={"panel_ratio": str, "block_ratio": str, "bond": str,
                                  "model": str, "status": str, "mechanism_class": str,
                                  "message": str, "alma_version": str, "key": str,
                                  "start": str, "lp_start_verified": str, "effort": str,
                                  "starts": str},
                     keep_default_na=False, na_values={c: [""] for c in COLUMNS
                                                       if c not in text_columns})
    for col in _NUMERIC:
        if col in df.columns:
            df[col] = pd.to_numeric(df[col], errors="coerce")
    for col in COLUMNS:  # a file of an older alma: the newer columns are empty
        if col not in df.columns and "key" in df.columns:
            df[col] = math.nan if col in _NUMERIC else ""
    if "key" in df.columns:
        df = df.drop_duplicates("key", keep="last")
    return df.reset_index(drop=True)


# ------------------------------------------------------------------------------------------
# Progress
# ------------------------------------------------------------------------------------------


class _Progress:
    """Plain-text progress bar on stderr: done/total, failures, elapsed, time left."""

    def __init__(self, total: int, resumed: int, enabled: bool, stream: Any = None,
                 work: float = 0.0) -> None:
        self.total = total
        self.work = work  # estimated work of the panels to solve (ETA weights)
        self.work_done = 0.0
        self.resumed = resumed
        self.done = resumed
        self.failed = 0
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.start = time.monotonic()
        self._last = 0.0
        self._last_len = 0
        self._shown: tuple[int, int] | None = None

    def update(self, failed: bool, work: float = 0.0) -> None:
        self.work_done += work
        self.done += 1
        self.failed += int(failed)
        self.show()

    def _line(self) -> str:
        elapsed = time.monotonic() - self.start
        new = self.done - self.resumed
        left = self.total - self.done
        if new == 0:
            eta = "--"
        elif self.work > 0 and self.work_done > 0:
            eta = _hms(elapsed / self.work_done * max(0.0, self.work - self.work_done))
        else:
            eta = _hms(elapsed / new * left)
        width = 24
        filled = int(width * self.done / self.total) if self.total else width
        resumed = f" ({self.resumed} resumed)" if self.resumed else ""
        return (f"doe [{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total}"
                f"{resumed}, {self.failed} failed, elapsed {_hms(elapsed)}, left {eta}")

    def show(self, force: bool = False) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        final = self.done >= self.total
        if not (force or final or now - self._last >= (0.2 if self.tty else 5.0)):
            return
        if final and self._shown == (self.done, self.failed):
            return
        self._shown = (self.done, self.failed)
        self._last = now
        line = self._line()
        if self.tty:
            pad = " " * max(0, self._last_len - len(line))
            self.stream.write("\r" + line + pad)
            self._last_len = len(line)
        else:
            self.stream.write(line + "\n")
        self.stream.flush()

    def close(self, note: str = "") -> None:
        if not self.enabled:
            return
        self.show(force=True)
        if self.tty:
            self.stream.write("\n")
        if note:
            self.stream.write(note + "\n")
        self.stream.flush()


def _hms(seconds: float) -> str:
    s = int(round(seconds))
    h, rem = divmod(s, 3600)
    m, s = divmod(rem, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


# ------------------------------------------------------------------------------------------
# Driver
# ------------------------------------------------------------------------------------------


def _models(model: str) -> tuple[str, ...]:
    if model not in _MODEL_CHOICES:
        raise ValueError(f"model must be one of {', '.join(_MODEL_CHOICES)}, got {model!r}")
    return MODELS if model == "both" else (model,)


def run_doe(out_dir: str | os.PathLike[str], model: str = "associative",
            workers: int | None = None, scheduler: Any = None, design: Design | str | os.PathLike[str] | None = None,
            progress: bool = True, retry_errors: bool = False,
            effort: str | None = None, time_limit: float | None = None) -> pd.DataFrame:
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
    if effort is not None and effort not in ("auto", "fast", "thorough"):
        raise ValueError(f"effort must be auto, fast or thorough, got {effort!r}")
    if time_limit is not None and not (math.isfinite(time_limit) and time_limit > 0):
        raise ValueError(f"time_limit must be a number of seconds > 0, got {time_limit!r}")
    if design is None:
        design = PAPER_DESIGN
    elif not isinstance(design, Design):
        design = load_design(design)
    if workers is not None and int(workers) < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    n_workers = int(workers) if workers is not None else (os.cpu_count() or 1)

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    results = _ResultsFile(out / RESULTS_FILE)
    try:
        version = _alma_version()
        settings = Settings(search=SearchSettings(effort=effort or "auto"), time_limit=time_limit)
        wanted: list[str] = []
        todo: dict[tuple[str, str, str], list[tuple[float, str, str]]] = {}
        for friction in design.friction:
            for geometry in design.geometries:
                for m in models:
                    key = panel_key(*geometry, friction, m, version=version, settings=settings)
                    wanted.append(key)
                    done = results.rows.get(key)
                    if done is not None and not (retry_errors and done["status"] == "error"):
                        continue
                    todo.setdefault(geometry, []).append((friction, m, key))
        tasks = [_Task(p, b, bond, tuple(items), version, settings)
                 for (p, b, bond), items in todo.items()]
        tasks.sort(key=lambda t: t.size, reverse=True)  # largest first: better load balance

        remaining = sum(len(t.items) for t in tasks)
        weight = {k: t.size / len(t.items) for t in tasks for _, _, k in t.items}
        bar = _Progress(total=len(wanted), resumed=len(wanted) - remaining, enabled=progress,
                        work=sum(weight.values()))
        written: set[str] = set()

        def record(row: dict[str, Any]) -> None:
            key = str(row["key"])
            if key in written:
                return
            written.add(key)
            picture = row.pop(PICTURE, None)
            if picture is not None:
                try:  # before the row: a row on disk has its picture
                    picture.save(picture_path(out, key))
                except Exception:  # the report solves the panel again to draw it
                    picture_path(out, key).unlink(missing_ok=True)
            results.append(row)
            bar.update(failed=row["status"] == "error", work=weight.get(key, 0.0))

        lost_rows: list[str] = []

        def lost(task: _Task, message: str) -> None:
            for _, _, key in task.items:
                if key not in written:
                    lost_rows.append(message)
                    bar.update(failed=True, work=weight.get(key, 0.0))

        bar.show(force=True)
        note = ""
        try:
            if not tasks:
                pass
            elif scheduler is not None:
                _run_dask(tasks, scheduler, record, lost)
            elif n_workers == 1 or len(tasks) == 1:
                for task in tasks:
                    _solve_task(task, emit=record)
            else:
                _run_local(tasks, min(n_workers, len(tasks)), record, lost)
        except KeyboardInterrupt:
            note = (f"interrupted: {bar.done} of {bar.total} results are in {results.path}; "
                    "run the same command again to resume")
            bar.close(note)
            raise
        bar.close(f"{bar.failed} failed" if bar.failed else "")
    finally:
        results.close()
    if lost_rows:
        raise RuntimeError(
            f"{len(lost_rows)} panel(s) were not solved ({lost_rows[0]}); the other results are in "
            f"{results.path}; run again to retry them")

    df = read_results(out / RESULTS_FILE)
    df = df[df["key"].isin(set(wanted))]
    order = {k: i for i, k in enumerate(wanted)}
    df = df.assign(_order=df["key"].map(order)).sort_values("_order").drop(columns="_order")
    return df.reset_index(drop=True)


def _run_local(tasks: Sequence[_Task], n_workers: int, record: Callable[[dict[str, Any]], None],
               lost: Callable[[_Task, str], None]) -> None:
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    # fork (POSIX) needs no re-import of the caller's __main__; spawn elsewhere.
    methods = mp.get_all_start_methods()
    ctx = mp.get_context("fork" if "fork" in methods and sys.platform != "darwin" else "spawn")
    q = ctx.Queue()
    pool = ProcessPoolExecutor(max_workers=n_workers, mp_context=ctx,
                               initializer=_init_worker, initargs=(q,))

    def drain(block: float | None) -> None:
        try:
            row = q.get(timeout=block) if block else q.get_nowait()
            record(row)
            while True:
                record(q.get_nowait())
        except queue_mod.Empty:
            pass

    futures = {}
    try:
        # The workers are forked at the first submit.  Freezing the collector first leaves every
        # object of the parent out of the children's collections: a child never traverses or
        # frees what it did not make.  (In the test suite a child's full collection once hit a
        # dangling instance dict inherited from the parent and died with SIGSEGV.)
        frozen = ctx.get_start_method() == "fork"
        if frozen:
            gc.freeze()
        try:
            futures = {pool.submit(_solve_task_pooled, t): t for t in tasks}
        finally:
            if frozen:
                gc.unfreeze()
        pending = set(futures)
        while pending:
            drain(0.2)
            finished, pending = wait(pending, timeout=0, return_when=FIRST_COMPLETED)
            for fut in finished:
                task = futures[fut]
                try:
                    rows = fut.result()
                except Exception as exc:  # a worker died (e.g. killed): not a result, retried next run
                    drain(None)
                    lost(task, f"worker failed: {_error_text(exc)}")
                    continue
                for row in rows:  # rows not yet received through the queue
                    record(row)
        drain(None)
    except BaseException:  # Ctrl-C or a failure here: stop the workers, keep what is done
        try:
            drain(None)  # whatever is finished goes to disk
        finally:
            for fut in futures:
                fut.cancel()
            procs = list((getattr(pool, "_processes", None) or {}).values())
            for p in procs:
                if p.is_alive():
                    p.terminate()
            pool.shutdown(wait=False, cancel_futures=True)
        raise
    else:
        pool.shutdown(wait=True)
    finally:
        q.close()


def _run_dask(tasks: Sequence[_Task], scheduler: Any, record: Callable[[dict[str, Any]], None],
              lost: Callable[[_Task, str], None]) -> None:
    try:
        from distributed import Client, as_completed
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise RuntimeError("--scheduler needs the dask extra: pip install 'alma[dask]'") from exc
    own = not isinstance(scheduler, Client)
    client = Client(scheduler) if own else scheduler
    futures = []
    try:
        futures = [client.submit(_solve_task, t, pure=False) for t in tasks]
        by_future = dict(zip(futures, tasks))
        for fut in as_completed(futures):
            task = by_future[fut]
            try:
                rows = fut.result()
            except Exception as exc:  # worker lost etc.: not a result, retried next run
                lost(task, f"dask task failed: {_error_text(exc)}")
                continue
            for row in rows:
                record(row)
    except BaseException:
        try:
            client.cancel(futures)
        finally:
            if own:
                client.close()
        raise
    else:
        if own:
            client.close()

