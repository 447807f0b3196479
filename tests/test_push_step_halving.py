"""A step over which the corrector finds no motion is halved, down to the probe step.

A mechanism that turns from sliding to rocking can lock over a long step: the running-bond paper
panels that slide on a bed joint met it after 144–449 mm and ended ``not_converged`` ("motion").
The step is now halved until the corrector moves, and the next step is the curve's own again.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest

import alma
from alma.geometry.panels import paper_panel

curve_module = importlib.import_module("alma.push.curve")  # alma.push is also the function's name


def _block() -> alma.Scene:
    return alma.Scene.from_dict(
        {
            "thickness": 120,
            "unit_weight": 18,
            "friction": 0.8,
            "blocks": [
                {"id": "ground", "vertices": [[-2000, -100], [3000, -100], [3000, 0], [-2000, 0]], "fixed": True},
                {"id": "b1", "vertices": [[0, 0], [240, 0], [240, 600], [0, 600]]},
            ],
        }
    )


def _locking(monkeypatch: pytest.MonkeyPatch, at: int, times: int) -> list[float]:
    """``_move`` whose ``at``-th call and the ``times`` − 1 after it find no motion; the steps asked."""
    real, asked = curve_module._move, []

    def move(run, state, d):
        asked.append(d - state.d)
        if at <= len(asked) < at + times:
            raise curve_module.MotionError("locked over this step")
        return real(run, state, d)

    monkeypatch.setattr(curve_module, "_move", move)
    return asked


def test_a_locked_step_is_halved_and_the_next_is_whole_again(monkeypatch):
    plain = np.diff([p.d for p in alma.push(_block(), steps=10).curve])
    asked = _locking(monkeypatch, at=4, times=2)
    curve = alma.push(_block(), steps=10)
    steps = np.diff([p.d for p in curve.curve])
    assert asked[3:6] == pytest.approx([plain[3], plain[3] / 2, plain[3] / 4], rel=1e-12)
    assert steps[3] == pytest.approx(plain[3] / 4, rel=1e-9) and steps[4] == pytest.approx(plain[3], rel=1e-9)
    assert curve.status == alma.Status.OPTIMAL and curve.end["reason"] == "alpha_zero"


def test_a_step_locked_down_to_the_probe_is_still_a_failure(monkeypatch):
    asked = _locking(monkeypatch, at=4, times=10**6)
    curve = alma.push(_block(), steps=10)
    assert curve.status == alma.Status.NOT_CONVERGED and curve.end["reason"] == "motion"
    length = float(np.sqrt(240.0 * 600.0))
    assert min(asked[3:]) >= alma.settings.PushSettings().probe * length > min(asked[3:]) / 2


def test_a_sliding_panel_that_turns_to_rocking_ends_at_a_proven_loss_of_equilibrium():
    curve = alma.push(paper_panel("running", "2:1", "2:1", 0.27), steps=20)
    classes = [p.mechanism_class for p in curve.curve]
    assert classes[0] == "sliding" and classes[-1] != "sliding"
    assert curve.curve[-1].d > 143.6  # where the corrector stopped over a whole step
    assert curve.status == alma.Status.OPTIMAL, curve.message
    assert curve.end["reason"] == "no_equilibrium"
