"""Numerics at the edges of scale (issue 32, item 6): loads far above the blocks' weight, huge
friction, and the contact-tolerance warning.

References are independent: a column of blocks under point loads is solved by a small static
LP written here from first principles (contact-point forces N ≥ 0, |T| ≤ f N at the two ends of
each bed joint, each block's three equilibrium equations), with scipy's HiGHS; a single block of
b/h = 4 with any friction ≥ 4 rocks at α = b/h = 4 exactly (moments about the toe).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.optimize import linprog

import alma
from alma.cli.main import main

from helpers import ground, rect

WIDTH = 400.0
HEIGHTS = (200.0, 150.0, 250.0)  # blocks of the column, bottom first (mm)
THICKNESS = 120.0


def column_scene(unit_weight: float, friction: float) -> dict:
    """Three blocks stacked on a ground, ~1 kN point loads (dead off-centre, live at two heights)."""
    blocks, y = [ground(-200.0, 600.0)], 0.0
    for k, h in enumerate(HEIGHTS):
        blocks.append({"id": f"c{k}", "vertices": rect(0.0, y, WIDTH, y + h)})
        y += h
    loads = [
        {"block": "c0", "point": [120.0, 100.0], "dead": [0.0, -1.2]},
        {"block": "c1", "point": [300.0, 280.0], "dead": [0.1, -0.8], "live": [0.4, 0.0]},
        {"block": "c2", "point": [60.0, 560.0], "dead": [0.0, -1.0], "live": [0.7, -0.1]},
    ]
    return {
        "thickness": THICKNESS,
        "unit_weight": unit_weight,
        "friction": friction,
        "blocks": blocks,
        "live_load": {"direction": [1, 0], "self_weight": False},
        "loads": loads,
    }


def column_reference(data: dict) -> float:
    """α_c of :func:`column_scene` by an independent static LP (maximise α; variables α, N, T)."""
    heights = np.array(HEIGHTS)
    tops = np.cumsum(heights)
    beds = np.concatenate([[0.0], tops[:-1]])  # y of the joint under each block
    n, f = len(heights), data["friction"]
    weight = WIDTH * heights * THICKNESS * data["unit_weight"] * 1e-9  # kN
    # Unknowns: α, then per joint j (under block j) and end p (x = 0, WIDTH): N_jp, T_jp.
    nv = 1 + 4 * n

    def col(j, p, kind):  # kind 0: N, 1: T
        return 1 + 4 * j + 2 * p + kind

    A = np.zeros((3 * n, nv))
    b = np.zeros(3 * n)
    for j in range(n):
        for p, x in enumerate((0.0, WIDTH)):
            # joint j pushes block j up (N, T on it at (x, beds[j])) and block j-1 down.
            for block, sign in ((j, 1.0), (j - 1, -1.0)):
                if block < 0:
                    continue
                y = beds[j]
                A[3 * block, col(j, p, 1)] += sign  # Fx = T
                A[3 * block + 1, col(j, p, 0)] += sign  # Fy = N
                A[3 * block + 2, col(j, p, 1)] += -sign * y  # M = x Fy − y Fx about the origin
                A[3 * block + 2, col(j, p, 0)] += sign * x
        cx = WIDTH / 2  # the weight is vertical: its moment needs x only
        b[3 * j + 1] += weight[j]
        b[3 * j + 2] += cx * weight[j]
    for load in data["loads"]:
        j = int(load["block"][1:])
        x, y = load["point"]
        dx, dy = load.get("dead", [0.0, 0.0])
        lx, ly = load.get("live", [0.0, 0.0])
        b[3 * j] -= dx
        b[3 * j + 1] -= dy
        b[3 * j + 2] -= x * dy - y * dx
        A[3 * j, 0] += lx
        A[3 * j + 1, 0] += ly
        A[3 * j + 2, 0] += x * ly - y * lx
    rows = []
    for j in range(n):
        for p in range(2):
            for s in (1.0, -1.0):  # s T − f N ≤ 0
                row = np.zeros(nv)
                row[col(j, p, 1)], row[col(j, p, 0)] = s, -f
                rows.append(row)
    bounds = [(None, None)] + [(0, None) if k % 2 == 0 else (None, None) for k in range(4 * n)]
    c = np.zeros(nv)
    c[0] = -1.0
    res = linprog(c, A_ub=np.array(rows), b_ub=np.zeros(len(rows)), A_eq=A, b_eq=b, bounds=bounds, method="highs")
    assert res.status == 0, res.message
    return float(res.x[0])


@pytest.mark.parametrize("unit_weight", [18.0, 1e-3, 1e-9, 1e-15])
@pytest.mark.parametrize("friction", [0.3, 0.8])
def test_kn_loads_on_blocks_of_almost_no_weight(unit_weight, friction):
    data = column_scene(unit_weight, friction)
    expected = column_reference(data)
    assert 0 < expected < 10
    result = alma.solve(alma.Scene.from_dict(data))
    assert result.status == "optimal", result.message
    assert result.alpha == pytest.approx(expected, rel=1e-7)
    assert result.bounds.lower <= expected * (1 + 1e-9) and result.bounds.upper >= expected * (1 - 1e-9)


def test_point_loads_alone_set_the_scale_of_a_single_block():
    """One 200 × 100 block, dead 1 kN at (50, 50), live 0.8 kN at (100, 90), f = 2: it rocks about
    its right toe at α = 1 · 150 / (0.8 · 90) (sliding needs α = 2 / 0.8)."""
    data = {
        "thickness": 120,
        "unit_weight": 1e-15,
        "friction": 2.0,
        "blocks": [ground(-200.0, 400.0), {"id": "b1", "vertices": rect(0.0, 0.0, 200.0, 100.0)}],
        "live_load": {"direction": [1, 0], "self_weight": False},
        "loads": [
            {"block": "b1", "point": [50, 50], "dead": [0, -1]},
            {"block": "b1", "point": [100, 90], "live": [0.8, 0]},
        ],
    }
    result = alma.solve(alma.Scene.from_dict(data))
    assert result.status == "optimal", result.message
    assert result.alpha == pytest.approx(150 / 72, rel=1e-8)


@pytest.mark.parametrize("friction", [4.0, 1e3, 1e6, 1e10, 1e12, 1e15, 1e308])
def test_huge_friction_never_proves_a_wrong_alpha(friction):
    """A 200 × 50 block rocks at α = b/h = 4 whatever f ≥ 4: a bound may be lost (not_converged),
    never put on the wrong side of 4, and ``optimal`` only with 4 inside the gap."""
    data = {
        "thickness": 120,
        "unit_weight": 18,
        "friction": friction,
        "blocks": [ground(-200.0, 400.0), {"id": "b1", "vertices": rect(0.0, 0.0, 200.0, 50.0)}],
    }
    result = alma.solve(alma.Scene.from_dict(data))
    lower, upper = result.bounds.lower, result.bounds.upper
    assert not (math.isnan(lower) or math.isnan(upper))
    assert lower <= upper
    assert lower <= 4.0 * (1 + 1e-9), (lower, result.message)
    assert upper >= 4.0 * (1 - 1e-9), (upper, result.message)
    assert result.status in ("optimal", "not_converged")
    if result.status == "optimal":
        assert result.alpha == pytest.approx(4.0, rel=1e-7)
    if friction <= 1e6:
        assert result.status == "optimal"


def test_json_holds_no_nan_when_the_solver_fails(tmp_path, capsys):
    data = {
        "thickness": 120,
        "unit_weight": 18,
        "friction": 1e308,
        "blocks": [ground(-200.0, 400.0), {"id": "b1", "vertices": rect(0.0, 0.0, 200.0, 50.0)}],
    }
    path = tmp_path / "f.json"
    path.write_text(json.dumps(data))
    assert main(["solve", str(path), "--json"]) == 0
    text = capsys.readouterr().out
    out = json.loads(text, parse_constant=lambda name: pytest.fail(f"{name} in the JSON output"))
    assert out["status"] in ("optimal", "not_converged")


def test_near_miss_warning_gives_the_gap_the_decision_used():
    """Two blocks side by side whose facing edges are apart by 0.03 mm at the bottom and 0.05 mm
    at the top: both ends lie beyond twice the tolerance (1e-4 × √(200 · 100) = 0.0141 mm), within
    which vertices of different blocks are one point (docs/scenes.md), so no joint is made; the
    warning must say 0.05 mm, the largest gap, which the decision used."""
    snap = 1e-4 * math.sqrt(200 * 100)
    low, high = 0.03, 0.05
    assert 2 * snap < low < high
    scene = alma.Scene.from_dict(
        {
            "thickness": 120,
            "unit_weight": 18,
            "friction": 0.6,
            "blocks": [
                ground(-200.0, 800.0),
                {"id": "left", "vertices": rect(0.0, 0.0, 200.0, 100.0)},
                {"id": "right", "vertices": [[200.0 + low, 0.0], [400.0, 0.0], [400.0, 100.0], [200.0 + high, 100.0]]},
            ],
        }
    )
    joints = alma.find_joints(scene)
    (warning,) = joints.warnings
    assert "'left' and 'right' nearly touch" in warning
    assert "0.05 mm" in warning and f"({snap:.3g} mm)" in warning
