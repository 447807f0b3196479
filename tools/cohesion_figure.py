"""The README's picture of cohesion (issue 17): a stack-bond panel without and with mortar
cohesion on every joint, each with its associative collapse mechanism.

    .venv/bin/python tools/cohesion_figure.py [OUT.png]   (default: docs/cohesion.png)

The same as ``alma panel --bond stack --panel-ratio 1:1 --block-ratio 4:1 --friction 0.6
--export-scene wall.json``, ``"cohesion": 2`` (kPa) in wall.json, ``alma solve wall.json --plot``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import alma
from alma.report.plot import plot_side_by_side

ROOT = Path(__file__).resolve().parents[1]
COHESION_KPA = 2.0


def main(out: Path) -> int:
    data = alma.paper_panel("stack", "1:1", "4:1", 0.6).to_dict()
    plain = alma.Scene.from_dict(data)
    data["cohesion"] = COHESION_KPA
    cohesive = alma.Scene.from_dict(data)
    results = [alma.solve(plain), alma.solve(cohesive)]
    plot_side_by_side(
        cohesive,
        results,
        out,
        titles=["cohesion 0", f"cohesion {COHESION_KPA:g} kPa on every joint"],
        suptitle="stack bond, panel 1:1, blocks 4:1, f = 0.6: "
        f"α = {results[0].alpha:.4f} without cohesion, {results[1].alpha:.4f} with it",
    )
    print(out, [round(r.alpha, 6) for r in results])
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "cohesion.png"))
