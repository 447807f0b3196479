"""``alma settle`` counts cohesion and ties (issue 32, item 8).

A block B (200 × 400 mm) stands on a support S that settles 1 mm down, beside a fixed abutment A
(a vertical joint of 400 mm).  By hand, two mechanisms compete (f = 0.5, d = 1 mm, W its weight):

- B translates with S, sliding down A by s and away from it by f s (dilatancy) and on S by
  f s (which S's drop d must make room for, opening f² s): s = d / (1 + f²); the dead load does
  W s, cohesion on A–B dissipates C s (C = c l t) and a tie from B to A stretched by f s
  dissipates f F s: W* = (W − C − f F) d / (1 + f²);
- B turns about its bottom-left corner (on A and S), its right edge following S: its centroid
  drops d / 2; the A–B joint opens without sliding (no cohesion work), the tie at height 300 mm,
  100 mm from the corner's vertical, stretches by 1.5 d: W* = W d / 2 − 1.5 F d;

and W* is the larger of them and 0 (nothing needs to move).
"""

from __future__ import annotations

import json

import pytest

import alma
from alma.cli.main import main

from helpers import rect

F = 0.5
W = 200 * 400 * 120 * 18e-9  # kN


def scene(cohesion: float = 0.0, tie: float | None = None) -> dict:
    data = {
        "thickness": 120,
        "unit_weight": 18,
        "friction": F,
        "blocks": [
            {"id": "A", "vertices": rect(-200, 0, 0, 400), "fixed": True},
            {"id": "S", "vertices": rect(0, -100, 200, 0), "fixed": True, "settlement": {"translation": [0, -1]}},
            {"id": "B", "vertices": rect(0, 0, 200, 400)},
        ],
    }
    if cohesion:
        data["joints"] = [{"blocks": ["A", "B"], "cohesion": cohesion}]
    if tie is not None:
        data["ties"] = [
            {
                "id": "t",
                "from": {"block": "B", "point": [100, 300]},
                "to": {"block": "A", "point": [-100, 300]},
                "strength": tie,
            }
        ]
    return data


def by_hand(cohesion: float, tie: float) -> float:
    c = cohesion * 400 * 120 * 1e-6  # kN
    return max(0.0, (W - c - F * tie) / (1 + F**2), W / 2 - 1.5 * tie)


@pytest.mark.parametrize("cohesion,tie", [(0, 0), (1.0, 0), (2.0, 0), (5.0, 0), (0, 0.1), (0, 0.5), (1.0, 0.1)])
def test_settlement_work_counts_cohesion_and_ties(cohesion, tie):
    result = alma.settle(alma.Scene.from_dict(scene(cohesion, tie if tie else None)))
    expected = by_hand(cohesion, tie)
    assert result.status == "optimal", result.message
    assert result.work == pytest.approx(expected, rel=1e-7, abs=1e-9)
    assert result.bounds.lower <= expected + 1e-9 and result.bounds.upper >= expected - 1e-9


def test_cohesion_changes_the_answer():
    plain = alma.settle(alma.Scene.from_dict(scene())).work
    cohesive = alma.settle(alma.Scene.from_dict(scene(1.0))).work
    assert cohesive < plain - 0.03


def test_reaction_of_the_settling_support_balances_the_block():
    """With the A–B joint sliding, S carries B's weight less what A's cohesion and the tie hold."""
    result = alma.settle(alma.Scene.from_dict(scene(1.0, 0.1)))
    (reaction,) = result.reactions
    assert reaction["block"] == "S"
    _fx, fy = reaction["force"]
    assert fy < 0 and abs(fy) < W  # S pushes down by less than B's weight: A and the tie carry a part


def test_cli_settle_json_with_cohesion(tmp_path, capsys):
    path = tmp_path / "s.json"
    path.write_text(json.dumps(scene(0.0)))
    assert main(["settle", str(path), "--cohesion", "1", "--json"]) == 0  # every joint: A–B, S–B
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "optimal"
    assert out["work"] < by_hand(0, 0) - 1e-3
