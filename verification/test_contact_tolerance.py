"""Imperfect drawings (issue 20): the contact tolerance snaps drawing noise, whatever the origin.

The contact tolerance is 1e-4 of the median √area of the free blocks (``alma.geometry.edges``):
a gap or an overlap below it is a joint (midway between the two edges), a gap up to 1e-2 of that
size is reported as a near miss, a deeper overlap is refused.  Perturbing every vertex by far
less than the tolerance must change neither the joints nor α beyond the order of the
perturbation; translating a drawing by 1e6 mm must change nothing.
"""

from __future__ import annotations

import numpy as np
import pytest

import alma
from alma.geometry.edges import CONTACT

from helpers import arch_dict

#: Relative change of α allowed for vertex noise of relative size ε: the collapse multiplier is a
#: Lipschitz function of the geometry, so |Δα| / α stays a small multiple of ε.
LIPSCHITZ = 100.0


def _scenes() -> dict[str, alma.Scene]:
    return {
        "running 2:1 4:1 f=0.6": alma.paper_panel("running", "2:1", "4:1", 0.6),
        "english 1:1 2:1 f=0.27": alma.paper_panel("english", "1:1", "2:1", 0.27),
        "flemish 2:1 1:1 f=1.0": alma.paper_panel("flemish", "2:1", "1:1", 1.0),
        "arch N=24 t/R=0.15": alma.Scene.from_dict(arch_dict(24, 150.0)),
        "running wall 2400x600": alma.wall("running", 2400.0, 600.0, 240.0),
    }


def _size(scene: alma.Scene) -> float:
    return float(np.median([np.sqrt(b.area) for b in scene.blocks if not b.fixed]))


def _perturbed(scene: alma.Scene, epsilon: float, seed: int) -> alma.Scene:
    """Every vertex of every block moved at random by up to ``epsilon`` × block size."""
    rng = np.random.default_rng(seed)
    data = scene.to_dict()
    size = _size(scene)
    for block in data["blocks"]:
        v = np.array(block["vertices"])
        block["vertices"] = (v + rng.uniform(-1, 1, v.shape) * epsilon * size).tolist()
    return alma.Scene.from_dict(data)


def _pairs(scene: alma.Scene) -> list[tuple[int, int]]:
    j = alma.find_joints(scene)
    return sorted(zip(j.block_a.tolist(), j.block_b.tolist(), strict=True))


@pytest.mark.parametrize("name", list(_scenes()))
@pytest.mark.parametrize("fraction", [1e-4, 1e-2, 0.3])
def test_vertex_noise_below_the_tolerance_keeps_joints_and_alpha(name, fraction):
    scene = _scenes()[name]
    epsilon = fraction * CONTACT.tolerance
    noisy = _perturbed(scene, epsilon, seed=7)
    assert _pairs(noisy) == _pairs(scene)
    assert alma.find_joints(noisy).warnings == ()
    a, b = alma.solve(scene), alma.solve(noisy)
    assert a.status == b.status == "optimal", b.message
    assert abs(b.alpha - a.alpha) <= LIPSCHITZ * epsilon * max(abs(a.alpha), 1.0), (a.alpha, b.alpha)


@pytest.mark.parametrize("epsilon", [1e-8, 1e-6, 3e-5])
def test_noise_on_a_pure_sliding_panel_is_certified(epsilon):
    """Every course of running 2:1 4:1 f = 0.6 slides at α = f: a fully degenerate optimal face.
    With noise on every vertex Clarabel may end 'AlmostSolved' with a pair that does not certify
    (static residual 2.5e-8 at ε = 1e-8); HiGHS's dual simplex then gives a vertex that does.
    Since vertices are snapped (alma.geometry.snap) the noise of 3e-5 is certified by Clarabel
    itself, 1e-8 and 1e-6 still through the simplex: either way the answer is proven."""
    noisy = _perturbed(_scenes()["running 2:1 4:1 f=0.6"], epsilon, seed=7)
    result = alma.solve(noisy)
    assert result.status == "optimal", result.message
    assert result.message.startswith("certified")
    assert result.alpha == pytest.approx(0.6, rel=LIPSCHITZ * epsilon)


@pytest.mark.parametrize("name", list(_scenes()))
def test_translation_by_1e6_mm_changes_nothing(name):
    scene = _scenes()[name]
    far = scene.transformed(np.eye(2), offset=(1e6, -1e6))
    far.validate()
    j0, j1 = alma.find_joints(scene), alma.find_joints(far)
    assert _pairs(far) == _pairs(scene)
    assert np.allclose(j1.start - [1e6, -1e6], j0.start, atol=1e-8)
    assert np.allclose(j1.end - [1e6, -1e6], j0.end, atol=1e-8)
    a, b = alma.solve(scene), alma.solve(far)
    assert b.status == a.status and b.alpha == pytest.approx(a.alpha, rel=1e-8)


def _hanging_node_scene(bump: float, offset: float = 0.0) -> alma.Scene:
    """A beam block (400 × 100 mm) on two piers, its bottom edge drawn with a hanging node at the
    piers' gap: the node raised by ``bump`` mm (LACT³'s wall.dxf has such nodes)."""
    o = offset
    return alma.Scene.from_dict(
        {
            "blocks": [
                {"id": "ground", "fixed": True, "vertices": [[o - 50, -50], [o + 450, -50], [o + 450, 0], [o - 50, 0]]},
                {"id": "left", "vertices": [[o, 0], [o + 200, 0], [o + 200, 300], [o, 300]]},
                {"id": "right", "vertices": [[o + 200, 0], [o + 400, 0], [o + 400, 300], [o + 200, 300]]},
                {"id": "beam", "vertices": [[o, 300], [o + 200, 300 + bump], [o + 400, 300], [o + 400, 400], [o, 400]]},
            ]
        }
    )


@pytest.mark.parametrize("offset", [0.0, 1e6])
@pytest.mark.parametrize("bump", [1e-9, 1e-7, 1e-5, 1e-3])
def test_a_bumped_hanging_node_keeps_its_joints(bump, offset):
    """Raising the hanging node by up to 1e-3 mm (CAD rounding) keeps both joints under the beam;
    1 km from the origin as well (before the tolerance was relative to the coordinates, 1e-7 mm
    here, and 1e-9 mm 1 km away, dropped them)."""
    exact, bumped = _hanging_node_scene(0.0, offset), _hanging_node_scene(bump, offset)
    assert _pairs(bumped) == _pairs(exact)
    assert alma.find_joints(bumped).count == alma.find_joints(exact).count == 5
    a, b = alma.solve(exact), alma.solve(bumped)
    assert a.status == b.status == "optimal"
    assert b.alpha == pytest.approx(a.alpha, rel=1e-4)


@pytest.mark.parametrize("lift", [1e-5, 1e-3])
def test_a_block_moved_by_drawing_noise_keeps_its_joints(lift):
    """A block of a wall moved up by drawing noise (the Ferris & Tin-Loi case: 1e-5 mm lost 4
    joints, 1e-3 mm was refused as an overlap) keeps all its joints and α."""
    scene = alma.wall("running", 2400.0, 600.0, 240.0)
    data = scene.to_dict()
    k = len(data["blocks"]) // 2
    data["blocks"][k]["vertices"] = (np.array(data["blocks"][k]["vertices"]) + np.array([0.0, lift])).tolist()
    moved = alma.Scene.from_dict(data)
    assert _pairs(moved) == _pairs(scene)
    assert alma.solve(moved).alpha == pytest.approx(alma.solve(scene).alpha, rel=1e-5)


def test_a_block_moved_beyond_the_tolerance_is_a_near_miss_or_an_overlap():
    scene = alma.wall("running", 2400.0, 600.0, 240.0)
    data = scene.to_dict()
    k = len(data["blocks"]) // 2
    block_id = data["blocks"][k]["id"]
    v = np.array(data["blocks"][k]["vertices"])
    data["blocks"][k]["vertices"] = (v + np.array([0.0, 0.2])).tolist()  # a 0.2 mm gap below, overlap above
    with pytest.raises(alma.SceneError, match=rf"'{block_id}'.*overlap|overlap.*'{block_id}'"):
        alma.Scene.from_dict(data)


def test_a_near_miss_is_a_warning_in_the_result_and_on_stderr(tmp_path, capsys):
    """A beam 0.2 mm above one pier: no joint there, and a warning naming the two blocks."""
    data = _hanging_node_scene(0.0).to_dict()
    data["blocks"][2]["vertices"] = [[200, 0], [400, 0], [400, 299.8], [200, 299.8]]
    scene = alma.Scene.from_dict(data)
    result = alma.solve(scene)
    assert len(result.warnings) == 1 and "'right' and 'beam' nearly touch" in result.warnings[0]
    assert result.to_dict()["warnings"] == list(result.warnings)
    path = tmp_path / "near.json"
    import json

    path.write_text(json.dumps(data))
    from alma.cli import main

    assert main(["solve", str(path), "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["warnings"] == list(result.warnings)
    assert "warning: blocks 'right' and 'beam' nearly touch" in err
    assert main(["solve", str(path), "--json", "--contact-tolerance", "0.01"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["warnings"] == [] and json.loads(out)["n_joints"] == 5


def test_an_overshooting_outline_is_refused_naming_the_block():
    """[a, b, c, d, a, b′] with b′ within 1e-12 of b (two voussoirs of LACT³'s arch are drawn so)
    was accepted and gave duplicate joints."""
    a, b, c, d = [0.0, 0.0], [100.0, 0.0], [100.0, 50.0], [0.0, 50.0]
    b2 = [100.0 + 1e-12, 1e-12]
    data = {
        "blocks": [
            {"id": "ground", "fixed": True, "vertices": [[-10, -10], [110, -10], [110, 0], [-10, 0]]},
            {"id": "v7", "vertices": [a, b, c, d, a, b2]},
        ]
    }
    with pytest.raises(alma.SceneError, match=r"'v7'.*(doubles back|self-intersecting|repeated)"):
        alma.Scene.from_dict(data)


def test_a_notched_fixed_base_is_accepted_and_a_non_convex_free_block_refused():
    """SPEC §2: a fixed block may be any simple polygon (a base with a seat for a block)."""
    base = [[-100, -100], [300, -100], [300, 0], [200, 0], [200, -20], [0, -20], [0, 0], [-100, 0]]
    block = [[0, -20], [200, -20], [200, 100], [0, 100]]
    scene = alma.Scene.from_dict(
        {"blocks": [{"id": "base", "fixed": True, "vertices": base}, {"id": "b", "vertices": block}]}
    )
    assert alma.find_joints(scene).count == 3  # the seat's floor and both of its walls
    assert alma.solve(scene).status == "no_collapse"  # the seat holds the block against sliding
    with pytest.raises(alma.SceneError, match=r"'b'.*not convex"):
        alma.Scene.from_dict(
            {
                "blocks": [
                    {"id": "base", "fixed": True, "vertices": block},
                    {"id": "b", "vertices": [[x, y + 120] for x, y in base]},
                ]
            }
        )
