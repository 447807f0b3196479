"""The generators (``alma wall``, ``alma arch``; issue 18): walls with openings, arches, portals.

Checks: the semicircular arch built by ``alma.arch`` reproduces Milankovitch's minimum thickness
t/R → 0.1075 (as ``test_arch.py`` does with its own geometry); a wall without openings is the
paper's panel; openings, lintels and the overburden are where they are asked; every kind of
arch, on abutments or piers, is a valid scene that solves.
"""

from __future__ import annotations

import json

import pytest

import alma
from alma.cli import main

R = 1000.0
MILANKOVITCH = 0.1075


def _stands(ratio: float, n: int = 60) -> bool:
    scene = alma.arch(2 * R, R, ratio * R, n, friction=10.0)
    result = alma.solve(scene)
    return result.status == "no_collapse" or (result.status == "optimal" and result.alpha >= 0)


def test_semicircular_arch_minimum_thickness_through_the_generator():
    lo, hi = 0.09, 0.12
    assert not _stands(lo) and _stands(hi)
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _stands(mid) else (mid, hi)
    assert abs(hi - MILANKOVITCH) <= 1e-3, (lo, hi)


def test_a_wall_without_openings_is_the_papers_panel():
    panel = alma.paper_panel("flemish", "1:1", "2:1", 0.27)
    built = alma.wall("flemish", 1440.0, 1440.0, 120.0, friction=0.27)
    assert alma.solve(built).alpha == alma.solve(panel).alpha


def test_openings_lintels_and_overburden():
    scene = alma.facade(
        "running", 3600.0, 2400.0, 240.0, openings=[(600, 600, 960, 1200), (2160, 0, 720, 1800)], overburden_kpa=50.0
    )
    boxes = {b.id: (b.vertices.min(axis=0), b.vertices.max(axis=0)) for b in scene.blocks}
    for x, y, w, h in [(600, 600, 960, 1200), (2160, 0, 720, 1800)]:
        inside = [
            i
            for i, (lo, hi) in boxes.items()
            if i != "ground" and lo[0] < x + w - 1e-9 and hi[0] > x + 1e-9 and lo[1] < y + h - 1e-9 and hi[1] > y + 1e-9
        ]
        assert inside == [], inside  # the opening is empty
    lintels = sorted((lo[0], hi[0], lo[1]) for i, (lo, hi) in boxes.items() if i.startswith("lintel"))
    assert lintels == [(480.0, 1680.0, 1800.0), (2040.0, 3000.0, 1800.0)]
    total = sum(-load.dead[1] for load in scene.loads)
    assert total == pytest.approx(50.0 * 120.0 * 3600.0 * 1e-6)  # q t width, kN
    result = alma.solve(scene)
    assert (
        result.status == "optimal"
        and result.alpha
        > alma.solve(
            alma.facade("running", 3600.0, 2400.0, 240.0, openings=[(600, 600, 960, 1200), (2160, 0, 720, 1800)])
        ).alpha
    )


@pytest.mark.parametrize("kind,rise", [("semicircular", 1000.0), ("segmental", 600.0), ("pointed", 1400.0)])
@pytest.mark.parametrize("springing", ["fixed", "piers"])
def test_every_arch_is_a_valid_scene(kind, rise, springing):
    scene = alma.arch(
        2000.0, rise, 200.0, 20, kind=kind, springing=springing, pier_height=1500.0, pier_width=400.0, pier_courses=5
    )
    scene.validate()
    joints = alma.find_joints(scene)
    # every voussoir touches its two neighbours; the springings rest on their supports
    assert joints.count == 21 if springing == "fixed" else 31
    result = alma.solve(scene)
    assert result.status in ("optimal", "no_equilibrium")
    if kind != "segmental" or springing == "fixed":
        assert result.status == "optimal" and result.alpha > 0


@pytest.mark.parametrize(
    "bad,match",
    [
        ({"openings": [(600, 610, 960, 1200)]}, "course line"),
        ({"openings": [(-10, 0, 500, 600)]}, "inside the wall"),
        ({"openings": [(600, 600, 960, 1200), (1200, 600, 960, 600)]}, "overlap"),
    ],
)
def test_bad_openings_are_refused(bad, match):
    with pytest.raises(alma.SceneError, match=match):
        alma.facade("running", 3600.0, 2400.0, 240.0, **bad)


def test_cli_wall_and_arch_write_the_scene(tmp_path, capsys):
    out = tmp_path / "facade.json"
    assert (
        main(
            [
                "wall",
                "--bond",
                "running",
                "--width",
                "3600",
                "--height",
                "2400",
                "--block",
                "240x60",
                "--opening",
                "600,600,960,1200",
                "--overburden",
                "50",
                "--export-scene",
                str(out),
                "--json",
            ]
        )
        == 0
    )
    result = json.loads(capsys.readouterr().out)
    scene = alma.load_scene(out)
    assert result["status"] == "optimal" and result["alpha"] == pytest.approx(alma.solve(scene).alpha, rel=1e-12)
    out = tmp_path / "portal.dxf"
    assert (
        main(
            [
                "arch",
                "--span",
                "2000",
                "--rise",
                "1000",
                "--thickness",
                "200",
                "--voussoirs",
                "20",
                "--springing",
                "piers",
                "--pier-height",
                "1500",
                "--pier-width",
                "400",
                "--pier-courses",
                "5",
                "--export-scene",
                str(out),
                "--json",
            ]
        )
        == 0
    )
    alpha = json.loads(capsys.readouterr().out)["alpha"]
    back = alma.load_scene(out, thickness=120.0, friction=0.6)
    assert alma.solve(back).alpha == pytest.approx(alpha, rel=1e-9)
    assert main(["wall", "--bond", "running", "--width", "3600", "--height", "2400", "--block", "240", "--json"]) == 2
    capsys.readouterr()


def test_a_coursed_wall_laid_like_a_paper_panel_is_that_panel():
    from alma.geometry.panels import course_lengths

    courses = [list(course_lengths("english", 240.0, 1440.0, c) / 240.0) for c in range(1440 // 60)]
    built = alma.coursed_wall(courses, 240.0, 60.0, friction=0.6)
    panel = alma.paper_panel("english", "1:1", "4:1", 0.6)
    assert len(built.blocks) == len(panel.blocks)
    assert alma.solve(built).alpha == pytest.approx(alma.solve(panel).alpha, rel=1e-9)


def test_coursed_wall_gaps_are_openings():
    scene = alma.coursed_wall([[1, 1, 1], [0.5, 1, 1, 0.5], [1, -1, 1], [1, 1, 1]], 300.0, 100.0)
    assert len(scene.blocks) == 1 + 3 + 4 + 2 + 3
    right = next(b for b in scene.blocks if b.id == "c3b2")
    assert right.vertices[:, 0].min() == 600.0 and right.vertices[:, 1].min() == 200.0
    assert alma.solve(scene).status == "optimal"


@pytest.mark.parametrize(
    "courses, match",
    [([], "at least one course"), ([[1, 0, 1]], "course 1"), ([[1, 1], [1, float("nan")]], "course 2")],
)
def test_bad_courses_are_refused(courses, match):
    with pytest.raises(alma.SceneError, match=match):
        alma.coursed_wall(courses, 300.0, 100.0)


def test_cli_wall_from_a_courses_file(tmp_path, capsys):
    drawing = tmp_path / "wall.txt"
    drawing.write_text("# top course first\n1 1 1\n0.5, 1, 1, 0.5\n\n1 1 1\n")
    assert main(["wall", "--courses", str(drawing), "--block", "300x100", "--friction", "0.6", "--json"]) == 0
    alpha = json.loads(capsys.readouterr().out)["alpha"]
    api = alma.coursed_wall([[1, 1, 1], [0.5, 1, 1, 0.5], [1, 1, 1]], 300.0, 100.0, friction=0.6)
    assert alpha == pytest.approx(alma.solve(api).alpha, rel=1e-12)
    drawing.write_text("1 1 x\n")
    assert main(["wall", "--courses", str(drawing), "--block", "300x100", "--json"]) == 2
    assert "line 1" in capsys.readouterr().err
    assert main(["wall", "--width", "3000", "--block", "300x100"]) == 2
    assert "--bond" in capsys.readouterr().err
