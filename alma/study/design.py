"""The factor levels of a full-factorial study (Table 1 of the paper by default).

Panels are enumerated in the order of Table 5: friction slowest, then bond, block ratio, and
panel ratio fastest.  A TOML or JSON file can change the levels (:func:`load_design`)::

    panel_ratio = ["2:1", "1:1"]
    block_ratio = ["4:1"]
    bond = ["running", "stack"]
    friction = [0.27, 0.6]
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from alma.geometry.panels import BLOCK_LENGTHS, BONDS, FRICTIONS, PANEL_HEIGHTS

_PANEL_RATIOS = tuple(PANEL_HEIGHTS)
_BLOCK_RATIOS = tuple(BLOCK_LENGTHS)
_BONDS = BONDS


@dataclass(frozen=True)
class Design:
    """Factor levels of a full-factorial study (Table 1 of the paper by default).

    Panels are enumerated in the order of Table 5: friction slowest, then bond, block ratio,
    and panel ratio fastest.
    """

    panel_ratio: tuple[str, ...] = _PANEL_RATIOS
    block_ratio: tuple[str, ...] = _BLOCK_RATIOS
    bond: tuple[str, ...] = _BONDS
    friction: tuple[float, ...] = FRICTIONS

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
