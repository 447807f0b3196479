"""The integrity of a study's rows: a checksum per row, and the reading of one line of
``results.csv`` that tells a sound row from a damaged or inconsistent one.

Every row is one physical line (the writer turns line breaks inside a field into spaces), so a
damaged line — an unbalanced quote, a line cut by a kill and continued by the next row, binary
garbage, a hand edit — spoils only itself: it is found here, set aside and solved again, and
the rows around it are kept.
"""

from __future__ import annotations

import csv
import hashlib
import math
from dataclasses import dataclass

#: The statuses whose row holds a value between its bounds (SPEC §3).
_BOUNDED_STATUSES = frozenset({"optimal", "feasible", "not_converged", "limit_reached"})
#: Relative slack of ``alpha_lower ≤ alpha_c ≤ alpha_upper``: the repr of a float round-trips
#: exactly, so any excess beyond round-off is an edit or a defect, never the file format.
BOUND_SLACK = 1e-12


def row_checksum(fields: list[str] | tuple[str, ...]) -> str:
    """The checksum of a row's fields as written (all but the checksum itself): 16 hex digits
    of SHA-256, so that any change of a value, of the key or of the order of the fields shows."""
    return hashlib.sha256("\x1f".join(fields).encode("utf-8")).hexdigest()[:16]


@dataclass(frozen=True)
class Line:
    """One line of a results file: its fields when sound, or why it is not (``problem``)."""

    number: int  # 1-based line number in the file (the header is line 1)
    raw: bytes
    fields: tuple[str, ...] = ()
    problem: str = ""


def read_line(number: int, raw: bytes, columns: tuple[str, ...], checked: bool) -> Line:
    """Parse one line (without its line break) of a results file of ``columns``.

    ``checked``: the last column is the row's checksum (:func:`row_checksum`), verified here
    together with the consistency of the row's values (:func:`inconsistency`).
    """
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        return Line(number, raw, problem="not UTF-8 text (binary garbage)")
    try:
        rows = list(csv.reader([text], strict=True))
    except csv.Error as exc:
        return Line(number, raw, problem=f"not a CSV line ({exc})")
    if len(rows) != 1:
        return Line(number, raw, problem="empty line")
    fields = tuple(rows[0])
    if len(fields) != len(columns):
        return Line(number, raw, problem=f"{len(fields)} fields, expected {len(columns)} (a cut or merged line)")
    if checked and row_checksum(fields[:-1]) != fields[-1]:
        return Line(number, raw, problem="its checksum does not match its content (edited or damaged)")
    problem = inconsistency(dict(zip(columns, fields, strict=True)))
    if problem:
        return Line(number, raw, problem=problem)
    return Line(number, raw, fields=fields)


def inconsistency(row: dict[str, str]) -> str:
    """Why the values of ``row`` cannot be a result (bounds out of order, a bounded status
    without its value), or ''."""
    if not row.get("key"):
        return "no key"
    if row.get("status") not in _BOUNDED_STATUSES:
        return ""
    try:
        alpha, lower, upper = (float(row.get(c) or "nan") for c in ("alpha_c", "alpha_lower", "alpha_upper"))
    except ValueError:
        return "a bound or alpha_c is not a number"
    if math.isnan(alpha):
        return f"status {row['status']} without alpha_c"
    slack = BOUND_SLACK * max(1.0, abs(alpha)) if math.isfinite(alpha) else 0.0
    if not math.isnan(lower) and lower > alpha + slack:
        return f"its lower bound {lower!r} exceeds alpha_c {alpha!r}"
    if not math.isnan(upper) and alpha > upper + slack:
        return f"alpha_c {alpha!r} exceeds its upper bound {upper!r}"
    return ""


def describe_lines(numbers: list[int], limit: int = 20) -> str:
    """'5, 9, 12' (at most ``limit`` numbers, then '…')."""
    shown = ", ".join(map(str, numbers[:limit]))
    return shown + (", …" if len(numbers) > limit else "")
