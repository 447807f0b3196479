"""The HTML report (issues 18, 36, ``--html``): one self-contained page that parses, says the
result in words, fits the structure in its SVG and has a legend entry for every mark it draws."""

from __future__ import annotations

import json
import math
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

import alma
from alma.cli import main
from alma.report.drawing import draw
from alma.report.html import write_html
from alma.report.numbers import NOT_PROVEN, interval, number
from alma.report.page import Frame, Header, build_page

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


class _Page(HTMLParser):
    """The page's mechanism SVGs (their attributes and marks), legends, data and visible text."""

    def __init__(self) -> None:
        super().__init__()
        self.svgs: list[dict] = []  # {"attrs", "marks": [(tag, attrs)], "legend": set}
        self.tags: list[tuple[str, dict]] = []
        self.data = ""
        self.text: list[str] = []
        self._svg = 0
        self._script = False
        self._data = False

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.tags.append((tag, attrs))
        if tag == "svg" and "mechanism" in attrs.get("class", ""):
            self.svgs.append({"attrs": attrs, "marks": [], "legend": set()})
            self._svg = 1
        elif self._svg and tag == "svg":
            self._svg += 1
        elif self._svg and "data-mark" in attrs:
            self.svgs[-1]["marks"].append((tag, attrs))
        elif tag == "li" and "data-mark" in attrs and self.svgs:
            self.svgs[-1]["legend"].add(attrs["data-mark"])
        self._script = tag in ("script", "style")
        self._data = tag == "script" and attrs.get("id") == "alma-data"

    def handle_endtag(self, tag):
        if tag == "svg" and self._svg:
            self._svg -= 1
        self._script = self._data = False

    def handle_data(self, data):
        if self._data:
            self.data += data
        elif not self._script:
            self.text.append(data)


def _parse(path) -> tuple[_Page, str]:
    text = Path(path).read_text(encoding="utf-8")
    page = _Page()
    page.feed(text)
    page.close()
    return page, text


def _single_block() -> alma.Scene:
    return alma.Scene(
        blocks=(
            alma.Block("ground", np.array([[-100, -50], [400, -50], [400, 0], [-100, 0]], float), fixed=True),
            alma.Block("b", np.array([[0, 0], [100, 0], [100, 400], [0, 400]], float)),
        ),
        friction=0.6,
    )


def _check_page(path, scene: alma.Scene) -> _Page:
    """What every page must hold: self-contained, no NaN or inf words, each SVG fitted to the
    structure with its aspect ratio, a legend entry for each mark class it draws."""
    page, text = _parse(path)
    assert page.svgs
    assert not re.search(r"""(src|href)\s*=\s*["']?\s*(https?:)?//""", text)  # no network
    assert not [a for t, a in page.tags if t == "script" and "src" in a]
    assert not [t for t, _ in page.tags if t == "link"]
    visible = " ".join(page.text)
    assert not re.search(r"\b(nan|inf|infinity)\b", visible, re.IGNORECASE), visible
    xy = np.concatenate([b.vertices for b in scene.blocks])
    low, high = xy.min(axis=0), xy.max(axis=0)
    size = float((high - low).max())
    for svg in page.svgs:
        x, y, w, h = map(float, svg["attrs"]["viewbox"].split())
        assert x <= low[0] and x + w >= high[0] and -y - h <= low[1] and -y >= high[1]  # y turned down
        margins = np.array([low[0] - x, x + w - high[0], low[1] - (-y - h), -y - high[1]])
        assert margins.max() < 0.45 * size, margins / size  # fitted: the structure fills its frame
        width, height = float(svg["attrs"]["width"]), float(svg["attrs"]["height"])
        assert width / height == pytest.approx(w / h, rel=0.01)  # the structure's aspect ratio
        used = {a["data-mark"] for _, a in svg["marks"]}
        assert used and used <= svg["legend"], used - svg["legend"]
    return page


def test_the_page_says_the_result_and_holds_the_scene(tmp_path):
    scene = _single_block()
    result = alma.solve(scene)
    page = _check_page(write_html(scene, result, tmp_path / "r.html"), scene)
    text = " ".join(page.text)
    assert len(page.svgs) == 1
    marks = page.svgs[0]["marks"]
    assert sum(a["data-mark"] in ("support", "block-moving", "block-rest") for _, a in marks) == len(scene.blocks)
    assert "α = 0.25 (proven)" in text and "rocking" in text and "1 of 1 block move" in text  # α = b / h
    assert "proven between" in text or "proven: 0.25" in text
    hinges = [a for _, a in marks if a["data-mark"] == "hinge"]
    assert len(hinges) == 1
    assert float(hinges[0]["cx"]) == pytest.approx(100.0) and float(hinges[0]["cy"]) == pytest.approx(0)
    assert "live" in {a["data-mark"] for _, a in marks}  # the live load's arrow
    data = json.loads(page.data)
    assert data["m0"]["u"][1] == pytest.approx(list(result.blocks[0].u))
    assert "block b: u = " in Path(tmp_path / "r.html").read_text() and "N = " in Path(tmp_path / "r.html").read_text()
    assert "hide-thrust" in next(a for t, a in page.tags if t == "body")["class"]  # thrust off by default
    assert any(t == "input" and a.get("id") == "thrust" and "checked" not in a for t, a in page.tags)


def test_the_carried_marks_are_drawn_displaced_as_the_png_draws_them(tmp_path):
    scene = _single_block()
    result = alma.solve(scene)
    page = _check_page(write_html(scene, result, tmp_path / "r.html"), scene)
    drawing = draw(scene, result)
    block = next(a for t, a in page.svgs[0]["marks"] if a["data-mark"] == "block-moving")
    _one, b, c, _d, e, f = map(float, re.findall(r"[-\d.e]+", block["transform"]))
    points = np.array([[float(v) for v in p.split(",")] for p in block["points"].split()])
    moved = np.column_stack([points[:, 0] + c * points[:, 1] + e, b * points[:, 0] + points[:, 1] + f])
    expected = drawing.placed(next(m for m in drawing.marks if m.cls == "block-moving")) * [1, -1]
    assert moved == pytest.approx(expected, abs=1e-6 * drawing.size)


def test_both_models_side_by_side_at_one_scale_through_the_command_line(tmp_path, capsys):
    out = tmp_path / "both.html"
    assert (
        main(
            [
                "panel",
                "--bond",
                "stack",
                "--panel-ratio",
                "2:1",
                "--block-ratio",
                "2:1",
                "--friction",
                "0.6",
                "--model",
                "both",
                "--effort",
                "fast",
                "--html",
                str(out),
                "--json",
            ]
        )
        == 0
    )
    result = json.loads(capsys.readouterr().out)
    scene = alma.paper_panel("stack", "2:1", "2:1", 0.6)
    page = _check_page(out, scene)
    assert len(page.svgs) == 2 and page.svgs[0]["attrs"]["viewbox"] == page.svgs[1]["attrs"]["viewbox"]
    assert set(json.loads(page.data)) == {"m0", "m1"}
    text = " ".join(page.text)
    assert "associative (Eq. 10)" in text and "non-associative (Eq. 9)" in text
    assert f"α = {number(result['associative']['alpha'])}" in text and f"α = {number(result['alpha'])}" in text
    assert "<details>" in out.read_text() and "@media print" in out.read_text()


def test_the_examples_pages_fit_and_explain_every_mark(tmp_path):
    for name in ("portal", "wall_with_window", "arch"):
        scene = alma.load_scene(EXAMPLES / f"{name}.json")
        page = _check_page(write_html(scene, alma.solve(scene), tmp_path / f"{name}.html"), scene)
        assert {"hinge", "crack", "support", "live"} <= {
            a["data-mark"] for _, a in page.svgs[0]["marks"]
        } or name == "wall_with_window"


def test_settle_and_tilt_write_pages(tmp_path, capsys):
    scene = alma.load_scene(EXAMPLES / "settlement.json")
    assert (
        main(
            [
                "settle",
                str(EXAMPLES / "settlement.json"),
                "--html",
                str(tmp_path / "s.html"),
                "--plot",
                str(tmp_path / "s.png"),
                "--json",
            ]
        )
        == 0
    )
    settled = json.loads(capsys.readouterr().out)
    page = _check_page(tmp_path / "s.html", scene)
    used = {a["data-mark"] for _, a in page.svgs[0]["marks"]}
    assert "settlement" in used and "live" not in used and "joint-separating" in used
    opened = sum(j["state"] != "rest" for j in settled["joints"])
    assert f"{opened} joints open" in " ".join(page.text)
    assert (tmp_path / "s.png").stat().st_size > 10_000
    portal = alma.load_scene(EXAMPLES / "portal.json")
    assert (
        main(
            [
                "tilt",
                str(EXAMPLES / "portal.json"),
                "--html",
                str(tmp_path / "t.html"),
                "--plot",
                str(tmp_path / "t.png"),
                "--json",
            ]
        )
        == 0
    )
    tilted = json.loads(capsys.readouterr().out)
    page = _check_page(tmp_path / "t.html", portal)
    used = {a["data-mark"] for _, a in page.svgs[0]["marks"]}
    assert "gravity" in used and "live" not in used and "hinge" in used
    assert f"θ_c = {number(tilted['angle_deg'])}°" in " ".join(page.text)
    assert (tmp_path / "t.png").stat().st_size > 10_000


def test_a_page_of_steps_shows_one_frame_at_a_time(tmp_path):
    scene = _single_block()
    result = alma.solve(scene)
    frames = [Frame(f"step {k}", draw(scene, result)) for k in range(3)]
    path = tmp_path / "steps.html"
    path.write_text(build_page("steps", Header("three steps"), frames, steps=True), encoding="utf-8")
    page = _check_page(path, scene)
    assert len(page.svgs) == 3 and any(t == "input" and a.get("id") == "step" and a["max"] == "2" for t, a in page.tags)


def test_numbers_read_as_words():
    assert number(math.nan) == number(-math.inf) == number(None) == NOT_PROVEN == "—"
    assert number(0.409706123) == "0.4097" and number(-1.5) == "−1.5"
    assert interval(0.4097061, 0.4097069) == "proven: 0.4097 (both bounds round to it)"
    assert interval(0.40971, 0.40989) == "proven between 0.4097 and 0.4099"  # rounded outwards
    assert interval(1.32787142e-23, 0.166666667) == "proven between 0 and 0.1667"  # solver round-off reads 0
    assert interval(-math.inf, 0.25) == "at most 0.25; no lower bound proven (—)"
    assert interval(0.6, 0.6) == "proven: 0.6 (both bounds round to it)"
    assert interval(12.7, 12.8, "°") == "proven between 12.7° and 12.8°"


def test_a_tilt_that_finds_no_equilibrium_still_writes_a_page_without_nan(tmp_path, capsys):
    data = {
        "name": "a leaning block",
        "blocks": [
            {"id": "g", "vertices": [[-500, -50], [500, -50], [500, 0], [-500, 0]], "fixed": True},
            {"id": "b", "vertices": [[0, 0], [100, 0], [400, 300], [300, 300]]},
        ],
    }
    (tmp_path / "lean.json").write_text(json.dumps(data))
    assert (
        main(
            [
                "tilt",
                str(tmp_path / "lean.json"),
                "--html",
                str(tmp_path / "t.html"),
                "--plot",
                str(tmp_path / "t.png"),
                "--json",
            ]
        )
        == 0
    )
    assert json.loads(capsys.readouterr().out)["status"] == "no_equilibrium"
    page = _check_page(tmp_path / "t.html", alma.Scene.from_dict(data))
    assert "No equilibrium" in " ".join(page.text) and NOT_PROVEN in " ".join(page.text)
    assert (tmp_path / "t.png").stat().st_size > 5_000
