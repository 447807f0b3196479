"""Keys of study rows: a hash of everything that changes a row (factors, model, the alma version,
alma's source code, the settings), so that a results file never serves a row computed otherwise."""

from __future__ import annotations

import functools
import hashlib
import json
from pathlib import Path
from typing import Any

import alma
from alma.settings import Settings


def _alma_version() -> str:
    return str(alma.__version__)


@functools.lru_cache(maxsize=1)
def code_revision() -> str:
    """A hash of alma's own source: every ``alma/**/*.py`` file's path (relative, sorted) and
    bytes, computed once per process.  It changes with any edit of the code, and needs neither
    git nor a source checkout (it reads the installed package, a wheel's as well)."""
    root = Path(alma.__file__).resolve().parent
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py"), key=lambda p: p.relative_to(root).as_posix()):
        digest.update(path.relative_to(root).as_posix().encode("utf-8") + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def key_settings(settings: Settings, model: str) -> dict[str, Any]:
    """What of ``settings`` changes a row of ``model``: the associative LP's settings for the
    associative model (so fast and thorough runs share those rows), all of them otherwise."""
    data = settings.to_dict()
    return {"associative": data["associative"]} if model == "associative" else data


def _friction_text(f: float) -> str:
    return format(float(f), ".12g")


def panel_key(
    panel_ratio: str,
    block_ratio: str,
    bond: str,
    friction: float,
    model: str,
    *,
    version: str | None = None,
    revision: str | None = None,
    settings: Settings | dict[str, Any] | None = None,
    chain: float = 0.0,
    chain_y: float | None = None,
    chain_anchored: bool = False,
    compressive_strength: float = 0.0,
) -> str:
    """Stable key of one result row: hash of factors, model, alma version, the code revision
    (``revision``, default :func:`code_revision`) and every setting that changes the row
    (:func:`key_settings`; a dict is taken as it is).

    A chain (strength ``chain`` kN > 0 at height ``chain_y`` mm, ``chain_anchored`` or not)
    enters the hash; without one (``chain`` 0) the key is the one of a study without the chain
    factor, so that such rows resume from earlier results files.  A ``compressive_strength``
    (MPa, > 0) enters it likewise; 0 (infinitely strong blocks) leaves the key as it was.
    """
    if not isinstance(settings, dict):
        settings = key_settings(settings if settings is not None else Settings(), model)
    payload = {
        "panel_ratio": panel_ratio,
        "block_ratio": block_ratio,
        "bond": bond,
        "friction": _friction_text(friction),
        "model": model,
        "alma": _alma_version() if version is None else version,
        "code": code_revision() if revision is None else revision,
        "solver": settings,
    }
    if chain > 0:
        if chain_y is None:
            raise ValueError("panel_key: a chain needs its height chain_y (mm)")
        payload["chain"] = {
            "strength": _friction_text(chain),
            "y": _friction_text(chain_y),
            "anchored": bool(chain_anchored),
        }
    if compressive_strength > 0:
        payload["compressive_strength"] = _friction_text(compressive_strength)
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:20]
