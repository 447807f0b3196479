"""LACT³'s three sample drawings on the tilting table, against the angles its solver test asserts.

LACT³ (GabrieleMilani/LACT3_v1.0, GPL-3) ships ``sample/Portal.dxf``, ``wall.dxf`` and
``arch_1.dxf``; its ``LACT3_SolverTest.m`` asserts that both of its bounds vanish (|·| < 1e-3)
at 27.30°, 16.73° and 17.10° (φ = 30°, 26°, 30°; c = 0; unit thickness; ρ = 25).  The drawings
are GPL-3 and are not copied into alma: fetch the repository and pass its ``sample`` folder.

    python -m studies.lact3_tilt PATH/TO/LACT3_v1.0/sample
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import alma

#: (drawing, friction angle φ in degrees, LACT³'s asserted critical angle in degrees)
CASES = (("Portal.dxf", 30.0, 27.30), ("wall.dxf", 26.0, 16.73), ("arch_1.dxf", 30.0, 17.10))


def main(folder: str) -> None:
    print("| drawing | blocks | joints | alma θ_c [°] | certified bounds [°] | LACT³ [°] | difference [°] | time [s] |")
    print("|---|---|---|---|---|---|---|---|")
    for name, phi, published in CASES:
        scene = alma.load_scene(
            Path(folder) / name,
            friction=math.tan(math.radians(phi)),
            thickness=1.0,
            unit_weight=25.0,
            supports="lowest",
        )
        start = time.perf_counter()
        result = alma.tilt(scene)
        seconds = time.perf_counter() - start
        lo, hi = result.bounds_deg
        print(
            f"| {name} | {len(scene.blocks)} | {alma.find_joints(scene).count} | {result.angle_deg:.4f} | "
            f"[{lo:.6f}, {hi:.6f}] | {published:.2f} | {result.angle_deg - published:+.4f} | {seconds:.2f} |"
        )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "sample")
