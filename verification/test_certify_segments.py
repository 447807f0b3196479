"""The course-segment energy cuts of the HiGHS certificate (``CertifySettings(segment_cuts=True)``,
``alma/certify/courses.py``), re-checked.

- The segments of a row of blocks on the ground are its runs of consecutive blocks, with the
  weights, bed joints and head points the cut's condition names.
- With the cuts, HiGHS proves the minimum found by enumerating every active set of a tiny scene
  (``verification/enumeration.py``: scipy ``linprog`` only, none of alma's certification code).
- On random rows of 2 to 4 blocks (hypothesis) the proven bound with the cuts equals the bound
  without them.
- Scenes with cohesion or ties get no segment (an open cohesive joint or a tie could carry part
  of a segment's weight).
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from enumeration import enumerated_minimum
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_certify import columns_on_ground_scene, side_by_side

import alma
from alma.associative.lp import solve_lp
from alma.certify.courses import course_segments
from alma.certify.milp import certify
from alma.mechanics.model import build_model
from alma.nonassociative.search import solve_nonassociative
from alma.settings import CertifySettings

CUTS = CertifySettings(segment_cuts=True)


def _inputs(scene: alma.Scene):
    model = build_model(scene)
    lp = solve_lp(model)
    sol = solve_nonassociative(model, lp.mechanism, lp.multipliers, effort="fast")
    best = sol.best.alpha if sol.best is not None else None
    return model, lp.alpha, [c.mechanism for c in sol.candidates] + [lp.mechanism], best


def _all_points(model) -> np.ndarray:
    return np.arange(2 * model.n_joints)


def test_segments_of_three_blocks_side_by_side():
    model = build_model(side_by_side(3, 1.0))
    segments = course_segments(model, _all_points(model))
    assert len(segments) == 6  # [0], [1], [2], [0, 1], [1, 2], [0, 1, 2]
    by_size = sorted(segments, key=lambda s: (s.bed_joints.size, s.bed_joints.min()))
    whole = by_size[-1]
    # The whole row: its three ground joints, its two heads closed (4 points), nothing to open.
    assert whole.bed_joints.size == 3 and whole.closed_points.size == 4 and whole.open_points.size == 0
    assert whole.weight == pytest.approx(3.0) and whole.friction == pytest.approx(1.0)  # 3 mean block weights
    singles = [s for s in segments if s.bed_joints.size == 1]
    # The middle block alone: both of its heads must open (4 points); an end block: one head.
    assert sorted(s.open_points.size for s in singles) == [2, 2, 4]
    assert all(s.closed_points.size == 0 and s.weight == pytest.approx(1.0) for s in singles)


def test_a_stack_gives_the_bottom_block_alone_with_the_upper_one_pressing():
    model = build_model(alma.Scene.from_dict(columns_on_ground_scene(0.6, [100.0], [[80.0, 120.0]])))
    segments = course_segments(model, _all_points(model))
    assert len(segments) == 1
    (seg,) = segments
    # The joint with the block above presses on the segment: no condition on it.
    assert seg.open_points.size == 0 and seg.closed_points.size == 0 and seg.bed_joints.size == 1


def test_no_segment_with_cohesion():
    scene = dataclasses.replace(side_by_side(3, 1.0), cohesion=1.0)
    model = build_model(scene)
    assert model.n_bounded > 0 and course_segments(model, _all_points(model)) == []


@pytest.mark.slow  # the enumeration of 1,728 active sets: ~10 s
def test_segment_cuts_prove_the_enumerated_minimum():
    model, alpha_lp, mechanisms, _ = _inputs(side_by_side(2, 1.0))
    cert = certify(model, alpha_lp, mechanisms, settings=CUTS)
    assert cert.status == "proven" and not cert.velocity_bound_active, cert
    exact = enumerated_minimum(model, cert.velocity_bound)
    assert cert.lower == pytest.approx(min(exact, alpha_lp), abs=1e-6), (cert, exact)


def test_segment_cuts_on_two_stacked_blocks_prove_the_enumerated_minimum():
    model, alpha_lp, mechanisms, _ = _inputs(
        alma.Scene.from_dict(columns_on_ground_scene(0.6, [100.0], [[80.0, 120.0]])))
    cert = certify(model, alpha_lp, mechanisms, settings=CUTS)
    assert cert.status == "proven" and not cert.velocity_bound_active, cert
    exact = enumerated_minimum(model, cert.velocity_bound)
    assert cert.lower == pytest.approx(min(exact, alpha_lp), abs=1e-6), (cert, exact)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(k=st.integers(2, 4), b=st.floats(0.5, 2.0), f=st.sampled_from([0.3, 0.6, 1.0]))
def test_segment_cuts_do_not_change_the_proven_bound(k, b, f):
    model, alpha_lp, mechanisms, best = _inputs(side_by_side(k, f, b=b))
    plain = certify(model, alpha_lp, mechanisms, alpha_best=best)
    cut = certify(model, alpha_lp, mechanisms, alpha_best=best, settings=CUTS)
    assert plain.status == cut.status == "proven", (plain, cut)
    assert cut.lower == pytest.approx(plain.lower, abs=1e-6)
