"""The Ferris & Tin-Loi walls (issues 18 and 20), laid with :func:`alma.coursed_wall`.

Ferris M.C., Tin-Loi F. (2001), Limit analysis of frictional block assemblies as a mathematical
program with complementarity constraints, Int. J. Mech. Sci. 43, 209-224; re-analysed by Gilbert
M., Casapulla C., Ahmed H.M. (2006), Comput. Struct. 84, 873-887.  Six walls of 400 × 175 mm
blocks on a rigid base, friction coefficient 0.65, a horizontal load proportional to the
self-weight (unit weight 10 kN/m³, 1 m thick, as in the pattern walls below).  The papers give the
walls in figures only; the course patterns below are read from the pattern walls of HybriDFEM's
examples (thlgrs/HybriDFEM-4, ``Ferris&Tin-Loi_Wall1..6``), written out here course by course
(bottom first; negative = an opening).

Published values: neither paper's table is reachable from this project; the only figure found is
secondary: "the collapse load multiplier of the initial configuration ... around 0.64" for wall 1
(qianqing-wanggg/mosek_optim, README, "Benchmark 3", citing both papers).  Everything else here is
checked against independent solvers and against alma's own earlier measurements
(``docs/accuracy.md``, "The Ferris & Tin-Loi walls").
"""

from __future__ import annotations

import math

import pytest

import alma
from alma.tilt import tilted

from helpers import check_against_independent

FRICTION = 0.65
_RUN = ([0.5, 1, 1, 1, 1, 0.5], [1] * 5)


def _courses(full_even, full_odd, window_odd, window_even, layout: str) -> list[list[float]]:
    """Courses from a layout string: E/U full even/odd courses, w/u window even/odd courses."""
    table = {"E": full_even, "U": full_odd, "w": window_even, "u": window_odd}
    return [list(table[c]) for c in layout]


WALLS = {
    1: [list(_RUN[i % 2]) for i in range(6)],
    2: [list(_RUN[i % 2]) for i in range(10)],
    3: _courses([1, 1, 1, 1], [0.5, 1, 1, 1, 0.5], [0.5, 1, -1, 1, 0.5], [1, 0.5, -1, 0.5, 1], "EUEuwuwuEUE"),
    4: _courses(
        [0.5, 1, 1, 1, 1, 0.5], [1] * 5, [1, -1, 1, -1, 1], [0.5, 0.5, -1, 0.5, 0.5, -1, 0.5, 0.5], "EUEuwuwuEUE"
    ),
    5: _courses([0.5, 1, 1, 0.5], [1] * 3, [1, -1, 1], [0.5, 0.5, -1, 0.5, 0.5], "EUEuwuwuEUEuwuwuEUE"),
    6: _courses(
        [0.5] + [1] * 6 + [0.5],
        [1] * 7,
        [0.5, 1, -1, 1, 1, -1, 1, 0.5],
        [1, 0.5, -1, 0.5, 1, 0.5, -1, 0.5, 1],
        "EUEUuwuwuUEUuwuwuUEUE",
    ),
}

#: alma's lowest verified non-associative α of each wall when this test was written (default
#: search, turned-table starts included); the search must not lose them.
MEASURED_NL = {1: 0.638982, 2: 0.557520, 3: 0.355817, 4: 0.263736, 5: 0.208629, 6: 0.295769}


def wall(k: int) -> alma.Scene:
    return alma.coursed_wall(
        WALLS[k], 400.0, 175.0, friction=FRICTION, thickness=1000.0, unit_weight=10.0, name=f"Ferris & Tin-Loi wall {k}"
    )


@pytest.fixture(scope="module")
def solved() -> dict:
    return {k: alma.solve(wall(k), model="both") for k in WALLS}


def test_the_walls_are_laid_as_drawn():
    counts = {k: len(wall(k).blocks) - 1 for k in WALLS}
    assert counts == {1: 33, 2: 55, 3: 46, 4: 55, 5: 61, 6: 146}
    for k in WALLS:  # every course is as wide as the wall: openings are gaps inside it
        assert len({sum(abs(v) for v in course) for course in WALLS[k]}) == 1, k


def test_wall_1_associative_against_the_literature():
    a = alma.solve(wall(1), model="associative")
    assert a.status == "optimal"
    assert abs(a.alpha - 0.64) <= 0.005, a.alpha  # "around 0.64" (secondary source, see above)


@pytest.mark.parametrize("k", sorted(WALLS))
def test_associative_against_independent_solvers(k):
    scene = wall(k)
    check_against_independent(alma.solve(scene, model="associative"), alma.build_model(scene))


#: Walls where the search on the canonical drawing (issue 30: one answer whatever the drawing's
#: order, units or frame) lands in a higher local minimum than the drawing's own order did: none
#: since the generators' form of the sloped capped LP (wall 2 had 0.558310 before it).
CANONICAL_HIGHER: dict[int, float] = {}

#: Walls whose lowest state came from a path that only the round-off of a CPU's BLAS kernel opened
#: (docs/decisions.md, "The same answer on another CPU"): none since the thorough search's restarts
#: (``SearchSettings.thorough_restarts``). Wall 6 gave 0.295769 (recorded), 0.295763 and 0.292706
#: under two BLAS kernels, 0.298900 with the dense sums out of BLAS, and 0.2957689 with the restarts.
ARITHMETIC_HIGHER: dict[int, float] = {}


@pytest.mark.slow  # the six walls' searches take about 40 s of one core
@pytest.mark.parametrize(
    "k",
    [
        pytest.param(
            k,
            marks=pytest.mark.xfail(
                strict=True,
                reason=f"canonical search gives {CANONICAL_HIGHER[k]} > {MEASURED_NL[k]}: a higher local "
                "minimum of the non-convex search (issue 30, docs/decisions.md)",
            ),
        )
        if k in CANONICAL_HIGHER
        else pytest.param(
            k,
            marks=pytest.mark.xfail(
                strict=True,
                reason=f"the search gives {ARITHMETIC_HIGHER[k]} > {MEASURED_NL[k]} on every CPU; the lower states "
                "were reached only by paths that a BLAS kernel's round-off opened (issue 30, docs/decisions.md)",
            ),
        )
        if k in ARITHMETIC_HIGHER
        else k
        for k in sorted(WALLS)
    ],
)
def test_nonassociative_states(solved, k):
    both = solved[k]
    a, n = both.associative, both.nonassociative
    assert n.status == "feasible", (n.status, n.message)
    assert n.alpha <= a.bounds.upper + 1e-9  # Radenkovic: below the associative collapse load
    assert n.alpha < a.alpha - 1e-3  # on these walls friction without dilatancy always costs
    assert n.bounds.lower <= n.alpha
    assert n.alpha <= MEASURED_NL[k] + 1e-6, (n.alpha, MEASURED_NL[k])


def test_a_negative_state_on_a_standing_wall_is_not_no_equilibrium():
    """Issue 20, defect 4: wall 3 turned by 20° still stands in the associative model; a verified
    non-associative state below zero says it may collapse under its dead load alone."""
    scene = tilted(wall(3), 20.0)
    a = alma.solve(scene, model="associative")
    n = alma.solve(scene, model="nonassociative")
    assert a.status == "optimal" and a.alpha > 0.03, (a.status, a.alpha)
    assert n.status == "feasible" and n.alpha < 0, (n.status, n.alpha)
    assert "may collapse under its dead load alone" in n.message
    assert math.isfinite(n.alpha)
