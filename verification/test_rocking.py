"""Macro-block rocking candidates (``alma.rocking``) and the search's ``rocking`` start.

Each candidate is a rigid rotation of a set of blocks about a support point; it must be a
mechanism of the non-associative model (no contact point interpenetrates), and its lifting
work bounds the α of any collapse state with that mechanism from below.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings, strategies as st

import alma
from alma.backends.linprog_backend import LPMethod
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import build_model
from alma.nonassociative.exact_states import exact_state, exact_state_by
from alma.nonassociative.rocking import rocking_candidates
from alma.nonassociative.starts import rocking_start

from helpers import assemblies, single_block_scene


def test_single_block_tips_over_its_toe():
    """A b × h block: one candidate that moves the live load, about its right toe, bound b/h."""
    model = build_model(single_block_scene(100.0, 400.0, 1.0))
    candidates = rocking_candidates(model, ContactPoints.from_model(model))
    assert len(candidates) == 1
    (candidate,) = candidates
    assert candidate.blocks == (0,) and candidate.rotation == -1.0
    pivot_mm = np.array(candidate.pivot) * model.length_scale + model.origin
    assert pivot_mm == pytest.approx([100.0, 0.0], abs=1e-9)
    assert candidate.lifting_bound == pytest.approx(100 / 400, rel=1e-12)


@given(data=assemblies(max_courses=3, max_per_course=4))
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_candidates_are_mechanisms_and_bound_their_states(data):
    """No interpenetration (ξ ≥ 0), f_Lᵀu = n_free, the bound is the lifting work, and a verified
    exact state of a candidate never lies below its bound (the dissipation f N |γ| is ≥ 0)."""
    model = build_model(alma.Scene.from_dict(data))
    points = ContactPoints.from_model(model)
    candidates = rocking_candidates(model, points)
    assume(candidates)
    for candidate in candidates:
        u = candidate.mechanism
        opening = points.normal.T @ u
        assert opening.min() >= -1e-9 * np.abs(u).max()
        assert model.live @ u == pytest.approx(model.n_free, rel=1e-12)
        assert candidate.lifting_bound == pytest.approx(-(model.dead @ u) / model.n_free, rel=1e-12, abs=1e-15)
        moving = np.flatnonzero(np.abs(u).reshape(-1, 3).max(axis=1) > 0)
        assert tuple(moving) == candidate.blocks
    bounds = [c.lifting_bound for c in candidates]
    assert bounds == sorted(bounds)
    state = exact_state(model, points, candidates[0].mechanism, "rocking", method=LPMethod.CLARABEL)
    if state is not None and state.verified:
        assert state.alpha >= candidates[0].lifting_bound - 1e-9


def test_corner_column_of_a_flemish_panel():
    """Flemish panel 1:1, blocks 1:1, f = 1 (780 blocks): the top-right header and the 3L/4 closer
    on it tip together off the stretcher beside them, sliding up its face with no normal force.
    α = Σ W (x_toe − x_G) / Σ W (y_G − y_toe) = (1800·15 + 2700·22.5) / (1800·30 + 2700·90) = 13/44,
    far below α_LP = 0.4853.  No other start found a verified state on this panel in the
    108-panel run of 2026-11-23; the associative LP cannot use this mechanism (its sliding face
    would have to open by f·|slip|)."""
    model = build_model(alma.paper_panel("flemish", "1:1", "1:1", 1.0))
    points = ContactPoints.from_model(model)
    first = rocking_candidates(model, points)[0]
    assert len(first.blocks) == 2 and first.lifting_bound == pytest.approx(13 / 44, rel=1e-12)
    state, tried = rocking_start(model, points, [], tries=1)
    assert tried == 1 and state is not None and state.verified
    assert state.alpha == pytest.approx(13 / 44, rel=1e-9)
    # Gilbert's exact states above `exact_ipm_points` contact points (4,520 here) take the same route.
    by_field = exact_state_by(LPMethod.CLARABEL, model, points, first.mechanism, "gilbert")
    assert by_field is not None and by_field.verified
    assert by_field.alpha == pytest.approx(13 / 44, rel=1e-9)


@given(data=assemblies(max_courses=3, max_per_course=4))
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_interior_fixed_set_lp_agrees_with_highs(data):
    """The smallest α with a fixed active set: Clarabel through the kinematic dual (used by the
    rocking start) and HiGHS's vertex of the static LP (every other exact state) agree, or both
    find no field."""
    from alma.nonassociative.states import active_set
    from alma.nonassociative.static_lps import LP_METHOD, fixed_set_static_interior, static_lp

    model = build_model(alma.Scene.from_dict(data))
    points = ContactPoints.from_model(model)
    candidates = rocking_candidates(model, points)
    assume(candidates)
    for candidate in candidates[:3]:
        open_points, slip_sign = active_set(model, points, candidate.mechanism)
        interior = fixed_set_static_interior(model, points, open_points, slip_sign)
        vertex = static_lp(model, points, open_points, slip_sign, method=LP_METHOD)
        assert (interior.status == "optimal") == (vertex.status == "optimal"), (interior.status, vertex.status)
        if vertex.status == "optimal":
            assert interior.alpha == pytest.approx(vertex.alpha, rel=1e-7, abs=1e-9)
            assert interior.alpha >= candidate.lifting_bound - 1e-9


def test_wedge_of_hundreds_of_blocks_on_a_running_panel():
    """Running bond, panel 1:2, blocks 2:1, f = 1 (600 blocks): a wedge of several hundred blocks
    above a stepped diagonal crack tips about a toe.  It is this panel's only verified state in
    60 s (the 108-panel runs of 2026-11-23; the macro-blocks were capped at 60 blocks before):
    its α equals the wedge's lifting work, the friction faces of the crack being unloaded, and
    lies below α_LP = 0.4277."""
    model = build_model(alma.paper_panel("running", "1:2", "2:1", 1.0))
    points = ContactPoints.from_model(model)
    lp = alma.solve(model, model="associative")
    state, tried = rocking_start(model, points, [], upper=lp.alpha)
    assert state is not None and state.verified and 1 <= tried <= 4
    wedge = [
        c for c in rocking_candidates(model, points)[:tried] if abs(c.lifting_bound - state.alpha) <= 1e-9 * state.alpha
    ]
    assert wedge and len(wedge[0].blocks) > 60
    assert state.alpha < lp.alpha - 0.05
    assert all(len(c.blocks) <= 60 for c in rocking_candidates(model, points, max_blocks=60))


def _closure_by_velocities(model, points, seed, pivot, omega, tolerance=1e-9):
    """Reference growth written on the contact points' velocities, not on the incidence offsets of
    ``alma.rocking``: turn the current set about the pivot, add every block on the other side of
    an interpenetrating point, repeat; None if a fixed block is pushed."""
    normal = points.normal.tocsr()
    members = {seed}
    while True:
        u = np.zeros(3 * model.n_free)
        index = np.array(sorted(members))
        arm = model.centroid[index] - np.asarray(pivot)
        u[3 * index], u[3 * index + 1], u[3 * index + 2] = -omega * arm[:, 1], omega * arm[:, 0], omega
        pushing = np.flatnonzero(normal.T @ u < -tolerance)
        if pushing.size == 0:
            return tuple(index.tolist())
        joint_of = points.joint[pushing]
        sides = np.concatenate(
            [model.free_index[model.joints.block_a[joint_of]], model.free_index[model.joints.block_b[joint_of]]]
        )
        if (sides < 0).any():
            return None
        members |= set(sides.tolist())


@given(data=assemblies(max_courses=3, max_per_course=4))
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_each_candidate_is_the_closure_grown_from_one_of_its_blocks(data):
    """Every macro-block equals the reference closure grown from one of its own blocks about its
    pivot: nothing is missing from it and nothing was added that was not pushed."""
    model = build_model(alma.Scene.from_dict(data))
    points = ContactPoints.from_model(model)
    candidates = rocking_candidates(model, points)
    assume(candidates)
    for candidate in candidates:
        grown = {
            _closure_by_velocities(model, points, b, candidate.pivot, candidate.rotation) for b in candidate.blocks
        }
        assert candidate.blocks in grown


@given(data=assemblies(max_courses=4, max_per_course=5), batch=st.integers(1, 7))
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_seeds_grown_in_batches_give_the_same_candidates(data, batch):
    """Growing all seeds together (dense tables, split in batches) changes nothing: the same
    candidates as with one seed per batch, in the same order."""
    import alma.nonassociative.rocking as rocking

    model = build_model(alma.Scene.from_dict(data))
    points = ContactPoints.from_model(model)
    default = rocking_candidates(model, points)
    saved = rocking._BATCH_ENTRIES
    try:
        rocking._BATCH_ENTRIES = batch * model.n_free
        batched = rocking_candidates(model, points)
        rocking._BATCH_ENTRIES = 1
        single = rocking_candidates(model, points)
    finally:
        rocking._BATCH_ENTRIES = saved
    for other in (batched, single):
        assert [(c.blocks, c.pivot, c.rotation, c.lifting_bound) for c in other] == [
            (c.blocks, c.pivot, c.rotation, c.lifting_bound) for c in default
        ]
