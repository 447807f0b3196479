"""The results file of a study: append-only, one fsync'ed line per finished row, resumable.

Each row is one line and ends with a checksum of its content and its key
(:func:`alma.study.integrity.row_checksum`).  On opening, damaged or inconsistent lines (an
unbalanced quote, a cut line, binary garbage, an edited value, bounds out of order) are
reported on stderr with their line numbers, moved to ``quarantine.txt`` beside the file and
left out, so that their panels are solved again; reading never fails on them.
"""

from __future__ import annotations

import csv
import math
import os
import sys
from pathlib import Path
from typing import Any

import pandas as pd

from alma.study.integrity import Line, describe_lines, read_line, row_checksum

#: Columns of ``results.csv``, in order. The first five are those of Table 5 (``alma anova``).
COLUMNS: tuple[str, ...] = (
    "panel_ratio",
    "block_ratio",
    "bond",
    "friction",
    "alpha_c",
    "model",
    "status",
    "alpha_lower",
    "alpha_upper",
    "gap",
    "mechanism_class",
    "joints_s",
    "build_s",
    "solve_s",
    "certify_s",
    "message",
    "alma_version",
    "key",
    # The model comparison (``alma compare``).
    "alpha_associative",
    "ratio",
    "start",
    "alpha_lp_start",
    "lp_start_verified",
    "n_candidates",
    "n_verified",
    "nonassociative_s",
    "n_blocks",
    "effort",
    # Each start of the non-associative search, as JSON [[start, seconds, verified], ...].
    "starts",
    # Strength (kN) of the chain across the panel; 0: none (a design's chain factor).
    "chain",
    # Compressive strength σ_c (MPa) of every joint; 0: infinitely strong blocks (a design factor).
    "compressive_strength",
    # row_checksum of the fields before it: a changed value or key shows.
    "checksum",
)
#: The columns of a results file written before the checksum, and before the chain factor:
#: read, and given their checksum (and ``chain`` 0).
_COLUMNS_BEFORE_STRENGTH: tuple[str, ...] = COLUMNS[:-2] + COLUMNS[-1:]
_COLUMNS_BEFORE_CHECKSUM: tuple[str, ...] = COLUMNS[:-2]
_COLUMNS_BEFORE_CHAIN: tuple[str, ...] = COLUMNS[:-3]
_HEADERS = (COLUMNS, _COLUMNS_BEFORE_STRENGTH, _COLUMNS_BEFORE_CHECKSUM, _COLUMNS_BEFORE_CHAIN)
#: The value an earlier header's row gets in a column it lacks: none of the factor.
_MISSING = {"chain": "0.0", "compressive_strength": "0.0"}
#: Numeric columns of ``results.csv``.
_NUMERIC = (
    "friction",
    "alpha_c",
    "alpha_lower",
    "alpha_upper",
    "gap",
    "joints_s",
    "build_s",
    "solve_s",
    "certify_s",
    "alpha_associative",
    "ratio",
    "alpha_lp_start",
    "n_candidates",
    "n_verified",
    "nonassociative_s",
    "n_blocks",
    "chain",
    "compressive_strength",
)
#: Where damaged lines go, beside ``results.csv``: each after a comment naming its line and fault.
QUARANTINE_FILE = "quarantine.txt"
RESULTS_FILE = "results.csv"
#: Folder of ``out_dir`` with the mechanism of every solved row (:class:`alma.plot.MechanismPicture`).
PICTURES_FOLDER = "mechanisms"
PICTURE = "_picture"  # the row's picture, on its way from the worker to the results file


def picture_path(out_dir: str | os.PathLike[str], key: str) -> Path:
    """Where :func:`run_doe` keeps the mechanism of the row with ``key``."""
    return Path(out_dir) / PICTURES_FOLDER / f"{key}.npz"


def _format(value: Any) -> str:
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    # One row, one line: a line break inside a message would split the row.
    return str(value).replace("\r", " ").replace("\n", " ")


def format_row(row: dict[str, Any]) -> list[str]:
    """The fields of ``row`` as written, its checksum last."""
    fields = [_format(row.get(c, "")) for c in COLUMNS[:-1]]
    return [*fields, row_checksum(fields)]


def _csv_line(fields: list[str] | tuple[str, ...]) -> str:
    buf = _LineBuffer()
    csv.writer(buf, lineterminator="\n").writerow(fields)
    return buf.text


def _fsync_write(path: Path, data: bytes, mode: str) -> None:
    with open(path, mode) as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())


def scan(path: Path) -> tuple[tuple[str, ...], list[Line], list[Line]]:
    """(header, sound lines, damaged lines) of a results file; the sound lines' fields are in
    :data:`COLUMNS` (a file of earlier columns is converted).  ``ValueError`` when the header is
    not one of a results file."""
    data = path.read_bytes()
    pieces = data.split(b"\n")
    unfinished = pieces.pop()  # b"" when the file ends with a line break
    if not pieces:  # even the header was cut: an empty study
        return COLUMNS, [], []
    header_text = pieces[0].rstrip(b"\r").decode("utf-8", "replace")
    header = tuple(next(csv.reader([header_text]), []))
    if header not in _HEADERS:
        raise ValueError(
            f"{path}: not a results file of this alma version (columns {list(header)}); choose another --out folder"
        )
    good: list[Line] = []
    bad: list[Line] = []
    for number, raw in enumerate(pieces[1:], start=2):
        if not raw.strip():
            continue
        line = read_line(number, raw.rstrip(b"\r"), header, checked=header[-1] == "checksum")
        (good if not line.problem else bad).append(_upgrade(line, header) if not line.problem else line)
    if unfinished:
        bad.append(Line(len(pieces) + 1, unfinished, problem="unfinished last line (a run stopped while writing it)"))
    return header, good, bad


def _upgrade(line: Line, header: tuple[str, ...]) -> Line:
    """A sound line of an earlier header, with :data:`COLUMNS` (the factors it lacks at 0, its
    checksum)."""
    if header == COLUMNS:
        return line
    values = dict(zip(header, line.fields, strict=True))
    fields = [values.get(c, _MISSING.get(c, "")) for c in COLUMNS[:-1]]
    fields.append(row_checksum(fields))
    return Line(line.number, _csv_line(fields).rstrip("\n").encode("utf-8"), fields=tuple(fields))


def report_damage(path: Path, bad: list[Line], action: str) -> None:
    """The count, line numbers and faults of ``bad`` on stderr."""
    if not bad:
        return
    faults = "; ".join(f"line {line.number}: {line.problem}" for line in bad[:5])
    more = f"; and {len(bad) - 5} more" if len(bad) > 5 else ""
    sys.stderr.write(
        f"alma: {path}: {len(bad)} damaged or inconsistent row(s) "
        f"(lines {describe_lines([line.number for line in bad])}) {action} — {faults}{more}\n"
    )


class _ResultsFile:
    """Append-only CSV: header once, one fsync'ed line per result, damaged lines set aside."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.quarantine = path.with_name(QUARANTINE_FILE)
        self.rows: dict[str, dict[str, str]] = {}
        self.set_aside_lines: list[Line] = []
        self._lines: list[Line] = []
        self._prepare()
        self._fh = open(self.path, "a", newline="", encoding="utf-8")

    def _prepare(self) -> None:
        if not self.path.exists() or self.path.stat().st_size == 0:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._rewrite()
            return
        header, good, bad = scan(self.path)
        self._lines = good
        for line in good:
            self.rows[line.fields[COLUMNS.index("key")]] = dict(zip(COLUMNS, line.fields, strict=True))
        if bad:
            self._set_aside(bad)
        elif header != COLUMNS or not self.path.read_bytes().endswith(b"\n"):
            self._rewrite()

    def set_aside(self, keys: dict[str, str]) -> None:
        """Move the rows of ``keys`` (key → why) to the quarantine, to be solved again."""
        if not keys:
            return
        bad = [
            Line(line.number, line.raw, problem=keys[line.fields[COLUMNS.index("key")]])
            for line in self._lines
            if line.fields[COLUMNS.index("key")] in keys
        ]
        self._lines = [line for line in self._lines if line.fields[COLUMNS.index("key")] not in keys]
        for key in keys:
            self.rows.pop(key, None)
        self._fh.close()
        self._set_aside(bad)
        self._fh = open(self.path, "a", newline="", encoding="utf-8")

    def _set_aside(self, bad: list[Line]) -> None:
        """Quarantine first, then the file without them: a kill in between keeps both copies."""
        text = b"".join(
            f"# {self.path.name} line {line.number}: {line.problem}\n".encode() + line.raw + b"\n" for line in bad
        )
        _fsync_write(self.quarantine, text, "ab")
        self._rewrite()
        self.set_aside_lines.extend(bad)
        report_damage(self.path, bad, f"set aside to {self.quarantine}; their panels are solved again")

    def _rewrite(self) -> None:
        """The header and the sound lines, replacing the file at once (a kill leaves either)."""
        body = b"".join(line.raw + b"\n" for line in self._lines)
        tmp = self.path.with_name(self.path.name + ".tmp")
        _fsync_write(tmp, _csv_line(COLUMNS).encode("utf-8") + body, "wb")
        os.replace(tmp, self.path)

    def append(self, row: dict[str, Any]) -> None:
        fields = format_row(row)
        text = _csv_line(fields)
        self._fh.write(text)  # one write per line
        self._fh.flush()
        os.fsync(self._fh.fileno())
        self.rows[str(row["key"])] = dict(zip(COLUMNS, fields, strict=True))
        self._lines.append(Line(0, text.rstrip("\n").encode("utf-8"), fields=tuple(fields)))

    def close(self) -> None:
        self._fh.close()


class _LineBuffer:
    def __init__(self) -> None:
        self.text = ""

    def write(self, s: str) -> None:
        self.text += s


def frame(rows: list[dict[str, str]]) -> pd.DataFrame:
    """The rows (fields as written) as a frame of :data:`COLUMNS`, numbers as floats, the last
    row of each key kept."""
    df = pd.DataFrame(rows, columns=list(COLUMNS), dtype=object).astype(str)
    for col in _NUMERIC:
        df[col] = pd.to_numeric(df[col].replace("", "nan"), errors="coerce")
    df = df.drop_duplicates("key", keep="last")
    return df.reset_index(drop=True)


def read_results(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read a ``results.csv`` written by :func:`run_doe` (last row per key wins).

    Damaged or inconsistent lines are left out and reported on stderr (``alma doe`` on the
    folder sets them aside and solves them again); ``ValueError`` when the file is not a
    results file."""
    path = Path(path)
    _, good, bad = scan(path)
    report_damage(path, bad, "left out (run alma doe on the folder to set them aside and solve them again)")
    return frame([dict(zip(COLUMNS, line.fields, strict=True)) for line in good])


def is_results_file(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` starts with the header of a study's results file (any of its versions)."""
    try:
        with open(path, "rb") as fh:
            first = fh.readline().rstrip(b"\r\n").decode("utf-8", "replace")
    except OSError:
        return False
    return tuple(next(csv.reader([first]), [])) in _HEADERS
