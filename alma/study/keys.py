"""Keys of study rows: a hash of everything that changes a row (factors, model, the alma version,
the settings), so that a results file never serves a row computed otherwise."""
from __future__ import annotations

import hashlib
import json
from typing import Any

import alma
from alma.settings import Settings


def _alma_version() -> str:
    return str(alma.__version__)


def key_settings(settings: Settings, model: str) -> dict[str, Any]:
    """What of ``settings`` changes a row of ``model``: the associative LP's settings for the
    associative model (so fast and thorough runs share those rows), all of them otherwise."""
    data = settings.to_dict()
    return {"associative": data["associative"]} if model == "associative" else data


def _friction_text(f: float) -> str:
    return format(float(f), ".12g")


def panel_key(panel_ratio: str, block_ratio: str, bond: str, friction: float, model: str,
              *, version: str | None = None, settings: Settings | dict[str, Any] | None = None,
              chain: float = 0.0, chain_y: float | None = None, chain_anchored: bool = False) -> str:
    """Stable key of one result row: hash of factors, model, alma version and every setting
    that changes the row (:func:`key_settings`; a dict is taken as it is).

    A chain (strength ``chain`` kN > 0 at height ``chain_y`` mm, ``chain_anchored`` or not)
    enters the hash; without one (``chain`` 0) the key is the one of a study without the chain
    factor, so that such rows resume from earlier results files.
    """
    if not isinstance(settings, dict):
        settings = key_settings(settings if settings is not None else Settings(), model)
    payload = {
        "panel_ratio": panel_ratio, "block_ratio": block_ratio, "bond": bond,
        "friction": _friction_text(friction), "model": model,
        "alma": _alma_version() if version is None else version,
        "solver": settings,
    }
    if chain > 0:
        if chain_y is None:
            raise ValueError("panel_key: a chain needs its height chain_y (mm)")
        payload["chain"] = {"strength": _friction_text(chain), "y": _friction_text(chain_y),
                            "anchored": bool(chain_anchored)}
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:20]
