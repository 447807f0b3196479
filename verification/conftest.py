"""Fixtures of the verification suite; the helpers themselves are in ``helpers.py``.

The tests import them as ``from helpers import ...``.  This folder is put on ``sys.path`` here,
by its own location, so that the import does not rest on pytest's rootdir or import mode
(``--import-mode=importlib``, xdist workers, a run started from another folder).
"""

import sys
from pathlib import Path

import pytest

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)

from helpers import table5  # noqa: E402  (needs the folder on sys.path, set just above)


@pytest.fixture(scope="session")
def table5_rows():
    return table5()
