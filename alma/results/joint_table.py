"""The joints of a result as columns, read as a sequence of :class:`JointResult`.

A panel has thousands of joints and a study hundreds of panels; most results are read for α,
the bounds and a picture, not joint by joint.  :class:`JointTable` keeps the columns (NumPy
arrays) that :func:`alma.results.joints.physical` computes and builds a :class:`JointResult`
only when one is asked for, so the typed API stays ``result.joints[i].N`` while a solve does not
pay for objects nobody reads.  Units as :class:`JointResult`: kN, kN·mm, mm.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any, overload

import numpy as np

from alma.results.types import JointResult


@dataclass(frozen=True, eq=False)
class JointTable(Sequence):
    """Immutable sequence of :class:`JointResult` backed by arrays of m joints.

    ``blocks`` (m, 2) block ids; ``N``, ``T`` (kN), ``M`` (kN·mm about the joint's centre),
    ``length`` (mm), ``slip`` (m,); ``state`` (m,) str; ``opening`` (m, 2), ``start``, ``end``
    (m, 2) mm, ``normal`` (m, 2); ``points`` (m, 2, 2): the (N, T) of the two contact points.
    With finite compressive strength (SPEC §2): ``capacity`` (m,) σ_c l t in kN and
    ``stress_block`` (m, 2, 2) mm, the rectangular stress block's segment on the joint (its
    extent N/(σ_c t), centred on the resultant); NaN on joints without a strength.
    """

    blocks: np.ndarray
    N: np.ndarray
    T: np.ndarray
    M: np.ndarray
    state: np.ndarray
    length: np.ndarray
    slip: np.ndarray
    opening: np.ndarray
    start: np.ndarray
    end: np.ndarray
    points: np.ndarray
    normal: np.ndarray
    capacity: np.ndarray | None = None
    stress_block: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.N.shape[0])

    @overload
    def __getitem__(self, index: int) -> JointResult: ...

    @overload
    def __getitem__(self, index: slice) -> tuple[JointResult, ...]: ...

    def __getitem__(self, index: Any) -> Any:
        if isinstance(index, slice):
            return tuple(self[i] for i in range(*index.indices(len(self))))
        i = int(index)
        if i < 0:
            i += len(self)
        if not 0 <= i < len(self):
            raise IndexError(f"joint index {index} out of range for {len(self)} joints")
        p = self.points[i].tolist()
        return JointResult(
            blocks=(str(self.blocks[i, 0]), str(self.blocks[i, 1])),
            N=float(self.N[i]),
            T=float(self.T[i]),
            M=float(self.M[i]),
            state=str(self.state[i]),
            length=float(self.length[i]),
            slip=float(self.slip[i]),
            opening=tuple(self.opening[i].tolist()),
            start=tuple(self.start[i].tolist()),
            end=tuple(self.end[i].tolist()),
            points=(tuple(p[0]), tuple(p[1])),
            normal=tuple(self.normal[i].tolist()),
            **self._strength(i),
        )

    def _strength(self, i: int) -> dict[str, Any]:
        """Joint i's crushing capacity and stress block, when it has a finite strength."""
        if self.capacity is None or not np.isfinite(self.capacity[i]):
            return {}
        assert self.stress_block is not None  # set together with capacity (alma.results.joints)
        block = self.stress_block[i]
        return {
            "capacity": float(self.capacity[i]),
            "stress_block": (tuple(block[0].tolist()), tuple(block[1].tolist())),
        }

    def __iter__(self) -> Iterator[JointResult]:
        return (self[i] for i in range(len(self)))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sequence) or isinstance(other, (str, bytes)) or len(other) != len(self):
            return False
        return all(a == b for a, b in zip(self, other, strict=True))

    __hash__ = None  # type: ignore[assignment]  # mutable arrays inside: not hashable, as a list

    def __repr__(self) -> str:
        return f"JointTable({len(self)} joints)"

    def records(self) -> list[dict[str, Any]]:
        """The joints as SPEC §3's JSON objects, built column-wise."""
        cols = zip(
            self.blocks.tolist(),
            self.N.tolist(),
            self.T.tolist(),
            self.M.tolist(),
            self.state.tolist(),
            self.length.tolist(),
            self.slip.tolist(),
            self.opening.tolist(),
            self.points.tolist(),
            strict=True,
        )
        out = [
            {
                "blocks": [str(a), str(b)],
                "N": n,
                "T": t,
                "M": mo,
                "state": str(s),
                "length": le,
                "slip": sl,
                "opening": op,
                "points": [{"N": pn, "T": pt} for pn, pt in pts],
            }
            for (a, b), n, t, mo, s, le, sl, op, pts in cols
        ]
        if self.capacity is not None:  # finite compressive strength only: other results stay as they were
            assert self.stress_block is not None  # set together with capacity (alma.results.joints)
            extent = np.hypot(*(self.stress_block[:, 1] - self.stress_block[:, 0]).T)
            for i in np.flatnonzero(np.isfinite(self.capacity)).tolist():
                out[i]["capacity"] = float(self.capacity[i])
                out[i]["stress_block"] = {
                    "extent": float(extent[i]),
                    "start": self.stress_block[i, 0].tolist(),
                    "end": self.stress_block[i, 1].tolist(),
                }
        return out
