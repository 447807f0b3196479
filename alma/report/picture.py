"""What a study keeps of a mechanism to draw it again (``mechanisms/<key>.npz``)."""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from alma.results.joint_table import JointTable
from alma.results.types import BlockMotion, Result


@dataclass(frozen=True, slots=True)
class PictureJoint:
    """What a picture needs of a joint: its state and its contact segment (mm)."""

    state: str
    start: tuple[float, float]
    end: tuple[float, float]


@dataclass(frozen=True, slots=True)
class MechanismPicture:
    """What :func:`plot_mechanism` draws of a result, small enough to keep for every panel of a study.

    Block motions, the joints that move (rest joints are not drawn), α, status, model and
    mechanism class.  A study keeps one per solved panel (``mechanisms/<key>.npz``), so its
    report draws the mechanisms that were computed instead of solving the panels again.
    """

    model: str
    status: str
    alpha: float
    mechanism_class: str
    blocks: tuple[BlockMotion, ...]
    joints: tuple[PictureJoint, ...]

    @classmethod
    def from_result(cls, result: Result | MechanismPicture) -> MechanismPicture:
        if isinstance(result, MechanismPicture):
            return result
        table = result.joints
        if isinstance(table, JointTable):  # columns: no JointResult is built
            moving = np.flatnonzero(table.state != "rest")
            joints = tuple(
                PictureJoint(str(s), (a[0], a[1]), (b[0], b[1]))
                for s, a, b in zip(
                    table.state[moving].tolist(), table.start[moving].tolist(), table.end[moving].tolist(), strict=True
                )
            )
        else:
            joints = tuple(
                PictureJoint(j.state, (float(j.start[0]), float(j.start[1])), (float(j.end[0]), float(j.end[1])))
                for j in table
                if j.state != "rest"
            )
        return cls(
            str(result.model),
            str(result.status),
            float(result.alpha),
            str(result.mechanism_class or ""),
            tuple(result.blocks),
            joints,
        )

    def save(self, path: str | Path) -> Path:
        """Write the picture as a compressed ``.npz`` (atomically: a temporary file renamed over it)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        segments = np.array([[*j.start, *j.end] for j in self.joints], dtype=float).reshape(-1, 4)
        handle, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".npz")
        try:
            with os.fdopen(handle, "wb") as fh:
                np.savez_compressed(
                    fh,
                    model=self.model,
                    status=self.status,
                    alpha=self.alpha,
                    mechanism_class=self.mechanism_class,
                    block_ids=np.array([b.id for b in self.blocks], dtype=str),
                    motions=np.array([b.u for b in self.blocks], dtype=float).reshape(-1, 3),
                    joint_states=np.array([j.state for j in self.joints], dtype=str),
                    segments=segments,
                )
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
        return path

    @classmethod
    def load(cls, path: str | Path) -> MechanismPicture:
        with np.load(Path(path), allow_pickle=False) as data:
            blocks = tuple(
                BlockMotion(str(i), (float(u[0]), float(u[1]), float(u[2])))
                for i, u in zip(data["block_ids"], data["motions"], strict=True)
            )
            joints = tuple(
                PictureJoint(str(state), (float(s[0]), float(s[1])), (float(s[2]), float(s[3])))
                for state, s in zip(data["joint_states"], data["segments"], strict=True)
            )
            return cls(
                str(data["model"]),
                str(data["status"]),
                float(data["alpha"]),
                str(data["mechanism_class"]),
                blocks,
                joints,
            )


@dataclass(frozen=True)
class StillPicture:
    """A result seen as a mechanism to draw: the motions and joints of a settlement, or none
    (a structure that does not collapse) — no α, no macro-blocks."""

    blocks: tuple = ()
    joints: tuple = ()
    status: str = "no_collapse"
    model: str = "settlement"
    mechanism_class: str = ""
    alpha: float = float("nan")
    macro_blocks: tuple = ()

    @classmethod
    def of(cls, result: object, status: str | None = None) -> StillPicture:
        return cls(
            tuple(getattr(result, "blocks", ())),
            tuple(getattr(result, "joints", ())),
            status or str(getattr(result, "status", "no_collapse")),
        )
