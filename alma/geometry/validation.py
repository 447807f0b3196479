"""Validation of a scene (SPEC §2): every bad input refused with a message naming block and rule.

Pure functions: a scene is read, never changed.  :func:`validated` returns the scene marked
validated (a new object when it was not) together with the joints the check had to find (a
free block must touch something), so that a caller building the model next does not detect
them again.  Lengths in mm.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from alma.geometry.contacts import Joints, find_joints
from alma.geometry.loads import check_items
from alma.geometry.parsing import SceneError
from alma.geometry.polygons import check_polygons, find_overlaps

if TYPE_CHECKING:
    from alma.geometry.scene import Scene


def validated(scene: Scene) -> tuple[Scene, Joints]:
    """(``scene`` marked validated, its joints) after :func:`check_scene`; ``scene`` itself is
    returned when it is marked already.  Raises SceneError on bad input."""
    joints = check_scene(scene)
    return (scene if scene.validated else dataclasses.replace(scene, validated=True)), joints


def check_scene(scene: Scene) -> Joints:
    """Refuse every bad input of SPEC §2 (materials, ids, polygons, supports, overlaps, free
    blocks that touch nothing, joint overrides of blocks that do not touch, loads and ties);
    returns the joints found (:func:`alma.geometry.contacts.find_joints`)."""
    _check_materials(scene)
    _check_ids(scene)
    check_polygons(scene)
    if not any(b.fixed for b in scene.blocks):
        raise SceneError("scene: no support — at least one block must be 'fixed': true")
    if all(b.fixed for b in scene.blocks):
        raise SceneError("scene: no free block — every block is fixed")
    overlaps, tolerance = find_overlaps(scene)
    if overlaps:
        i, j, depth = overlaps[0]
        raise SceneError(
            f"blocks '{scene.blocks[i].id}' and '{scene.blocks[j].id}' overlap: blocks may touch "
            f"but not interpenetrate (a sliver {depth:.3g} mm deep, beyond the contact tolerance of "
            f"{tolerance:.3g} mm; {len(overlaps)} overlapping pair(s) in all)"
        )
    joints = find_joints(scene)
    _check_joints(scene, joints)
    check_items(scene.blocks, scene.loads, scene.ties)
    return joints


def _check_materials(scene: Scene) -> None:
    """Thickness and unit weight > 0, friction and cohesion ≥ 0, σ_c > 0, the contact tolerance
    in (0, 0.01]."""
    if not scene.thickness > 0:
        raise SceneError(f"scene: thickness must be > 0, got {scene.thickness}")
    if not scene.unit_weight > 0:
        raise SceneError(f"scene: unit_weight must be > 0, got {scene.unit_weight}")
    if scene.friction < 0:
        raise SceneError(f"scene: friction must be >= 0, got {scene.friction}")
    if scene.cohesion < 0:
        raise SceneError(f"scene: cohesion must be >= 0, got {scene.cohesion}")
    if scene.compressive_strength is not None and not scene.compressive_strength > 0:
        raise SceneError(
            "scene: compressive_strength (MPa) must be > 0 (omit it for infinitely strong "
            f"blocks), got {scene.compressive_strength}"
        )
    if scene.contact_tolerance is not None and not 0 < scene.contact_tolerance <= 0.01:
        raise SceneError(
            "scene: contact_tolerance (relative to the blocks' size) must lie in (0, 0.01], "
            f"got {scene.contact_tolerance}"
        )


def _check_ids(scene: Scene) -> None:
    """Block ids unique; every joint override names blocks of the scene."""
    seen: set[str] = set()
    for block_id in (b.id for b in scene.blocks):
        if block_id in seen:
            raise SceneError(f"block '{block_id}': duplicate id")
        seen.add(block_id)
    for override in scene.joint_overrides:
        for block_id in override.blocks:
            if block_id not in seen:
                raise SceneError(f"joint {list(override.blocks)}: unknown block '{block_id}'")


def _check_joints(scene: Scene, joints: Joints) -> None:
    """Every free block touches something; every joint override names two blocks that touch."""
    touched = np.zeros(len(scene.blocks), dtype=bool)
    touched[joints.block_a] = True
    touched[joints.block_b] = True
    for index, block in enumerate(scene.blocks):
        if not block.fixed and not touched[index]:
            raise SceneError(f"block '{block.id}': touches nothing — a free block needs at least one joint")
    if scene.joint_overrides:
        position = {b.id: i for i, b in enumerate(scene.blocks)}
        pairs = set(
            zip(
                np.minimum(joints.block_a, joints.block_b).tolist(),
                np.maximum(joints.block_a, joints.block_b).tolist(),
                strict=True,
            )
        )
        for override in scene.joint_overrides:
            i, j = sorted(position[k] for k in override.blocks)
            if (i, j) not in pairs:
                raise SceneError(f"joint {list(override.blocks)}: these blocks do not touch")
