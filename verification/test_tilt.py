"""The tilting table (``alma tilt``): the critical tilt angle against closed forms.

A rigid block b × h on a table with friction f: it rocks about its downhill corner at
tan θ = b / h and slides at tan θ = f, whichever comes first.  With cohesion c on the base
(length b, thickness t) it slides when W sin θ = f W cos θ + c b t, i.e.
θ = atan f + asin(c b t / (W √(1 + f²))).  A dead point load P at the top centre turns with
the table like a weight: rocking at tan θ = (b/2)(W + P) / (W h/2 + P h).  Without cohesion,
ties or applied loads θ_c = atan(α_c) of the horizontal self-weight load (``method="exact"``);
the general bisection must agree with it.
"""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.cli import main

#: Width of the bisection's certified bracket (``TiltSettings.tolerance_deg``).
BRACKET = alma.TiltSettings().tolerance_deg
T, RHO = 120.0, 18.0  # mm, kN/m³ (the scene defaults)


def block(b: float, h: float, f: float = 0.6, c: float = 0.0, load: float = 0.0) -> alma.Scene:
    data = {
        "friction": f,
        "cohesion": c,
        "blocks": [
            {"id": "table", "fixed": True, "vertices": [[-2 * b, -100], [3 * b, -100], [3 * b, 0], [-2 * b, 0]]},
            {"id": "b", "vertices": [[0, 0], [b, 0], [b, h], [0, h]]},
        ],
    }
    if load:
        data["loads"] = [{"block": "b", "point": [b / 2, h], "dead": [0.0, -load]}]
    return alma.Scene.from_dict(data)


def weight(b: float, h: float) -> float:
    return b * h * T * RHO * 1e-9  # kN


@settings(max_examples=20, deadline=None)
@given(b=st.floats(50, 500), h=st.floats(50, 500), f=st.floats(0.1, 1.5))
def test_single_block_rocks_or_slides(b, h, f):
    expected = math.degrees(min(math.atan(b / h), math.atan(f)))
    result = alma.tilt(block(b, h, f))
    assert result.status == "optimal" and result.method == "exact"
    assert result.angle_deg == pytest.approx(expected, abs=1e-6)
    lo, hi = result.bounds_deg
    assert lo <= expected + 1e-7 and hi >= expected - 1e-7


@pytest.mark.parametrize("b,h,f", [(100, 400, 0.6), (400, 100, 0.6), (200, 200, 0.8)])
def test_bisection_agrees_with_the_exact_angle(b, h, f):
    exact = alma.tilt(block(b, h, f))
    bisected = alma.tilt(block(b, h, f), method="bisection")
    assert bisected.status == "optimal" and bisected.method == "bisection"
    lo, hi = bisected.bounds_deg
    assert hi - lo <= BRACKET
    assert lo - 1e-7 <= exact.angle_deg <= hi + 1e-7


@pytest.mark.parametrize("c", [0.25, 0.5, 1.0])
def test_cohesion_raises_the_sliding_angle(c):
    b, h, f = 400.0, 100.0, 0.6
    w = weight(b, h)
    expected = math.degrees(math.atan(f) + math.asin(c * 1e-6 * b * T / (w * math.sqrt(1 + f * f))))
    assert expected < math.degrees(math.atan(b / h))  # sliding governs
    result = alma.tilt(block(b, h, f, c=c))
    assert result.status == "optimal" and result.method == "bisection"
    lo, hi = result.bounds_deg
    assert lo - 1e-7 <= expected <= hi + 1e-7


@pytest.mark.parametrize("load", [0.05, 0.5])
def test_a_dead_load_on_top_lowers_the_rocking_angle(load):
    b, h = 100.0, 400.0
    w = weight(b, h)
    expected = math.degrees(math.atan((b / 2) * (w + load) / (w * h / 2 + load * h)))
    result = alma.tilt(block(b, h, f=1.5, load=load))
    assert result.status == "optimal" and result.method == "bisection"
    lo, hi = result.bounds_deg
    assert lo - 1e-7 <= expected <= hi + 1e-7


def test_a_small_wall_bisection_agrees_with_exact():
    wall = alma.wall("running", 1200.0, 600.0, 240.0)
    exact, bisected = alma.tilt(wall), alma.tilt(wall, method="bisection")
    assert exact.status == bisected.status == "optimal"
    lo, hi = bisected.bounds_deg
    assert lo - 1e-7 <= exact.angle_deg <= hi + 1e-7


def test_cli_prints_one_json_object(tmp_path, capsys):
    path = tmp_path / "block.json"
    path.write_text(json.dumps(block(100, 400).to_dict()))
    assert main(["tilt", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "optimal"
    assert out["angle_deg"] == pytest.approx(math.degrees(math.atan(0.25)), abs=1e-6)
    assert len(out["bounds_deg"]) == 2


def test_a_structure_that_cannot_stand_level_is_reported():
    """A block on a ground tilted by 40° with friction 0.5 slides before the table turns."""
    scene = block(400, 100, f=0.5).transformed(_rotation(math.radians(40)), rotate_loads=False)
    result = alma.tilt(scene)
    assert result.status == "no_equilibrium"


def _rotation(theta: float):
    import numpy as np

    return np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
