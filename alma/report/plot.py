"""Pictures of collapse mechanisms: blocks in their displaced position, coloured by velocity."""
from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from alma.report.motion import Motion
from alma.report.overlays import THRUST_COLOUR, draw_macro_blocks, draw_settlements, draw_thrust, draw_ties
from alma.results.joint_table import JointTable
from alma.results.types import BlockMotion, Result
from alma.geometry.scene import Scene

STATE_COLOURS = {"rest": None, "hinging": "tab:orange", "sliding": "tab:red", "separating": "tab:blue"}


@dataclass(frozen=True, slots=True)
class PictureJoint:
    """What a picture needs of a joint: its state and its contact segment (mm)."""

    state: str
    start: tuple[float, float]
    end: tuple[float, float]


@dataclass(frozen=True, slots=True)
class MechanismPicture:
    """What :func:`plot_mechanism` draws of a result, small enough to keep for every panel of a study.

    Block motions, the joints that move (rest joints are not drawn), α, status, model and
    mechanism class.  A study keeps one per solved panel (``mechanisms/<key>.npz``), so its
    report draws the mechanisms that were computed instead of solving the panels again.
    """

    model: str
    status: str
    alpha: float
    mechanism_class: str
    blocks: tuple[BlockMotion, ...]
    joints: tuple[PictureJoint, ...]

    @classmethod
    def from_result(cls, result: "Result | MechanismPicture") -> "MechanismPicture":
        if isinstance(result, MechanismPicture):
            return result
        table = result.joints
        if isinstance(table, JointTable):  # columns: no JointResult is built
            moving = np.flatnonzero(table.state != "rest")
            joints = tuple(PictureJoint(str(s), tuple(a), tuple(b)) for s, a, b in zip(
                table.state[moving].tolist(), table.start[moving].tolist(), table.end[moving].tolist()))
        else:
            joints = tuple(PictureJoint(j.state, tuple(map(float, j.start)), tuple(map(float, j.end)))
                           for j in table if j.state != "rest")
        return cls(str(result.model), str(result.status), float(result.alpha), str(result.mechanism_class or ""),
                   tuple(result.blocks), joints)

    def save(self, path: str | Path) -> Path:
        """Write the picture as a compressed ``.npz`` (atomically: a temporary file renamed over it)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        segments = np.array([[*j.start, *j.end] for j in self.joints], dtype=float).reshape(-1, 4)
        handle, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".npz")
        try:
            with os.fdopen(handle, "wb") as fh:
                np.savez_compressed(
                    fh, model=self.model, status=self.status, alpha=self.alpha,
                    mechanism_class=self.mechanism_class,
                    block_ids=np.array([b.id for b in self.blocks], dtype=str),
                    motions=np.array([b.u for b in self.blocks], dtype=float).reshape(-1, 3),
                    joint_states=np.array([j.state for j in self.joints], dtype=str), segments=segments)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
        return path

    @classmethod
    def load(cls, path: str | Path) -> "MechanismPicture":
        with np.load(Path(path), allow_pickle=False) as data:
            blocks = tuple(BlockMotion(str(i), tuple(float(x) for x in u))
                           for i, u in zip(data["block_ids"], data["motions"]))
            joints = tuple(PictureJoint(str(state), (float(s[0]), float(s[1])), (float(s[2]), float(s[3])))
                           for state, s in zip(data["joint_states"], data["segments"]))
            return cls(str(data["model"]), str(data["status"]), float(data["alpha"]),
                       str(data["mechanism_class"]), blocks, joints)


def plot_mechanism(scene: Scene, result: "Result | MechanismPicture", path: str | Path, *, title: str | None = None,
                   displacement: float = 0.08, ax=None, macro_blocks: bool = True,
                   line_of_thrust: bool = True) -> Path:
    """Draw the mechanism of ``result`` on ``scene`` and save it as PNG.

    Blocks are drawn displaced by the collapse velocity field scaled so that
    the largest displacement is ``displacement`` × the scene size; face colour
    is the block's speed, joint segments are coloured by state; α is in the title.
    With ``macro_blocks`` (and a result that has them) the moving macro-blocks are outlined,
    the crack between them drawn as one line and their rotation centres marked
    (:func:`alma.report.overlays.draw_macro_blocks`).  With ``line_of_thrust`` each compressed
    joint's centre of pressure and line of action are drawn (:func:`alma.report.overlays.draw_thrust`).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PolyCollection

    path = Path(path)
    all_xy = np.concatenate([b.vertices for b in scene.blocks])
    size = float(np.ptp(all_xy, axis=0).max())
    motion = Motion.of(scene, result)
    speeds = motion.speeds(scene)
    peak = max(float(speeds.max()), 1e-300)
    scale = displacement * size / peak if result.status in ("optimal", "not_converged") else 0.0
    motion = motion.scaled(scale)
    polygons = motion.outlines(scene)
    colours = np.where([b.fixed for b in scene.blocks], np.nan, speeds / peak)

    own_figure = ax is None
    if own_figure:
        width = 7.0
        extent = np.ptp(all_xy, axis=0)
        fig, ax = plt.subplots(figsize=(width, max(3.0, min(12.0, width * extent[1] / max(extent[0], 1e-9)))))
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.75")  # fixed blocks in grey
    collection = PolyCollection(polygons, array=np.ma.masked_invalid(colours), cmap=cmap, edgecolors="k",
                                linewidths=0.3)
    collection.set_clim(0, 1)
    ax.add_collection(collection)
    lines, line_colours = [], []
    for joint in result.joints:
        colour = STATE_COLOURS.get(joint.state)
        if colour is None:
            continue
        lines.append(np.array([joint.start, joint.end]))
        line_colours.append(colour)
    if lines:
        drawn = bool(macro_blocks and getattr(result, "macro_blocks", ()))  # thinner under the crack
        ax.add_collection(LineCollection(lines, colors=line_colours, linewidths=0.6 if drawn else 1.2))
    if macro_blocks:
        draw_macro_blocks(ax, scene, result, motion, speeds / peak)
    if line_of_thrust:
        draw_thrust(ax, result, motion)
    draw_ties(ax, scene, result)
    draw_settlements(ax, scene)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    alpha_text = f"α = {result.alpha:.4f}" if np.isfinite(result.alpha) else f"status: {result.status}"
    ax.set_title((title + "\n" if title else "") + f"{alpha_text} ({result.model}, {result.mechanism_class})",
                 fontsize=10)
    if own_figure:
        _finish(fig, ax, collection, path, line_of_thrust)
    return path


def _finish(fig, ax, collection, path: Path, line_of_thrust: bool) -> None:
    """Colour bar, legend of joint states (and of the line of thrust), save and close."""
    import matplotlib.pyplot as plt

    fig.colorbar(collection, ax=ax, label="relative speed", shrink=0.7)
    handles = [plt.Line2D([], [], color=c, label=s) for s, c in STATE_COLOURS.items() if c]
    handles += [plt.Line2D([], [], color=THRUST_COLOUR, marker=".", label="line of thrust")] if line_of_thrust else []
    ax.legend(handles=handles, loc="upper left", fontsize=7, title="joints", title_fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def plot_side_by_side(scene: Scene, results: "list[Result | MechanismPicture] | tuple[Result | MechanismPicture, ...]", path: str | Path, *,
                      titles: "list[str | None] | None" = None, suptitle: str | None = None,
                      displacement: float = 0.08) -> Path:
    """Draw the mechanisms of several results of the same scene side by side and save a PNG.

    Typically the associative and the non-associative solution of one panel; each panel of
    the figure is :func:`plot_mechanism` (α, model and mechanism class in its title, after
    the optional entry of ``titles``), with one shared speed colour bar and joint legend.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    results = list(results)
    if not results:
        raise ValueError("no result to draw")
    titles = list(titles) if titles is not None else [None] * len(results)
    if len(titles) != len(results):
        raise ValueError(f"{len(titles)} titles for {len(results)} results")
    path = Path(path)
    all_xy = np.concatenate([b.vertices for b in scene.blocks])
    extent = np.ptp(all_xy, axis=0)
    width = 5.5
    height = max(3.0, min(10.0, width * extent[1] / max(extent[0], 1e-9)))
    fig, axes = plt.subplots(1, len(results), figsize=(width * len(results) + 1.2, height + 0.8),
                             squeeze=False)
    for ax, result, title in zip(axes[0], results, titles):
        plot_mechanism(scene, result, path, title=title, displacement=displacement, ax=ax)
    collection = axes[0][-1].collections[0] if axes[0][-1].collections else None
    if collection is not None:
        fig.colorbar(collection, ax=list(axes[0]), label="relative speed", shrink=0.7)
    handles = [plt.Line2D([], [], color=c, label=s) for s, c in STATE_COLOURS.items() if c]
    axes[0][0].legend(handles=handles, loc="upper left", fontsize=7, title="joints", title_fontsize=7)
    if suptitle:
        fig.suptitle(suptitle, fontsize=11)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path
