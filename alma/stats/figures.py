"""Figures 5 to 10 of the paper from the 108-panel results (Table 5).

Each function writes one PNG (matplotlib, Agg backend) and returns its path:

- :func:`main_effects_plot` — Figure 5, mean alpha_c at each level of each factor;
- :func:`interaction_plot_matrix` — Figure 6, two-way interaction means;
- :func:`pareto_chart` — Figure 7, standardized effects with the t reference line;
- :func:`residual_plots` — Figure 8, four-in-one standardized residual plots;
- :func:`scale_factor_plots` — Figures 9 and 10, mean alpha_c against H/b and B/b.
"""

from __future__ import annotations

from collections.abc import Sequence
from os import PathLike
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # files only, never a display

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import scipy.stats
from matplotlib.figure import Figure

from alma.stats.anova import BLOCK_LENGTH_MM, FACTORS, PANEL_HEIGHT_MM, PANEL_LENGTH_MM, AnovaResult, anova
from alma.stats.effects import pareto_reference, standardized_effects
from alma.stats.levels import level_label as _level_label, levels as _levels

__all__ = [
    "interaction_plot_matrix",
    "main_effects_overlay",
    "main_effects_plot",
    "pareto_chart",
    "residual_plots",
    "scale_factor_plots",
]

_LABELS = {"panel_ratio": "Panel ratio", "block_ratio": "Block ratio", "bond": "Bond type", "friction": "Friction"}
_RESPONSE_LABEL = r"mean $\langle\alpha_c\rangle$"
_DPI = 150


# --------------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------------


def _save(fig: Figure, path: str | PathLike[str]) -> Path:
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=_DPI, bbox_inches="tight")
    plt.close(fig)
    return out


def _normalized(df: pd.DataFrame, response: str) -> pd.DataFrame:
    """Copy with factor columns in canonical form (lower-case bond, float friction)."""
    need = [c for c, _ in FACTORS] + [response]
    missing = [c for c in need if c not in df.columns]
    if missing:
        raise ValueError(f"missing column {missing[0]!r}")
    out = df[need].copy()
    out["panel_ratio"] = out["panel_ratio"].astype(str).str.strip()
    out["block_ratio"] = out["block_ratio"].astype(str).str.strip()
    out["bond"] = out["bond"].astype(str).str.strip().str.lower()
    out["friction"] = pd.to_numeric(out["friction"]).astype(float).round(6)
    out[response] = pd.to_numeric(out[response]).astype(float)
    return out


def _means(df: pd.DataFrame, by: list[str], response: str) -> pd.Series:
    return df.groupby(by, sort=False)[response].mean()


# --------------------------------------------------------------------------------------------
# Figure 7: Pareto chart
# --------------------------------------------------------------------------------------------


def pareto_chart(result: AnovaResult, path: str | PathLike[str], alpha: float = 0.05) -> Path:
    """Pareto chart of the standardized effects (Figure 7) with the reference line
    t_{1-alpha/2, DFE} (1.995 for the paper's DFE = 68)."""
    effects = standardized_effects(result, alpha)
    ref = pareto_reference(result.dfe, alpha)
    names = [e.source for e in effects][::-1]  # largest on top
    values = [e.effect for e in effects][::-1]
    colors = ["tab:blue" if e.significant else "tab:gray" for e in effects][::-1]

    fig, ax = plt.subplots(figsize=(7.0, 0.45 * len(names) + 1.5))
    ax.barh(names, values, color=colors)
    ax.axvline(ref, color="tab:red", linestyle="--", linewidth=1.2)
    ax.text(ref, len(names) - 0.4, f" {ref:.3f}", color="tab:red", va="bottom", ha="left")
    ax.set_xlabel("Standardized effect")
    ax.set_ylabel("Term")
    ax.set_title(
        f"Pareto chart of the standardized effects\n(response {result.response}, "
        f"\u03b1 = {alpha:g}, DFE = {result.dfe})"
    )
    ax.grid(axis="x", alpha=0.3)
    return _save(fig, path)


# --------------------------------------------------------------------------------------------
# Figure 5: main effects
# --------------------------------------------------------------------------------------------


def main_effects_plot(
    df: pd.DataFrame,
    path: str | PathLike[str],
    response: str = "alpha_c",
    ylabel: str | None = None,
    title: str | None = None,
) -> Path:
    """Main effects plot (Figure 5): mean response at each level of each factor, the other
    factors averaged out (e.g. the 2:1 point is the mean of the 36 panels with ratio 2:1)."""
    return main_effects_overlay(
        df, path, {response: None}, ylabel=ylabel or _RESPONSE_LABEL, title=title or f"Main effects plot for {response}"
    )


def main_effects_overlay(
    df: pd.DataFrame,
    path: str | PathLike[str],
    responses: dict[str, str | None],
    ylabel: str = _RESPONSE_LABEL,
    title: str | None = None,
) -> Path:
    """Main effects of several responses of the same panels on shared axes (one line per
    response, labelled by the values of ``responses``; e.g. the associative and the
    non-associative α), each with its grand mean dashed."""
    if not responses:
        raise ValueError("no response to plot")
    frames = {r: _normalized(df, r) for r in responses}
    factors = [c for c, _ in FACTORS]
    fig, axes = plt.subplots(1, len(factors), figsize=(3.2 * len(factors), 3.6), sharey=True)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (response, label) in enumerate(responses.items()):
        data = frames[response]
        grand = float(data[response].mean())
        colour = colours[k % len(colours)]
        for ax, col in zip(axes, factors, strict=True):
            levels = _levels(data, col)
            means = _means(data, [col], response)
            ax.plot(
                range(len(levels)),
                [means[v] for v in levels],
                "o-",
                color=colour,
                label=label if col == factors[0] else None,
            )
            ax.axhline(grand, color=colour if len(responses) > 1 else "gray", linestyle="--", linewidth=0.8)
            ax.set_xticks(range(len(levels)), [_level_label(col, v) for v in levels])
            ax.set_xlim(-0.5, len(levels) - 0.5)
            ax.set_title(_LABELS[col])
            ax.grid(alpha=0.3)
    axes[0].set_ylabel(ylabel)
    if any(label for label in responses.values()):
        axes[0].legend(fontsize=8)
    fig.suptitle(title or "Main effects plot for " + ", ".join(responses))
    fig.tight_layout()
    return _save(fig, path)


# --------------------------------------------------------------------------------------------
# Figure 6: interaction plot matrix
# --------------------------------------------------------------------------------------------


def interaction_plot_matrix(df: pd.DataFrame, path: str | PathLike[str], response: str = "alpha_c") -> Path:
    """Two-way interaction plot matrix (Figure 6), Minitab layout: the cell in row i and
    column j (j > i) plots the mean response against the levels of factor j, one line per
    level of factor i; each point is the mean over the two other factors."""
    data = _normalized(df, response)
    factors = [c for c, _ in FACTORS]
    k = len(factors)
    fig, axes = plt.subplots(k - 1, k - 1, figsize=(3.4 * (k - 1), 3.0 * (k - 1)), sharey=True)
    axes = np.atleast_2d(axes)
    for r in range(k - 1):
        for c in range(k - 1):
            ax = axes[r, c]
            i, j = r, c + 1
            if j <= i:
                ax.set_axis_off()
                continue
            trace, xcol = factors[i], factors[j]
            xlev = _levels(data, xcol)
            means = _means(data, [trace, xcol], response)
            for tv in _levels(data, trace):
                ys = [means.get((tv, xv), np.nan) for xv in xlev]
                ax.plot(range(len(xlev)), ys, "o-", label=_level_label(trace, tv), markersize=4)
            ax.set_xticks(range(len(xlev)), [_level_label(xcol, v) for v in xlev])
            ax.set_xlim(-0.3, len(xlev) - 0.7)
            ax.grid(alpha=0.3)
            ax.set_title(f"{_LABELS[trace]} * {_LABELS[xcol]}", fontsize=9)
            ax.tick_params(labelleft=True)  # shared y, but cells stand apart in the triangle
            if c == r:  # first plotted cell of the row carries the trace legend
                ax.legend(title=_LABELS[trace], fontsize=7, title_fontsize=8)
                ax.set_ylabel(_RESPONSE_LABEL)
    fig.suptitle(f"Interaction plot for {response} (data means)")
    fig.tight_layout()
    return _save(fig, path)


# --------------------------------------------------------------------------------------------
# Figure 8: residual plots
# --------------------------------------------------------------------------------------------


def _fits_and_std_residuals(df: pd.DataFrame, result_or_model: Any, response: str) -> tuple[np.ndarray, np.ndarray]:
    if result_or_model is None:
        result_or_model = anova(df, response=response)
    if isinstance(result_or_model, AnovaResult):
        return np.asarray(result_or_model.fitted), np.asarray(result_or_model.std_residuals)
    # A statsmodels OLS results object (e.g. alma.stats.anova.fit_model).
    influence = result_or_model.get_influence()
    return (
        np.asarray(result_or_model.fittedvalues, dtype=float),
        np.asarray(influence.resid_studentized_internal, dtype=float),
    )


def residual_plots(
    df: pd.DataFrame, result_or_model: Any, path: str | PathLike[str], response: str = "alpha_c"
) -> Path:
    """Four-in-one residual plots of Figure 8 for the standardized residuals
    e_i / (S sqrt(1 - h_ii)): normal probability plot, versus fits, histogram and versus
    observation order (the row order of ``df``).

    ``result_or_model`` is an :class:`AnovaResult`, a statsmodels OLS result, or ``None``
    (the order-2 model of Table 2 is fitted).
    """
    fits, std = _fits_and_std_residuals(df, result_or_model, response)
    if len(std) != len(df):
        raise ValueError(f"model has {len(std)} residuals but the data frame {len(df)} rows")
    n = len(std)

    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    # Normal probability plot with Minitab's plotting positions (i - 3/8) / (n + 1/4).
    ax = axes[0, 0]
    order = np.sort(std)
    pos = (np.arange(1, n + 1) - 0.375) / (n + 0.25)
    z = scipy.stats.norm.ppf(pos)
    ax.plot(order, z, "o", markersize=3, color="tab:blue")
    mu, sd = float(np.mean(std)), float(np.std(std, ddof=1))
    xs = np.array([order[0], order[-1]])
    ax.plot(xs, (xs - mu) / sd, color="tab:red", linewidth=1)
    pct = np.array([0.1, 1, 5, 10, 20, 30, 50, 70, 80, 90, 95, 99, 99.9])
    ax.set_yticks(scipy.stats.norm.ppf(pct / 100.0), [f"{p:g}" for p in pct])
    ax.set_xlabel("Standardized residual")
    ax.set_ylabel("Percent")
    ax.set_title("Normal probability plot")
    ax.grid(alpha=0.3)

    ax = axes[0, 1]
    ax.plot(fits, std, "o", markersize=3, color="tab:blue")
    ax.axhline(0.0, color="gray", linewidth=0.8)
    ax.set_xlabel("Fitted value")
    ax.set_ylabel("Standardized residual")
    ax.set_title("Versus fits")
    ax.grid(alpha=0.3)

    ax = axes[1, 0]
    ax.hist(std, bins="auto", color="tab:blue", edgecolor="white")
    ax.set_xlabel("Standardized residual")
    ax.set_ylabel("Frequency")
    ax.set_title("Histogram")

    ax = axes[1, 1]
    ax.plot(np.arange(1, n + 1), std, "o-", markersize=3, linewidth=0.6, color="tab:blue")
    ax.axhline(0.0, color="gray", linewidth=0.8)
    ax.set_xlabel("Observation order")
    ax.set_ylabel("Standardized residual")
    ax.set_title("Versus order")
    ax.grid(alpha=0.3)

    fig.suptitle(f"Residual plots for {response}")
    fig.tight_layout()
    return _save(fig, path)


# --------------------------------------------------------------------------------------------
# Figures 9 and 10: scale factors
# --------------------------------------------------------------------------------------------


def _with_scale_factors(data: pd.DataFrame) -> pd.DataFrame:
    unknown = sorted(set(data["panel_ratio"]) - set(PANEL_HEIGHT_MM)) or sorted(
        set(data["block_ratio"]) - set(BLOCK_LENGTH_MM)
    )
    if unknown:
        raise ValueError(f"no panel/block dimensions for level {unknown[0]!r}")
    out = data.copy()
    b = out["block_ratio"].map(BLOCK_LENGTH_MM)
    out["H_over_b"] = out["panel_ratio"].map(PANEL_HEIGHT_MM) / b
    out["B_over_b"] = PANEL_LENGTH_MM / b
    return out


def _scale_axes(ax: Any, xs: Sequence[float]) -> None:
    ax.set_xscale("log", base=2)  # H/b doubles from level to level: 3, 6, 12, 24, 48
    ax.set_xticks(list(xs), [f"{x:g}" for x in xs])
    ax.minorticks_off()
    ax.grid(alpha=0.3)


def scale_factor_plots(
    df: pd.DataFrame,
    path_h: str | PathLike[str],
    path_b: str | PathLike[str],
    response: str = "alpha_c",
    bonds: Sequence[str] = ("running", "english", "flemish"),
) -> tuple[Path, Path]:
    """Figures 9 and 10: mean collapse multiplier against the scale factors.

    Figure 9: one panel per bond — running (left), english (centre), flemish (right), as in
    the paper — mean alpha_c against H/b, one line per friction; each point averages all
    panel/block-ratio combinations with that H/b (H = 720/1440/2880 mm, b = 240/120/60 mm,
    so H/b = 3 ... 48). Figure 10: one panel per panel ratio B/H = 2, 1, 0.5, mean alpha_c
    against B/b (B = 1440 mm: 6, 12, 24), one line per friction, averaged over the bonds.
    """
    data = _with_scale_factors(_normalized(df, response))
    frictions = _levels(data, "friction")
    bond_list = [b.lower() for b in bonds if b.lower() in set(data["bond"])]
    if not bond_list:
        raise ValueError(f"none of the bonds {list(bonds)} is in the data")

    # Figure 9: alpha vs H/b per bond, lines by friction.
    fig, axes = plt.subplots(1, len(bond_list), figsize=(4.2 * len(bond_list), 3.8), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, bond in zip(axes, bond_list, strict=True):
        sub = data[data["bond"] == bond]
        means = sub.groupby(["friction", "H_over_b"])[response].mean()
        xs = sorted(sub["H_over_b"].unique())
        for f in frictions:
            ys = [means.get((f, x), np.nan) for x in xs]
            ax.plot(xs, ys, "o-", label=f"f = {f:.2f}")
        _scale_axes(ax, xs)
        ax.set_xlabel("H/b")
        ax.set_title(bond.capitalize())
    axes[0].set_ylabel(_RESPONSE_LABEL)
    axes[-1].legend(title="friction")
    fig.suptitle(r"Mean collapse multiplier vs scale factor H/b")
    fig.tight_layout()
    out_h = _save(fig, path_h)

    # Figure 10: alpha vs B/b per panel ratio (B/H = 2, 1, 0.5), lines by friction.
    panels = _levels(data, "panel_ratio")
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.8), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, pr in zip(axes, panels, strict=True):
        sub = data[data["panel_ratio"] == pr]
        means = sub.groupby(["friction", "B_over_b"])[response].mean()
        xs = sorted(sub["B_over_b"].unique())
        for f in frictions:
            ys = [means.get((f, x), np.nan) for x in xs]
            ax.plot(xs, ys, "o-", label=f"f = {f:.2f}")
        _scale_axes(ax, xs)
        ax.set_xlabel("B/b")
        ax.set_title(f"Panel ratio B/H = {PANEL_LENGTH_MM / PANEL_HEIGHT_MM[pr]:g}")
    axes[0].set_ylabel(_RESPONSE_LABEL)
    axes[-1].legend(title="friction")
    fig.suptitle(r"Mean collapse multiplier vs scale factor B/b")
    fig.tight_layout()
    out_b = _save(fig, path_b)
    return out_h, out_b
