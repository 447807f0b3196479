"""The settlement capacity against its closed forms, with its cost (issue 33, item 4).

``python -m benchmarks.bench_settle_capacity`` prints, per case: s_u, the reference where one is
written from the geometry (verification/test_settlement_capacity.py), the relative error, the
points of the curve, the configurations solved (each one Eq. 10 and one settlement LP) and the
wall time of the analysis (a ratio to compare on one machine, not an absolute).
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import alma

ROOT = Path(__file__).resolve().parents[1]


def tilting(b: float, h: float, f: float, heights: tuple[float, ...] = ()) -> alma.Scene:
    """A block b × h (and blocks of ``heights`` above it) on a support turning clockwise about (100, 0)."""
    blocks = [
        {
            "id": "ground",
            "vertices": [[-300, -100], [600, -100], [600, 0], [-300, 0]],
            "fixed": True,
            "settlement": {"rotation": -1.0, "about": [100, 0]},
        },
        {"id": "b0", "vertices": [[0, 0], [b, 0], [b, h], [0, h]]},
    ]
    y = h
    for k, hk in enumerate(heights, start=1):
        blocks.append({"id": f"b{k}", "vertices": [[0, y], [b, y], [b, y + hk], [0, y + hk]]})
        y += hk
    return alma.Scene.from_dict(
        {"name": "tilting support", "thickness": 100, "unit_weight": 20, "friction": f, "blocks": blocks}
    )


def lintel(
    f: float,
    unit: float = 1.0,
    origin: tuple[float, float] = (0.0, 0.0),
    reverse: bool = False,
    b: float = 400.0,
    h: float = 300.0,
    c: float = 100.0,
) -> alma.Scene:
    """Case 3 in ``unit`` mm per drawing unit, moved by ``origin``, blocks listed in reverse if asked."""

    def poly(*pts: tuple[float, float]) -> list[list[float]]:
        return [[(x + origin[0]) / unit, (y + origin[1]) / unit] for x, y in pts]

    blocks = [
        {"id": "support", "vertices": poly((-200, -100), (c, -100), (c, 0), (-200, 0)), "fixed": True},
        {
            "id": "pier",
            "vertices": poly((c, -100), (700, -100), (700, 0), (c, 0)),
            "fixed": True,
            "settlement": {"translation": [0, -1]},
        },
        {"id": "lintel", "vertices": poly((0, 0), (b, 0), (b, h), (0, h))},
    ]
    return alma.Scene.from_dict(
        {
            "name": "lintel over a sinking pier",
            "thickness": 100 / unit,
            "unit_weight": 20 * unit**3,
            "friction": f,
            "blocks": blocks[::-1] if reverse else blocks,
            "joints": [{"blocks": ["lintel", "pier"], "friction": 0.0}],
        }
    )


def _cases() -> list[tuple[str, alma.Scene, float]]:
    arch = alma.Scene.from_dict(json.loads((ROOT / "examples" / "spreading_arch.json").read_text()))
    return [
        ("block 200x600 f=1, tilting support [rad]", tilting(200, 600, 1.0), math.atan(200 / 600)),
        ("block 200x600 f=0.2, tilting support [rad]", tilting(200, 600, 0.2), math.atan(0.2)),
        ("block 400x300 f=0.9, tilting support [rad]", tilting(400, 300, 0.9), math.atan(0.9)),
        ("stack 200x(300+250) f=1, tilting [rad]", tilting(200, 300, 1.0, (250,)), math.atan(200 / 550)),
        *[(f"lintel f={f}, sinking pier [mm]", lintel(f), 300 * f / math.hypot(1, f)) for f in (0.3, 0.5, 1.0)],
        ("spreading arch (examples/) [mm]", arch, math.nan),
    ]


def main() -> None:
    print(
        f"{'case':44s} {'s_u':>16s} {'reference':>16s} {'rel. error':>10s} {'points':>6s} {'solves':>6s} {'time s':>7s}"
    )
    for name, scene, reference in _cases():
        t0 = time.perf_counter()
        result = alma.settlement_capacity(scene)
        seconds = time.perf_counter() - t0
        error = abs(result.s_u / reference - 1) if math.isfinite(reference) else math.nan
        print(
            f"{name:44s} {result.s_u:16.10g} {reference:16.10g} {error:10.1e} {len(result.curve.curve):6d} "
            f"{result.curve.solves:6d} {seconds:7.2f}  {result.status}"
        )


if __name__ == "__main__":
    main()
