"""Look at the HTML report in a real browser (issue 18): write the reports of ``examples/`` and of
a paper panel with ``--html``, and screenshot each with headless Chromium (Debian's ``chromium``
package; ``make html-screenshot``, not part of CI).

    .venv/bin/python tools/html_screenshot.py [OUT_DIR]   (default: build/html)
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import alma
from alma.report.html import write_html

ROOT = Path(__file__).resolve().parents[1]
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--window-size=1400,1000"]


def main(out: Path) -> int:
    browser = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if browser is None:
        print("no chromium on PATH: apt-get install chromium", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    cases = {"portal": (alma.load_scene(ROOT / "examples" / "portal.json"), "both"),
             "wall_with_window": (alma.load_scene(ROOT / "examples" / "wall_with_window.json"), "associative"),
             "panel_running_1-1_1-1_f0.27": (alma.paper_panel("running", "1:1", "1:1", 0.27), "associative")}
    for name, (scene, model) in cases.items():
        page = write_html(scene, alma.solve(scene, model=model, effort="fast"), out / f"{name}.html")
        with tempfile.TemporaryDirectory() as profile:
            subprocess.run([browser, *FLAGS, f"--user-data-dir={profile}", f"--screenshot={out / name}.png",
                            page.resolve().as_uri()], check=True, capture_output=True, timeout=120)
        print(out / f"{name}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "build" / "html"))
