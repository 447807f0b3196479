"""Scenes: assemblies of convex polygonal rigid blocks (SPEC §2).

A scene holds geometry and material data only; joints are found from it
(``alma.geometry.contacts``) and the mechanical model is built downstream
(``alma.mechanics.model``).  Lengths in mm, unit weight in kN/m³.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from alma.floats import dot, times
from alma.geometry import validation
from alma.geometry.dxf import read_dxf
from alma.geometry.loads import (
    PointLoad,
    Settlement,
    Tie,
    load_from_dict,
    load_to_dict,
    settlement_from_dict,
    settlement_to_dict,
    tie_from_dict,
    tie_to_dict,
)
from alma.geometry.parsing import (
    SceneError,
    direction as _direction,
    flag as _flag,
    listed as _list,
    number as _number,
    optional_number as _optional_number,
)

_SCENE_KEYS = {
    "name",
    "thickness",
    "unit_weight",
    "friction",
    "cohesion",
    "blocks",
    "live_load",
    "gravity",
    "joints",
    "loads",
    "ties",
    "contact_tolerance",
    "compressive_strength",
}
_BLOCK_KEYS = {"id", "vertices", "fixed", "weight", "settlement"}
_LIVE_KEYS = {"direction", "self_weight"}
_JOINT_KEYS = {"blocks", "friction", "cohesion", "compressive_strength"}


@dataclass(frozen=True)
class Block:
    """A rigid convex block; ``vertices`` counter-clockwise, shape (k, 2), in mm."""

    id: str
    vertices: np.ndarray
    fixed: bool = False
    weight: float | None = None  # kN, overrides area × thickness × unit weight
    settlement: Settlement | None = None  # a prescribed motion of a support (fixed blocks only)

    @property
    def area(self) -> float:
        return float(polygon_area(self.vertices))

    @property
    def centroid(self) -> np.ndarray:
        return polygon_centroid(self.vertices)


@dataclass(frozen=True)
class JointOverride:
    """Per-joint material (SPEC §2): friction/cohesion/compressive strength (MPa) of the joint
    between two blocks."""

    blocks: tuple[str, str]
    friction: float | None = None
    cohesion: float | None = None
    compressive_strength: float | None = None


@dataclass(frozen=True)
class Scene:
    """A validated assembly of blocks with its material and load data."""

    blocks: tuple[Block, ...]
    thickness: float = 120.0
    unit_weight: float = 18.0
    friction: float = 0.6
    cohesion: float = 0.0
    name: str = ""
    gravity: tuple[float, float] = (0.0, -1.0)
    live_load_direction: tuple[float, float] = (1.0, 0.0)
    joint_overrides: tuple[JointOverride, ...] = field(default=())
    loads: tuple[PointLoad, ...] = ()
    ties: tuple[Tie, ...] = ()
    #: The live load includes each free block's weight along ``live_load_direction``.
    live_self_weight: bool = True
    #: Gaps and overlaps snapped to a joint, relative to the median √area of the free blocks
    #: (None: :data:`alma.geometry.edges.CONTACT`'s default).
    contact_tolerance: float | None = None
    #: σ_c of every joint in MPa (SPEC §2): N ≤ σ_c l t, |M| ≤ N (l/2 − N/(2 σ_c t)); None:
    #: infinitely strong blocks.
    compressive_strength: float | None = None
    #: True on the scene :meth:`validate` returns (and on the loaders'): a scene built by hand is
    #: validated before it is solved.  A change of geometry or material passes ``validated=False``.
    validated: bool = field(default=False, compare=False, repr=False)

    # ------------------------------------------------------------------ I/O
    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, validate: bool = True) -> Scene:
        """Build a scene from the JSON object of SPEC §2 and validate it."""
        if not isinstance(data, Mapping):
            raise SceneError("scene: the top level must be a JSON object")
        unknown = set(data) - _SCENE_KEYS
        if unknown:
            raise SceneError(f"scene: unknown key(s) {sorted(unknown)}; allowed: {sorted(_SCENE_KEYS)}")
        if "blocks" not in data:
            raise SceneError("scene: missing 'blocks'")
        raw_blocks = data["blocks"]
        if not isinstance(raw_blocks, list) or not raw_blocks:
            raise SceneError("scene: 'blocks' must be a non-empty list")
        blocks = []
        for index, raw in enumerate(raw_blocks):
            blocks.append(_block_from_dict(raw, index))
        live = data.get("live_load", {}) or {}
        if not isinstance(live, Mapping):
            raise SceneError("scene: 'live_load' must be an object")
        unknown = set(live) - _LIVE_KEYS
        if unknown:
            raise SceneError(f"live_load: unknown key(s) {sorted(unknown)}")
        overrides = tuple(_joint_override(raw, i) for i, raw in enumerate(data.get("joints", []) or []))
        scene = cls(
            blocks=tuple(blocks),
            thickness=_number(data.get("thickness", 120.0), "scene: thickness"),
            unit_weight=_number(data.get("unit_weight", 18.0), "scene: unit_weight"),
            friction=_number(data.get("friction", 0.6), "scene: friction"),
            cohesion=_number(data.get("cohesion", 0.0), "scene: cohesion"),
            name=str(data.get("name", "")),
            gravity=_direction(data.get("gravity", (0.0, -1.0)), "scene: gravity"),
            live_load_direction=_direction(live.get("direction", (1.0, 0.0)), "live_load: direction"),
            joint_overrides=overrides,
            loads=tuple(load_from_dict(raw, i) for i, raw in enumerate(_list(data, "loads"))),
            ties=tuple(tie_from_dict(raw, i) for i, raw in enumerate(_list(data, "ties"))),
            live_self_weight=_flag(live.get("self_weight", True), "live_load: self_weight"),
            contact_tolerance=_optional_number(data.get("contact_tolerance"), "scene: contact_tolerance"),
            compressive_strength=_optional_number(data.get("compressive_strength"), "scene: compressive_strength"),
        )
        return scene.validate() if validate else scene

    def to_dict(self) -> dict[str, Any]:
        """The scene as the JSON object of SPEC §2."""
        out: dict[str, Any] = {
            "name": self.name,
            "thickness": self.thickness,
            "unit_weight": self.unit_weight,
            "friction": self.friction,
            "cohesion": self.cohesion,
            "gravity": list(self.gravity),
            "blocks": [],
            "live_load": {"direction": list(self.live_load_direction), "self_weight": self.live_self_weight},
        }
        for block in self.blocks:
            entry: dict[str, Any] = {"id": block.id, "vertices": block.vertices.tolist()}
            if block.fixed:
                entry["fixed"] = True
            if block.weight is not None:
                entry["weight"] = block.weight
            if block.settlement is not None:
                entry["settlement"] = settlement_to_dict(block.settlement)
            out["blocks"].append(entry)
        if self.loads:
            out["loads"] = [load_to_dict(load) for load in self.loads]
        if self.ties:
            out["ties"] = [tie_to_dict(tie) for tie in self.ties]
        if self.contact_tolerance is not None:
            out["contact_tolerance"] = self.contact_tolerance
        if self.compressive_strength is not None:
            out["compressive_strength"] = self.compressive_strength
        if self.joint_overrides:
            out["joints"] = [
                {
                    k: v
                    for k, v in (
                        ("blocks", list(o.blocks)),
                        ("friction", o.friction),
                        ("cohesion", o.cohesion),
                        ("compressive_strength", o.compressive_strength),
                    )
                    if v is not None
                }
                for o in self.joint_overrides
            ]
        return out

    def with_friction(self, friction: float) -> Scene:
        """The same geometry with another friction coefficient (no re-validation needed)."""
        if not (math.isfinite(friction) and friction >= 0):
            raise SceneError(f"scene: friction must be a finite number >= 0, got {friction}")
        return dataclasses.replace(self, friction=float(friction))

    # ----------------------------------------------------------- validation
    def validate(self) -> Scene:
        """Refuse every bad input of SPEC §2 with a message naming block and rule
        (:func:`alma.geometry.validation.check_scene`); return the scene marked validated.

        Pure: ``self`` is not changed, so a caller keeps the returned scene (a loaded scene is
        returned validated).  :func:`~alma.geometry.validation.validated` also gives the joints
        the check found, for a caller that builds the model next.
        """
        return validation.validated(self)[0]

    # --------------------------------------------------------------- helpers
    @property
    def block_ids(self) -> list[str]:
        return [b.id for b in self.blocks]

    def transformed(self, matrix: np.ndarray, offset: Sequence[float] = (0.0, 0.0), rotate_loads: bool = True) -> Scene:
        """Apply x -> matrix @ x + offset to every block (and to gravity/live load directions)."""
        matrix = np.asarray(matrix, dtype=float)
        shift = np.asarray(offset, dtype=float)
        blocks = tuple(dataclasses.replace(b, vertices=_ccw(times(b.vertices, matrix.T) + shift)) for b in self.blocks)
        gravity, live = self.gravity, self.live_load_direction
        if rotate_loads:
            gravity = _direction(times(np.asarray(gravity, dtype=float), matrix.T), "transformed gravity")
            live = _direction(times(np.asarray(live, dtype=float), matrix.T), "transformed live load direction")
        return dataclasses.replace(self, blocks=blocks, gravity=gravity, live_load_direction=live, validated=False)


def load_scene(path: str | Path, **dxf_options: Any) -> Scene:
    """Read and validate a scene file (SPEC §2): JSON, or a DXF drawing (``.dxf``), whose
    ``thickness``, ``unit_weight``, ``friction``, ``cohesion`` and ``supports`` ("layers" or
    "lowest") are keyword arguments (:func:`alma.geometry.dxf.read_dxf`)."""
    path = Path(path)
    if path.suffix.lower() == ".dxf":
        try:
            data = read_dxf(path, **{k: v for k, v in dxf_options.items() if v is not None})
        except SceneError:
            raise
        except (StopIteration, EOFError, ValueError, IndexError, KeyError) as exc:  # ezdxf on a damaged file
            raise SceneError(
                f"DXF file '{path}': cannot be read, truncated or damaged ({type(exc).__name__}: {exc})"
            ) from exc
        try:
            return Scene.from_dict(data)
        except SceneError as exc:
            raise SceneError(f"DXF file '{path}': {exc} (blocks are named LAYER/HANDLE)") from exc
    if dxf_options:
        raise SceneError(
            f"scene file '{path}': {sorted(dxf_options)} apply to DXF drawings only; a JSON "
            "scene holds its own materials"
        )
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError(f"scene file '{path}': cannot be read ({exc.strerror})") from exc
    except UnicodeDecodeError as exc:
        raise SceneError(
            f"scene file '{path}': not UTF-8 text (byte {exc.start}); a scene is a JSON file or a .dxf drawing"
        ) from exc
    try:
        data = json.loads(text)  # NaN/Infinity parse to floats; validation names the block
    except json.JSONDecodeError as exc:
        raise SceneError(f"scene file '{path}': not valid JSON ({exc.msg} at line {exc.lineno})") from exc
    except RecursionError as exc:
        raise SceneError(f"scene file '{path}': nested too deeply to be a scene") from exc
    try:
        return Scene.from_dict(data)
    except SceneError as exc:
        raise SceneError(f"scene file '{path}': {exc}") from exc


# ---------------------------------------------------------------- geometry
def cyclic(values: np.ndarray, shift: int) -> np.ndarray:
    """``np.roll(values, shift, axis=0)``, the same array, without np.roll's general-axis
    overhead, a third of the canonical drawing's time on a 1,752-block panel (0.85 s against 0.53 s)."""
    k = -shift % len(values) if len(values) else 0
    return np.concatenate((values[k:], values[:k]))


def polygon_area(vertices: np.ndarray) -> float:
    """Signed area (positive when counter-clockwise), shoelace formula."""
    x, y = vertices[:, 0], vertices[:, 1]
    return 0.5 * (dot(x, cyclic(y, -1)) - dot(cyclic(x, -1), y))


def polygon_centroid(vertices: np.ndarray) -> np.ndarray:
    """Centroid of a simple polygon, computed about its first vertex for accuracy."""
    origin = vertices[0]
    local = vertices - origin
    x, y = local[:, 0], local[:, 1]
    xn, yn = cyclic(x, -1), cyclic(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    cx = ((x + xn) * cross).sum() / (6 * area)
    cy = ((y + yn) * cross).sum() / (6 * area)
    return origin + np.array([cx, cy])


def _ccw(vertices: np.ndarray) -> np.ndarray:
    return vertices if polygon_area(vertices) >= 0 else vertices[::-1].copy()


def _block_from_dict(raw: Any, index: int) -> Block:
    if not isinstance(raw, Mapping):
        raise SceneError(f"block #{index}: must be an object")
    block_id = str(raw.get("id", f"b{index}"))
    unknown = set(raw) - _BLOCK_KEYS
    if unknown:
        raise SceneError(f"block '{block_id}': unknown key(s) {sorted(unknown)}; allowed: {sorted(_BLOCK_KEYS)}")
    if "vertices" not in raw:
        raise SceneError(f"block '{block_id}': missing 'vertices'")
    try:
        vertices = np.array(raw["vertices"], dtype=float)
    except (TypeError, ValueError) as exc:
        raise SceneError(f"block '{block_id}': vertices must be a list of [x, y] numbers") from exc
    if vertices.ndim != 2 or vertices.shape[1] != 2:
        raise SceneError(f"block '{block_id}': vertices must be a list of [x, y] pairs")
    if len(vertices) < 3:
        raise SceneError(f"block '{block_id}': a polygon needs at least 3 vertices, got {len(vertices)}")
    if not np.all(np.isfinite(vertices)):
        raise SceneError(f"block '{block_id}': vertices contain NaN or inf")
    fixed = raw.get("fixed", False)
    if not isinstance(fixed, bool):
        raise SceneError(f"block '{block_id}': 'fixed' must be true or false")
    weight = raw.get("weight")
    if weight is not None:
        weight = _number(weight, f"block '{block_id}': weight")
        if weight < 0:
            raise SceneError(f"block '{block_id}': weight must be >= 0")
    settlement = None
    if raw.get("settlement") is not None:
        if not fixed:
            raise SceneError(f"block '{block_id}': a settlement is a motion of a support; the block is not fixed")
        settlement = settlement_from_dict(raw["settlement"], block_id)
    return Block(id=block_id, vertices=_ccw(vertices), fixed=fixed, weight=weight, settlement=settlement)


def _joint_override(raw: Any, index: int) -> JointOverride:
    if not isinstance(raw, Mapping):
        raise SceneError(f"joint #{index}: must be an object")
    unknown = set(raw) - _JOINT_KEYS
    if unknown:
        raise SceneError(f"joint #{index}: unknown key(s) {sorted(unknown)}")
    pair = raw.get("blocks")
    if not isinstance(pair, list) or len(pair) != 2:
        raise SceneError(f"joint #{index}: 'blocks' must name two blocks")
    friction = raw.get("friction")
    cohesion = raw.get("cohesion")
    strength = _optional_number(raw.get("compressive_strength"), f"joint {pair}: compressive_strength")
    if strength is not None and not strength > 0:
        raise SceneError(f"joint {pair}: compressive_strength (MPa) must be > 0, got {strength}")
    if friction is not None:
        friction = _number(friction, f"joint {pair}: friction")
        if friction < 0:
            raise SceneError(f"joint {pair}: friction must be >= 0, got {friction}")
    if cohesion is not None:
        cohesion = _number(cohesion, f"joint {pair}: cohesion")
        if cohesion < 0:
            raise SceneError(f"joint {pair}: cohesion must be >= 0, got {cohesion}")
    return JointOverride(
        blocks=(str(pair[0]), str(pair[1])), friction=friction, cohesion=cohesion, compressive_strength=strength
    )
