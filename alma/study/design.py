"""The factor levels of a full-factorial study (Table 1 of the paper by default).

Panels are enumerated in the order of Table 5: friction slowest, then bond, block ratio, and
panel ratio fastest.  A TOML or JSON file can change the levels (:func:`load_design`)::

    panel_ratio = ["2:1", "1:1"]
    block_ratio = ["4:1"]
    bond = ["running", "stack"]
    friction = [0.27, 0.6]
    chain = [0, 0.25, 1, 5]     # kN: a retrofitting chain across the top course, one more factor
    chain_height = 1.0          # fraction of the panel's height: the course the chain runs in
    chain_anchored = false      # true: its ends tied to fixed anchors (stiff orthogonal walls)
    compressive_strength = [0, 2, 5, 10]   # MPa, σ_c on every joint; 0: infinitely strong blocks

The chain factor (default ``[0]``: no chain, today's study with today's keys) puts one
horizontal chain of that strength across the panel, as ``alma panel --chain`` does
(:func:`alma.geometry.chains.with_chain`): at mid-height of the course at ``chain_height`` × H
(1.0: the top course, where a chain ties a wall at its floor or roof), its anchor plates on the
outer faces of that course's two end blocks, so that it ties the panel's ends together.

The compressive-strength factor (default ``[0]``: infinitely strong blocks, today's keys) gives
every joint of the panel, the ground joint included, the crushing strength σ_c in MPa, as the
scene key ``compressive_strength`` does (issue 34; associative model only).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from alma.geometry.panels import BLOCK_HEIGHT, BLOCK_LENGTHS, BONDS, FRICTIONS, PANEL_HEIGHTS

_PANEL_RATIOS = tuple(PANEL_HEIGHTS)
_BLOCK_RATIOS = tuple(BLOCK_LENGTHS)
_BONDS = BONDS


@dataclass(frozen=True)
class Design:
    """Factor levels of a full-factorial study (Table 1 of the paper by default).

    Panels are enumerated in the order of Table 5: friction slowest, then bond, block ratio,
    and panel ratio fastest; every panel runs at each ``chain`` strength (kN; 0: no chain), the
    chain levels slower, and at each ``compressive_strength`` (MPa; 0: infinitely strong blocks),
    slowest of all.  ``chain_height`` is the fraction of the panel's height whose
    course the chain runs in (at its mid-height; 1.0: the top course); ``chain_anchored`` ties
    its ends to fixed anchors instead of to each other.
    """

    panel_ratio: tuple[str, ...] = _PANEL_RATIOS
    block_ratio: tuple[str, ...] = _BLOCK_RATIOS
    bond: tuple[str, ...] = _BONDS
    friction: tuple[float, ...] = FRICTIONS
    chain: tuple[float, ...] = (0.0,)
    chain_height: float = 1.0
    chain_anchored: bool = False
    compressive_strength: tuple[float, ...] = (0.0,)

    def __post_init__(self) -> None:
        for name, allowed in (("panel_ratio", _PANEL_RATIOS), ("block_ratio", _BLOCK_RATIOS), ("bond", _BONDS)):
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
        object.__setattr__(self, "friction", _levels("friction", self.friction))
        object.__setattr__(self, "chain", _levels("chain", self.chain))
        object.__setattr__(self, "compressive_strength", _levels("compressive_strength", self.compressive_strength))
        h = self.chain_height
        if isinstance(h, bool) or not isinstance(h, (int, float)) or not (0.0 < float(h) <= 1.0):
            raise ValueError(f"design: bad chain_height {h!r}; expected a fraction of the panel's height in (0, 1]")
        object.__setattr__(self, "chain_height", float(h))
        if not isinstance(self.chain_anchored, bool):
            raise ValueError(f"design: bad chain_anchored {self.chain_anchored!r}; expected true or false")

    @property
    def geometries(self) -> list[tuple[str, str, str]]:
        """(panel_ratio, block_ratio, bond) of every geometry, Table 5 order."""
        return [(p, b, bond) for bond in self.bond for b in self.block_ratio for p in self.panel_ratio]

    def panels(self) -> list[tuple[str, str, str, float]]:
        """(panel_ratio, block_ratio, bond, friction) of every panel, Table 5 order."""
        return [
            (p, b, bond, f)
            for f in self.friction
            for bond in self.bond
            for b in self.block_ratio
            for p in self.panel_ratio
        ]

    def runs(self) -> list[tuple[str, str, str, float, float, float]]:
        """(panel_ratio, block_ratio, bond, friction, chain, compressive_strength) of every run,
        the compressive strength slowest, then the chain."""
        return [(*panel, c, s) for s in self.compressive_strength for c in self.chain for panel in self.panels()]

    @property
    def has_chain(self) -> bool:
        """Whether some run has a chain (a level > 0)."""
        return any(c > 0 for c in self.chain)

    def chain_y(self, panel_ratio: str) -> float:
        """Height (mm) of the chain on a panel: mid-height of the course at ``chain_height`` × H."""
        height = PANEL_HEIGHTS[panel_ratio]
        course = min(math.floor(self.chain_height * height / BLOCK_HEIGHT), round(height / BLOCK_HEIGHT) - 1)
        return (course + 0.5) * BLOCK_HEIGHT

    def __len__(self) -> int:
        """Number of runs per contact model (panels × chain levels × compressive strengths)."""
        return (
            len(self.panel_ratio)
            * len(self.block_ratio)
            * len(self.bond)
            * len(self.friction)
            * len(self.chain)
            * len(self.compressive_strength)
        )

    def to_dict(self) -> dict[str, Any]:
        return {k: list(v) if isinstance(v, tuple) else v for k, v in dataclasses.asdict(self).items()}


def _levels(name: str, values: tuple[Any, ...]) -> tuple[float, ...]:
    """Numeric levels (friction coefficient, chain strength in kN, compressive strength in MPa):
    finite, >= 0, distinct."""
    out: list[float] = []
    for v in values:
        if isinstance(v, bool):
            raise ValueError(f"design: bad {name} level {v!r}")
        try:
            f = float(v)
        except (TypeError, ValueError):
            raise ValueError(f"design: bad {name} level {v!r}; expected a number") from None
        if not (math.isfinite(f) and f >= 0):
            raise ValueError(f"design: bad {name} level {v!r}; expected a finite number >= 0")
        out.append(f)
    if not out:
        raise ValueError(f"design: {name} needs at least one level")
    if len(set(out)) != len(out):
        raise ValueError(f"design: repeated {name} level in {out}")
    return tuple(out)


PAPER_DESIGN = Design()

_DESIGN_KEYS = {
    "panel_ratio": "panel_ratio",
    "panel_ratios": "panel_ratio",
    "block_ratio": "block_ratio",
    "block_ratios": "block_ratio",
    "bond": "bond",
    "bonds": "bond",
    "friction": "friction",
    "frictions": "friction",
    "chain": "chain",
    "chains": "chain",
    "chain_height": "chain_height",
    "chain_anchored": "chain_anchored",
    "compressive_strength": "compressive_strength",
    "compressive_strengths": "compressive_strength",
}
#: Options of the design that take one value, not a list of levels.
_SCALARS = ("chain_height", "chain_anchored")


def load_design(path: str | os.PathLike[str]) -> Design:
    """Read factor levels from a TOML (``.toml``) or JSON file; missing factors keep the paper's.

    Keys: ``panel_ratio``, ``block_ratio``, ``bond``, ``friction``, ``chain``,
    ``compressive_strength`` (plural forms accepted), each a list of levels (a single value is a
    one-level list), and the single values ``chain_height`` and ``chain_anchored``; they may also sit in
    a ``[design]`` table.
    Unknown keys and bad levels raise ``ValueError``.
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
            raise ValueError(
                f"{p}: unknown key {key!r}; expected panel_ratio, block_ratio, bond, friction, "
                "chain, chain_height, chain_anchored, compressive_strength"
            )
        if field in kwargs:
            raise ValueError(f"{p}: factor {field!r} given twice")
        if field in _SCALARS:
            if isinstance(value, (list, dict)):
                raise ValueError(f"{p}: {field} takes one value, got {value!r}")
            kwargs[field] = value
            continue
        values = value if isinstance(value, list) else [value]
        kwargs[field] = tuple(values)
    try:
        return Design(**kwargs)
    except ValueError as exc:
        raise ValueError(f"{p}: {exc}") from None
