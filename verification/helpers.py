"""Shared helpers for the scientific verification of alma (``pytest verification/``).

Imported by the tests as ``from helpers import ...``: ``conftest.py`` beside it puts this folder
on ``sys.path`` (whatever pytest's rootdir or import mode) and holds only fixtures.

Scene builders (single block, column, random small assemblies, semicircular arch), the
Table 5 loader, and a hypothesis profile that keeps the whole run within a few minutes.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping
from functools import cache, lru_cache
from pathlib import Path
from typing import TypedDict

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

import alma

try:  # hypothesis is a test dependency; the profile keeps property tests bounded in time
    from hypothesis import HealthCheck, settings, strategies as st

    # Every property test here sets max_examples and deadline=None itself (the whole directory
    # runs in a few minutes on 2 cores).  The profile is registered, not loaded, so importing this
    # conftest does not change the settings of other test directories; opt in with
    #   pytest verification/ --hypothesis-profile=verification
    settings.register_profile(
        "verification",
        deadline=None,
        max_examples=25,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )
except ImportError:  # pragma: no cover
    st = None  # type: ignore[assignment]  # no hypothesis: no strategies below (None is the sign)


class SiteArgs(TypedDict):
    """A site's keys of :func:`elastic_spectrum` (the arguments ``alma.seismic.Site`` shares with it)."""

    ag: float
    F0: float
    Tc_star: float
    soil: str
    topography: str


DATA = Path(__file__).resolve().parent / "data"
TABLE5 = DATA / "table5_collapse_multipliers.csv"

THICKNESS = 120.0
UNIT_WEIGHT = 18.0


# --------------------------------------------------------------------------- scene builders
def rect(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    """Counter-clockwise rectangle [x0, x1] × [y0, y1]."""
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


def scene_dict(
    blocks: list[dict],
    friction: float = 0.6,
    *,
    live=(1.0, 0.0),
    gravity=None,
    thickness: float = THICKNESS,
    unit_weight: float = UNIT_WEIGHT,
    name: str = "",
) -> dict:
    data = {
        "name": name,
        "thickness": thickness,
        "unit_weight": unit_weight,
        "friction": friction,
        "cohesion": 0.0,
        "blocks": blocks,
        "live_load": {"direction": list(live)},
    }
    if gravity is not None:
        data["gravity"] = list(gravity)
    return data


def ground(x0: float, x1: float, depth: float = 50.0) -> dict:
    return {"id": "ground", "vertices": rect(x0, -depth, x1, 0.0), "fixed": True}


def single_block_dict(b: float, h: float, f: float) -> dict:
    """One b × h block on a wider fixed ground (its bottom face [0, b] on y = 0)."""
    return scene_dict(
        [ground(-b, 2 * b, depth=max(1.0, 0.25 * min(b, h))), {"id": "b1", "vertices": rect(0.0, 0.0, b, h)}],
        friction=f,
    )


def single_block_scene(b: float, h: float, f: float) -> alma.Scene:
    return alma.Scene.from_dict(single_block_dict(b, h, f))


def column_dict(k: int, size: float = 100.0, f: float = 2.0) -> dict:
    blocks = [ground(-size, 2 * size)]
    for i in range(k):
        blocks.append({"id": f"c{i}", "vertices": rect(0.0, i * size, size, (i + 1) * size)})
    return scene_dict(blocks, friction=f)


def column_scene(k: int, size: float = 100.0, f: float = 2.0) -> alma.Scene:
    return alma.Scene.from_dict(column_dict(k, size, f))


def assembly_dict(courses: list[tuple[float, list[float], float]], friction: float, live=(1.0, 0.0)) -> dict:
    """Courses stacked on a ground block.

    Each course is (x offset, list of block lengths, course height); course c rests on
    course c − 1 (or on the ground).  The generator guarantees every course overlaps the one
    below over a positive length, so each block touches something (its neighbour in the course
    or the course below), and no two blocks overlap.
    """
    xs = [c[0] for c in courses] + [c[0] + sum(c[1]) for c in courses]
    lo, hi = min(xs), max(xs)
    span = hi - lo
    blocks = [ground(lo - 0.5 * span, hi + 0.5 * span, depth=courses[0][2])]
    y = 0.0
    n = 0
    for x0, lengths, height in courses:
        x = x0
        for length in lengths:
            n += 1
            blocks.append({"id": f"b{n}", "vertices": rect(x, y, x + length, y + height)})
            x += length
        y += height
    return scene_dict(blocks, friction=friction, live=live)


if st is not None:

    @st.composite
    def assemblies(draw, max_courses: int = 3, max_per_course: int = 4, friction=None) -> dict:
        """Random small assembly: 1–3 courses of 1–4 rectangular blocks of random sizes.

        Courses are contiguous rows; each course's x offset is drawn so that it overlaps the
        course below over at least 20 % of the shorter of the two rows, so every block of the
        course is connected to the structure through its neighbours.
        """
        n_courses = draw(st.integers(1, max_courses))
        courses = []
        prev = None
        for _ in range(n_courses):
            k = draw(st.integers(1, max_per_course))
            lengths = [float(draw(st.integers(20, 300))) for _ in range(k)]
            height = float(draw(st.integers(20, 200)))
            width = sum(lengths)
            if prev is None:
                x0 = 0.0
            else:
                px0, pw = prev
                overlap = 0.2 * min(width, pw)
                # x0 in [px0 - width + overlap, px0 + pw - overlap], on an integer grid
                a = math.ceil(px0 - width + overlap)
                b = math.floor(px0 + pw - overlap)
                x0 = float(draw(st.integers(a, max(a, b))))
            courses.append((x0, lengths, height))
            prev = (x0, width)
        f = draw(st.sampled_from([0.3, 0.6, 1.0])) if friction is None else friction
        return assembly_dict(courses, f)
else:  # pragma: no cover
    assemblies = None


def arch_dict(n: int, t: float, radius: float = 1000.0, friction: float = 10.0, live=(1.0, 0.0)) -> dict:
    """Semicircular arch of ``n`` voussoirs (centre-line radius ``radius``, thickness ``t``).

    Voussoir faces are radial; the springings lie on y = 0 at angles 0 (right) and π (left) and
    rest on two fixed abutments whose horizontal top faces contain the springing faces.
    Intrados and extrados are the chords of the circles of radii R ∓ t/2.
    """
    ri, ro = radius - t / 2.0, radius + t / 2.0
    pad = 0.5 * t + 50.0
    phi = np.linspace(0.0, np.pi, n + 1)
    cos, sin = np.cos(phi), np.sin(phi)
    cos[0], sin[0], cos[-1], sin[-1] = 1.0, 0.0, -1.0, 0.0  # exact springing faces on y = 0
    blocks = [
        {"id": "abutment_right", "vertices": rect(ri - pad, -t - 100.0, ro + pad, 0.0), "fixed": True},
        {"id": "abutment_left", "vertices": rect(-ro - pad, -t - 100.0, -ri + pad, 0.0), "fixed": True},
    ]
    for i in range(n):
        a, b = i, i + 1
        blocks.append(
            {
                "id": f"v{i}",
                "vertices": [
                    [ri * cos[a], ri * sin[a]],
                    [ro * cos[a], ro * sin[a]],
                    [ro * cos[b], ro * sin[b]],
                    [ri * cos[b], ri * sin[b]],
                ],
            }
        )
    return scene_dict(blocks, friction=friction, live=live, name=f"arch N={n} t={t:g}")


# --------------------------------------------------------------------------- paper data
@lru_cache(maxsize=1)
def table5() -> tuple[tuple[str, str, str, float, float], ...]:
    """Rows (bond, panel_ratio, block_ratio, friction, alpha_c) of Table 5 (ratios kept as str)."""
    rows = []
    with open(TABLE5, newline="") as handle:
        for row in csv.DictReader(handle):
            rows.append(
                (
                    row["bond"],
                    str(row["panel_ratio"]),
                    str(row["block_ratio"]),
                    float(row["friction"]),
                    float(row["alpha_c"]),
                )
            )
    return tuple(rows)


def panel_id(bond: str, panel_ratio: str, block_ratio: str, friction: float) -> str:
    return f"{bond}-{panel_ratio}-{block_ratio}-{friction:g}"


@cache
def panel_geometry(bond: str, panel_ratio: str, block_ratio: str) -> alma.Model:
    """Model of a paper panel (friction 0.6), built once per geometry; use ``.with_friction``."""
    return alma.build_model(alma.paper_panel(bond, panel_ratio, block_ratio, 0.6))


@cache
def solve_panel(bond: str, panel_ratio: str, block_ratio: str, friction: float) -> alma.Result:
    """alma's associative result for one paper panel (cached across test modules)."""
    model = panel_geometry(bond, panel_ratio, block_ratio).with_friction(friction)
    return alma.solve(model)


# --------------------------------------------------------------------------- independent solvers
#: Agreement required between alma and the independent solvers (relative to max(1, |α|)).
AGREE = 1e-6


def static_highs(model: alma.Model) -> tuple[str, float]:
    """(status, α) of the static LP solved by scipy's HiGHS (linprog)."""
    H = model.equilibrium
    k = H.shape[1]
    A = sp.hstack([H, sp.csc_matrix(model.live.reshape(-1, 1))]).tocsc()
    c = np.zeros(k + 1)
    c[-1] = -1.0
    bounds = [(0, None)] * k + [(None, None)]
    # HiGHS interior point (+ crossover): 10x faster than its simplex on the larger panels
    res = linprog(c, A_eq=A, b_eq=-model.dead, bounds=bounds, method="highs-ipm")
    if res.status not in (0, 2, 3):
        res = linprog(c, A_eq=A, b_eq=-model.dead, bounds=bounds, method="highs")
    if res.status == 0:
        return "optimal", float(res.x[-1])
    if res.status == 2:
        return "infeasible", -math.inf
    if res.status == 3:
        return "unbounded", math.inf
    raise AssertionError(f"linprog: {res.message}")


def kinematic_cvxpy(model: alma.Model, solver: str = "HIGHS") -> tuple[str, float]:
    """(status, α) of the kinematic LP (Eq. 10) written in cvxpy."""
    import cvxpy as cp

    H = model.equilibrium
    u = cp.Variable(H.shape[0])
    problem = cp.Problem(cp.Minimize(-model.dead @ u), [model.live @ u == 1, H.T @ u >= 0])
    problem.solve(solver=solver)
    if problem.status == cp.OPTIMAL:
        return "optimal", float(problem.value)
    if problem.status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
        return "infeasible", math.inf
    if problem.status in (cp.UNBOUNDED, cp.UNBOUNDED_INACCURATE):
        return "unbounded", -math.inf
    raise AssertionError(f"cvxpy: {problem.status}")


def check_against_independent(result: alma.Result, model: alma.Model) -> None:
    s_status, s_alpha = static_highs(model)
    k_status, k_alpha = kinematic_cvxpy(model)
    # LP duality between the two independent solves (static infeasible <-> kinematic unbounded)
    assert {"optimal": "optimal", "infeasible": "unbounded", "unbounded": "infeasible"}[s_status] == k_status
    if s_status == "optimal":
        scale = max(1.0, abs(s_alpha))
        assert abs(s_alpha - k_alpha) <= AGREE * scale, (s_alpha, k_alpha)
        assert abs(result.alpha - s_alpha) <= AGREE * scale, (result.alpha, s_alpha, result.status)
        assert result.bounds.lower <= s_alpha + AGREE * scale
        assert result.bounds.upper >= s_alpha - AGREE * scale
        assert_bounds_bracket(result)
        assert result.status == ("optimal" if s_alpha >= 0 else "no_equilibrium"), (
            result.status,
            s_alpha,
            result.message,
        )
    elif s_status == "unbounded":  # any α can be carried
        assert result.status == "no_collapse", (result.status, result.alpha)
        assert result.alpha == math.inf
    else:  # no α at all can be carried
        assert result.status == "no_equilibrium", (result.status, result.alpha)
        assert result.alpha == -math.inf


# --------------------------------------------------------------------------- tolerances
#: alma's certificates are admissible to a residual of 1e-9 (RESIDUAL_TOLERANCE: equilibrium per
#: mean block weight, flow rule relative), so its bounds are proven to that accuracy only: the
#: static lower bound has been seen to exceed the exact α_c (and the upper bound) by up to 4e-12.
CERTIFICATE = 1e-9


def number(row: Mapping[str, float | bool | None], key: str) -> float:
    """``row[key]`` of a report whose values may be numbers, flags or None, where the test expects
    a number: a flag or None fails the test here, not later in the arithmetic."""
    value = row[key]
    assert value is not None and not isinstance(value, bool), f"{key} is {value!r}, not a number"
    return value


def assert_bounds_bracket(result, certificate: float = CERTIFICATE) -> None:
    """lower ≤ α ≤ upper; α is the kinematic value, the lower bound is proven up to its residual."""
    lo, up, a = result.bounds.lower, result.bounds.upper, result.alpha
    assert a <= up, f"alpha {a!r} above upper bound {up!r}"
    assert lo <= a + certificate * max(1.0, abs(a)), f"lower bound {lo!r} above alpha {a!r}"
