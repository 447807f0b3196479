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
    def of(cls, scene: Scene, result: Any, *, settling: bool = False) -> Motion:
        """The motion of ``result``; with ``settling`` the settling supports move by their
        prescribed settlement (translation and rotation about its point), the others stand."""
        index = {b.id: i for i, b in enumerate(scene.blocks)}
        u = np.zeros((len(scene.blocks), 3))
        listed = [(index[m.id], m.u) for m in result.blocks if m.id in index]
        if listed:
            rows, values = zip(*listed, strict=True)
            u[list(rows)] = np.nan_to_num(np.asarray(values, dtype=float))
        centroid = np.array([b.centroid for b in scene.blocks]).reshape(-1, 2)
        u[[i for i, b in enumerate(scene.blocks) if b.fixed]] = 0.0
        for i, b in enumerate(scene.blocks):  # the few settling supports
            s = b.settlement if settling and b.fixed else None
            if s is not None:
                arm = centroid[i] - np.asarray(s.about, dtype=float)
                u[i] = (s.translation[0] - s.rotation * arm[1], s.translation[1] + s.rotation * arm[0], s.rotation)
        return cls(index, centroid, u)

    def affine(self, carrier: tuple[int, ...]) -> np.ndarray:
        """The displacement map of a mark carried by ``carrier`` (the mean of its blocks' rigid
        motions, −1 standing still) at :attr:`scale` as (b, e, f): x' = x − b y + e,
        y' = y + b x + f, with b = s θ (the small-rotation form of a rigid motion, mm)."""
        if not carrier:
            return np.zeros(3)
        rows = np.asarray(carrier, dtype=int)
        known = (rows >= 0)[:, None]
        u = self.u[np.where(rows >= 0, rows, 0)] * known
        c = self.centroid[np.where(rows >= 0, rows, 0)]
        s = self.scale
        w = s * u[:, 2]
        e = s * u[:, 0] + w * c[:, 1]
        f = s * u[:, 1] - w * c[:, 0]
        return np.array([w.mean(), e.mean(), f.mean()])

    def carry(self, carrier: tuple[int, ...], xy: np.ndarray) -> np.ndarray:
        """``xy`` (k, 2) mm moved by :meth:`affine` of ``carrier``."""
        b, e, f = self.affine(carrier)
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        return np.column_stack([xy[:, 0] - b * xy[:, 1] + e, xy[:, 1] + b * xy[:, 0] + f])

    def scaled(self, scale: float) -> Motion:
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
    """The joints of a result as arrays: block indices ``a``, ``b`` (−1 where a kept picture's
    joint does not name its blocks), ends ``start``, ``end`` (mm)."""
    joints = tuple(joints)
    pairs = [getattr(j, "blocks", ("", "")) for j in joints]
    return {
        "a": motion.blocks(p[0] for p in pairs),
        "b": motion.blocks(p[1] for p in pairs),
        "start": np.array([j.start for j in joints], dtype=float).reshape(-1, 2),
        "end": np.array([j.end for j in joints], dtype=float).reshape(-1, 2),
    }
