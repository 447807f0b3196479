"""Look at the HTML reports in a real browser (issues 18, 36): write the pages of the examples with
the command line's ``--html`` and screenshot each with headless Chromium (Debian's ``chromium``
package; ``make html-screenshot``, not part of CI).  The portal's page is also the README's
``docs/html_report.png``.

    .venv/bin/python tools/html_screenshot.py [OUT_DIR]   (default: docs/screenshots)
"""

from __future__ import annotations

import contextlib
import io
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from alma.cli import main as alma_main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
DEFAULT = ROOT / "docs" / "screenshots"
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
    "--hide-scrollbars",
]
#: name: (the alma command, the browser window's size in pixels)
CASES = {
    "wall_with_window": (["solve", str(EXAMPLES / "wall_with_window.json"), "--crisp"], "1200,900"),
    "arch": (["solve", str(EXAMPLES / "arch.json")], "1200,900"),
    "portal": (["solve", str(EXAMPLES / "portal.json"), "--thrust"], "1200,1100"),
    "panel_both": (
        [
            "panel",
            "--bond",
            "running",
            "--panel-ratio",
            "2:1",
            "--block-ratio",
            "2:1",
            "--friction",
            "0.6",
            "--model",
            "both",
            "--effort",
            "fast",
        ],
        "1400,900",
    ),
    "settlement": (["settle", str(EXAMPLES / "settlement.json")], "1200,1050"),
    "tilt": (["tilt", str(EXAMPLES / "portal.json")], "1200,1150"),
}


def main(out: Path) -> int:
    browser = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if browser is None:
        print("no chromium on PATH: apt-get install -y chromium", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    for name, (command, window) in CASES.items():
        page = out / f"{name}.html"
        with contextlib.redirect_stdout(io.StringIO()):
            if alma_main([*command, "--html", str(page), "--json"]):
                return 1
        with tempfile.TemporaryDirectory() as profile:
            subprocess.run(
                [
                    browser,
                    *FLAGS,
                    f"--user-data-dir={profile}",
                    f"--window-size={window}",
                    f"--screenshot={out / name}.png",
                    page.resolve().as_uri(),
                ],
                check=True,
                capture_output=True,
                timeout=120,
            )
        page.unlink()  # the screenshots are kept; the pages are one command away
        print(out / f"{name}.png", file=sys.stderr)
    if out.resolve() == DEFAULT.resolve():
        shutil.copyfile(out / "portal.png", ROOT / "docs" / "html_report.png")
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT))
