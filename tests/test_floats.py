"""alma.floats: the dense sums written without BLAS agree with NumPy's products to round-off."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from alma.floats import dot, least_squares, rows_dot, times

RNG = np.random.default_rng(11)


def test_dot_is_the_rounded_sum_of_products() -> None:
    x, y = RNG.normal(size=2001), RNG.normal(size=2001)
    exact = math.fsum(float(a) * float(b) for a, b in zip(x, y, strict=True))
    assert dot(x, y) == pytest.approx(exact, rel=1e-13, abs=1e-13)
    # NumPy's pairwise reduction, in the same order whatever the CPU
    assert dot(x, y) == float(np.add.reduce(x * y))


def test_rows_dot_and_times_match_matmul() -> None:
    a, b = RNG.normal(size=(50, 2)), RNG.normal(size=(50, 2))
    assert np.allclose(rows_dot(a, b), np.einsum("ij,ij->i", a, b), rtol=0, atol=1e-15)
    m = RNG.normal(size=(2, 3))
    assert np.allclose(times(a, m), a @ m, rtol=0, atol=1e-14)
    assert np.allclose(times(a[0], m), a[0] @ m, rtol=0, atol=1e-14)
    wide = RNG.normal(size=(5, 400))
    g = RNG.normal(size=5)
    assert np.allclose(times(g, wide), g @ wide, rtol=0, atol=1e-13)


@pytest.mark.parametrize("columns", [1, 3, 5])
def test_least_squares_full_rank(columns: int) -> None:
    a, b = RNG.normal(size=(300, columns)), RNG.normal(size=300)
    expected = np.linalg.lstsq(a, b, rcond=None)[0]
    assert np.allclose(least_squares(a, b), expected, rtol=0, atol=1e-12)


def test_least_squares_drops_a_dependent_column() -> None:
    a = RNG.normal(size=(300, 3))
    a = np.column_stack([a, a[:, 0] - 2 * a[:, 2]])
    b = RNG.normal(size=300)
    x = least_squares(a, b)
    assert x[3] == 0.0
    best = np.linalg.lstsq(a, b, rcond=None)[0]
    assert np.linalg.norm(a @ x - b) == pytest.approx(np.linalg.norm(a @ best - b), rel=1e-12)


def test_least_squares_of_nothing() -> None:
    assert least_squares(np.zeros((10, 2)), np.ones(10)).tolist() == [0.0, 0.0]


#: Dense products that go to BLAS, written out: the folders of the friction search and what
#: feeds it must use alma.floats instead (sparse products do not use BLAS and are not matched).
_DENSE = ("np.dot(", "np.linalg.lstsq", "np.linalg.solve", "np.inner(", ".live @", ".dead @", "capacity @")
_SEARCH_PATH = ("geometry", "mechanics", "associative", "nonassociative")


def test_no_blas_sum_on_the_search_path() -> None:
    root = Path(__file__).resolve().parents[1] / "alma"
    found = [
        f"{path.relative_to(root)}:{k + 1}: {line.strip()}"
        for folder in _SEARCH_PATH
        for path in sorted((root / folder).glob("*.py"))
        for k, line in enumerate(path.read_text().splitlines())
        if any(token in line for token in _DENSE) and not line.lstrip().startswith("#")
    ]
    assert not found, "\n".join(found)
