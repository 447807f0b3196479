"""Fixtures of the verification suite; the helpers themselves are in ``helpers.py``."""
import pytest

from helpers import table5


@pytest.fixture(scope="session")
def table5_rows():
    return table5()

