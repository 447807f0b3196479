"""The refinement of a capacity curve's end: a loss of equilibrium is bracketed by bisection,
one solve per halving (a secant's guard point only where α has a value on both sides), and
proven by a step from the bracket's low end."""

from __future__ import annotations

import dataclasses
import importlib
import itertools
import math
from pathlib import Path

import pytest

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
    refining = len(calls) - first - 2
    # with a guard beside each bisection point it took 28 solves for these 15 halvings
    assert refining <= halvings
    low, high = curve.end["bracket"]
    assert 0 < high - low <= tol
    # and one more: the loss is proven where a step from the bracket's low end goes
    assert calls[-1][:2] == (low, high) and not math.isfinite(calls[-1][2])
    assert curve.status == alma.Status.OPTIMAL and "low_end_step" not in curve.end


def test_a_refining_step_the_corrector_cannot_take_is_halved(monkeypatch):
    # running 2:1 2:1 f = 1 ended `not_converged` where its refinement's first point could not
    # be reached from the bracket's low end; a point halfway to it splits the bracket as well
    real = curve_module._move
    calls: list[tuple[float, float, bool, float]] = []
    lost: list[float] = []

    def move(run, lo, d):
        locked = bool(lost) and not any(c[2] for c in calls)
        calls.append((lo.d, d, locked, run.push.d0_tolerance * run.length))
        if locked:
            raise curve_module.MotionError("locked over this step")
        s = real(run, lo, d)
        lost.extend([] if math.isfinite(s.alpha) else [d])
        return s

    monkeypatch.setattr(curve_module, "_move", move)
    curve = alma.push(alma.load_scene(ROOT / "examples" / "arch.json"), steps=20)
    k = next(k for k, c in enumerate(calls) if c[2])
    (lo, target, _, tol), (lo_next, halfway, _, _) = calls[k], calls[k + 1]
    assert lo_next == lo and halfway - lo == pytest.approx((target - lo) / 2, rel=1e-12)
    assert curve.status == alma.Status.OPTIMAL and curve.end["reason"] == "no_equilibrium", curve.message
    low, high = curve.end["bracket"]
    assert 0 < high - low <= tol


def test_a_refining_point_whose_alpha_is_not_certified_is_replaced_by_one_nearer_the_low_end(monkeypatch):
    # examples/wall_with_window.json ended `not_converged` where an LP next to its loss of
    # equilibrium did not certify (Clarabel's gap 1.3e-8); a usable point halfway splits as well
    real_move, real_usable, real_refine = curve_module._move, curve_module._usable, curve_module._refine
    calls: list[tuple[float, float]] = []
    refining: list[bool] = []
    refused: list[float] = []

    def move(run, lo, d):
        calls.append((lo.d, d))
        return real_move(run, lo, d)

    def refine(run, lo, hi):
        refining.append(True)
        return real_refine(run, lo, hi)

    def usable(state):  # the refinement's first point is taken as not certified
        if refining and not refused:
            refused.append(state.d)
            return False
        return real_usable(state)

    monkeypatch.setattr(curve_module, "_move", move)
    monkeypatch.setattr(curve_module, "_refine", refine)
    monkeypatch.setattr(curve_module, "_usable", usable)
    curve = alma.push(alma.load_scene(ROOT / "examples" / "arch.json"), steps=20)
    k = next(k for k, c in enumerate(calls) if c[1] == refused[0])
    (lo, target), (lo_next, halfway) = calls[k], calls[k + 1]
    assert lo_next == lo and halfway - lo == pytest.approx((target - lo) / 2, rel=1e-12)
    assert curve.status == alma.Status.OPTIMAL and curve.end["reason"] == "no_equilibrium", curve.message


def test_a_loss_only_a_long_step_shows_is_passed_from_the_low_end(monkeypatch):
    # a long step's configuration can lose contacts that the curve's own short steps keep (it
    # follows an earlier mechanism): here every step longer than 0.15 d0 into the second half of
    # a rocking block's curve finds "no equilibrium".  The end is bisected, the step from its low
    # end finds equilibrium, and the curve goes on from there to the block's own d0 (before: it
    # ended `not_converged`, the loss "not proven on the curve's way")
    scene = alma.Scene.from_dict(
        {
            "thickness": 120,
            "unit_weight": 18,
            "friction": 0.8,
            "blocks": [
                {"id": "ground", "vertices": [[-1000, -100], [1000, -100], [1000, 0], [-1000, 0]], "fixed": True},
                {"id": "block", "vertices": [[0, 0], [200, 0], [200, 600], [0, 600]]},
            ],
        }
    )
    clean = alma.push(scene, steps=5)
    assert clean.status == alma.Status.OPTIMAL and clean.end["reason"] == "alpha_zero"
    real = curve_module._move
    faults: list[float] = []

    def move(run, state, d):
        s = real(run, state, d)
        if d - state.d > 0.15 * clean.d0 and d > 0.5 * clean.d0:
            faults.append(d)
            lost = dataclasses.replace(s.result, status=alma.Status.NO_EQUILIBRIUM, alpha=-math.inf)
            return dataclasses.replace(s, result=lost)
        return s

    monkeypatch.setattr(curve_module, "_move", move)
    curve = alma.push(scene, steps=5)
    assert len(faults) >= 2 and curve.end["reason"] == "alpha_zero", curve.message
    assert curve.status == alma.Status.OPTIMAL and curve.d0 == pytest.approx(
        clean.d0, abs=curve.d0_bracket[1] - curve.d0_bracket[0]
    )
    assert all(math.isfinite(p.alpha) for p in curve.curve)
    assert all(b.d > a.d for a, b in itertools.pairwise(curve.curve))


def test_a_refining_point_whose_mechanism_turns_the_control_back_ends_the_curve_there(monkeypatch):
    # measured on running 1:1 1:1 f = 0.6 (before contacts were measured on the displaced
    # geometry): the walk's step from 15.44 mm landed at 17.63 mm without equilibrium, and the
    # bisection's first point, 16.53 mm (α 0.2055), had a mechanism that moves the control block
    # backwards: the walk's own control end, not a failure of the refinement (before:
    # `not_converged`, "the bracket of the loss is not closed").  Here the arch's refining points
    # are made to have such a mechanism.
    real = curve_module._move
    refining: list = []
    lost: list[float] = []

    def move(run, state, d):
        if any(state is s for s in refining):
            raise curve_module.ControlLeft("control_reverses", "its mechanism moves the control block backwards")
        s = real(run, state, d)
        if not (math.isfinite(s.alpha) and s.alpha > 0):
            lost.append(d)
        elif lost:
            refining.append(s)
        return s

    monkeypatch.setattr(curve_module, "_move", move)
    curve = alma.push(alma.load_scene(ROOT / "examples" / "arch.json"), steps=20)
    assert lost and refining
    assert curve.status == alma.Status.OPTIMAL and curve.end["reason"] == "control_reverses", curve.message
    assert curve.end["d"] == curve.curve[-1].d == refining[0].d
    assert curve.end["alpha"] == curve.curve[-1].alpha > 0
