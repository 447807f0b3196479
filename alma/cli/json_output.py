"""The one JSON object a command prints with ``--json`` (SPEC §3): strict JSON, never NaN.

A quantity that is not a finite number (an unproven bound, a mechanism a failed solver left
undefined) is ``null``: Python's ``json`` would write ``NaN``/``Infinity``, which are not JSON
and which strict parsers (JavaScript's, jq) refuse.
"""

from __future__ import annotations

import json
import math
from typing import Any


def strict(value: Any) -> Any:
    """``value`` with every non-finite float replaced by ``None`` (nested dicts, lists, tuples)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: strict(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [strict(item) for item in value]
    return value


def dumps(value: Any) -> str:
    """One line of strict JSON (``allow_nan=False``: a non-finite number left over is a bug, loud)."""
    return json.dumps(strict(value), allow_nan=False)
