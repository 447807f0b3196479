"""Pictures of capacity curves: α(d) of ``alma.push``, a*(d*) of ``alma.seismic`` with the
demand, and the structure at chosen steps of the curve (its displaced geometry, drawn to scale)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from alma.geometry.scene import Scene
from alma.push import PushResult
from alma.push.motion import displaced
from alma.seismic import SeismicResult

#: The 2019 edition's names of the nonlinear check's ultimate displacement and displacement demand.
_NAMES_2019 = {"du_star": "d_SLV", "demand": "displacement_demand"}


def nonlinear_value(check: SeismicResult, key: str) -> float:
    """A number of the nonlinear check (``du_star``: the ultimate displacement, ``demand``: the
    displacement demand, both m, under either edition's name), NaN where it has none."""
    value = check.nonlinear.get(_NAMES_2019.get(key, key) if check.edition == "2019" else key)
    return float(value) if isinstance(value, (int, float)) else float("nan")


def linear_line(check: SeismicResult) -> float:
    """The spectral acceleration a₀* must reach for the linear check (m/s²): the 2009 demand, or
    the 2019 check's a_g S / q."""
    value = check.linear.get("a0_star_required", check.linear["demand"])
    return float(value) if isinstance(value, (int, float)) else float("nan")


def plot_capacity(
    scene: Scene,
    result: PushResult,
    path: str | Path,
    *,
    check: SeismicResult | None = None,
    title: str | None = None,
    snapshots: int = 3,
    abscissa: tuple[str, str, str] | None = None,
) -> Path:
    """Save a PNG: α(d) (mm), the configurations at ``snapshots`` steps from d = 0 to d₀, and with
    ``check`` the curve a*(d*) (m, m/s²) with a₀*, d_u*, the demand displacement and the linear
    demand.  ``abscissa``: (axis label, name of the root, unit) of another abscissa than the
    control block's displacement (the settlement capacity's s, s_u, mm or rad)."""
    label, root, unit = abscissa or (f"d: horizontal displacement of {result.control} [mm]", "d₀", "mm")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    panels = 3 if check is not None else 2
    fig, axes = plt.subplots(1, panels, figsize=(5.2 * panels, 4.4))
    d = np.array([p.d for p in result.curve])
    alpha = np.array([p.alpha for p in result.curve])
    ax = axes[0]
    ax.plot(d, alpha, "-", color="tab:blue", lw=1.5, label=f"α({label.split(':')[0]})")
    ax.plot(d, alpha, ".", color="tab:blue", ms=3)
    changed = np.array([p.mechanism_changed for p in result.curve], dtype=bool)
    if changed.any():
        ax.plot(d[changed], alpha[changed], "o", mfc="none", color="tab:red", label="mechanism changes")
    if np.isfinite(result.d0):
        ax.axvline(result.d0, color="0.4", ls=":", lw=1)
        ax.annotate(
            f"{root} = {result.d0:.4g} {unit}", (result.d0, 0), textcoords="offset points", xytext=(-70, 10), fontsize=8
        )
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel(label)
    ax.set_ylabel("α")
    ax.set_title(f"capacity curve ({result.model}, {result.status})", fontsize=10)
    ax.legend(fontsize=8)
    _snapshots(axes[1], scene, result, snapshots, label.split(":")[0], unit)
    if check is not None:
        _spectral(axes[2], check)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def _snapshots(ax, scene: Scene, result: PushResult, count: int, name: str = "d", unit: str = "mm") -> None:
    """Outlines of the structure at ``count`` points of the curve spread from d = 0 to d₀."""
    from matplotlib.collections import PolyCollection

    points = result.curve
    picks = sorted({int(round(k)) for k in np.linspace(0, len(points) - 1, max(count, 2))})
    colours = ["0.55", "tab:orange", "tab:red", "tab:purple", "tab:green"]
    for n, k in enumerate(picks):
        moved = displaced(scene, points[k].pose)
        polygons = [b.vertices for b in moved.blocks]
        fixed = [b.fixed for b in moved.blocks]
        face = ["0.8" if f else "none" for f in fixed]
        label = f"{name} = {points[k].d:.3g} {unit}, α = {points[k].alpha:.3g}"
        ax.add_collection(
            PolyCollection(polygons, facecolors=face, edgecolors=colours[n % len(colours)], linewidths=0.8, label=label)
        )
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title("displaced geometry (to scale)", fontsize=10)
    ax.legend(fontsize=7, loc="upper left")


def _spectral(ax, check: SeismicResult) -> None:
    """a*(d*) with the checks' quantities."""
    if not check.curve_star:
        return
    ds, a = np.array(check.curve_star).T
    ax.plot(ds * 1e3, a, "-", color="tab:blue", lw=1.5, label="a*(d*)")
    ax.axhline(
        linear_line(check), color="tab:red", ls="--", lw=1, label=f"linear check: a₀* ≥ {linear_line(check):.3g} m/s²"
    )
    ax.plot([0], [check.a0_star], "o", color="tab:blue", label=f"a₀* = {check.a0_star:.3g} m/s²")
    du, demand = nonlinear_value(check, "du_star"), nonlinear_value(check, "demand")
    if check.nonlinear and np.isfinite(du):
        name = "d_SLV" if check.edition == "2019" else "d_u*"
        ax.axvline(du * 1e3, color="tab:green", lw=1, label=f"{name} = {du * 1e3:.3g} mm")
        ax.axvline(demand * 1e3, color="tab:red", lw=1, label=f"demand Δ = {demand * 1e3:.3g} mm")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("d* [mm]")
    ax.set_ylabel("a* [m/s²]")
    si = check.linear["safety_index"]
    si2 = nonlinear_value(check, "safety_index")
    ax.set_title(f"kinematic check (Circolare {check.edition}): linear {si:.3g}, nonlinear {si2:.3g}", fontsize=10)
    ax.legend(fontsize=7)
