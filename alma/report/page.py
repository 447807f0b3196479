"""One self-contained HTML page of pictures (issue 36), for any command: a header that says the
result in words, a list of frames (an SVG each, with its caption and legend), the details folded
below.  Frames side by side (``--model both``) share one scale; ``steps=True`` shows one frame at
a time under a slider instead (a capacity curve's steps).  A print stylesheet puts one frame per
page, in vector graphics.  No network: the page carries its own style, script and data.
"""

from __future__ import annotations

import html
import json
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from alma.display_settings import PictureSettings
from alma.report.drawing import Drawing
from alma.report.svg import legend_html, render_svg


@dataclass(frozen=True)
class Header:
    """What the page says first: a headline and a few lines, in words; ``details`` (label, text)
    rows are folded below the pictures."""

    headline: str
    lines: tuple[str, ...] = ()
    details: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Frame:
    """One picture: its caption (words above it) and its drawing."""

    caption: str
    drawing: Drawing


def build_page(
    title: str,
    header: Header,
    frames: list[Frame] | tuple[Frame, ...],
    *,
    steps: bool = False,
    thrust: bool = False,
    settings: PictureSettings | None = None,
) -> str:
    """The page: ``header``, ``frames`` (side by side, or one at a time under a step slider with
    ``steps``), details folded.  The line of thrust is hidden unless ``thrust``; the page's
    switches move every frame's mechanism and show the line of thrust."""
    s = settings or PictureSettings()
    frames = list(frames)
    if not frames:
        raise ValueError("a page needs at least one frame")
    box = np.array([f.drawing.box for f in frames])
    union = (*box[:, :2].min(axis=0), *box[:, 2:].max(axis=0))  # one box: one scale, frames aligned
    four = (float(union[0]), float(union[1]), float(union[2]), float(union[3]))
    frames = [replace(f, drawing=replace(f.drawing, box=four)) for f in frames]
    figures = [
        f'<figure class="frame" id="f{k}"><figcaption>{html.escape(f.caption)}</figcaption>'
        f'{render_svg(f.drawing, f"m{k}")}<ul class="legend">{legend_html(f.drawing.classes())}</ul></figure>'
        for k, f in enumerate(frames)
    ]
    data = {f"m{k}": _motion_data(f.drawing, s) for k, f in enumerate(frames)}
    stepper = (
        (
            f'<label>step <input type="range" id="step" min="0" max="{len(frames) - 1}" step="1" value="0"> '
            f'<span id="step-text">1 / {len(frames)}</span></label>'
        )
        if steps and len(frames) > 1
        else ""
    )
    lines = "".join(f"<p>{html.escape(line)}</p>" for line in header.lines)
    rows = "".join(f"<tr><th>{html.escape(a)}</th><td>{html.escape(b)}</td></tr>" for a, b in header.details)
    return _PAGE.format(
        title=html.escape(title),
        headline=html.escape(header.headline),
        lines=lines,
        stepper=stepper,
        figures="".join(figures),
        details=rows,
        displacement=s.displacement,
        style=_STYLE,
        script=_SCRIPT,
        hidden="" if thrust else " hide-thrust",
        checked=" checked" if thrust else "",
        steps=" steps" if steps and len(frames) > 1 else "",
        data=json.dumps(data, separators=(",", ":")).replace("<", "\\u003c"),
    )


def _motion_data(drawing: Drawing, s: PictureSettings) -> dict[str, Any]:
    """What the script needs to move a frame: each block's motion (u, v in mm, θ in rad) and
    centroid (mm), and the displacement scale per unit of the slider's share."""
    m = drawing.motion
    return {"u": m.u.tolist(), "c": m.centroid.tolist(), "unit": m.scale / s.displacement if s.displacement else 0.0}


_STYLE = """body{font-family:system-ui,sans-serif;margin:1em 2em;color:#222;max-width:110em}
h1{font-size:1.3em;margin:.2em 0}.headline{font-size:1.6em;font-weight:600;margin:.3em 0}
.summary p{margin:.15em 0}.controls{position:sticky;top:0;background:#fffe;padding:.4em 0;z-index:1;font-size:90%;
border-bottom:1px solid #ddd}.controls label{margin-right:1.5em}
.frames{display:flex;gap:1.5em;align-items:flex-start;margin-top:.8em}.frames.steps .frame{display:none}
.frames.steps .frame.current{display:block}.frame{margin:0;flex:1 1 0;min-width:0}
figcaption{font-weight:600;margin-bottom:.3em;min-height:2.6em}svg.mechanism{width:100%;height:auto;max-height:70vh;display:block}
.hide-thrust .m-thrust{display:none}.legend{list-style:none;padding:0;margin:.4em 0;font-size:85%;columns:2 16em}
.legend li{margin:.1em 0;break-inside:avoid}.legend li[data-mark=thrust]{display:var(--thrust,list-item)}
.hide-thrust .legend li[data-mark=thrust]{display:none}svg.swatch{vertical-align:middle;margin-right:.4em}
details{margin-top:1em}table.details{border-collapse:collapse;font-size:90%}table.details th{text-align:left;
padding-right:1em;vertical-align:top;font-weight:500;color:#555}
@media print{.controls,details{display:none}body{margin:0}.frames{display:block}
.frame{display:block!important;page-break-after:always;break-after:page}.frame:last-child{page-break-after:auto}
svg.mechanism{max-height:22cm}}"""

_SCRIPT = """const DATA=JSON.parse(document.getElementById('alma-data').textContent);
function matrix(m,carrier,s){let b=0,e=0,f=0;for(const k of carrier){if(k<0)continue;const u=m.u[k],c=m.c[k],w=s*u[2];
b+=w;e+=s*u[0]+w*c[1];f+=s*u[1]-w*c[0];}const n=carrier.length;b/=n;e/=n;f/=n;
return 'matrix(1 '+(-b)+' '+b+' 1 '+e+' '+(-f)+')';}
const CARRIED={};for(const k in DATA){CARRIED[k]=[...document.querySelectorAll('#'+k+' [data-carrier]')].map(
el=>[el,el.getAttribute('data-carrier').split(',').map(Number)]);}
function draw(share){for(const k in DATA){const m=DATA[k],s=share*m.unit;for(const [el,c] of CARRIED[k])el.setAttribute('transform',matrix(m,c,s));}
document.getElementById('share').textContent=share.toFixed(3);}
const slider=document.getElementById('scale');let t0=null;
function frame(t){if(!document.getElementById('animate').checked){t0=null;draw(+slider.value);return;}
if(t0===null)t0=t;draw(+slider.value*(0.5-0.5*Math.cos((t-t0)/600)));requestAnimationFrame(frame);}
slider.addEventListener('input',()=>draw(+slider.value));
document.getElementById('animate').addEventListener('change',()=>requestAnimationFrame(frame));
document.getElementById('thrust').addEventListener('change',e=>document.body.classList.toggle('hide-thrust',!e.target.checked));
const step=document.getElementById('step');function show(i){document.querySelectorAll('.frame').forEach((f,k)=>f.classList.toggle('current',k===i));
if(step)document.getElementById('step-text').textContent=(i+1)+' / '+document.querySelectorAll('.frame').length;}
if(step){step.addEventListener('input',()=>show(+step.value));}show(0);draw(+slider.value);"""

_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width">
<title>{title} — alma</title><style>{style}</style></head>
<body class="page{hidden}"><h1>{title}</h1>
<div class="summary"><p class="headline">{headline}</p>{lines}</div>
<div class="controls">displacement <input type="range" id="scale" min="0" max="0.3" step="0.005"
value="{displacement}"> <span id="share"></span> × the structure's size
<label><input type="checkbox" id="animate"> animate</label>
<label><input type="checkbox" id="thrust"{checked}> line of thrust</label>{stepper}</div>
<div class="frames{steps}">{figures}</div>
<details><summary>details: bounds, message, timings</summary><table class="details">{details}</table>
<p>Hover a block for its motion, a joint for its forces (N compression &gt; 0, kN; M about the joint's
centre, kN·mm). The JSON output (<code>--json</code>) keeps every digit. Written by alma; no network needed.</p>
</details>
<script type="application/json" id="alma-data">{data}</script>
<script>{script}</script>
</body></html>
"""
