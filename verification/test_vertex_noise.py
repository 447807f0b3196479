"""Drawings with independent noise on every vertex (issue 32): the contact tolerance's guarantee.

A CAD export or a digitised survey moves every vertex independently, so the copies of one corner
(one per block meeting there) disagree.  The contact tolerance ``tol`` (``alma.geometry.edges``:
1e-4 of the median √area of the free blocks) is read as the drawing's accuracy, and
``alma.geometry.snap`` makes that a promise: if every vertex lies within ``tol`` of where it is
meant to be (|noise| ≤ tol, Euclidean), alma finds the joints of the clean drawing.  Issue 32's
case — each coordinate moved by up to 0.6 tol, so two copies of a corner up to 1.7 tol apart —
gave ``no_equilibrium`` on 3 of 9 runs of a panel, an arch and a portal; it is inside the promise.

What is checked, and why each bound is what it is (no number here is tuned to pass):

- the same joints (block pairs) and no warning, for noise up to the guarantee;
- each joint end within ``2 δ`` of the clean one and each length within ``4 δ`` (δ the noise):
  a merged corner is the mean of copies each within δ of it; a T-junction's point is the
  projection of a point within δ of it on a line within δ of the clean line, hence within 2 δ;
- α (associative) within ``K δ / ℓ`` relative, ℓ the shortest joint of the clean drawing,
  K = 2 (4 + 4) + 4 (1 + f).  To first order, for the collapse mechanism, α is the ratio of the
  dead load's work to the live load's; each is a sum over blocks of a weight times a lever arm.
  A block's area changes by at most its perimeter × δ, i.e. by 2 δ (1/b + 1/h) ≤ 4 δ / ℓ
  relative; a lever arm (centroid to hinge, at least ℓ/2) by at most 2 δ, 4 δ / ℓ relative: 8 δ/ℓ
  per work, twice that for the ratio.  A joint's normal turns by at most 4 δ / l (ends moved by
  2 δ) and the dilatant sliding work turns with it, weighted by 1 + f: 4 (1 + f) δ / ℓ more;
- above the guarantee, never a silent other structure: the same joints and α within the bound,
  or a warning naming blocks, or a refusal naming a block.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.geometry.contacts import snapped_vertices
from alma.geometry.edges import CONTACT
from alma.geometry.snap import _on_their_edges

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _scenes() -> dict[str, alma.Scene]:
    return {
        "stack 2:1 2:1 f=0.6": alma.paper_panel("stack", "2:1", "2:1", 0.6),
        "running 2:1 4:1 f=0.27": alma.paper_panel("running", "2:1", "4:1", 0.27),
        "english 1:1 2:1 f=0.6": alma.paper_panel("english", "1:1", "2:1", 0.6),
        "arch": alma.load_scene(EXAMPLES / "arch.json"),
        "portal": alma.load_scene(EXAMPLES / "portal.json"),
        "wall with a window": alma.load_scene(EXAMPLES / "wall_with_window.json"),
    }


SCENES = _scenes()
SEEDS = (0, 1, 2)


def _tol(scene: alma.Scene) -> float:
    """The contact tolerance in mm (CONTACT.tolerance × the median √area of the free blocks)."""
    return CONTACT.tolerance * float(np.median([np.sqrt(b.area) for b in scene.blocks if not b.fixed]))


def _noisy(scene: alma.Scene, delta: float, seed: int, *, per_coordinate: bool = False) -> dict:
    """The scene with every vertex of every block moved independently: by a vector of length at
    most ``delta`` (uniform in the disc), or by up to ``delta`` in each coordinate."""
    rng = np.random.default_rng(seed)
    data = scene.to_dict()
    for block in data["blocks"]:
        v = np.array(block["vertices"], dtype=float)
        if per_coordinate:
            v = v + rng.uniform(-delta, delta, v.shape)
        else:
            r = delta * np.sqrt(rng.uniform(0.0, 1.0, len(v)))
            angle = rng.uniform(0.0, 2.0 * np.pi, len(v))
            v = v + np.column_stack([r * np.cos(angle), r * np.sin(angle)])
        block["vertices"] = v.tolist()
    return data


def _joints(scene: alma.Scene) -> tuple[list[tuple[int, int]], alma.Joints]:
    j = alma.find_joints(scene)
    return sorted(zip(j.block_a.tolist(), j.block_b.tolist(), strict=True)), j


def _alpha_bound(scene: alma.Scene, delta: float) -> float:
    """K δ / ℓ (module docstring): the relative change of α the noise δ may cause."""
    shortest = float(alma.find_joints(scene).length.min())
    return (2 * (4 + 4) + 4 * (1 + scene.friction)) * delta / shortest


def _same_joints(clean: alma.Scene, noisy: alma.Scene, delta: float) -> None:
    pairs0, j0 = _joints(clean)
    pairs1, j1 = _joints(noisy)
    assert pairs1 == pairs0
    assert j1.warnings == ()
    # Joints in one order: by pair, then by the clean joint's position (noise far below the
    # distance between two joints of one pair).
    o0 = np.lexsort((j0.centre[:, 1], j0.centre[:, 0], j0.block_b, j0.block_a))
    o1 = np.lexsort((j1.centre[:, 1], j1.centre[:, 0], j1.block_b, j1.block_a))
    ends0 = np.stack([j0.start[o0], j0.end[o0]], axis=1)
    ends1 = np.stack([j1.start[o1], j1.end[o1]], axis=1)
    same = np.hypot(*(ends1 - ends0).transpose(2, 0, 1)).max(axis=1)
    swapped = np.hypot(*(ends1[:, ::-1] - ends0).transpose(2, 0, 1)).max(axis=1)
    assert np.minimum(same, swapped).max() <= 2 * delta * (1 + 1e-9)
    assert np.abs(j1.length[o1] - j0.length[o0]).max() <= 4 * delta * (1 + 1e-9)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("name", ["english 1:1 2:1 f=0.6", "arch", "portal"])
def test_issue_32_noise_of_0_6_tol_per_coordinate_keeps_the_structure(name, seed):
    """The issue's case: each coordinate moved by up to 0.6 tol (|noise| up to 0.85 tol); it
    gave no_equilibrium on 3 of 9 runs (a joint lost, a block floating)."""
    clean = SCENES[name]
    noisy = alma.Scene.from_dict(_noisy(clean, 0.6 * _tol(clean), seed, per_coordinate=True))
    _same_joints(clean, noisy, 0.6 * np.sqrt(2) * _tol(clean))
    a, b = alma.solve(clean), alma.solve(noisy)
    assert a.status == b.status == "optimal", b.message
    assert b.warnings == ()


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("name", list(SCENES))
def test_noise_up_to_the_tolerance_gives_the_clean_joints_and_alpha(name, seed):
    """|noise| ≤ tol on every vertex: the clean joints (ends to 2 δ, lengths to 4 δ) and α to
    K δ / ℓ (module docstring)."""
    clean = SCENES[name]
    delta = _tol(clean)
    noisy = alma.Scene.from_dict(_noisy(clean, delta, seed))
    _same_joints(clean, noisy, delta)
    a, b = alma.solve(clean), alma.solve(noisy)
    assert a.status == b.status == "optimal", b.message
    assert abs(b.alpha - a.alpha) <= _alpha_bound(clean, delta) * abs(a.alpha), (a.alpha, b.alpha)


@pytest.mark.parametrize("factor", [1.5, 3.0])
@pytest.mark.parametrize("name", list(SCENES))
def test_noise_beyond_the_tolerance_is_the_same_structure_or_said(name, factor):
    """Above the guarantee: the clean joints and α, or a warning naming blocks, or a refusal
    naming a block — never another structure in silence."""
    clean = SCENES[name]
    delta = factor * _tol(clean)
    for seed in SEEDS:
        try:
            noisy = alma.Scene.from_dict(_noisy(clean, delta, seed))
        except alma.SceneError as exc:
            assert "block" in str(exc)
            continue
        pairs0, _ = _joints(clean)
        pairs1, j1 = _joints(noisy)
        result = alma.solve(noisy)
        if j1.warnings:
            assert result.warnings == j1.warnings and all("blocks" in w for w in result.warnings)
            continue
        assert pairs1 == pairs0
        a = alma.solve(clean)
        assert result.status == a.status
        assert abs(result.alpha - a.alpha) <= _alpha_bound(clean, delta) * abs(a.alpha), (a.alpha, result.alpha)


def _stack(middle: float) -> dict:
    """Three 100 mm blocks stacked on a ground, the middle one ``middle`` mm high."""

    def rect(y0: float, y1: float) -> list[list[float]]:
        return [[0.0, y0], [100.0, y0], [100.0, y1], [0.0, y1]]

    return {
        "blocks": [
            {"id": "ground", "fixed": True, "vertices": [[-50.0, -50.0], [150.0, -50.0], [150.0, 0.0], [-50.0, 0.0]]},
            {"id": "low", "vertices": rect(0.0, 100.0)},
            {"id": "thin", "vertices": rect(100.0, 100.0 + middle)},
            {"id": "high", "vertices": rect(100.0 + middle, 200.0 + middle)},
        ]
    }


def test_a_block_thinner_than_the_tolerance_is_refused_naming_it():
    """tol = 1e-4 × 100 mm = 0.01 mm: a 0.005 mm block is refused by the outline check (as
    before snapping); a 0.015 mm one would have its top and bottom merged through its
    neighbours' corners (1.5 tol apart, within 2 tol), and is refused naming it."""
    with pytest.raises(alma.SceneError, match=r"'thin'.*(degenerate|zero area|repeated)"):
        alma.Scene.from_dict(_stack(0.005))
    with pytest.raises(alma.SceneError, match=r"'thin': vertices .* would be merged into one point"):
        alma.Scene.from_dict(_stack(0.015))
    # 3 tol thick: nothing is merged across it; the block stands as drawn.
    scene = alma.Scene.from_dict(_stack(0.03))
    assert _joints(scene)[0] == [(0, 1), (1, 2), (2, 3)]
    assert all(len(v) == 4 for v in snapped_vertices(scene))


def _strip(height: float) -> dict:
    """A 100 × ``height`` mm strip on a ground, beside a 100 mm block (which sets tol = 0.01 mm)."""
    return {
        "blocks": [
            {"id": "ground", "fixed": True, "vertices": [[-50.0, -50.0], [350.0, -50.0], [350.0, 0.0], [-50.0, 0.0]]},
            {"id": "block", "vertices": [[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]]},
            {"id": "strip", "vertices": [[150.0, 0.0], [250.0, 0.0], [250.0, height], [150.0, height]]},
            {"id": "block2", "vertices": [[260.0, 0.0], [340.0, 0.0], [340.0, 100.0], [260.0, 100.0]]},
        ]
    }


def test_a_small_block_keeps_its_own_vertices():
    """A block's own vertices are never merged with each other, however close, nor put on an
    edge its own edge does not face: a strip 3 tol or 1.5 tol high on the ground keeps its four
    corners as drawn (its top corners lie within 2 tol of the ground's edge, which faces up as
    the strip's top does)."""
    for height in (0.03, 0.015):
        scene = alma.Scene.from_dict(_strip(height))
        assert np.array_equal(snapped_vertices(scene)[2], scene.blocks[2].vertices)
        assert _joints(scene)[0] == [(0, 1), (0, 2), (0, 3)]


def test_a_chain_of_merges_wider_than_the_guarantee_is_a_warning():
    """Four blocks meeting at one corner, their copies of it drawn 1.8 tol apart in a row (each
    within 2 tol of the next): one point, 2.7 tol from the first and last copies — beyond what
    noise of tol per vertex can do, so a warning names the blocks."""
    s = 1.8 * 0.01  # tol = 1e-4 × 100 mm
    a = [[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]]
    b = [[100.0, 0.0], [200.0, 0.0], [200.0, 100.0], [100.0 + s, 100.0]]
    c = [[100.0 + 2 * s, 100.0], [200.0, 100.0], [200.0, 200.0], [100.0, 200.0]]
    d = [[0.0, 100.0], [100.0 + 3 * s, 100.0], [100.0, 200.0], [0.0, 200.0]]
    data = {
        "blocks": [
            {"id": "ground", "fixed": True, "vertices": [[-50.0, -50.0], [250.0, -50.0], [250.0, 0.0], [-50.0, 0.0]]},
            {"id": "a", "vertices": a},
            {"id": "b", "vertices": b},
            {"id": "c", "vertices": c},
            {"id": "d", "vertices": d},
        ]
    }
    joints = alma.find_joints(alma.Scene.from_dict(data, validate=False))
    merged = [w for w in joints.warnings if "merged point" in w]
    assert len(merged) == 1, joints.warnings
    assert "'a'" in merged[0] and "'d'" in merged[0]


def _permuted(scene: alma.Scene, order: list[int], rolls: list[int]) -> alma.Scene:
    data = scene.to_dict()
    blocks = []
    for k, roll in zip(order, rolls, strict=True):
        block = dict(data["blocks"][k])
        block["vertices"] = np.roll(np.array(block["vertices"]), roll, axis=0).tolist()
        blocks.append(block)
    data["blocks"] = blocks
    return alma.Scene.from_dict(data)


_NOISY_ENGLISH = alma.Scene.from_dict(_noisy(SCENES["english 1:1 2:1 f=0.6"], _tol(SCENES["english 1:1 2:1 f=0.6"]), 5))


@settings(max_examples=5, deadline=None)
@given(st.randoms(use_true_random=False))
def test_block_and_vertex_order_do_not_change_the_snapped_scene(rnd):
    """The snapped points are the same, bit for bit, whatever the order of the blocks and the
    first vertex of each (means summed in lexicographic order, ties broken by position)."""
    scene = _NOISY_ENGLISH
    order = list(range(len(scene.blocks)))
    rnd.shuffle(order)
    rolls = [rnd.randrange(len(scene.blocks[k].vertices)) for k in order]
    shuffled = _permuted(scene, order, rolls)
    before = {b.id: v for b, v in zip(scene.blocks, snapped_vertices(scene), strict=True)}
    after = {b.id: v for b, v in zip(shuffled.blocks, snapped_vertices(shuffled), strict=True)}
    for block_id, v in before.items():
        w = after[block_id]
        assert np.array_equal(v[np.lexsort(v.T[::-1])], w[np.lexsort(w.T[::-1])]), block_id
    pairs0 = {tuple(sorted((scene.blocks[a].id, scene.blocks[b].id))) for a, b in _joints(scene)[0]}
    pairs1 = {tuple(sorted((shuffled.blocks[a].id, shuffled.blocks[b].id))) for a, b in _joints(shuffled)[0]}
    assert pairs1 == pairs0


def test_a_clean_drawing_is_not_moved():
    """Exact corners stay bit for bit: snapping changes nothing on the generators' drawings."""
    for name, scene in SCENES.items():
        for block, v in zip(scene.blocks, snapped_vertices(scene), strict=True):
            assert np.array_equal(v, block.vertices), (name, block.id)


def test_a_ring_of_t_junctions_is_put_on_its_edges_as_they_lie():
    """Three points each on the edge between the other two (a ring with no fixed corner): the
    system x_p = (1 − t) x_a + t x_b is singular (any common translation solves it), so each
    point goes to its foot on its edge as that edge lies — finite, never an exception."""
    centre = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]])
    p, a, b = np.array([0, 1, 2]), np.array([1, 2, 0]), np.array([2, 0, 1])
    t = np.full(3, 0.5)
    out = _on_their_edges(centre, p, a, b, t, radius=10.0)
    assert np.array_equal(out, 0.5 * centre[a] + 0.5 * centre[b])
