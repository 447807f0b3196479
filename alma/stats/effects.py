"""Effects of the ANOVA's terms: standardized effects for the Pareto chart (Figure 7) and
Tukey's comparisons of the bonds (the paper's "Results and discussion")."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import scipy.stats
from statsmodels.stats.multicomp import pairwise_tukeyhsd

if TYPE_CHECKING:  # pragma: no cover
    from alma.stats.anova import AnovaResult


@dataclass(frozen=True)
class StandardizedEffect:
    """One bar of the Pareto chart of standardized effects (Figure 7)."""

    source: str
    dof: int
    effect: float
    p_value: float
    significant: bool


@dataclass(frozen=True)
class TukeyComparison:
    """One pairwise comparison of Tukey's HSD (family-wise confidence level 1 - alpha)."""

    group1: str
    group2: str
    mean_diff: float
    p_adj: float
    lower: float
    upper: float
    reject: bool


@dataclass(frozen=True)
class TukeyResult:
    """Tukey's simultaneous comparisons of the bond means (paper, Results and discussion)."""

    factor: str
    alpha: float
    means: tuple[tuple[str, float], ...]
    comparisons: tuple[TukeyComparison, ...]

    def significant_pairs(self) -> tuple[tuple[str, str], ...]:
        return tuple((c.group1, c.group2) for c in self.comparisons if c.reject)


def equivalent_t(p_value: float, dfe: int) -> float:
    """The |t| whose two-sided p-value with ``dfe`` DoF equals ``p_value``.

    Uses the inverse survival function: ``t.ppf(1 - p/2)`` would round 1 - p/2 to 1.0 for
    p below ~1e-16 and return inf.
    """
    if not 0.0 <= p_value <= 1.0:
        raise ValueError(f"p-value must lie in [0, 1] (got {p_value!r})")
    return float(scipy.stats.t.isf(p_value / 2.0, dfe))


def pareto_reference(dfe: int, alpha: float = 0.05) -> float:
    """Reference line of the Pareto chart: t_{1-alpha/2, DFE} (1.995 for DFE = 68)."""
    return float(scipy.stats.t.isf(alpha / 2.0, dfe))


def standardized_effects(result: AnovaResult, alpha: float = 0.05) -> tuple[StandardizedEffect, ...]:
    """Standardized effects of the model terms for the Pareto chart (Figure 7).

    One-DoF terms: |t| of the coefficient, which equals sqrt(F). Several-DoF terms: the t
    value with the same two-sided p-value as the term's F-test (Minitab's convention for
    categorical terms). Sorted by decreasing effect.
    """
    ref = pareto_reference(result.dfe, alpha)
    effects = []
    for r in result.terms:
        assert r.f_value is not None and r.p_value is not None
        if r.dof == 1:
            eff = math.sqrt(r.f_value)
        else:
            eff = equivalent_t(r.p_value, result.dfe)
        effects.append(StandardizedEffect(r.source, r.dof, eff, r.p_value, eff > ref))
    return tuple(sorted(effects, key=lambda e: e.effect, reverse=True))


# --------------------------------------------------------------------------------------------
# Tukey's multiple comparisons of the bond types (Results and discussion)
# --------------------------------------------------------------------------------------------


def tukey_bond(df: pd.DataFrame, response: str = "alpha_c", alpha: float = 0.05) -> TukeyResult:
    """Tukey's HSD pairwise comparisons of the mean response of the bond types.

    The paper finds stack differs from every other bond and running/english/flemish do not
    differ from one another.
    """
    for col in ("bond", response):
        if col not in df.columns:
            raise ValueError(f"missing column {col!r}")
    groups = df["bond"].astype(str).str.strip().str.lower().to_numpy()
    y = pd.to_numeric(df[response], errors="coerce").to_numpy(dtype=float)
    if not np.all(np.isfinite(y)):
        raise ValueError(f"column {response!r} has missing or non-finite values")
    hsd = pairwise_tukeyhsd(endog=y, groups=groups, alpha=alpha)
    g1, g2 = np.triu_indices(len(hsd.groupsunique), 1)
    names = [str(g) for g in hsd.groupsunique]
    comparisons = tuple(
        TukeyComparison(
            group1=names[i],
            group2=names[j],
            mean_diff=float(hsd.meandiffs[k]),
            p_adj=float(hsd.pvalues[k]),
            lower=float(hsd.confint[k, 0]),
            upper=float(hsd.confint[k, 1]),
            reject=bool(hsd.reject[k]),
        )
        for k, (i, j) in enumerate(zip(g1, g2, strict=True))
    )
    means = tuple((g, float(y[groups == g].mean())) for g in names)
    return TukeyResult(factor="bond", alpha=alpha, means=means, comparisons=comparisons)
