"""The restarts' spread factors (``alma.nonassociative.spread``) and their place in the plan."""

from __future__ import annotations

import numpy as np
from hypothesis import given, strategies as st

from alma.nonassociative.policy import plan, start_name
from alma.nonassociative.spread import splitmix64, spread_factors
from alma.settings import SearchSettings


def test_splitmix64_gives_the_published_sequence():
    """The first outputs of SplitMix64 seeded with 0 (Vigna's reference splitmix64.c: the state
    advances by the golden gamma before each output)."""
    gamma = 0x9E3779B97F4A7C15
    states = np.array([(k * gamma) % 2**64 for k in range(3)], dtype=np.uint64)
    assert [hex(int(z)) for z in splitmix64(states)] == [
        "0xe220a8397b1dcdaf",
        "0x6e789e6aa1b965f4",
        "0x6c45d188009454f",
    ]


@given(st.integers(1, 500), st.integers(0, 50), st.floats(1e-6, 0.5))
def test_the_factors_lie_within_the_spread_and_do_not_depend_on_the_count(count, restart, width):
    factors = spread_factors(count, restart, width)
    assert factors.shape == (count,)
    assert np.all(np.abs(factors - 1.0) <= width)
    # a point's factor is its own: more points append factors, they do not change the others
    assert np.array_equal(spread_factors(count + 7, restart, width)[:count], factors)


def test_restarts_draw_different_factors():
    a, b = spread_factors(1000, 0, 1e-3), spread_factors(1000, 1, 1e-3)
    assert not np.any(a == b)
    assert abs(float(np.mean(a)) - 1.0) < 1e-4 and float(np.std(a)) > 5e-4  # uniform: σ = w/√3


def test_the_thorough_plan_ends_its_fixed_starts_with_its_restarts():
    s = SearchSettings()
    thorough = [start_name(kind, s, "thorough") for kind in plan(s, "thorough")]
    restarts = [name for name in thorough if "±" in name]
    assert restarts == [f"gilbert(N̄=1·N_LP·(1±0.001)#{k}, r=0.5, steps=0)" for k in range(s.thorough_restarts)]
    assert thorough.index(restarts[-1]) + 1 == thorough.index("gilbert-projected")
    assert not any("±" in start_name(kind, s, "fast") for kind in plan(s, "fast"))
    assert not any(
        "±" in start_name(kind, s, "thorough") for kind in plan(SearchSettings(thorough_restarts=0), "thorough")
    )
