"""Finite compressive strength (issue 34, SPEC §2 ``compressive_strength``): references written here.

- A single block b × h (thickness t, weight W) under W and a horizontal α W at its centroid,
  rocking about its toe.  With a rectangular stress block of stress σ_c the base reaction N = W
  acts at W/(2 σ_c t) from the toe, so about the toe: α W h/2 = W (b/2 − W/(2 σ_c t)), i.e.

      α = (b − W/(σ_c t)) / h,

  b/h as σ_c → ∞, and no equilibrium at all once W > σ_c b t (the block crushes under its weight).
- A column of stacked blocks, a portal and a semicircular arch: α falls monotonically as σ_c falls,
  tends to the rigid value as σ_c grows, and equals an independent formulation, a small cone
  program written here in cvxpy on joint resultants (N, T, M about the joint's centre) with the
  domain N ≥ 0, |T| ≤ f N, N l/2 − |M| ≥ N²/(2 σ_c t) — not on alma's contact-point generators.
  Only the joint geometry (alma.geometry.contacts.find_joints) is shared.
- The pier formula of the Italian code, NTC 2018 §7.8.2.2.1, Eq. (7.8.2): a masonry pier of
  length l and thickness t under the axial stress σ₀ = N/(l t) resists in its plane the moment
  M_u = (l² t σ₀ / 2)(1 − σ₀ / (0.85 f_d)) — the same rectangular stress block at 0.85 f_d.  With
  compressive_strength = 0.85 f_d, a one-block pier under a top load P and a horizontal α at its
  top carries α h = M_u.  A published worked example (EC6's top-of-wall factor) is in
  test_compressive_published.py; a published limit-analysis case (an arch with finite crushing
  strength) is not reproduced: see docs/compressive.md.
"""

from __future__ import annotations

import copy
import itertools
import math

import cvxpy as cp
import numpy as np
import pytest

import alma
from alma.geometry.contacts import find_joints
from alma.status import Status

from helpers import arch_dict, column_dict, ground, rect, scene_dict, single_block_dict

#: kN per (MPa · mm²)
MPA_MM2 = 1e-3
T = 120.0
GAMMA = 18.0


def _with_strength(data: dict, sigma: float | None) -> alma.Scene:
    data = copy.deepcopy(data)
    if sigma is not None:
        data["compressive_strength"] = sigma
    return alma.Scene.from_dict(data)


def _alpha(data: dict, sigma: float | None) -> alma.AssociativeResult:
    return alma.solve(_with_strength(data, sigma))


# --------------------------------------------------------------------------- single block
@pytest.mark.parametrize("b, h", [(240.0, 600.0), (400.0, 300.0)])
@pytest.mark.parametrize("fraction", [1e-3, 0.1, 0.5, 0.9])
def test_single_block_rocking_with_crushing(b, h, fraction):
    """α = (b − W/(σ_c t))/h to 1e-9, σ_c chosen so that the stress block is ``fraction`` of b."""
    W = b * h * T * GAMMA * 1e-9
    sigma = W / (fraction * b * T * MPA_MM2)
    result = _alpha(single_block_dict(b, h, 10.0), sigma)
    expected = (b - W / (sigma * MPA_MM2 * T)) / h
    assert result.status == Status.OPTIMAL, result.message
    assert result.alpha == pytest.approx(expected, rel=1e-9)
    assert result.bounds.lower <= expected * (1 + 1e-9) and result.bounds.upper >= expected * (1 - 1e-9)
    joint = result.joints[0]
    assert joint.stress_block is not None
    extent = math.dist(*joint.stress_block)
    assert extent == pytest.approx(W / (sigma * MPA_MM2 * T), rel=1e-7)  # N/(σ_c t)
    assert joint.capacity == pytest.approx(sigma * MPA_MM2 * b * T, rel=1e-12)
    assert joint.state == "hinging"


def test_single_block_strong_limit():
    """σ_c → ∞: at 1e7 MPa (c = σ_c b t ≈ 10⁹ block weights, where the formula is 1.1e-9 below
    b/h) still the formula to 1e-9.  At 1e8 MPa the cone program's own accuracy (1.3e-9 above
    the formula, measured) is the limit: docs/compressive.md."""
    b, h, sigma = 240.0, 600.0, 1e7
    W = b * h * T * GAMMA * 1e-9
    result = _alpha(single_block_dict(b, h, 10.0), sigma)
    assert result.status == Status.OPTIMAL, result.message
    assert result.alpha == pytest.approx((b - W / (sigma * MPA_MM2 * T)) / h, rel=1e-9)
    assert result.alpha == pytest.approx(b / h, rel=2e-9)  # the formula's own 1.1e-9 from b/h


def test_single_block_crushes_under_its_weight():
    b, h = 240.0, 600.0
    W = b * h * T * GAMMA * 1e-9
    sigma = 0.99 * W / (b * T * MPA_MM2)  # σ_c below W/(b t)
    result = _alpha(single_block_dict(b, h, 10.0), sigma)
    assert result.status == Status.NO_EQUILIBRIUM
    assert "compressive strength" in result.message and "dead load" in result.message


# --------------------------------------------------------------------------- independent cone program
def cvxpy_alpha(scene: alma.Scene) -> float:
    """max α of the scene with joint resultants (N, T, M about the joint's centre) in the domain
    N ≥ 0, |T| ≤ f N, N l/2 ∓ M ≥ N²/(2 σ_c t) (cvxpy, Clarabel); kN and mm throughout."""
    joints = find_joints(scene)
    blocks = scene.blocks
    free = [i for i, blk in enumerate(blocks) if not blk.fixed]
    m = joints.count
    N, Tt, M, alpha = cp.Variable(m), cp.Variable(m), cp.Variable(m), cp.Variable()
    rows = {(i, c): 0 for i in free for c in range(3)}
    centre = 0.5 * (joints.start + joints.end)
    length = np.hypot(*(joints.end - joints.start).T)
    tangent = np.column_stack([-joints.normal[:, 1], joints.normal[:, 0]])
    for k in range(m):  # force N n + T t and moment M on block b at the centre, the opposite on a
        for blk, sign in ((joints.block_b[k], 1.0), (joints.block_a[k], -1.0)):
            if blocks[blk].fixed:
                continue
            r = centre[k] - blocks[blk].centroid
            fx = N[k] * joints.normal[k, 0] + Tt[k] * tangent[k, 0]
            fy = N[k] * joints.normal[k, 1] + Tt[k] * tangent[k, 1]
            rows[blk, 0] = rows[blk, 0] + sign * fx
            rows[blk, 1] = rows[blk, 1] + sign * fy
            rows[blk, 2] = rows[blk, 2] + sign * (r[0] * fy - r[1] * fx + M[k])
    constraints = []
    for i in free:
        w = blocks[i].area * scene.thickness * scene.unit_weight * 1e-9
        g, d = scene.gravity, scene.live_load_direction
        constraints += [
            rows[i, 0] + w * g[0] + alpha * w * d[0] == 0,
            rows[i, 1] + w * g[1] + alpha * w * d[1] == 0,
            rows[i, 2] == 0,
        ]
    assert scene.compressive_strength is not None
    capacity = scene.compressive_strength * MPA_MM2 * length * scene.thickness
    constraints += [
        N >= 0,
        cp.abs(Tt) <= scene.friction * N,
        cp.multiply(cp.square(N), length / (2 * capacity)) <= cp.multiply(N, length / 2) - M,
        cp.multiply(cp.square(N), length / (2 * capacity)) <= cp.multiply(N, length / 2) + M,
    ]
    problem = cp.Problem(cp.Maximize(alpha), constraints)
    problem.solve(solver=cp.CLARABEL, tol_gap_abs=1e-10, tol_gap_rel=1e-10, tol_feas=1e-10)
    assert problem.status == cp.OPTIMAL, problem.status
    assert alpha.value is not None
    return float(alpha.value)


def portal_dict(friction: float = 10.0) -> dict:
    """Two piers of two 200 × 400 blocks each and a 1000 × 200 lintel over a 600 mm opening."""
    blocks = [ground(-200.0, 1200.0)]
    for side, x0 in (("l", 0.0), ("r", 800.0)):
        blocks += [{"id": f"{side}{k}", "vertices": rect(x0, 400.0 * k, x0 + 200.0, 400.0 * (k + 1))} for k in range(2)]
    blocks.append({"id": "lintel", "vertices": rect(0.0, 800.0, 1000.0, 1000.0)})
    return scene_dict(blocks, friction=friction)


CASES = {
    # name: (scene dict, strengths in MPa from strong to weak; the weakest near crushing under the
    # dead load: column 0.0072 MPa, portal ≈ 0.023, arch ≈ 0.05)
    "column": (column_dict(4, size=100.0, f=10.0), [1e3, 1e2, 1.0, 0.1, 0.02, 0.01]),
    "portal": (portal_dict(), [1e3, 1e2, 1.0, 0.1, 0.05, 0.03]),
    "arch": (arch_dict(12, 200.0, radius=1000.0, friction=10.0), [1e3, 1e2, 1.0, 0.2, 0.1, 0.06]),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_monotone_convergent_and_independent(name):
    """Certified, equal to the cvxpy program to 1e-6, falling with σ_c, and converging to the rigid
    α as 1/σ_c (the first-order effect of the stress block's extent)."""
    data, strengths = CASES[name]
    rigid = _alpha(data, None)
    assert rigid.status == Status.OPTIMAL
    alphas = []
    for sigma in strengths:
        result = _alpha(data, sigma)
        assert result.status == Status.OPTIMAL, (sigma, result.message)
        assert result.alpha == pytest.approx(cvxpy_alpha(_with_strength(data, sigma)), rel=1e-6, abs=1e-9)
        alphas.append(result.alpha)
    assert all(a >= b for a, b in itertools.pairwise([rigid.alpha, *alphas]))  # α falls with σ_c ...
    assert alphas[-1] < 0.9 * rigid.alpha  # ... and visibly so near crushing
    d3, d2 = rigid.alpha - alphas[0], rigid.alpha - alphas[1]  # σ_c = 1000 and 100 MPa
    assert 0.0 <= d3 <= 0.2 * d2 and d3 <= 1e-3 * rigid.alpha


def test_weakest_case_crushes():
    """Below the dead load's stress at the column's base, no equilibrium (said in words)."""
    result = _alpha(column_dict(4, size=100.0, f=10.0), 0.007)
    assert result.status == Status.NO_EQUILIBRIUM and "compressive strength" in result.message


# --------------------------------------------------------------------------- NTC 2018, Eq. (7.8.2)
def test_pier_moment_of_the_italian_code():
    """M_u = (l² t σ₀ / 2)(1 − σ₀ / (0.85 f_d)) for a pier l × h under a top load P (NTC 2018)."""
    length, h, P, fd = 1000.0, 2000.0, 60.0, 1.2  # mm, mm, kN, MPa
    data = scene_dict([ground(-500.0, 1500.0), {"id": "pier", "vertices": rect(0.0, 0.0, length, h)}], friction=10.0)
    data["live_load"] = {"direction": [1.0, 0.0], "self_weight": False}
    data["loads"] = [{"block": "pier", "point": [length / 2, h], "dead": [0.0, -P], "live": [1.0, 0.0]}]
    result = _alpha(data, 0.85 * fd)
    W = length * h * T * GAMMA * 1e-9
    sigma0 = (P + W) / (length * T) / MPA_MM2  # MPa, the axial stress at the base
    Mu = (length**2 * T * sigma0 * MPA_MM2 / 2) * (1 - sigma0 / (0.85 * fd))  # kN·mm
    assert result.status == Status.OPTIMAL
    assert result.alpha == pytest.approx(Mu / h, rel=1e-9)  # live load 1 kN × α at height h


@pytest.mark.parametrize("h", [60.0, 600.0])
def test_with_cohesion_the_weaker_mechanism(h):
    """Cohesion and crushing together: α = min(f + c b t / W, (b − W/(σ_c t))/h)."""
    b, f, c, sigma = 240.0, 0.3, 1.0, 0.05
    data = single_block_dict(b, h, f)
    data["cohesion"] = c
    W = b * h * T * GAMMA * 1e-9
    expected = min(f + c * b * T * 1e-6 / W, (b - W / (sigma * MPA_MM2 * T)) / h)
    result = _alpha(data, sigma)
    assert result.status == Status.OPTIMAL, result.message
    assert result.alpha == pytest.approx(expected, rel=1e-9)


def test_tilt_bisects_with_crushing():
    """On a tilting table the block rocks when tan θ = (b − W cos θ/(σ_c t))/h (the base force is
    W cos θ); alma tilt brackets that angle (bisection: the capacity does not scale with g)."""
    b, h, sigma = 240.0, 600.0, 0.02
    W = b * h * T * GAMMA * 1e-9
    data = single_block_dict(b, h, 10.0)
    data["compressive_strength"] = sigma
    result = alma.tilt(alma.Scene.from_dict(data))
    theta = 0.3
    for _ in range(100):  # a contraction: converges to the root
        theta = math.atan((b - W * math.cos(theta) / (sigma * MPA_MM2 * T)) / h)
    lo, hi = result.bounds_deg
    assert result.method == "bisection" and lo <= math.degrees(theta) <= hi
