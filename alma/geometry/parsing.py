"""Reading numbers and directions from a scene file, and the error every bad input raises."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any


class SceneError(ValueError):
    """A scene broke a rule of SPEC §2; the message names the block and the rule."""


def number(value: Any, what: str) -> float:
    """A finite float, or a :class:`SceneError` naming ``what``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(f"{what} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise SceneError(f"{what} is NaN or inf")
    return value


def pair(value: Any, what: str) -> tuple[float, float]:
    """A pair [x, y] of finite numbers."""
    try:
        items = list(value)
    except TypeError as exc:
        raise SceneError(f"{what} must be a pair [x, y]") from exc
    if len(items) != 2:
        raise SceneError(f"{what} must be a pair [x, y]")
    x, y = (number(v, what) for v in items)
    return (x, y)


def direction(value: Iterable[Any], what: str) -> tuple[float, float]:
    """A unit vector from a non-zero pair [x, y]."""
    x, y = pair(value, what)
    norm = math.hypot(x, y)
    if norm == 0:
        raise SceneError(f"{what} must be a non-zero vector")
    return (x / norm, y / norm)


def listed(data: Mapping[str, Any], key: str) -> list[Any]:
    """``data[key]`` as a list (absent or empty: []), else a SceneError naming the key."""
    value = data.get(key) or []
    if not isinstance(value, list):
        raise SceneError(f"scene: '{key}' must be a list")
    return value


def optional_number(value: Any, what: str) -> float | None:
    """None, or a finite number (:func:`number`)."""
    return None if value is None else number(value, what)


def flag(value: Any, what: str) -> bool:
    """A JSON boolean, else a SceneError naming ``what``."""
    if not isinstance(value, bool):
        raise SceneError(f"{what} must be true or false, got {value!r}")
    return value
