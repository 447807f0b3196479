"""Regenerate the paper's tables and figures with alma, next to the published values.

    python paper_tables/make_paper.py --out DIR [--workers N] [--nonassociative]

The same as ``alma paper --out DIR``: this script passes the published tables of
``paper_tables/data/`` to :func:`alma.paper.tables.make_paper`, which does the work.
"""

from __future__ import annotations

import sys
from pathlib import Path

from alma.cli.main import main

DATA = Path(__file__).resolve().parent / "data"

if __name__ == "__main__":
    sys.exit(main(["paper", "--published", str(DATA), *sys.argv[1:]]))
