"""The results file of a study: append-only, one fsync'ed line per finished row, resumable."""
from __future__ import annotations

import csv
import math
import os
from pathlib import Path
from typing import Any

import pandas as pd

#: Columns of ``results.csv``, in order. The first five are those of Table 5 (``alma anova``).
COLUMNS: tuple[str, ...] = (
    "panel_ratio", "block_ratio", "bond", "friction", "alpha_c",
    "model", "status", "alpha_lower", "alpha_upper", "gap", "mechanism_class",
    "joints_s", "build_s", "solve_s", "certify_s", "message", "alma_version", "key",
    # The model comparison (``alma compare``).
    "alpha_associative", "ratio", "start", "alpha_lp_start", "lp_start_verified",
    "n_candidates", "n_verified", "nonassociative_s", "n_blocks", "effort",
    # Each start of the non-associative search, as JSON [[start, seconds, verified], ...].
    "starts",
    # Strength (kN) of the chain across the panel; 0: none (a design's chain factor).
    "chain",
)
#: The columns of a results file written before the chain factor: read, and given ``chain`` 0.
_COLUMNS_BEFORE_CHAIN: tuple[str, ...] = COLUMNS[:-1]
#: Numeric columns of ``results.csv``.
_NUMERIC = ("friction", "alpha_c", "alpha_lower", "alpha_upper", "gap", "joints_s", "build_s",
            "solve_s", "certify_s", "alpha_associative", "ratio", "alpha_lp_start",
            "n_candidates", "n_verified", "nonassociative_s", "n_blocks", "chain")
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
        if header == list(_COLUMNS_BEFORE_CHAIN):
            self._add_chain_column(text)
            text = self.path.read_text(encoding="utf-8")
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

    def _add_chain_column(self, text: str) -> None:
        """Rewrite a file of the columns before the chain factor with ``chain`` 0 on every row
        (its rows had no chain); a new file replaces the old one at once, so a kill leaves either."""
        rows = list(csv.reader(text.splitlines()))
        buf = _LineBuffer()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(COLUMNS)
        writer.writerows(r + ["0.0"] if len(r) == len(_COLUMNS_BEFORE_CHAIN) else r for r in rows[1:])
        tmp = self.path.with_name(self.path.name + ".tmp")
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.write(buf.text)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, self.path)

    def append(self, row: dict[str, Any]) -> None:
        buf = _LineBuffer()
        csv.writer(buf, lineterminator="\n").writerow([_format(row.get(c, "")) for c in COLUMNS])
        self._fh.write(buf.text)  # one write per line
        self._fh.flush()
        os.fsync(self._fh.fileno())
        self.rows[str(row["key"])] = {c: _format(row.get(c, "")) for c in COLUMNS}

    def close(self) -> None:
        self._fh.close()


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
    if "chain" not in df.columns:  # a file from before the chain factor: no chains
        df["chain"] = 0.0
    if "key" in df.columns:
        df = df.drop_duplicates("key", keep="last")
    return df.reset_index(drop=True)
