"""What acts on a scene besides self-weight (SPEC §2): point loads, ties, support settlements.

Lengths in mm, forces in kN, rotations in radians (counter-clockwise).  Each item is read from
the scene file here and checked against the blocks by :func:`check_items` (a point must lie in
its block, a settlement belongs to a fixed block, ...), with an error naming the item.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from alma.geometry.parsing import SceneError, number, pair

_LOAD_KEYS = {"block", "point", "dead", "live"}
_TIE_KEYS = {"id", "from", "to", "strength"}
_END_KEYS = {"block", "point"}
_SETTLEMENT_KEYS = {"translation", "rotation", "about"}


@dataclass(frozen=True)
class PointLoad:
    """A point load on a free block: ``dead`` acts always, ``live`` is multiplied by α (kN).
    ``point`` None means the block's centroid."""

    block: str
    point: tuple[float, float] | None = None
    dead: tuple[float, float] = (0.0, 0.0)
    live: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class Tie:
    """A straight tension-only member (a retrofitting chain, a tie rod) of ``strength`` kN
    between a point of one block and a point of another (either may be fixed: an anchor)."""

    id: str
    from_block: str
    from_point: tuple[float, float]
    to_block: str
    to_point: tuple[float, float]
    strength: float


@dataclass(frozen=True)
class Settlement:
    """A prescribed small rigid motion of a support: translation (mm) and rotation (rad) about
    ``about`` (mm)."""

    translation: tuple[float, float] = (0.0, 0.0)
    rotation: float = 0.0
    about: tuple[float, float] = (0.0, 0.0)


def load_from_dict(raw: Any, index: int) -> PointLoad:
    what = f"load #{index}"
    if not isinstance(raw, Mapping):
        raise SceneError(f"{what}: must be an object")
    _no_unknown(raw, _LOAD_KEYS, what)
    if "block" not in raw:
        raise SceneError(f"{what}: missing 'block'")
    what = f"load #{index} on block '{raw['block']}'"
    point = pair(raw["point"], f"{what}: point") if raw.get("point") is not None else None
    return PointLoad(
        block=str(raw["block"]),
        point=point,
        dead=pair(raw.get("dead", (0.0, 0.0)), f"{what}: dead"),
        live=pair(raw.get("live", (0.0, 0.0)), f"{what}: live"),
    )


def tie_from_dict(raw: Any, index: int) -> Tie:
    if not isinstance(raw, Mapping):
        raise SceneError(f"tie #{index}: must be an object")
    tie_id = str(raw.get("id", f"tie{index}"))
    what = f"tie '{tie_id}'"
    _no_unknown(raw, _TIE_KEYS, what)
    ends = []
    for key in ("from", "to"):
        end = raw.get(key)
        if not isinstance(end, Mapping) or "block" not in end or "point" not in end:
            raise SceneError(f'{what}: \'{key}\' must be {{"block": ..., "point": [x, y]}}')
        _no_unknown(end, _END_KEYS, f"{what}: '{key}'")
        ends.append((str(end["block"]), pair(end["point"], f"{what}: '{key}' point")))
    if "strength" not in raw:
        raise SceneError(f"{what}: missing 'strength' (kN)")
    strength = number(raw["strength"], f"{what}: strength")
    if strength < 0:
        raise SceneError(f"{what}: strength must be >= 0 kN, got {strength}")
    if np.hypot(*np.subtract(ends[1][1], ends[0][1])) == 0:
        raise SceneError(f"{what}: its two points coincide (a tie needs a length)")
    return Tie(tie_id, ends[0][0], ends[0][1], ends[1][0], ends[1][1], strength)


def settlement_from_dict(raw: Any, block_id: str) -> Settlement:
    what = f"block '{block_id}': settlement"
    if not isinstance(raw, Mapping):
        raise SceneError(f"{what} must be an object")
    _no_unknown(raw, _SETTLEMENT_KEYS, what)
    return Settlement(
        translation=pair(raw.get("translation", (0.0, 0.0)), f"{what}: translation"),
        rotation=number(raw.get("rotation", 0.0), f"{what}: rotation"),
        about=pair(raw.get("about", (0.0, 0.0)), f"{what}: about"),
    )


def check_items(blocks: Sequence[Any], loads: Sequence[PointLoad], ties: Sequence[Tie]) -> None:
    """Every load and tie names an existing block and a point inside it; loads act on free blocks."""
    by_id = {b.id: b for b in blocks}
    for k, load in enumerate(loads):
        what = f"load #{k} on block '{load.block}'"
        block = _block(by_id, load.block, what)
        if block.fixed:
            raise SceneError(f"{what}: the block is fixed (a support carries no load)")
        if load.point is not None and not _inside(block.vertices, load.point):
            raise SceneError(f"{what}: point {list(load.point)} lies outside the block")
    for tie in ties:
        for end, (name, point) in (("from", (tie.from_block, tie.from_point)), ("to", (tie.to_block, tie.to_point))):
            block = _block(by_id, name, f"tie '{tie.id}' ({end})")
            if not _inside(block.vertices, point):
                raise SceneError(f"tie '{tie.id}': its '{end}' point {list(point)} lies outside block '{name}'")
        if tie.from_block == tie.to_block:
            raise SceneError(f"tie '{tie.id}': both ends are on block '{tie.from_block}'")


def load_to_dict(load: PointLoad) -> dict[str, Any]:
    out: dict[str, Any] = {"block": load.block, "dead": list(load.dead), "live": list(load.live)}
    if load.point is not None:
        out["point"] = list(load.point)
    return out


def tie_to_dict(tie: Tie) -> dict[str, Any]:
    return {
        "id": tie.id,
        "from": {"block": tie.from_block, "point": list(tie.from_point)},
        "to": {"block": tie.to_block, "point": list(tie.to_point)},
        "strength": tie.strength,
    }


def settlement_to_dict(s: Settlement) -> dict[str, Any]:
    return {"translation": list(s.translation), "rotation": s.rotation, "about": list(s.about)}


def _block(by_id: Mapping[str, Any], name: str, what: str) -> Any:
    if name not in by_id:
        raise SceneError(f"{what}: no block '{name}' in the scene")
    return by_id[name]


def _inside(vertices: np.ndarray, point: tuple[float, float]) -> bool:
    """``point`` in the closed polygon (even-odd rule; the boundary counts as inside, to a
    relative 1e-9 of the polygon's size)."""
    v = np.asarray(vertices, dtype=float)
    x, y = point
    scale = max(float(np.ptp(v[:, 0])), float(np.ptp(v[:, 1])), 1e-300)
    a, b = v, np.roll(v, -1, axis=0)
    edge = b - a
    t = np.clip(((x - a[:, 0]) * edge[:, 0] + (y - a[:, 1]) * edge[:, 1]) / (edge**2).sum(axis=1), 0.0, 1.0)
    nearest = np.hypot(a[:, 0] + t * edge[:, 0] - x, a[:, 1] + t * edge[:, 1] - y).min()
    if nearest <= 1e-9 * scale:
        return True
    crosses = ((a[:, 1] > y) != (b[:, 1] > y)) & (
        x < a[:, 0] + (y - a[:, 1]) * edge[:, 0] / np.where(edge[:, 1] == 0, 1.0, edge[:, 1])
    )
    return bool(crosses.sum() % 2 == 1)


def _no_unknown(raw: Mapping[str, Any], allowed: set[str], what: str) -> None:
    unknown = set(raw) - allowed
    if unknown:
        raise SceneError(f"{what}: unknown key(s) {sorted(unknown)}; allowed: {sorted(allowed)}")
