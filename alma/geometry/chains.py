"""Retrofitting chains across a wall (``alma panel --chain HEIGHT:STRENGTH``).

A chain is a horizontal tie (SPEC §2 ``ties``) at a given height across the whole wall, its
anchor plates on the outer faces of the two end blocks of the course it crosses, so that it ties
the wall's ends together.  ``anchored``: each end is tied instead to a fixed anchor just outside
the wall, as a chain running into stiff orthogonal walls would be.  Lengths mm, strength kN.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from alma.geometry.loads import Tie
from alma.geometry.parsing import SceneError
from alma.geometry.scene import Block, Scene

#: Width (mm) of an anchor block outside the wall, and its gap to the wall (no joint forms).
ANCHOR_WIDTH = 100.0
ANCHOR_GAP = 50.0


def with_chain(scene: Scene, height: float, strength: float, *, anchored: bool = False, name: str = "") -> Scene:
    """``scene`` with a chain at ``height`` (mm) of ``strength`` (kN) across its free blocks."""
    if strength < 0:
        raise SceneError(f"chain at {height:g} mm: strength must be >= 0 kN, got {strength}")
    free = [b for b in scene.blocks if not b.fixed]
    lo = np.array([b.vertices[:, 1].min() for b in free])
    hi = np.array([b.vertices[:, 1].max() for b in free])
    crossed = [b for b, a, c in zip(free, lo, hi, strict=True) if a < height < c]
    if not crossed:
        raise SceneError(
            f"chain at {height:g} mm: no block of the wall spans that height "
            f"(the wall's free blocks lie between {lo.min():g} and {hi.max():g} mm)"
        )
    left = min(crossed, key=lambda b: b.vertices[:, 0].min())
    right = max(crossed, key=lambda b: b.vertices[:, 0].max())
    x0, x1 = float(left.vertices[:, 0].min()), float(right.vertices[:, 0].max())
    label = name or f"chain{len(scene.ties) + 1}"
    if not anchored:
        chain = (Tie(label, left.id, (x0, height), right.id, (x1, height), float(strength)),)
        return dataclasses.replace(scene, ties=scene.ties + chain, validated=False)
    anchors = (
        _anchor(f"{label}-anchor-left", x0 - ANCHOR_GAP - ANCHOR_WIDTH, height),
        _anchor(f"{label}-anchor-right", x1 + ANCHOR_GAP, height),
    )
    ties = (
        Tie(
            f"{label}-left",
            left.id,
            (x0, height),
            anchors[0].id,
            (x0 - ANCHOR_GAP - ANCHOR_WIDTH / 2, height),
            float(strength),
        ),
        Tie(
            f"{label}-right",
            right.id,
            (x1, height),
            anchors[1].id,
            (x1 + ANCHOR_GAP + ANCHOR_WIDTH / 2, height),
            float(strength),
        ),
    )
    return dataclasses.replace(scene, blocks=scene.blocks + anchors, ties=scene.ties + ties, validated=False)


def _anchor(block_id: str, x0: float, height: float) -> Block:
    v = np.array(
        [
            [x0, height - ANCHOR_WIDTH / 2],
            [x0 + ANCHOR_WIDTH, height - ANCHOR_WIDTH / 2],
            [x0 + ANCHOR_WIDTH, height + ANCHOR_WIDTH / 2],
            [x0, height + ANCHOR_WIDTH / 2],
        ]
    )
    return Block(id=block_id, vertices=v, fixed=True)


def parse_chain(text: str) -> tuple[float, float]:
    """``HEIGHT:STRENGTH`` (mm, kN) of the command line."""
    try:
        height, strength = (float(x) for x in text.split(":"))
    except ValueError as exc:
        raise SceneError(f"--chain takes HEIGHT:STRENGTH in mm and kN, e.g. 690:5, got {text!r}") from exc
    return height, strength
