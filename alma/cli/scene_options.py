"""The scene options every scene-reading command shares (SPEC §3), and the scene they build.

``add_scene_options(parser)`` gives a subcommand ``--thickness --unit-weight --friction
--cohesion --supports --contact-tolerance``; ``scene_from_args(args)`` reads ``args.scene`` with
them.  A command that reads a scene (``solve``, ``tilt``, ``settle`` and any later one) calls
both, so that one drawing is read the same way by every command.  A new scene option is one
entry of :data:`MATERIALS` (a scene field set on every joint or block without an override) or
one argument in :func:`add_scene_options` and its use in :func:`scene_from_args`.  Values are
checked as they are parsed (finite, and > 0 or >= 0 as the quantity requires).

- DXF drawings hold no materials: the options give them (defaults of SPEC §4).
- A JSON scene holds its own materials: an option given on the command line replaces the
  scene's top-level value (joints with an override in ``"joints"`` keep theirs), so that
  ``--friction 0.4`` is never silently ignored. ``--supports`` applies to drawings only.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from alma.geometry.scene import Scene, SceneError, load_scene


def finite_float(text: str) -> float:
    """An argparse type: a finite number (NaN and inf are refused with the option named)."""
    try:
        value = float(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from exc
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def positive_float(text: str) -> float:
    """An argparse type: a finite number > 0."""
    value = finite_float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text!r}")
    return value


def non_negative_float(text: str) -> float:
    """An argparse type: a finite number >= 0."""
    value = finite_float(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text!r}")
    return value


#: The materials a command line may set: (scene field = option destination, argparse type, help).
#: Each is a top-level scene value applying to every joint or block without an override.
MATERIALS: tuple[tuple[str, Callable[[str], float], str], ...] = (
    ("thickness", positive_float, "mm (default 120)"),
    ("unit_weight", positive_float, "kN/m³ (default 18)"),
    ("friction", non_negative_float, "f = tan φ on every joint without an override (default 0.6)"),
    ("cohesion", non_negative_float, "kPa on every joint without an override (default 0)"),
)


def add_scene_options(parser: argparse.ArgumentParser) -> argparse._ArgumentGroup:
    """Add the shared scene options to ``parser``; returns the group, for options added later."""
    group = parser.add_argument_group(
        "scene options",
        "materials of a DXF drawing (SPEC §4 defaults); for a JSON scene they replace the scene's own top-level values",
    )
    for field, kind, text in MATERIALS:
        group.add_argument("--" + field.replace("_", "-"), type=kind, default=None, help=text)
    group.add_argument(
        "--supports",
        choices=("layers", "lowest"),
        default=None,
        help="DXF only: supports from layer names (fixed/support/ground, the default) or every "
        "block reaching the lowest y",
    )
    group.add_argument(
        "--contact-tolerance",
        type=positive_float,
        default=None,
        metavar="REL",
        help="gaps and overlaps snapped to a joint, relative to the median block size "
        "(default 1e-4; overrides the scene's contact_tolerance)",
    )
    return group


def add_compressive_strength(group: argparse._ArgumentGroup) -> None:
    """Add ``--compressive-strength MPA`` (SPEC §2 ``compressive_strength`` on every joint) to a
    command whose analysis takes a finite compressive strength; :func:`scene_from_args` applies it."""
    group.add_argument(
        "--compressive-strength",
        type=positive_float,
        default=None,
        metavar="MPA",
        help="σ_c of every joint in MPa (overrides the scene's compressive_strength; default: the "
        "scene's, else infinitely strong blocks)",
    )


def with_compressive_strength(scene: Scene, value: float | None) -> Scene:
    """``scene`` with ``--compressive-strength`` (MPa) for every joint, when given (SPEC §2)."""
    if value is None:
        return scene
    if not (math.isfinite(value) and value > 0):
        raise SceneError(f"--compressive-strength (MPa) must be a finite number > 0, got {value}")
    return dataclasses.replace(scene, compressive_strength=float(value))


def scene_from_args(args: argparse.Namespace) -> Scene:
    """The validated scene of ``args.scene`` with the scene options of ``args`` applied.

    Raises
    ------
    SceneError
        The file cannot be read, is not a scene, or an option does not apply to it.
    """
    path = Path(args.scene)
    given: dict[str, Any] = {field: getattr(args, field, None) for field, _, _ in MATERIALS}
    given = {field: value for field, value in given.items() if value is not None}
    supports = getattr(args, "supports", None)
    if path.suffix.lower() == ".dxf":
        scene = load_scene(path, supports=supports, **given)
    else:
        if supports is not None:
            raise SceneError(
                f"--supports applies to DXF drawings; the JSON scene '{path}' marks its supports with \"fixed\": true"
            )
        scene = load_scene(path)
        if given:
            scene = dataclasses.replace(scene, **given, validated=False)
    scene = with_compressive_strength(scene, getattr(args, "compressive_strength", None))
    tolerance = getattr(args, "contact_tolerance", None)
    if tolerance is not None:
        scene = dataclasses.replace(scene, contact_tolerance=tolerance, validated=False)
    return scene if scene.validated else scene.validate()
