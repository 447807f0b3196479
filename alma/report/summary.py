"""The result in words (issue 36): the headline, the lines under it and the folded details of a
page, and the caption of each picture, for ``solve``/``panel`` (one model or both), ``settle``
and ``tilt``.  Numbers for people (:mod:`alma.report.numbers`); the JSON keeps every digit."""

from __future__ import annotations

import math
from typing import Any

from alma.report.drawing import Drawing
from alma.report.numbers import count, interval, mechanism_words, number, status_line, status_short
from alma.report.page import Header

MODEL_WORDS = {
    "associative": "associative (Eq. 10)",
    "nonassociative": "non-associative (Eq. 9)",
    "settlement": "settlement",
    "tilt": "tilting table",
}


def parts(result: Any) -> list[Any]:
    """The results a picture shows: both of a ``model="both"`` comparison, else the one."""
    if hasattr(result, "associative") and hasattr(result, "nonassociative"):
        return [result.associative, result.nonassociative]
    return [result]


def alpha_words(r: Any) -> str:
    """ "α = 0.2264 (proven)", or what the status says instead of a value."""
    status = str(r.status)
    if status == "no_collapse":
        return "no collapse"
    if status in ("no_equilibrium", "invalid_input"):
        return status_short(status)
    proven = {"optimal": "proven", "feasible": "an upper bound"}.get(status, "not proven")
    return f"α = {number(r.alpha)} ({proven})"


def caption(r: Any, drawing: Drawing | None) -> str:
    """One line over a picture: model, α, mechanism class and how many blocks move."""
    words = f"{MODEL_WORDS.get(str(r.model), str(r.model))}: {alpha_words(r)}"
    if r.mechanism_class:
        words += f"; {r.mechanism_class}"
    if drawing is not None and drawing.moving:
        words += f"; {drawing.moving} of {count(_free(r, drawing), 'block')} move"
    return words


def _free(r: Any, drawing: Drawing) -> int:
    return int(getattr(r, "n_blocks", 0) or sum(1 for m in drawing.marks if m.cls.startswith("block-")))


def solve_header(result: Any, drawings: list[Drawing]) -> Header:
    """The page of ``alma solve``/``panel``: α with its proven interval, the status in plain
    language, the mechanism class and how many blocks move, per model; details folded."""
    rs = parts(result)
    headline = "; ".join(
        (MODEL_WORDS[str(r.model)].split(" (")[0] + " " if len(rs) > 1 else "Collapse multiplier ") + alpha_words(r)
        for r in rs
    )
    lines, details = [], []
    for r, d in zip(rs, drawings, strict=True):
        who = f"{MODEL_WORDS[str(r.model)]}: " if len(rs) > 1 else ""
        moving = f", {d.moving} of {count(_free(r, d), 'block')} move" if d.moving else ""
        lines.append(
            f"{who}α {interval(r.bounds.lower, r.bounds.upper)}. {status_line(r.status)} "
            f"Mechanism: {mechanism_words(r.mechanism_class)}, "
            f"{count(len(r.macro_blocks), 'rigid part')}{moving}."
        )
        details += _details(r, who)
    return Header(headline, tuple(lines), tuple(details))


def _details(r: Any, who: str) -> list[tuple[str, str]]:
    b = r.bounds
    rows = [
        (f"{who}status", str(r.status)),
        (f"{who}α", number(r.alpha, 9)),
        (f"{who}bounds", f"lower {number(b.lower, 9)}, upper {number(b.upper, 9)}, relative gap {number(b.gap, 2)}"),
        (f"{who}message", r.message),
    ]
    if str(r.model) == "nonassociative":
        rows.append((f"{who}associative α", number(r.alpha_associative, 9)))
        rows += [(f"{who}certificate", r.certificate["message"])] if getattr(r, "certificate", None) else []
    rows += [
        (f"{who}time, {key.removesuffix('_s').replace('_', ' ')}", f"{number(v, 3)} s") for key, v in r.timings.items()
    ]
    return rows + [(f"{who}warning", w) for w in r.warnings]


def settle_header(scene: Any, result: Any, drawing: Drawing) -> Header:
    """The page of ``alma settle``: which support settles, how many joints open, the work and
    the reactions."""
    moving = [b for b in scene.blocks if b.settlement is not None]
    who = ", ".join(b.id for b in moving) or "no support"
    headline = f"Settlement of {who}: {count(len(result.opened), 'joint')} open (the crack pattern)"
    lines = [
        f"Work of the dead load on the mechanism {interval(result.bounds.lower, result.bounds.upper, 'kN·mm')}. "
        f"{status_line(result.status)}",
        f"{drawing.moving} of {count(sum(not b.fixed for b in scene.blocks), 'block')} move.",
    ]
    lines += [
        f"Reaction on {r['block']}: force ({number(r['force'][0])}, {number(r['force'][1])}) kN, "
        f"moment {number(r['moment'])} kN·mm."
        for r in result.reactions
    ]
    details = [("status", str(result.status)), ("work", f"{number(result.work, 9)} kN·mm"), ("message", result.message)]
    details += [(f"time, {k.removesuffix('_s')}", f"{number(v, 3)} s") for k, v in result.timings.items()]
    return Header(headline, tuple(lines), tuple(details))


def tilt_header(result: Any, drawing: Drawing | None) -> Header:
    """The page of ``alma tilt``: the critical angle with its proven bracket and the method."""
    lo, hi = result.bounds_deg
    angle = result.angle_deg
    headline = (
        f"Critical tilt θ_c = {number(angle)}°" if math.isfinite(angle) else status_short(result.status).capitalize()
    )
    method = (
        "exact: θ_c = atan α_c of the horizontal live load"
        if result.method == "exact"
        else f"bisection, {count(result.steps, 'certified LP solve')}"
    )
    lines = [
        f"The structure stands up to {number(lo)}° and collapses from {number(hi)}° on ({method}). "
        f"θ_c {interval(lo, hi, '°')}.",
        status_line(result.status),
    ]
    if drawing is not None and drawing.moving:
        lines.append(f"{drawing.moving} blocks move in the collapse on the tilted table.")
    details = (
        ("status", str(result.status)),
        ("angle", f"{number(angle, 9)}°"),
        ("message", result.message),
        ("method", result.method),
        ("LP solves", str(result.steps)),
    )
    return Header(headline, tuple(lines), details)
