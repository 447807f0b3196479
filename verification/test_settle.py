"""Foundation settlements (``alma.settle``): the mechanism a support motion opens and its statics.

(a) a semicircular arch whose abutments spread: the horizontal reaction of the settling support
is the arch's minimum thrust, against an independent thrust-line computation written here
(voussoir weights and the crown thrust, nothing of alma's); (b) a wall whose base has a settling
part: the opened joints bound a region over the settling part, and the dead load's work equals
the work of the settling support's reaction on the prescribed motion (virtual work, 1e-9);
(c) zero settlement changes nothing, a rigid motion of every support opens no joint, a single
block over two supports turns about the fixed support's edge with the reaction of statics.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import alma
from alma.settle import after_settlement
from alma.status import Status

from helpers import arch_dict, rect

R = 1000.0


def _with_settlement(data: dict, block_id: str, **settlement) -> alma.Scene:
    for b in data["blocks"]:
        if b["id"] == block_id:
            b["settlement"] = settlement
    return alma.Scene.from_dict(data)


def thrust_line_minimum(n: int, t: float, radius: float = R, samples: int = 4001) -> float:
    """Minimum horizontal thrust (per unit weight density and thickness: area units, mm²) of a
    semicircular arch of ``n`` radial voussoirs, by the thrust line.

    Half arch, crown at the top (n even: a joint at the crown; the thrust there is horizontal by
    symmetry, acting at height y₀ on the crown joint).  Through joint i (angle φ_i from the
    crown) passes the resultant of the thrust H and the weights of the voussoirs between the
    crown and joint i; it must cross the joint within [R − t/2, R + t/2].  For each y₀ the
    admissible H form an interval (each joint gives a linear condition in H); the least H over
    y₀ is the minimum thrust.
    """
    ri, ro = radius - t / 2, radius + t / 2
    phi = np.linspace(0.0, math.pi / 2, n // 2 + 1)  # joints from the crown (0) to the springing (π/2)
    # Voussoir between φ_j and φ_{j+1}: area and centroid of the annular sector.
    a = 0.5 * (ro**2 - ri**2) * np.diff(phi)
    rc = (2.0 / 3.0) * (ro**3 - ri**3) / (ro**2 - ri**2) * np.sin(np.diff(phi) / 2) / (np.diff(phi) / 2)
    mid = 0.5 * (phi[:-1] + phi[1:])
    xc = rc * np.sin(mid)  # x from the crown line
    w_cum = np.concatenate([[0.0], np.cumsum(a)])
    m_cum = np.concatenate([[0.0], np.cumsum(a * xc)])  # moment of the weights about x = 0
    best = math.inf
    for y0 in np.linspace(ri, ro, samples):
        lo, hi = 0.0, math.inf
        for i in range(1, phi.size):
            # Joint i: the radial line at angle φ_i; points r (sin φ, cos φ), r in [ri, ro].
            # Resultant: H to the right (on the half arch, from the other half) at height y0, and the
            # weights W_i at x̄_i = M_i / W_i.  Moment about the joint point P(r): zero when the line passes P.
            # Σ M about P = H (y0 − r cos φ) − W_i (r sin φ − x̄_i) = 0  →  r = (H y0 + M_i) / (H cos φ + W_i sin φ)
            s, c = math.sin(phi[i]), math.cos(phi[i])
            W, M = w_cum[i], m_cum[i]
            # ri ≤ (H y0 + M) / (H c + W s) ≤ ro  (the denominator is positive)
            # → H (y0 − ri c) ≥ ri W s − M  and  H (y0 − ro c) ≤ ro W s − M
            for coef, rhs, upper in ((y0 - ri * c, ri * W * s - M, False), (y0 - ro * c, ro * W * s - M, True)):
                if upper:
                    coef, rhs = -coef, -rhs
                if abs(coef) < 1e-12:
                    if rhs > 1e-9:
                        lo = math.inf
                elif coef > 0:
                    lo = max(lo, rhs / coef)
                else:
                    hi = min(hi, rhs / coef)
        if lo <= hi:
            best = min(best, lo)
    return best


@pytest.mark.parametrize("ratio", [0.12, 0.15, 0.2, 0.25])
def test_spreading_arch_reaction_is_the_minimum_thrust(ratio):
    """(a) abutment_right moves outwards: its horizontal reaction is the minimum thrust."""
    n = 20
    data = arch_dict(n, ratio * R, radius=R, friction=10.0)
    scene = _with_settlement(data, "abutment_right", translation=[1.0, 0.0])
    result = alma.settle(scene)
    assert result.status == Status.OPTIMAL, result.message
    (reaction,) = result.reactions
    density = scene.thickness * scene.unit_weight * 1e-9  # kN per mm² of arch
    expected = thrust_line_minimum(n, ratio * R) * density
    assert reaction["force"][0] == pytest.approx(expected, rel=2e-3)  # the thrust line's y₀ grid: 4001 samples
    assert result.work == pytest.approx(reaction["force"][0] * 1.0, rel=1e-7)
    # Hinges (opened joints): at the springings or the crown region and the rupture joints.
    assert 3 <= len(result.opened) <= 6


def _wall(parts: list[tuple[float, float, bool]], courses: int = 12) -> alma.Scene:
    """A running-bond wall 1440 mm long of 240 × 60 blocks on ground pieces (x0, x1, settles):
    the settling pieces move down by 1 mm."""
    blocks = [
        {
            "id": f"ground{i}",
            "vertices": rect(a, -60, b, 0),
            "fixed": True,
            **({"settlement": {"translation": [0.0, -1.0]}} if settles else {}),
        }
        for i, (a, b, settles) in enumerate(parts)
    ]
    for c in range(courses):
        edges = [0.0] + ([120.0 + 240 * k for k in range(6)] if c % 2 else [240.0 * k for k in range(1, 6)]) + [1440.0]
        for a, b in itertools.pairwise(edges):
            blocks.append({"id": f"c{c}x{int(a)}", "vertices": rect(a, 60 * c, b, 60 * (c + 1))})
    return alma.Scene.from_dict({"friction": 0.6, "blocks": blocks})


def _wall_over_a_settling_base() -> alma.Scene:
    return _wall([(-100, 960, False), (960, 1540, True)])


def _moving_per_course(scene: alma.Scene, result) -> list[list[float]]:
    centroid = {b.id: b.centroid for b in scene.blocks}
    courses: list[list[float]] = [[] for _ in range(12)]
    for b in result.blocks:
        if np.hypot(*b.u[:2]) > 1e-6:
            courses[int(centroid[b.id][1] // 60)].append(float(centroid[b.id][0]))
    return courses


def test_settling_base_part_opens_a_region_over_it():
    """(b) the end of the base settles: the moving blocks form a region over the settling part,
    narrowing course by course upwards, bounded by a stepped diagonal crack (as the laboratory
    and DEM patterns of Pepe et al. 2020 and Portioli & Cascini 2017 for an end settlement);
    virtual work holds to 1e-9."""
    scene = _wall_over_a_settling_base()
    result = alma.settle(scene)
    assert result.status == Status.OPTIMAL, result.message
    assert result.bounds.upper - result.bounds.lower <= 1e-9 * max(1.0, abs(result.bounds.upper))
    (reaction,) = result.reactions
    assert result.work == pytest.approx(-reaction["force"][1] * 1.0, rel=1e-9)  # support moved by (0, −1)
    courses = _moving_per_course(scene, result)
    assert all(x > 960 for xs in courses for x in xs)  # only over the settling part
    assert len(courses[0]) >= 2 and courses[-1] == []
    counts = [len(xs) for xs in courses]
    assert all(a >= b for a, b in itertools.pairwise(counts))  # narrowing upwards
    lefts = [min(xs) for xs in courses if xs]
    assert all(a < b for a, b in itertools.pairwise(lefts))  # the crack steps outwards, course by course
    cracked = [j for j in result.joints if j.state != "rest" and "ground" not in "".join(j.blocks)]
    assert cracked and all(j.state in ("separating", "sliding", "hinging") for j in cracked)


@pytest.mark.xfail(
    strict=True,
    reason="measured: the settlement of the middle 480 mm of the base moves no block "
    "(work 7.5e-12 kN·mm): in the associative model a block confined between neighbours can only "
    "slide down its head joints by opening them by f·|slip|, which its neighbours prevent, so the "
    "interlocked wall bridges the settlement; the arch-shaped region of the laboratory needs "
    "sliding without dilatancy",
)
def test_settling_middle_part_opens_an_arch_over_it():
    scene = _wall([(-100, 480, False), (480, 960, True), (960, 1540, False)])
    result = alma.settle(scene)
    assert len(_moving_per_course(scene, result)[0]) >= 2


def test_zero_settlement_changes_nothing():
    scene = _with_settlement(alma.paper_panel("running", "2:1", "4:1", 0.6).to_dict(), "ground", translation=[0, 0])
    result = alma.settle(scene)
    assert result.status == Status.OPTIMAL
    assert abs(result.work) <= 1e-9 and result.opened == ()


def test_rigid_motion_of_every_support_opens_no_joint():
    data = _wall_over_a_settling_base().to_dict()
    for b in data["blocks"]:
        if b.get("fixed"):
            b["settlement"] = {"translation": [0.3, -1.0], "rotation": 1e-4, "about": [720.0, 0.0]}
    result = alma.settle(alma.Scene.from_dict(data))
    assert result.status == Status.OPTIMAL
    assert result.opened == ()
    weight = sum(b.area for b in alma.Scene.from_dict(data).blocks if not b.fixed) * 120 * 18e-9
    # Every block follows the supports: the dead load works on the motion of its centroid.
    assert result.work > 0.9 * weight * 1.0 - 1e-9


@pytest.mark.parametrize("end", [500.0, 600.0])
def test_single_block_over_two_supports_turns_about_the_fixed_edge(end):
    """(c) a beam on a fixed support [..., 100] and a settling one [300, ...], centroid over the
    settling one: it turns about (100, 0) until its far end follows the support down by 1 mm, so
    the settling reaction is R = W (x_c − 100) / (x_end − 100) and the work R · 1 mm."""
    data = {
        "friction": 0.6,
        "blocks": [
            {"id": "left", "vertices": rect(-200, -100, 100, 0), "fixed": True},
            {"id": "right", "vertices": rect(300, -100, 700, 0), "fixed": True},
            {"id": "beam", "vertices": rect(0, 0, end, 100)},
        ],
    }
    result = alma.settle(_with_settlement(data, "right", translation=[0.0, -1.0]))
    W = end * 100 * 120 * 18e-9
    expected = W * (end / 2 - 100) / (end - 100)
    (reaction,) = result.reactions
    assert result.status == Status.OPTIMAL
    assert -reaction["force"][1] == pytest.approx(expected, rel=1e-9)
    assert result.work == pytest.approx(expected, rel=1e-9)
    (beam,) = result.blocks
    assert beam.u[2] == pytest.approx(-1.0 / (end - 100), rel=1e-9)  # clockwise about the fixed edge


def test_settlement_command_prints_one_json_object(tmp_path, capsys):
    import json

    from alma.cli.main import main

    path = tmp_path / "wall.json"
    path.write_text(json.dumps(_wall_over_a_settling_base().to_dict()))
    assert main(["settle", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "optimal" and out["reactions"][0]["block"] == "ground1"
    assert {"work", "bounds", "blocks", "joints"} <= set(out)


def test_after_settlement_cohesion_is_lost_on_the_opened_joints():
    data = _wall_over_a_settling_base().to_dict()
    data["cohesion"] = 5.0
    scene = alma.Scene.from_dict(data)
    settled = alma.settle(scene)
    cracked = after_settlement(scene, settled)
    zeroed = {tuple(sorted(o.blocks)) for o in cracked.joint_overrides if o.cohesion == 0.0}
    assert zeroed == {tuple(sorted(p)) for p in settled.opened} and zeroed
    intact, weakened = alma.solve(scene), alma.solve(cracked)
    assert weakened.status == intact.status == Status.OPTIMAL
    assert weakened.alpha < intact.alpha  # the crack costs strength
