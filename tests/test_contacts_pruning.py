"""The candidate search of find_joints loses no joint: same output as trying every edge pair.

``find_joints`` prunes the edge pairs with a line-key hash and an interval join
(``_facing_candidates``) before applying its exact tests.  Here that pruning is replaced by all
pairs of facing edges (the brute-force reference) on random small scenes pushed to the
detection tolerances: rotations (including near the 0 ≡ π wrap of the line angle), far
translations, length scales 1e-3 to 1e4, tiny and huge blocks mixed, overlaps and gaps of a few
detection tolerances, edges tilted by a few angle tolerances.  The joints must be identical, bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from alma.geometry import contacts
from alma.geometry.contacts import find_joints
from alma.geometry.edges import CONTACT
from alma.geometry.scene import Block, Scene


def _all_pairs(angle, midpoint, length, band, plus, minus, angle_tol):
    p, q = np.meshgrid(np.arange(len(plus)), np.arange(len(minus)), indexing="ij")
    return p.ravel(), q.ravel()


def _brute_force(scene: Scene) -> contacts.Joints:
    pruned = contacts._facing_candidates
    contacts._facing_candidates = _all_pairs
    try:
        return find_joints(scene)
    finally:
        contacts._facing_candidates = pruned


def _random_scene(seed: int) -> Scene:
    """Courses of rectangles on a ground, then perturbed, rotated, scaled and translated."""
    rng = np.random.default_rng(seed)
    lref = 10.0 ** rng.uniform(-1, 3)
    spread = rng.choice([0.2, 1.0, 3.0])  # log10 spread of block sizes: 3 mixes tiny and huge
    polys = []
    y = 0.0
    x_prev = (0.0, 0.0)
    for _ in range(rng.integers(1, 5)):
        lengths = lref * 10.0 ** rng.uniform(-spread / 2, spread / 2, rng.integers(1, 7))
        height = lref * 10.0 ** rng.uniform(-spread / 2, spread / 2)
        x0 = x_prev[0] + rng.uniform(-0.5, 0.5) * max(x_prev[1], lengths.sum())
        x = x0
        for length in lengths:
            polys.append(np.array([[x, y], [x + length, y], [x + length, y + height], [x, y + height]]))
            x += length
        x_prev = (x0, x - x0)
        y += height
    xs = np.concatenate([p[:, 0] for p in polys])
    ground = np.array(
        [[xs.min() - lref, -lref], [xs.max() + lref, -lref], [xs.max() + lref, 0.0], [xs.min() - lref, 0.0]]
    )
    polys.insert(0, ground)
    tol = CONTACT.tolerance * lref  # about the contact tolerance (the median block is near lref)
    for k in range(1, len(polys)):  # perturbations at the scale of the detection tolerances
        kind = rng.integers(0, 5)
        p = polys[k]
        if kind == 1:  # a gap or an interpenetration of a few tolerances
            p[:, 1] += rng.choice([-1, 1]) * rng.uniform(0, 30) * tol
        elif kind == 2:  # a tilt of a few angle tolerances about the bottom-left corner
            t = rng.uniform(-3, 3) * tol / lref
            c, s = math.cos(t), math.sin(t)
            polys[k] = (p - p[0]) @ np.array([[c, -s], [s, c]]).T + p[0]
        elif kind == 3:  # slide so the end points meet within a few tolerances
            p[:, 0] += rng.choice([-1, 1]) * rng.uniform(0, 30) * tol
    theta = rng.choice(
        [
            0.0,
            rng.uniform(0, 2 * math.pi),
            math.pi / 2,
            math.pi,
            3 * math.pi / 2,
            math.pi / 2 + rng.uniform(-1e-9, 1e-9),
            rng.uniform(-1e-9, 1e-9),
        ]
    )
    c, s = math.cos(theta), math.sin(theta)
    scale = 10.0 ** rng.uniform(-3, 4) / lref
    shift = rng.uniform(-1, 1, 2) * 10.0 ** rng.uniform(0, 6) * lref * scale
    blocks = tuple(
        Block(id=f"b{k}", vertices=scale * p @ np.array([[c, -s], [s, c]]).T + shift, fixed=k == 0)
        for k, p in enumerate(polys)
    )
    return Scene(blocks=blocks)


@pytest.mark.parametrize("seed", range(300))
def test_same_joints_as_all_pairs(seed):
    scene = _random_scene(seed)
    fast, reference = find_joints(scene), _brute_force(scene)
    for field in ("block_a", "block_b", "start", "end", "normal", "warnings"):
        assert np.array_equal(getattr(fast, field), getattr(reference, field)), field


def test_wall_same_joints_as_all_pairs():
    """A small running-bond wall, whose ground edge spans every course (the case that was slow)."""
    import alma

    scene = alma.wall("running", 2400.0, 600.0, 240.0)
    fast, reference = find_joints(scene), _brute_force(scene)
    assert fast.count == reference.count > 0
    for field in ("block_a", "block_b", "start", "end", "normal", "warnings"):
        assert np.array_equal(getattr(fast, field), getattr(reference, field)), field


@pytest.mark.parametrize("seed", range(20))
def test_interval_join_matches_all_pairs(seed):
    """The interval join behind the pruning, on grouped intervals with many shared end points."""
    rng = np.random.default_rng(seed)
    nx, ny = rng.integers(0, 40, 2)
    gx, gy = rng.integers(0, 3, nx), rng.integers(0, 3, ny)
    lox, loy = rng.integers(0, 10, nx).astype(float), rng.integers(0, 10, ny).astype(float)
    hix, hiy = lox + rng.integers(0, 4, nx), loy + rng.integers(0, 4, ny)
    x, y = contacts._overlapping_intervals(gx, lox, hix, gy, loy, hiy)
    expected = {
        (a, b) for a in range(nx) for b in range(ny) if gx[a] == gy[b] and max(lox[a], loy[b]) <= min(hix[a], hiy[b])
    }
    assert sorted(zip(x.tolist(), y.tolist(), strict=True)) == sorted(expected)
