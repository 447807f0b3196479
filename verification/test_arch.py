"""Minimum thickness of a semicircular arch under its own weight (Milankovitch).

A semicircular arch of N voussoirs with radial joints (centre-line radius R = 1000 mm) standing
on two fixed abutments carries its own weight only if t/R ≥ 0.1075 (Milankovitch 1907; an
independent calculation gives 0.10745).  With a horizontal live load proportional to the
weight, alma's α_c is positive above the limit and the dead load alone cannot be carried
below it; bisection on the sign of α gives the limit thickness, which must approach 0.1075
within 1e-3 as N grows.  At the limit the arch turns into a mechanism with hinges at the
springings and at the rupture joints ≈ 54.5° from the crown.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import alma

from helpers import arch_dict, check_against_independent, static_highs

R = 1000.0
MILANKOVITCH = 0.1075
INDEPENDENT = 0.10745


def solve_arch(n: int, ratio: float, live=(1.0, 0.0)) -> alma.Result:
    return alma.solve(alma.Scene.from_dict(arch_dict(n, ratio * R, radius=R, live=live)))


def stands(result: alma.Result) -> bool:
    """The arch carries its dead load: a statically admissible field with α ≥ 0 exists."""
    return result.status == "no_collapse" or (result.status == "optimal" and result.alpha >= 0)


def limit_ratio(n: int, lo: float = 0.09, hi: float = 0.12, tol: float = 2e-6) -> tuple[float, float]:
    """Bracket [lo, hi] of the limit t/R: the arch fails at lo and stands at hi."""
    assert not stands(solve_arch(n, lo)) and stands(solve_arch(n, hi))
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if stands(solve_arch(n, mid)):
            hi = mid
        else:
            lo = mid
    return lo, hi


_LIMITS: dict[int, tuple[float, float]] = {}


def limit(n: int) -> tuple[float, float]:
    if n not in _LIMITS:
        _LIMITS[n] = limit_ratio(n)
    return _LIMITS[n]


def test_arch_joints_are_found():
    n = 60
    scene = alma.Scene.from_dict(arch_dict(n, 0.11 * R))
    joints = alma.find_joints(scene)
    assert joints.count == n + 1  # n − 1 radial joints between voussoirs + 2 springings
    length = joints.length
    assert np.allclose(length, 0.11 * R, rtol=1e-9)
    # normals are radial: perpendicular to the joint line through the centre
    centre = joints.centre
    radial = centre / np.linalg.norm(centre, axis=1)[:, None]
    tangential = np.abs(joints.normal[:, 0] * radial[:, 1] - joints.normal[:, 1] * radial[:, 0])
    assert np.all(np.abs(tangential - 1.0) <= 1e-9)


@pytest.mark.parametrize("n", [20, 60, 120])
def test_arch_limit_thickness(n):
    lo, hi = limit(n)
    print(f"N = {n:4d}: t/R limit in [{lo:.6f}, {hi:.6f}]")
    # the discrete arch can only be thinner than the continuous one (hinges only at joints)
    assert hi <= MILANKOVITCH + 1e-3
    if n >= 60:
        assert abs(hi - MILANKOVITCH) <= 1e-3
        assert abs(hi - INDEPENDENT) <= 1e-3
    # the bracket is confirmed by an independent solver on alma's model (scipy HiGHS)
    status_hi, alpha_hi = static_highs(alma.build_model(alma.Scene.from_dict(arch_dict(n, hi * R))))
    assert status_hi == "optimal" and alpha_hi >= -1e-9
    status_lo, alpha_lo = static_highs(alma.build_model(alma.Scene.from_dict(arch_dict(n, lo * R))))
    assert status_lo == "infeasible" or alpha_lo < 1e-9


def test_arch_limit_converges_with_n():
    values = [limit(n)[1] for n in (20, 60, 120)]
    print("t/R limits for N = 20, 60, 120:", ", ".join(f"{v:.6f}" for v in values))
    assert values[0] < values[1] < values[2] + 2e-6
    assert abs(values[2] - INDEPENDENT) <= 2e-4


@pytest.mark.parametrize(
    "ratio,expected", [(0.09, "no_equilibrium"), (0.105, "no_equilibrium"), (0.11, "optimal"), (0.15, "optimal")]
)
def test_arch_status_away_from_limit(ratio, expected):
    n = 60
    scene = alma.Scene.from_dict(arch_dict(n, ratio * R))
    result = alma.solve(scene)
    assert result.status == expected, (result.status, result.alpha, result.message)
    check_against_independent(result, alma.build_model(scene))


def test_arch_alpha_increases_with_thickness():
    alphas = [solve_arch(60, r).alpha for r in (0.108, 0.11, 0.12, 0.15, 0.2)]
    assert all(a > 0 for a in alphas)
    assert all(b > a for a, b in itertools.pairwise(alphas)), alphas


def test_arch_rupture_joints_at_limit():
    """Just above the limit the mechanism hinges at ≈ 35.5° above each springing (54.5° from the crown)."""
    n = 60
    result = solve_arch(n, limit(n)[1] + 1e-4)
    assert result.status == "optimal" and result.alpha > 0
    assert result.mechanism_class == "rocking"
    hinge_angles = []
    for joint in result.joints:
        if joint.state != "hinging":
            continue
        a, b = joint.blocks
        if a.startswith("abutment") or b.startswith("abutment"):
            hinge_angles.append(0.0 if "right" in a + b else 180.0)
        else:
            i = max(int(a[1:]), int(b[1:]))  # joint between v(i−1) and v(i) at angle i·180/n
            hinge_angles.append(i * 180.0 / n)
    step = 180.0 / n
    assert any(abs(h - 35.5) <= step for h in hinge_angles), hinge_angles
    assert any(abs(h - 144.5) <= step for h in hinge_angles), hinge_angles
    assert len(hinge_angles) == 4, hinge_angles


def test_arch_gravity_live_load():
    """Live load along gravity: above the limit any α is carried, below only α = −1 (no load)."""
    above = solve_arch(60, 0.11, live=(0.0, -1.0))
    assert above.status == "no_collapse" and above.alpha == math.inf
    below = solve_arch(60, 0.10, live=(0.0, -1.0))
    assert below.status == "no_equilibrium"
    assert below.alpha == pytest.approx(-1.0, abs=1e-9)


def test_arch_just_below_limit_is_classified():
    scene = alma.Scene.from_dict(arch_dict(60, 0.107447 * R))
    assert static_highs(alma.build_model(scene))[0] == "infeasible"
    result = alma.solve(scene)
    assert result.bounds.lower <= result.bounds.upper, (result.bounds, result.residuals)
    assert result.status == "no_equilibrium", (result.status, result.alpha, result.residuals)
