"""The settlement capacity against its closed forms, with its cost (issue 33, item 4).

``python -m benchmarks.bench_settle_capacity`` prints, per case: s_u, the reference where one is
written from the geometry (verification/test_settlement_capacity.py), the relative error, the
points of the curve, the configurations solved (each one Eq. 10 and one settlement LP) and the
wall time of the analysis (a ratio to compare on one machine, not an absolute).
"""
from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import alma

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "verification"))

from test_settlement_capacity import lintel, tilting  # noqa: E402


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
    print(f"{'case':44s} {'s_u':>16s} {'reference':>16s} {'rel. error':>10s} {'points':>6s} {'solves':>6s} "
          f"{'time s':>7s}")
    for name, scene, reference in _cases():
        t0 = time.perf_counter()
        result = alma.settlement_capacity(scene)
        seconds = time.perf_counter() - t0
        error = abs(result.s_u / reference - 1) if math.isfinite(reference) else math.nan
        print(f"{name:44s} {result.s_u:16.10g} {reference:16.10g} {error:10.1e} {len(result.curve.curve):6d} "
              f"{result.curve.solves:6d} {seconds:7.2f}  {result.status}")


if __name__ == "__main__":
    main()
