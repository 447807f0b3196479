"""The README's picture of the structures users bring (issue 18): a façade with openings from
``alma wall``, a portal from ``alma arch`` and the drawing ``examples/facade.dxf``, each with its
associative collapse mechanism.

    .venv/bin/python tools/structures_figure.py [OUT.png]   (default: docs/structures.png)
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import alma
from alma.report.plot import plot_mechanism

ROOT = Path(__file__).resolve().parents[1]


def main(out: Path) -> int:
    scenes = {
        "alma wall --bond running --width 3600 --height 2400 --block 240x60\n"
        "--opening 600,600,960,1200 --opening 2160,600,960,1200": alma.wall(
            "running", 3600.0, 2400.0, 240.0, 60.0, openings=[(600, 600, 960, 1200), (2160, 600, 960, 1200)]
        ),
        "alma arch --span 2000 --rise 1000 --thickness 200 --voussoirs 20\n"
        "--springing piers --pier-height 1500": alma.arch(
            2000.0, 1000.0, 200.0, 20, springing="piers", pier_height=1500.0, pier_width=400.0, pier_courses=5
        ),
        "alma solve examples/facade.dxf": alma.load_scene(ROOT / "examples" / "facade.dxf"),
    }
    fig, axes = plt.subplots(1, 3, figsize=(18, 6))
    for ax, (command, scene) in zip(axes, scenes.items(), strict=True):
        plot_mechanism(scene, alma.solve(scene), out, title=command, ax=ax, line_of_thrust=False)
        ax.title.set_fontsize(8)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "structures.png"))
