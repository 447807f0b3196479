"""The blocks' rigid motions as arrays, for pictures: velocities and displaced points of many
points of many blocks at once (mm, rad), the blocks' speeds, the joints' blocks and ends."""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from alma.geometry.scene import Scene


@dataclass(frozen=True)
class Motion:
    """Each block's centroid and collapse velocity (u, v in mm, θ in rad; zero for fixed blocks and
    blocks the result does not list), and the ``scale`` by which :meth:`moved` displaces points."""

    index: dict[str, int]
    centroid: np.ndarray  # (n, 2)
    u: np.ndarray  # (n, 3)
    scale: float = 1.0

    @classmethod
    def of(cls, scene: Scene, result: Any) -> "Motion":
        index = {b.id: i for i, b in enumerate(scene.blocks)}
        u = np.zeros((len(scene.blocks), 3))
        listed = [(index[m.id], m.u) for m in result.blocks if m.id in index]
        if listed:
            rows, values = zip(*listed)
            u[list(rows)] = np.nan_to_num(np.asarray(values, dtype=float))
        u[[i for i, b in enumerate(scene.blocks) if b.fixed]] = 0.0
        return cls(index, np.array([b.centroid for b in scene.blocks]).reshape(-1, 2), u)

    def scaled(self, scale: float) -> "Motion":
        return replace(self, scale=float(scale))

    def blocks(self, ids) -> np.ndarray:
        """Indices of block ids (−1 for an id the scene does not have)."""
        return np.array([self.index.get(i, -1) for i in ids], dtype=int)

    def velocity(self, blocks: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Velocity (k, 2) of ``points`` (k, 2) carried by ``blocks`` (k,); −1 stands still."""
        blocks = np.asarray(blocks, dtype=int)
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        known = blocks >= 0
        safe = np.where(known, blocks, 0)
        r = points - self.centroid[safe]
        u = self.u[safe] * known[:, None]
        return u[:, :2] + u[:, 2:3] * np.column_stack([-r[:, 1], r[:, 0]])

    def moved(self, blocks: np.ndarray, points: np.ndarray) -> np.ndarray:
        return np.asarray(points, dtype=float).reshape(-1, 2) + self.scale * self.velocity(blocks, points)

    def midway(self, a: np.ndarray, b: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Points of joints between blocks ``a`` and ``b``, midway between their two displaced sides."""
        return 0.5 * (self.moved(a, points) + self.moved(b, points))

    def speeds(self, scene: Scene) -> np.ndarray:
        """Each block's largest vertex speed (mm per unit mechanism), fixed blocks 0."""
        owner, vertices, first = _vertices(scene)
        return np.maximum.reduceat(np.abs(self.velocity(owner, vertices)).max(axis=1), first)

    def outlines(self, scene: Scene) -> list[np.ndarray]:
        """Each block's outline, displaced (mm)."""
        owner, vertices, first = _vertices(scene)
        return np.split(self.moved(owner, vertices), first[1:])


def _vertices(scene: Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every vertex of the scene with its block's index, and where each block's vertices start."""
    counts = np.array([len(b.vertices) for b in scene.blocks])
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    return np.repeat(np.arange(len(scene.blocks)), counts), np.concatenate([b.vertices for b in scene.blocks]), first


def joint_arrays(motion: Motion, joints) -> dict[str, np.ndarray]:
    """The joints of a result as arrays: block indices ``a``, ``b``, ends ``start``, ``end`` (mm)."""
    joints = tuple(joints)
    return {"a": motion.blocks(j.blocks[0] for j in joints), "b": motion.blocks(j.blocks[1] for j in joints),
            "start": np.array([j.start for j in joints], dtype=float).reshape(-1, 2),
            "end": np.array([j.end for j in joints], dtype=float).reshape(-1, 2)}
