"""The blocks of a capacity curve do not pass through each other (alma.push.step, alma.push.landing).

Measured on the code before: Ferris & Tin-Loi's wall 3 pushed in 20 steps overlapped its blocks
by up to 1,130 contact tolerances (c4b1 and c5b1, a sliver 30 mm deep at d = 37.9 mm), and the
sliding running-bond panel at f = 0.27 pushed two bottom-course blocks 0.6 mm into each other at
its first main step.
"""

from __future__ import annotations

import importlib
import itertools

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.geometry.edges import contact_lengths, scene_edges
from alma.geometry.panels import paper_panel
from alma.push.motion import displaced
from alma.settings import PushSettings
from benchmarks.bench_friction import FRICTION, WALLS

landing = importlib.import_module("alma.push.landing")


def _growth(scene: alma.Scene, curve) -> float:
    """The largest growth of an overlap of the drawing over the curve's points, in contact tolerances."""
    snap = contact_lengths(scene, scene_edges(scene))[0]
    base = landing.overlap_depths(scene)
    return max(landing.grown(base, landing.overlap_depths(displaced(scene, p.pose))) for p in curve.curve) / snap


def test_ferris_and_tin_lois_wall_3_keeps_its_blocks_apart():
    wall = alma.coursed_wall(WALLS[3], 400.0, 175.0, friction=FRICTION, thickness=1000.0, unit_weight=10.0)
    curve = alma.push(wall, steps=20)
    assert _growth(wall, curve) <= 0.5
    assert curve.end["reason"] == "no_equilibrium", curve.message
    # measured: a step from the bracket's low end (34.1133 mm) keeps the contacts the longer step
    # dropped at the tolerance, so the loss is not proven on the curve's way
    assert "low_end_step" in curve.end and curve.status == alma.Status.NOT_CONVERGED
    assert len(curve.curve) >= 10 and curve.curve[-1].d > 10.0


def test_a_sliding_panel_follows_one_sliding_part_to_alpha_zero():
    # at α = f every part of the wall above a bed joint can slide, and the interior point returns
    # their blend: head joints opened past the tolerance and closed again, each re-contact landed
    # a step, and the curve ran out of steps at α = f (39 mm; 82 configurations).  The part that
    # moves the control block slides on at the regular step until its mechanism turns to rocking.
    panel = paper_panel("running", "2:1", "2:1", 0.27)
    curve = alma.push(panel, steps=20)
    assert _growth(panel, curve) <= 0.5
    assert curve.status == alma.Status.OPTIMAL and curve.end["reason"] == "alpha_zero", curve.message
    sliding = [p for p in curve.curve if p.mechanism_class == "sliding"]
    assert len(sliding) >= 5 and all(p.alpha == pytest.approx(0.27, abs=1e-9) for p in sliding)
    regular = PushSettings().flat_step * float(sum(b.area for b in panel.blocks if not b.fixed)) ** 0.5
    steps = [b.d - a.d for a, b in itertools.pairwise(sliding[1:])]
    assert steps and all(step == pytest.approx(regular, rel=1e-9) for step in steps)  # none landed
    assert curve.d0 > len(steps) * regular


def test_a_pair_already_in_contact_is_not_landed_again_at_every_step():
    # measured from the drawing, a pair a landing left 0.46 tolerances deep crossed half the
    # tolerance at the next motion along its contact: every later step landed within 1.2e-9 mm of
    # its start (179.2040524 mm) and the curve ended by the time limit.  Measured from the step's
    # start it moves on, to the loss of equilibrium just beyond, and stays within the tolerance.
    panel = paper_panel("english", "2:1", "4:1", 1.0)
    curve = alma.push(panel, steps=20)
    assert curve.end["reason"] == "no_equilibrium", curve.message
    assert "low_end_step" in curve.end and curve.status == alma.Status.NOT_CONVERGED  # as wall 3's
    assert curve.curve[-1].d > 179.205
    assert _growth(panel, curve) <= 1.0


@pytest.mark.parametrize("stalls", [False, True])
def test_the_landing_bisects_to_where_the_overlap_first_grows(stalls):
    # a corner meets a face at d = 3 and enters it at unit rate; a stand-in corrector that fails
    # past d = 3.8 counts as an overlap (the step is shortened)
    def growth_at(d: float) -> float | None:
        if stalls and d > 3.8:
            return None
        return max(0.0, d - 3.0)

    touch = landing.landing(growth_at, 0.0, 10.0, 1.0, 40)
    assert touch is not None and 3.125 < touch <= 3.5


def test_a_landing_that_never_moves_past_its_start_is_none():
    assert landing.landing(lambda d: 1.0, 0.0, 10.0, 1.0, 40) is None


@given(
    st.lists(st.tuples(st.integers(0, 6), st.integers(0, 6), st.sampled_from([0.0, 0.5, 1.0])), min_size=2, max_size=8),
    st.data(),
)
@settings(max_examples=40, deadline=None)
def test_overlaps_among_some_blocks_are_all_overlaps_with_one_of_them(squares, data):
    """A step's overlaps are measured only for the blocks it moves: every pair with one of them,
    at the depth the full search gives; pairs that only touch (a joint) have none."""
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    vertices = np.concatenate([corners * 2.0 + np.array([x, y]) + shift for x, y, shift in squares])
    owner = np.repeat(np.arange(len(squares)), 4)
    among = np.array(data.draw(st.lists(st.booleans(), min_size=len(squares), max_size=len(squares))))
    full = landing.depths(vertices, owner)
    some = landing.depths(vertices, owner, among)
    assert some == {pair: depth for pair, depth in full.items() if among[pair[0]] or among[pair[1]]}
    assert all(depth > 0 for depth in full.values())
