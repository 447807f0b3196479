"""Pictures of mechanisms (issues 19, 36): the drawing layer (rigid parts, the crack, hinges, the
line of thrust, loads, supports) and its PNG, the same picture as the HTML's SVG."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from hypothesis import given, settings, strategies as st
from matplotlib.collections import PolyCollection

import alma
from alma.report.drawing import draw
from alma.report.marks import LEGEND, MACRO_COLOURS, STATE_COLOURS
from alma.report.mpl import render_axes
from alma.report.plot import MechanismPicture, plot_mechanism


def _column(n: int = 3, shift: tuple[float, float] = (0.0, 0.0)) -> alma.Scene:
    """A column of ``n`` 100 × 300 mm blocks on the ground: it rocks as one macro-block about the
    ground's right corner (α = b / h of the whole column)."""
    dx, dy = shift

    def rect(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float) + np.array([dx, dy])

    blocks = [alma.Block("ground", rect(-200, -50, 300, 0), fixed=True)]
    blocks += [alma.Block(f"b{k}", rect(0, 300 * k, 100, 300 * (k + 1))) for k in range(n)]
    return alma.Scene(blocks=tuple(blocks), friction=2.0)


def test_a_rocking_column_is_one_outlined_part_with_a_hinge_on_the_crack():
    scene = _column()
    result = alma.solve(scene)
    assert abs(result.alpha - 100 / 900) < 1e-9 and len(result.macro_blocks) == 1
    drawing = draw(scene, result)
    cracks = [m for m in drawing.marks if m.cls == "crack"]
    assert len(cracks) == 1  # the base joint, one line
    segment = drawing.placed(cracks[0])
    hinge_end = segment[np.argmax(segment[:, 0])]
    assert np.allclose(hinge_end, (100.0, 0.0), atol=1e-6)  # drawn midway: fixed at the hinge
    assert segment[np.argmin(segment[:, 0]), 1] > 0  # and open at the heel
    hinges = [m for m in drawing.marks if m.cls == "hinge"]
    assert len(hinges) == 1 and np.allclose(drawing.placed(hinges[0]), [(100.0, 0.0)], atol=1e-6)
    outlines = [m for m in drawing.marks if m.cls == "macro"]
    assert len(outlines) == 1 and outlines[0].stroke in MACRO_COLOURS
    assert outlines[0].stroke not in STATE_COLOURS.values()  # its own colour, not a joint state's
    assert drawing.moving == 3
    assert {"support", "block-moving", "live", "crack", "macro", "hinge"} <= set(drawing.classes())
    assert set(drawing.classes()) <= set(LEGEND)


def test_macro_blocks_can_be_left_out_and_single_blocks_keep_no_outline():
    scene = _column(1)
    result = alma.solve(scene)
    assert not [m for m in draw(scene, result, macro_blocks=False).marks if m.cls in ("hinge", "centre", "macro")]
    marks = draw(scene, result).marks
    assert [m.cls for m in marks if m.cls in ("hinge", "centre", "macro")] == ["hinge"]


def test_the_line_of_thrust_passes_the_hinge_and_is_off_on_the_png_by_default(tmp_path):
    scene = _column(1)
    result = alma.solve(scene)
    drawing = draw(scene, result)
    centres = [m for m in drawing.marks if m.cls == "thrust" and m.kind == "point"]
    assert len(centres) == 1 and np.allclose(drawing.placed(centres[0]), [(100.0, 0.0)], atol=1e-6)
    fig, ax = plt.subplots()
    plot_mechanism(scene, result, tmp_path / "m.png", ax=ax)
    assert not [p for p in ax.patches if p.get_facecolor()[:3] == matplotlib.colors.to_rgb("#9400d3")]
    plt.close(fig)


def test_a_column_of_two_joints_per_block_gives_one_line_of_thrust():
    scene = _column(3)
    drawing = draw(scene, alma.solve(scene))
    segments = [drawing.placed(m) for m in drawing.marks if m.cls == "thrust" and m.kind == "line"]
    assert len(segments) == 2  # one per block with two compressed joints (the top block has one)
    ends = np.round(np.concatenate(segments), 6)
    _, counts = np.unique(ends, axis=0, return_counts=True)
    assert sorted(counts) == [1, 1, 2]  # joined end to end: one line from the ground up


def test_a_kept_picture_without_forces_draws_without_a_line_of_thrust():
    scene = _column(2)
    picture = MechanismPicture.from_result(alma.solve(scene))
    assert not [m for m in draw(scene, picture).marks if m.cls == "thrust"]


def test_the_png_draws_the_marks_where_the_drawing_places_them(tmp_path):
    scene = _column(2)
    drawing = draw(scene, alma.solve(scene))
    fig, ax = plt.subplots()
    render_axes(ax, drawing)
    polygons = [
        v[:-1] if len(v) > 4 else v
        for c in ax.collections
        if isinstance(c, PolyCollection)
        for p in c.get_paths()
        for v in [np.asarray(p.vertices)]  # matplotlib types vertices as ArrayLike
    ]
    blocks = [drawing.placed(m) for m in drawing.marks if m.cls.startswith("block-")]
    for b in blocks:
        assert any(len(p) >= len(b) and np.allclose(p[: len(b)], b) for p in polygons)
    assert ax.get_xlim() == drawing.box[::2] and ax.get_ylim() == drawing.box[1::2]
    plt.close(fig)
    assert plot_mechanism(scene, alma.solve(scene), tmp_path / "m.png").stat().st_size > 10_000


@settings(max_examples=8, deadline=None)
@given(st.floats(-5e4, 5e4), st.floats(-5e4, 5e4))
def test_the_picture_moves_with_the_origin(dx, dy):
    """One structure, one picture: moving the origin moves every mark and the box, nothing else."""
    here, there = draw(_column(2), alma.solve(_column(2))), draw(_column(2, (dx, dy)), alma.solve(_column(2, (dx, dy))))
    assert [m.cls for m in here.marks] == [m.cls for m in there.marks]
    size = here.size
    for a, b in zip(here.marks, there.marks, strict=True):
        assert np.allclose(here.placed(a) + np.array([dx, dy]), there.placed(b), atol=1e-6 * size)
    assert np.allclose(np.array(here.box) + np.array([dx, dy, dx, dy]), there.box, atol=1e-6 * size)


def test_a_crushing_joint_is_marked_and_has_its_legend_entry(tmp_path):
    """Another analysis may give a joint the state ``crushing`` (finite compressive strength):
    the picture draws it by name, a star at its middle, with its legend entry."""
    import dataclasses

    scene = _column(1)
    result = alma.solve(scene)
    joints = [dataclasses.replace(j, state="crushing") for j in result.joints]
    crushed = dataclasses.replace(result, joints=tuple(joints))
    drawing = draw(scene, crushed)
    stars = [m for m in drawing.marks if m.cls == "crushing" and m.kind == "point"]
    assert len(stars) == 1 and np.allclose(stars[0].xy, [(50.0, 0.0)])
    assert "crushing" in drawing.classes() and LEGEND["crushing"].label == "crushing joint"
    assert plot_mechanism(scene, crushed, tmp_path / "c.png").stat().st_size > 10_000


@settings(max_examples=5, deadline=None)
@given(st.permutations(range(17)))
def test_the_picture_does_not_depend_on_the_block_order(order):
    """The arch of examples/ with its blocks listed in any order: the same marks, colours included."""
    from pathlib import Path

    scene = alma.load_scene(Path(__file__).resolve().parents[1] / "examples" / "arch.json")
    assert len(scene.blocks) == 17
    shuffled = alma.Scene.from_dict({**scene.to_dict(), "blocks": [scene.to_dict()["blocks"][i] for i in order]})

    def marks(s):
        d = draw(s, alma.solve(s))
        return sorted(
            (m.cls, m.stroke or "", m.fill or "", tuple(np.round(np.sort(d.placed(m), axis=0), 3).ravel()))
            for m in d.marks
        )

    assert marks(scene) == marks(shuffled)


def test_an_overburden_and_a_chain_are_drawn_with_their_legend_entries():
    """The overburden of ``alma wall`` (a row of dead point loads on the top course) as arrows
    pointing down at the wall's top, one label with their total; a chain as a tie with its force."""
    from alma.geometry.chains import with_chain

    scene = with_chain(alma.wall("running", 1440.0, 600.0, 240.0, 60.0, overburden_kpa=10.0), 570.0, 1.0)
    scene.validate()
    drawing = draw(scene, alma.solve(scene))
    top = max(float(b.vertices[:, 1].max()) for b in scene.blocks)
    heads = [m.xy for m in drawing.marks if m.cls == "dead" and m.kind == "polygon"]
    assert len(heads) == len(scene.loads) > 1
    assert all(abs(h[0, 1] - top) < 1e-6 and np.all(h[1:, 1] > top) for h in heads)  # tips on the top, pointing down
    labels = [m.text for m in drawing.marks if m.cls == "dead" and m.kind == "text"]
    total = sum(-ld.dead[1] for ld in scene.loads)
    assert len(labels) == 1 and f"total {total:.4g} kN" in labels[0]
    ties = [m for m in drawing.marks if m.cls == "tie"]
    assert {m.kind for m in ties} == {"line", "text"} and "kN of 1" in next(m for m in ties if m.kind == "text").text
    assert {"dead", "tie", "live"} <= set(drawing.classes())
