"""The paper's masonry panels (Table 1, SPEC §4): four bonds on a rigid ground.

Bond conventions (L = block length, h = 60 mm; pieces are cut at the panel
ends so both vertical edges are straight; the live load acts in +x):

- stack: a grid of L × h blocks;
- running: full blocks in even courses; odd courses offset by L/2 with L/2 bats at both ends;
- english: stretchers (L) in even courses; headers (L/2) in odd courses with L/4 queen closers at both ends;
- flemish: each course alternates stretcher and header, each header centred on the stretcher
  below; even courses S H S H … S H, odd courses L/4, H, S, H, …, S, H, 3L/4.
"""

from __future__ import annotations

import numpy as np

from alma.geometry.scene import Block, Scene, SceneError

PANEL_LENGTH = 1440.0
BLOCK_HEIGHT = 60.0
PANEL_HEIGHTS = {"2:1": 720.0, "1:1": 1440.0, "1:2": 2880.0}
BLOCK_LENGTHS = {"4:1": 240.0, "2:1": 120.0, "1:1": 60.0}
BONDS = ("running", "stack", "english", "flemish")
FRICTIONS = (0.27, 0.60, 1.00)


def course_lengths(bond: str, block_length: float, panel_length: float, course: int) -> np.ndarray:
    """Lengths of the pieces of one course, left to right (course 0 is the base)."""
    L = block_length
    odd = course % 2 == 1
    if bond == "stack" or (bond in ("running", "english") and not odd):
        count = panel_length / L
        return np.full(_whole(count, bond, L), L)
    if bond == "running":
        return np.concatenate([[L / 2], np.full(_whole(panel_length / L, bond, L) - 1, L), [L / 2]])
    if bond == "english":
        return np.concatenate([[L / 4], np.full(_whole((panel_length - L / 2) / (L / 2), bond, L), L / 2), [L / 4]])
    if bond == "flemish":
        pairs = _whole(panel_length / (1.5 * L), bond, L)
        if not odd:
            return np.tile([L, L / 2], pairs)
        return np.concatenate([[L / 4, L / 2], np.tile([L, L / 2], pairs - 1), [0.75 * L]])
    raise SceneError(f"bond must be one of {BONDS}, got {bond!r}")


def _whole(count: float, bond: str, L: float) -> int:
    n = int(round(count))
    if abs(n - count) > 1e-9 or n < 1:
        raise SceneError(f"{bond} bond: block length {L} does not fit the panel length a whole number of times")
    return n


def wall(
    bond: str,
    panel_length: float,
    panel_height: float,
    block_length: float,
    block_height: float = BLOCK_HEIGHT,
    *,
    friction: float = 0.6,
    thickness: float = 120.0,
    unit_weight: float = 18.0,
    name: str | None = None,
) -> Scene:
    """A bonded wall of ``panel_height / block_height`` courses on a fixed ground block."""
    courses = int(round(panel_height / block_height))
    if courses < 1 or abs(courses * block_height - panel_height) > 1e-9 * panel_height:
        raise SceneError(f"panel height {panel_height} is not a whole number of courses of {block_height}")
    pieces = []
    for course in range(courses):
        lengths = course_lengths(bond, block_length, panel_length, course)
        x = np.concatenate([[0.0], np.cumsum(lengths)])
        x[-1] = panel_length
        y0, y1 = course * block_height, (course + 1) * block_height
        pieces.append(np.column_stack([x[:-1], x[1:], np.full(len(lengths), y0), np.full(len(lengths), y1)]))
    boxes = np.vstack(pieces)
    blocks = [
        Block(
            id="ground",
            vertices=np.array([[0.0, -block_height], [panel_length, -block_height], [panel_length, 0.0], [0.0, 0.0]]),
            fixed=True,
        )
    ]
    for k, (x0, x1, y0, y1) in enumerate(boxes):
        blocks.append(Block(id=f"b{k + 1}", vertices=np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])))
    return Scene(
        blocks=tuple(blocks),
        thickness=thickness,
        unit_weight=unit_weight,
        friction=friction,
        name=name or (f"{bond} wall {panel_length:g}x{panel_height:g}, blocks {block_length:g}x{block_height:g}"),
    )


def paper_panel(bond: str, panel_ratio: str, block_ratio: str, friction: float) -> Scene:
    """One of the 108 panels of the paper's design of experiments (Table 1)."""
    if bond not in BONDS:
        raise SceneError(f"bond must be one of {BONDS}, got {bond!r}")
    if panel_ratio not in PANEL_HEIGHTS:
        raise SceneError(f"panel ratio must be one of {sorted(PANEL_HEIGHTS)}, got {panel_ratio!r}")
    if block_ratio not in BLOCK_LENGTHS:
        raise SceneError(f"block ratio must be one of {sorted(BLOCK_LENGTHS)}, got {block_ratio!r}")
    if not (np.isfinite(friction) and friction >= 0):
        raise SceneError(f"friction must be a finite number >= 0, got {friction}")
    return wall(
        bond,
        PANEL_LENGTH,
        PANEL_HEIGHTS[panel_ratio],
        BLOCK_LENGTHS[block_ratio],
        friction=float(friction),
        name=f"paper panel: {bond} bond, panel {panel_ratio}, blocks {block_ratio}, f = {friction:g}",
    )
