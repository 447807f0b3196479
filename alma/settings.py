"""Every tuned number of alma, in frozen dataclasses with a one-line reason each.

``alma.solve(scene, settings=Settings(...))`` takes them; the study keys hash them together
with the package version, so a change of any of them is never served from an old results file.
The evidence behind each default is in ``docs/decisions.md``.

No setting is a share of the wall clock: the searches spend work budgets (iterations, LP
solves, branch-and-bound nodes), so the same input gives the same answer on any machine.  The
only clock is :attr:`Settings.time_limit`, a user's hard cap whose cut is reported as
``limit_reached``.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class AssociativeSettings:
    """The associative LP (Eq. 10) and its certificate."""

    #: Clarabel's gap and feasibility tolerances: the certificate closes from 1e-10 on the largest walls.
    tolerance: float = 1e-11
    #: Clarabel's iteration cap: the certified paper panels and walls need 40-80.
    max_iter: int = 200
    #: f_Lᵀu = normalisation · n_free: block velocities of this order balance Clarabel's residuals.
    normalisation: float = 1000.0
    #: Relative gap (upper − lower) / max(1, |upper|) under which the bounds count as closed.
    gap_tolerance: float = 1e-7
    #: Largest admissibility residual (equilibrium, flow rule) of a field that counts as proof.
    residual_tolerance: float = 1e-9
    #: "clarabel", "ipm" (alma.engine; Clarabel if it does not converge) or "auto" (the interior
    #: point from alma.engine.select.AUTO_MIN_BLOCKS free blocks when a fast factorisation is installed).
    engine: str = "auto"


@dataclass(frozen=True)
class CertifySettings:
    """The mixed-integer certification of the non-associative lower bound (``alma.certify``)."""

    #: Branch-and-bound nodes of HiGHS's MIP: the 12-block scenes prove within ~10^4.
    node_limit: int = 200_000
    #: Simplex iterations of the LPs that derive the big-M constants (per LP).
    bound_lp_iterations: int = 200_000
    #: Velocity bound U as a multiple of the largest candidate mechanism's |u|∞.
    velocity_factor: float = 10.0
    #: Above this many contact points, one global normal-force bound replaces the per-point LPs.
    per_point_bounds: int = 400


@dataclass(frozen=True)
class SearchSettings:
    """The non-associative search (Eq. 9): which starts run and the work each may spend."""

    #: "fast", "thorough", or "auto" (thorough up to :attr:`thorough_blocks` free blocks).
    effort: str = "auto"
    #: Free blocks up to which "auto" means "thorough".
    thorough_blocks: int = 200


@dataclass(frozen=True)
class Settings:
    """All settings of one analysis.  ``time_limit`` (s) is a user's cap, not a budget."""

    associative: AssociativeSettings = field(default_factory=AssociativeSettings)
    search: SearchSettings = field(default_factory=SearchSettings)
    certify: CertifySettings = field(default_factory=CertifySettings)
    #: Wall-clock cap in seconds (None: none).  Hitting it gives ``limit_reached``.
    time_limit: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """Plain nested dict (JSON-ready) of every setting."""
        return dataclasses.asdict(self)

    def digest(self) -> str:
        """A short hash of every setting that changes a result (the time cap excluded)."""
        data = self.to_dict()
        data.pop("time_limit")
        text = json.dumps(data, sort_keys=True, default=repr)
        return hashlib.sha256(text.encode()).hexdigest()[:16]
