"""Typed results, plain frozen data in physical units (mm, rad, kN, kN·mm).

- :class:`AssociativeResult` — Eq. 10: certified bounds, both residuals, mechanism, joint forces;
- :class:`NonAssociativeResult` — Eq. 9: the verified state, its residuals, the search record,
  the certificate (if any) and the associative result it was started from;
- :class:`Comparison` — ``model="both"``: both results whole and their ratio.

Each serialises to the JSON object of SPEC §3 with ``to_dict()``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from alma.status import Status


@dataclass(frozen=True)
class Bounds:
    """Proven interval of the collapse multiplier: lower ≤ α_c ≤ upper.

    ``lower_is`` and ``upper_is`` say what each side is (e.g. "proven bound (MILP certificate)",
    "verified collapse state"); empty when the producer does not say.
    """

    lower: float
    upper: float
    lower_is: str = ""
    upper_is: str = ""

    @property
    def gap(self) -> float:
        """Relative gap (upper − lower) / max(1, |upper|)."""
        if not (math.isfinite(self.lower) and math.isfinite(self.upper)):
            return float("nan")
        return (self.upper - self.lower) / max(1.0, abs(self.upper))

    def describe(self, digits: int = 9) -> str:
        """The interval as text, ``[lower, upper]`` with what each side is and the relative gap when
        both sides are finite; a side that proves nothing is written "none" (never ±inf or nan)."""

        def side(value: float) -> str:
            return f"{value:.{digits}g}" if math.isfinite(value) else "none"

        text = f"[{side(self.lower)}, {side(self.upper)}]"
        named = [f"{label}: {what}" for label, what in (("lower", self.lower_is), ("upper", self.upper_is)) if what]
        if named:
            text += f"  ({'; '.join(named)})"
        if math.isfinite(self.gap):
            text += f"  relative gap {self.gap:.1e}"
        return text


@dataclass(frozen=True)
class BlockMotion:
    """Collapse velocity of a free block: (u, v) at its centroid in mm, θ in rad."""

    id: str
    u: tuple[float, float, float]


@dataclass(frozen=True)
class JointResult:
    """A joint's generalised stresses and motion.

    ``N`` (compression > 0) and ``T`` in kN, ``M`` in kN·mm about the joint's centre;
    ``points`` the (N, T) of its two contact points (start, end) in kN; ``slip`` and ``opening``
    relative velocities (mm per unit mechanism).
    """

    blocks: tuple[str, str]
    N: float
    T: float
    M: float
    state: str
    length: float
    slip: float
    opening: tuple[float, float]
    start: tuple[float, float]
    end: tuple[float, float]
    points: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
    #: Unit normal of the joint line, from ``blocks[0]`` towards ``blocks[1]`` (N acts along it).
    normal: tuple[float, float] = (0.0, 0.0)
    #: Finite compressive strength only (SPEC §2): σ_c l t (kN) and the stress block's segment
    #: on the joint (mm; extent N/(σ_c t), centred on the resultant).
    capacity: float | None = None
    stress_block: tuple[tuple[float, float], tuple[float, float]] | None = None


@dataclass(frozen=True)
class MacroBlock:
    """Blocks that move as one rigid body (SPEC §3 ``macro_blocks``): a ``rotation`` about
    ``centre`` (mm) or a ``translation`` along ``direction`` (unit vector)."""

    blocks: tuple[str, ...]
    motion: str
    centre: tuple[float, float] | None
    direction: tuple[float, float] | None

    def to_dict(self) -> dict[str, Any]:
        return {
            "blocks": list(self.blocks),
            "motion": self.motion,
            "centre": list(self.centre) if self.centre is not None else None,
            "direction": list(self.direction) if self.direction is not None else None,
        }


@dataclass(frozen=True)
class Result:
    """What every analysis gives, shaped like ``scipy.optimize.OptimizeResult``."""

    model: str
    status: Status
    message: str
    alpha: float
    bounds: Bounds
    alpha_associative: float
    blocks: tuple[BlockMotion, ...]
    #: A :class:`~alma.results.joint_table.JointTable` from the solvers (any sequence is accepted).
    joints: Sequence[JointResult]
    mechanism_class: str
    residuals: dict[str, float]
    timings: dict[str, float]  # seconds only
    n_blocks: int = 0
    n_joints: int = 0
    #: Near misses of the contact detection (facing edges apart beyond the contact tolerance).
    warnings: tuple[str, ...] = ()
    #: The moving macro-blocks of the mechanism (:mod:`alma.results.macro_blocks`).
    macro_blocks: tuple[MacroBlock, ...] = ()

    @property
    def success(self) -> bool:
        """True when α is proven (``optimal``)."""
        return self.status == Status.OPTIMAL

    @property
    def extra(self) -> dict[str, Any]:
        """The fields beyond SPEC §3's minimum, by name (as ``to_dict`` writes them)."""
        return {"n_blocks": self.n_blocks, "n_joints": self.n_joints}

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of SPEC §3 (non-finite numbers become null)."""
        out: dict[str, Any] = {
            "model": self.model,
            "status": str(self.status),
            "message": self.message,
            "alpha": finite(self.alpha),
            "bounds": {
                "lower": finite(self.bounds.lower),
                "upper": finite(self.bounds.upper),
                "gap": finite(self.bounds.gap),
                "lower_is": self.bounds.lower_is,
                "upper_is": self.bounds.upper_is,
            },
            "alpha_associative": finite(self.alpha_associative),
            "mechanism_class": self.mechanism_class,
            "macro_blocks": [m.to_dict() for m in self.macro_blocks],
            "blocks": [{"id": b.id, "u": [float(x) for x in b.u]} for b in self.blocks],
            "joints": _joint_records(self.joints),
            "residuals": {k: finite(v) for k, v in self.residuals.items()},
            "timings": dict(self.timings),
            "warnings": list(self.warnings),
        }
        for key, value in self.extra.items():
            out[key] = finite(value) if isinstance(value, float) else value
        return out


@dataclass(frozen=True)
class AssociativeResult(Result):
    """Eq. 10, certified from both sides: ``bounds`` are the static and kinematic values."""

    iterations: int = 0
    #: Each tie's id, force (kN) and elongation rate (mm per unit mechanism).
    ties: tuple[dict[str, Any], ...] = ()

    @property
    def extra(self) -> dict[str, Any]:
        out = {**super().extra, "iterations": self.iterations}
        if self.ties:
            out["ties"] = [dict(t) for t in self.ties]
        return out


@dataclass(frozen=True)
class NonAssociativeResult(Result):
    """Eq. 9: the lowest verified collapse state found, and what is proven below it.

    ``status`` is ``feasible`` for a verified state (``bounds.upper`` = α), ``optimal`` only when
    a proof (certification) closes the bounds.  ``associative`` is the certified LP result the
    search started from.
    """

    start: str | None = None
    candidates: tuple[dict[str, Any], ...] = ()
    starts: tuple[dict[str, Any], ...] = ()
    search: dict[str, Any] = field(default_factory=dict)
    certificate: dict[str, Any] | None = None
    associative: AssociativeResult | None = None
    #: Each tie's id, force (kN) and elongation rate in the collapse state (as the associative's).
    ties: tuple[dict[str, Any], ...] = ()

    @property
    def extra(self) -> dict[str, Any]:
        out = {
            **super().extra,
            "start": self.start,
            "candidates": list(self.candidates),
            "starts": list(self.starts),
            "search": dict(self.search),
        }
        if self.certificate is not None:
            out["certificate"] = dict(self.certificate)
        if self.ties:
            out["ties"] = [dict(t) for t in self.ties]
        return out


@dataclass(frozen=True)
class Comparison:
    """``model="both"``: the associative and the non-associative result, whole, and their ratio."""

    associative: AssociativeResult
    nonassociative: NonAssociativeResult

    @property
    def ratio(self) -> float | None:
        """α_nonassociative / α_associative (None where it is not defined)."""
        a, b = self.associative.alpha, self.nonassociative.alpha
        if not (math.isfinite(a) and math.isfinite(b)) or a == 0.0:
            return None
        return b / a

    def __getattr__(self, name: str) -> Any:
        # The top level reads as the non-associative result (SPEC §3: ``alpha`` of ``both``).
        if name in ("associative", "nonassociative"):
            raise AttributeError(name)
        return getattr(self.nonassociative, name)

    @property
    def model(self) -> str:
        return "both"

    @property
    def extra(self) -> dict[str, Any]:
        return {**self.nonassociative.extra, "alpha_nonassociative": self.nonassociative.alpha, "ratio": self.ratio}

    def to_dict(self) -> dict[str, Any]:
        """SPEC §3 for ``both``: the non-associative object at the top, ``alpha_associative``,
        ``alpha_nonassociative``, ``ratio``, and both results whole."""
        out = self.nonassociative.to_dict()
        out.update(
            model="both",
            alpha_associative=finite(self.associative.alpha),
            alpha_nonassociative=finite(self.nonassociative.alpha),
            ratio=finite(self.ratio),
            associative=self.associative.to_dict(),
            nonassociative=self.nonassociative.to_dict(),
        )
        return out


def finite(value: float | None) -> float | None:
    """``value`` as a float, or None when it is None or not finite (JSON has no inf/NaN)."""
    return float(value) if value is not None and math.isfinite(value) else None


def _joint_records(joints: Sequence[JointResult]) -> list[dict[str, Any]]:
    """SPEC §3's joint objects; column-wise when the joints are a table."""
    records = getattr(joints, "records", None)
    if records is not None:
        return records()
    return [
        {
            "blocks": list(j.blocks),
            "N": j.N,
            "T": j.T,
            "M": j.M,
            "state": j.state,
            "length": j.length,
            "slip": j.slip,
            "opening": list(j.opening),
            "points": [{"N": n, "T": t} for n, t in j.points],
        }
        for j in joints
    ]
