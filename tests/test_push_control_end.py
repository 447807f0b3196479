"""A capacity curve whose mechanism leaves the control block ends as a finding, not a failure;
a step the corrector cannot take is halved before the curve fails.

When the mechanism at a point of the curve leaves the control block still (or moves it
backwards), the structure collapses there, at that point's α, by a mechanism the control point
does not follow: the curve of d ends with α > 0 (``end.reason`` "control_still" or
"control_reverses"), its status is that of its points, and the seismic check reads the stop
as the bound of the ultimate displacement, as it reads a loss of equilibrium.
"""

from __future__ import annotations

import importlib
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import alma
from alma.geometry.panels import paper_panel
from alma.push.result import STOPPED_ENDS
from alma.seismic.check_2019 import d0_star_of

curve_module = importlib.import_module("alma.push.curve")  # alma.push is also the function's name

ROOT = Path(__file__).resolve().parents[1]
B, H = 240.0, 600.0


def _block() -> alma.Scene:
    return alma.Scene.from_dict(
        {
            "thickness": 120,
            "unit_weight": 18,
            "friction": 0.8,
            "blocks": [
                {"id": "ground", "vertices": [[-2000, -100], [3000, -100], [3000, 0], [-2000, 0]], "fixed": True},
                {"id": "b1", "vertices": [[0, 0], [B, 0], [B, H], [0, H]]},
            ],
        }
    )


@pytest.fixture
def fails_after(monkeypatch):
    """``_move`` that takes ``n`` real steps and then raises ``error`` ``times`` times (None: on every
    call after); returns the steps asked (mm)."""

    def install(n: int, error: Exception, times: int | None = None) -> list[float]:
        real, asked = curve_module._move, []

        def move(run, state, d):
            asked.append(d - state.d)
            if n < len(asked) and (times is None or len(asked) <= n + times):
                raise error
            return real(run, state, d)

        monkeypatch.setattr(curve_module, "_move", move)
        return asked

    return install


def _left(reason: str) -> Exception:
    return curve_module.ControlLeft(reason, f"its mechanism ({reason})")


@pytest.mark.parametrize("reason", ["control_still", "control_reverses"])
def test_the_curve_ends_at_the_last_point_with_its_own_status(fails_after, reason):
    fails_after(3, _left(reason))
    curve = alma.push(_block(), steps=10)
    last = curve.curve[-1]
    assert len(curve.curve) == 4 and last.alpha > 0
    assert curve.end["reason"] == reason and curve.end["d"] == last.d and curve.end["alpha"] == last.alpha
    # a finding of the analysis: every α certified, so the curve is optimal, not not_converged
    assert curve.status == alma.Status.OPTIMAL, curve.message
    assert math.isnan(curve.d0) and "d₀ is not defined" in curve.message and "certified" in curve.message
    assert curve.to_dict()["end"]["reason"] == reason


def test_the_seismic_check_reads_the_stop_as_the_ultimate_displacement_bound(fails_after):
    fails_after(3, _left("control_still"))
    curve = alma.push(_block(), steps=10)
    (d1, a1), (d2, a2) = [(p.d, p.alpha) for p in curve.curve[-2:]]
    d0_star, lost = d0_star_of(curve, 1.0)
    assert lost == pytest.approx(d2 * 1e-3, rel=1e-15)
    assert d0_star == pytest.approx((d2 + (d2 - d1) * a2 / (a1 - a2)) * 1e-3, rel=1e-12)
    site = tomllib.loads((ROOT / "examples" / "site.toml").read_text())
    checked = alma.seismic(_block(), site, curve=curve)
    assert checked.nonlinear["d0_extrapolated"] is True and math.isfinite(checked.nonlinear["safety_index"])


def test_a_failed_step_is_still_a_failure(fails_after):
    fails_after(2, curve_module.MotionError("the corrector stalled"))
    curve = alma.push(_block(), steps=10)
    assert curve.status == alma.Status.NOT_CONVERGED and curve.end["reason"] == "motion"
    assert "motion" not in STOPPED_ENDS


@pytest.mark.parametrize(
    ("panel", "control", "reason"),
    [
        (("stack", "2:1", "4:1", 1.0), "b19", "control_reverses"),
        (("english", "2:1", "4:1", 0.6), "b7", "control_still"),
    ],
)
def test_a_paper_panel_pushed_by_a_low_block_ends_where_its_mechanism_leaves_it(panel, control, reason):
    """Real structures, no stand-in: a paper panel whose control is a block low in its collapse
    mechanism. The mechanism changes along the curve until, at the last point, it moves that block
    backwards (the stack bond's upper courses slide on) or leaves it still."""
    curve = alma.push(paper_panel(*panel), control=control, steps=20)
    first = {b.id: b.u[0] for b in curve.first.blocks}
    assert curve.sense == 1.0 and first[control] > 0  # it moved forwards at d = 0
    last = curve.curve[-1]
    assert curve.end["reason"] == reason and curve.end["d"] == last.d > 0
    assert last.alpha > 0 and last.mechanism_changed
    assert curve.status == alma.Status.OPTIMAL, curve.message
    assert math.isnan(curve.d0)


def test_a_locked_step_is_halved_and_the_next_is_whole_again(fails_after):
    """A mechanism that turns from sliding to rocking can lock over a long step (the running-bond
    paper panels after 144–449 mm of sliding): the step is halved until the corrector moves."""
    plain = np.diff([p.d for p in alma.push(_block(), steps=10).curve])
    asked = fails_after(3, curve_module.MotionError("locked over this step"), times=2)
    curve = alma.push(_block(), steps=10)
    steps = np.diff([p.d for p in curve.curve])
    assert asked[3:6] == pytest.approx([plain[3], plain[3] / 2, plain[3] / 4], rel=1e-12)
    assert steps[3] == pytest.approx(plain[3] / 4, rel=1e-9) and steps[4] == pytest.approx(plain[3], rel=1e-9)
    assert curve.status == alma.Status.OPTIMAL and curve.end["reason"] == "alpha_zero"


def test_a_step_locked_down_to_the_probe_is_still_a_failure(fails_after):
    asked = fails_after(3, curve_module.MotionError("locked over this step"))
    curve = alma.push(_block(), steps=10)
    assert curve.status == alma.Status.NOT_CONVERGED and curve.end["reason"] == "motion"
    probe = alma.settings.PushSettings().probe * np.sqrt(B * H)
    assert min(asked[3:]) >= probe > min(asked[3:]) / 2
