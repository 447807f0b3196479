"""A report to look at (issue 18, SPEC §3 ``--html``): one self-contained HTML page.

The scene and the mechanism in SVG; a slider for the displacement scale and a switch that
animates the mechanism; blocks coloured by speed and joints by state; the line of thrust (each
compressed joint's centre of pressure and the line of action of its resultant); hover details
(block id and velocities; joint N, T, M and state); the certified bounds, the message and the
timings; for ``model="both"`` the two mechanisms side by side.  No network: the page carries its
own script, style and data.
"""
from __future__ import annotations

import html
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from alma.geometry.scene import Scene
from alma.report.motion import Motion
from alma.report.overlays import THRUST_COLOUR, thrust, thrust_joints

STATE_COLOURS = {"rest": "#b0b0b0", "hinging": "#ff7f0e", "sliding": "#d62728", "separating": "#1f77b4"}
#: Initial largest displacement as a share of the scene size (the slider's starting point).
DISPLACEMENT = 0.08


def write_html(scene: Scene, result: Any, path: str | Path, *, title: str | None = None) -> Path:
    """Write the report of ``result`` (a result of :func:`alma.solve`, ``both`` included) on ``scene``.

    Lengths in mm, forces in kN, moments in kN·mm, as in the JSON of SPEC §3.
    """
    parts = ([("associative", result.associative), ("non-associative", result.nonassociative)]
             if hasattr(result, "associative") and hasattr(result, "nonassociative") else [(result.model, result)])
    title = title or scene.name or "alma"
    panels = "\n".join(_panel(scene, r, k, label) for k, (label, r) in enumerate(parts))
    data = {f"m{k}": _data(scene, r) for k, (_, r) in enumerate(parts)}
    page = _PAGE.format(title=html.escape(title), panels=panels, data=json.dumps(data, separators=(",", ":")).replace("<", "\\u003c"),
                        style=_STYLE, script=_SCRIPT, displacement=DISPLACEMENT,
                        thrust=THRUST_COLOUR, legend=_legend())
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(page, encoding="utf-8")
    return path


def _panel(scene: Scene, result: Any, k: int, label: str) -> str:
    """The heading, the numbers and the SVG of one result."""
    b = result.bounds
    alpha = f"{result.alpha:.6g}" if math.isfinite(result.alpha) else str(result.alpha)
    rows = [("model", label), ("status", str(result.status)), ("α", alpha),
            ("bounds", b.describe()),
            ("mechanism", f"{result.mechanism_class} ({len(result.macro_blocks)} macro-blocks)"),
            ("message", result.message)]
    rows += [(f"time: {key.removesuffix('_s')}", f"{value:.3f} s") for key, value in result.timings.items()]
    rows += [("warning", w) for w in result.warnings]
    table = "".join(f"<tr><th>{html.escape(a)}</th><td>{html.escape(str(v))}</td></tr>" for a, v in rows)
    return (f'<section class="panel"><h2>{html.escape(label)}: α = {html.escape(alpha)}</h2>'
            f'<table class="numbers">{table}</table>{_svg(scene, result, k)}</section>')


def _svg(scene: Scene, result: Any, k: int) -> str:
    """Blocks, joints and the line of thrust at rest; the script moves them."""
    xy = np.concatenate([b.vertices for b in scene.blocks])
    low, high = xy.min(axis=0), xy.max(axis=0)
    pad = 0.15 * float((high - low).max())
    box = f"{low[0] - pad:.6g} {-(high[1] + pad):.6g} {high[0] - low[0] + 2 * pad:.6g} {high[1] - low[1] + 2 * pad:.6g}"
    speeds = Motion.of(scene, result).speeds(scene)
    speed = speeds / speeds.max() if speeds.max() > 0 else speeds
    motion = {m.id: m.u for m in result.blocks}
    items = []
    for i, block in enumerate(scene.blocks):
        colour = "#c8c8c8" if block.fixed else _colour(speed[i])
        items.append(f'<polygon id="m{k}b{i}" class="block" fill="{colour}" points="{_points(block.vertices)}">'
                     f'<title>{html.escape(_block_text(block, motion))}</title></polygon>')
    for i, j in enumerate(result.joints):
        width = "0.6" if j.state == "rest" else "1.6"
        items.append(f'<line id="m{k}j{i}" class="joint {j.state}" stroke="{STATE_COLOURS.get(j.state, "#000")}" '
                     f'stroke-width="{width}" vector-effect="non-scaling-stroke" {_ends(j.start, j.end)}>'
                     f'<title>{html.escape(_joint_text(j))}</title></line>')
    for i, (point, *ends) in enumerate(zip(*thrust(result))):
        items.append(f'<g class="thrust"><line id="m{k}t{i}" stroke="{THRUST_COLOUR}" stroke-width="1.2" '
                     f'vector-effect="non-scaling-stroke" {_ends(*ends)}/><circle id="m{k}c{i}" '
                     f'r="{0.003 * pad / 0.15:.4g}" cx="{point[0]:.6g}" cy="{-point[1]:.6g}" fill="{THRUST_COLOUR}"/></g>')
    return (f'<svg id="m{k}" class="mechanism" viewBox="{box}" xmlns="http://www.w3.org/2000/svg">'
            + "".join(items) + "</svg>")


def _data(scene: Scene, result: Any) -> dict[str, Any]:
    """What the script needs to move the picture: vertices, centroids and motions of the blocks,
    the joints' ends and blocks, the thrust points' joints (mm; θ in rad)."""
    motion = {b.id: b.u for b in result.blocks}
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    blocks = [{"v": np.round(b.vertices, 6).tolist(), "c": np.round(b.centroid, 6).tolist(),
               "u": list(motion.get(b.id, (0.0, 0.0, 0.0))) if not b.fixed else [0.0, 0.0, 0.0]}
              for b in scene.blocks]
    joints = [{"a": index.get(j.blocks[0], -1), "b": index.get(j.blocks[1], -1),
               "s": list(j.start), "e": list(j.end)} for j in result.joints]
    centres = [{"j": i, "p": point.tolist(), "s": ends[0].tolist(), "e": ends[1].tolist()}
              for i, point, *ends in zip(thrust_joints(result).tolist(), *thrust(result))]
    return {"blocks": blocks, "joints": joints, "thrust": centres}


def _colour(share: float) -> str:
    from matplotlib import colormaps

    r, g, b, _ = colormaps["viridis"](float(np.clip(share, 0.0, 1.0)))
    return f"#{int(255 * r):02x}{int(255 * g):02x}{int(255 * b):02x}"


def _points(v: np.ndarray) -> str:
    return " ".join(f"{x:.6g},{-y:.6g}" for x, y in v)


def _ends(start, end) -> str:
    return f'x1="{start[0]:.6g}" y1="{-start[1]:.6g}" x2="{end[0]:.6g}" y2="{-end[1]:.6g}"'


def _block_text(block: Any, motion: dict[str, Any]) -> str:
    if block.fixed:
        return f"block {block.id} (fixed)"
    u = motion.get(block.id, (0.0, 0.0, 0.0))
    return f"block {block.id}: u = {u[0]:.4g} mm, v = {u[1]:.4g} mm, θ = {u[2]:.4g} rad"


def _joint_text(j: Any) -> str:
    return (f"joint {j.blocks[0]} | {j.blocks[1]} ({j.state}): N = {j.N:.4g} kN, T = {j.T:.4g} kN, "
            f"M = {j.M:.4g} kN·mm, slip {j.slip:.3g} mm, length {j.length:.4g} mm")


def _legend() -> str:
    swatches = "".join(f'<span class="swatch" style="background:{c}"></span>{s} ' for s, c in STATE_COLOURS.items())
    return swatches + f'<span class="swatch" style="background:{THRUST_COLOUR}"></span>line of thrust'


_STYLE = """body{font-family:sans-serif;margin:1em;color:#222}.panels{display:flex;flex-wrap:wrap;gap:2em}
.panel{flex:1 1 30em;min-width:24em}svg.mechanism{width:100%;height:70vh;border:1px solid #ccc;background:#fff}
.block{stroke:#333;stroke-width:0.3;vector-effect:non-scaling-stroke}.block:hover{stroke:#000;stroke-width:2}
.joint:hover{stroke-width:4}table.numbers{border-collapse:collapse;font-size:90%;margin-bottom:.5em}
table.numbers th{text-align:left;padding-right:1em;vertical-align:top}.swatch{display:inline-block;width:1em;
height:.6em;margin:0 .3em 0 1em}.controls{position:sticky;top:0;background:#fff;padding:.4em 0;z-index:1}"""

_SCRIPT = """const DATA=JSON.parse(document.getElementById('alma-data').textContent);
function moved(b,p,s){const dx=p[0]-b.c[0],dy=p[1]-b.c[1];return[p[0]+s*(b.u[0]-b.u[2]*dy),p[1]+s*(b.u[1]+b.u[2]*dx)];}
function peak(m){let v=0;for(const b of m.blocks)for(const p of b.v){const q=moved(b,p,1);v=Math.max(v,Math.hypot(q[0]-p[0],q[1]-p[1]));}return v;}
function size(m){let lo=[1e300,1e300],hi=[-1e300,-1e300];for(const b of m.blocks)for(const p of b.v){lo=[Math.min(lo[0],p[0]),Math.min(lo[1],p[1])];hi=[Math.max(hi[0],p[0]),Math.max(hi[1],p[1])];}return Math.max(hi[0]-lo[0],hi[1]-lo[1]);}
const SCALE={};for(const k in DATA){const p=peak(DATA[k]);SCALE[k]=p>0?size(DATA[k])/p:0;}
function mid(m,j,p,s){const zero=[0,0,0];const a=j.a>=0?m.blocks[j.a]:{c:p,u:zero},b=j.b>=0?m.blocks[j.b]:{c:p,u:zero};
const q=moved(a,p,s),r=moved(b,p,s);return[(q[0]+r[0])/2,(q[1]+r[1])/2];}
function draw(share){for(const k in DATA){const m=DATA[k],s=share*SCALE[k];
m.blocks.forEach((b,i)=>{document.getElementById(k+'b'+i).setAttribute('points',b.v.map(p=>{const q=moved(b,p,s);return q[0]+','+(-q[1]);}).join(' '));});
m.joints.forEach((j,i)=>{const e=document.getElementById(k+'j'+i),p=mid(m,j,j.s,s),q=mid(m,j,j.e,s);
e.setAttribute('x1',p[0]);e.setAttribute('y1',-p[1]);e.setAttribute('x2',q[0]);e.setAttribute('y2',-q[1]);});
m.thrust.forEach((t,i)=>{const j=m.joints[t.j],p=mid(m,j,t.s,s),q=mid(m,j,t.e,s),c=mid(m,j,t.p,s),e=document.getElementById(k+'t'+i),o=document.getElementById(k+'c'+i);
e.setAttribute('x1',p[0]);e.setAttribute('y1',-p[1]);e.setAttribute('x2',q[0]);e.setAttribute('y2',-q[1]);o.setAttribute('cx',c[0]);o.setAttribute('cy',-c[1]);});}
document.getElementById('share').textContent=share.toFixed(3);}
const slider=document.getElementById('scale');let t0=null;
function frame(t){if(!document.getElementById('animate').checked){t0=null;draw(+slider.value);return;}
if(t0===null)t0=t;draw(+slider.value*(0.5-0.5*Math.cos((t-t0)/600)));requestAnimationFrame(frame);}
slider.addEventListener('input',()=>draw(+slider.value));
document.getElementById('animate').addEventListener('change',()=>requestAnimationFrame(frame));
document.getElementById('thrust').addEventListener('change',e=>{for(const g of document.querySelectorAll('.thrust'))g.style.display=e.target.checked?'':'none';});
draw(+slider.value);"""

_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title} — alma</title><style>{style}</style></head>
<body><h1>{title}</h1>
<div class="controls">largest displacement <input type="range" id="scale" min="0" max="0.3" step="0.005"
value="{displacement}"> <span id="share"></span> × the scene size
<label><input type="checkbox" id="animate"> animate</label>
<label><input type="checkbox" id="thrust" checked> line of thrust</label>
<div>joints: {legend}</div></div>
<div class="panels">{panels}</div>
<p>Hover a block for its velocities, a joint for its forces (N compression &gt; 0, kN; M about the
joint's centre, kN·mm). Written by alma; no network needed.</p>
<script type="application/json" id="alma-data">{data}</script>
<script>{script}</script>
</body></html>
"""
