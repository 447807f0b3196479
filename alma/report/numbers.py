"""Numbers and words for people (issue 36): significant digits, intervals said in words, `—` where
nothing is proven.  The JSON keeps every digit; these strings are for pictures and pages only."""

from __future__ import annotations

import math
from decimal import ROUND_CEILING, ROUND_FLOOR, Context, Decimal
from typing import Any

from alma.display_settings import PictureSettings

#: What a person reads where no number is proven (a missing or infinite bound, NaN).
NOT_PROVEN = "—"

_STATUS_WORDS = {
    "optimal": "proven — the certified lower and upper bounds meet",
    "feasible": "a verified collapse state — α is an upper bound, proven only down to the lower bound",
    "no_collapse": "no collapse — the structure carries any multiple of the live load",
    "no_equilibrium": "no equilibrium — the structure cannot carry its own dead load",
    "not_converged": "not proven — the solver stopped before the bounds met; α is its best value",
    "limit_reached": "not proven — the time limit stopped the analysis",
    "invalid_input": "invalid input — nothing was solved",
}

_CLASS_WORDS = {
    "sliding": "sliding (every moving part translates)",
    "rocking": "rocking (every moving part turns about a hinge)",
    "mixed": "mixed (rocking and sliding together)",
    "settlement": "settlement",
}


def number(x: Any, digits: int | None = None, unit: str = "") -> str:
    """``x`` with ``digits`` significant digits (a true minus sign), or :data:`NOT_PROVEN` for
    None, NaN and ±inf."""
    digits = digits or PictureSettings().digits
    if x is None or not isinstance(x, (int, float)) or not math.isfinite(x):
        return NOT_PROVEN
    text = f"{float(x):.{digits}g}".replace("-", "−")
    if "e" in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa} × 10^{int(exponent.replace('−', '-'))}".replace("-", "−")
    return text + unit if unit in ("", "°") else f"{text} {unit}"


def interval(lower: Any, upper: Any, unit: str = "", digits: int | None = None) -> str:
    """The certified bracket in words: "proven: a" where both bounds round to the same ``digits``
    significant digits, else "proven between a and b" rounded outwards, "—" for a side that is
    not proven.  A bound within 1e-12 of the other's
    size of zero reads 0 (solver round-off, not a value)."""
    digits = digits or PictureSettings().digits
    lo, hi = (float(v) if isinstance(v, (int, float)) else math.nan for v in (lower, upper))
    scale = max(abs(v) for v in (lo, hi, 1.0) if math.isfinite(v))
    lo, hi = (0.0 if math.isfinite(v) and abs(v) < 1e-12 * scale else v for v in (lo, hi))
    if not math.isfinite(lo) and not math.isfinite(hi):
        return "not proven (no bound: —)"
    if not math.isfinite(lo):
        return f"at most {number(hi, digits, unit)}; no lower bound proven (—)"
    if not math.isfinite(hi):
        return f"at least {number(lo, digits, unit)}; no upper bound proven (—)"
    if number(lo, digits, unit) == number(hi, digits, unit):
        return f"proven: {number(lo, digits, unit)} (both bounds round to it)"
    a = number(_outward(lo, digits, ROUND_FLOOR), digits, unit)
    b = number(_outward(hi, digits, ROUND_CEILING), digits, unit)
    return f"proven between {a} and {b}"


def _outward(x: float, digits: int, rounding: str) -> float:
    """``x`` rounded to ``digits`` significant digits away from the bracket's inside (the lower
    bound down, the upper up), so that the digits shown still bracket what is proven."""
    return float(Context(prec=digits, rounding=rounding).plus(Decimal(repr(x))))


def status_words(status: Any) -> str:
    """The status of SPEC §3 in plain language: "proven — …"."""
    return _STATUS_WORDS.get(str(status), str(status))


def status_line(status: Any) -> str:
    """ "Status: proven — … (optimal).", the JSON's word kept in brackets."""
    return f"Status: {status_words(status)} ({status})."


def status_short(status: Any) -> str:
    """The plain words before the dash: "proven", "no equilibrium"."""
    return status_words(status).split(" — ")[0]


def mechanism_words(mechanism_class: Any) -> str:
    """The mechanism class in plain language ("no mechanism" when there is none)."""
    return _CLASS_WORDS.get(str(mechanism_class or ""), str(mechanism_class or "no mechanism"))


def count(n: int, word: str) -> str:
    """ "1 block", "3 blocks"."""
    return f"{n} {word}" + ("" if n == 1 else "s")
