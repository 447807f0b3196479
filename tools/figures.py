"""The README's and docs' pictures of single mechanisms (issue 36; ``make figures`` runs this,
``structures_figure.py``, ``cohesion_figure.py`` and ``html_screenshot.py``).

    .venv/bin/python tools/figures.py [OUT_DIR]   (default: docs/)

Each picture is what the README's command beside it writes with ``--plot``.
"""

from __future__ import annotations

import sys
from pathlib import Path

from alma.cli import main as alma_main

ROOT = Path(__file__).resolve().parents[1]


def main(out: Path) -> int:
    out.mkdir(parents=True, exist_ok=True)
    commands = {
        "mechanism.png": [
            "panel",
            "--bond",
            "english",
            "--panel-ratio",
            "1:1",
            "--block-ratio",
            "2:1",
            "--friction",
            "0.6",
        ],
        "fig13a_crisp.png": [
            "panel",
            "--bond",
            "running",
            "--panel-ratio",
            "1:1",
            "--block-ratio",
            "1:1",
            "--friction",
            "0.27",
            "--crisp",
        ],
        "chains.png": [
            "panel",
            "--bond",
            "running",
            "--panel-ratio",
            "1:2",
            "--block-ratio",
            "4:1",
            "--friction",
            "0.6",
            "--chain",
            "2850:5",
            "--anchored",
        ],
        "settlement.png": ["settle", str(ROOT / "examples" / "settlement.json")],
        "settlement_capacity.png": ["settle", str(ROOT / "examples" / "spreading_arch.json"), "--capacity"],
    }
    for name, command in commands.items():
        code = alma_main([*command, "--plot", str(out / name), "--json"])
        if code:
            return code
        print(out / name, file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs"))
