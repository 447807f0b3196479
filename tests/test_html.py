"""The HTML report (issue 18, ``--html``): one self-contained page that parses and carries the
scene, the mechanism and the numbers."""
from __future__ import annotations

import json
import re
from html.parser import HTMLParser

import pytest

import alma
from alma.cli import main
from alma.report.html import write_html


class _Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict]] = []
        self.data: str | None = None
        self._in_data = False
        self.stack: list[str] = []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.tags.append((tag, attrs))
        self._in_data = tag == "script" and attrs.get("id") == "alma-data"

    def handle_data(self, data):
        if self._in_data:
            self.data = (self.data or "") + data

    def handle_endtag(self, tag):
        self._in_data = False


def _parse(path) -> tuple[_Page, str]:
    text = path.read_text(encoding="utf-8")
    page = _Page()
    page.feed(text)
    page.close()
    return page, text


def _single_block() -> alma.Scene:
    import numpy as np

    return alma.Scene(blocks=(
        alma.Block("ground", np.array([[-100, -50], [400, -50], [400, 0], [-100, 0]], float), fixed=True),
        alma.Block("b", np.array([[0, 0], [100, 0], [100, 400], [0, 400]], float))), friction=0.6)


def test_the_page_holds_the_svg_the_data_and_the_numbers(tmp_path):
    scene = _single_block()
    result = alma.solve(scene)
    page, text = _parse(write_html(scene, result, tmp_path / "r.html"))
    svgs = [a for t, a in page.tags if t == "svg"]
    assert len(svgs) == 1 and svgs[0]["viewbox"]
    assert sum(t == "polygon" for t, _ in page.tags) == len(scene.blocks)
    joints = [a for t, a in page.tags if t == "line" and "joint" in a.get("class", "")]
    assert len(joints) == len(result.joints) == 1 and "hinging" in joints[0]["class"]
    data = json.loads(page.data)
    assert [b["u"] for b in data["m0"]["blocks"]][1] == pytest.approx(list(result.blocks[0].u))
    assert f"{result.alpha:.6g}" in text and "0.25" in text  # α = b / h
    assert "block b: u = " in text and "N = " in text  # hover details
    thrust = data["m0"]["thrust"]
    assert len(thrust) == 1 and thrust[0]["p"] == pytest.approx([100.0, 0.0], abs=1e-6)  # all at the hinge
    assert not re.search(r"(src|href)=\"https?:", text)  # no network
    assert any(t == "input" and a.get("type") == "range" for t, a in page.tags)


def test_both_models_side_by_side_through_the_command_line(tmp_path, capsys):
    out = tmp_path / "both.html"
    assert main(["panel", "--bond", "stack", "--panel-ratio", "2:1", "--block-ratio", "2:1", "--friction", "0.6",
                 "--model", "both", "--effort", "fast", "--html", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    page, text = _parse(out)
    assert sum(t == "svg" for t, _ in page.tags) == 2
    assert set(json.loads(page.data)) == {"m0", "m1"}
    assert "associative: α = " in text and "non-associative: α = " in text
    assert f"{result['alpha']:.6g}" in text and f"{result['associative']['alpha']:.6g}" in text
