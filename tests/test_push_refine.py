"""The refinement of a capacity curve's end: a loss of equilibrium is bracketed by bisection,
one solve per halving (a secant's guard point only where α has a value on both sides)."""

from __future__ import annotations

import importlib
import math
from pathlib import Path

import alma

curve_module = importlib.import_module("alma.push.curve")
ROOT = Path(__file__).resolve().parents[1]


def test_a_loss_of_equilibrium_is_bracketed_by_one_solve_per_halving(monkeypatch):
    real, calls = curve_module._move, []

    def move(run, state, d):
        s = real(run, state, d)
        calls.append((state.d, d, s.alpha, run.push.d0_tolerance * run.length))
        return s

    monkeypatch.setattr(curve_module, "_move", move)
    curve = alma.push(alma.load_scene(ROOT / "examples" / "arch.json"), steps=20)
    assert curve.end["reason"] == "no_equilibrium"
    first = next(k for k, c in enumerate(calls) if not (math.isfinite(c[2]) and c[2] > 0))
    lo, hi, _, tol = calls[first]
    halvings = math.ceil(math.log2((hi - lo) / tol))
    refining = len(calls) - first - 1
    # with a guard beside each bisection point it took 28 solves for these 15 halvings
    assert refining <= halvings
    low, high = curve.end["bracket"]
    assert 0 < high - low <= tol
