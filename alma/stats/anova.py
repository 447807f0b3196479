"""ANOVA of the paper's full-factorial design of experiments (Appendix A, Table 2).

The study is a single-replicate general full factorial: panel ratio (3 levels) x block ratio
(3) x bond type (4) x friction (3) = 108 panels (paper, Table 1 and Appendix B, Table 5).
The paper fits main effects plus all two-way interactions with Minitab and pools the higher
order interactions into the error term (Appendix A, Table 4: DoF_Error = DoF_Total -
DoF_Model = 107 - 39 = 68).  A study with a retrofitting chain (``alma doe --design``, column
``chain``, strength in kN) has it as a fifth factor, ``Chain``, with its interactions like the
others'; results without it, or with a single chain level, give the four-factor table.

Everything here is plain data in, frozen dataclasses out; no plotting (see ``figures.py``).
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Iterable, Sequence
from os import PathLike
from typing import Any

import numpy as np
import pandas as pd
import scipy.stats
import statsmodels.formula.api as smf
from statsmodels.regression.linear_model import RegressionResultsWrapper
from statsmodels.stats.anova import anova_lm

from alma.geometry.panels import BLOCK_LENGTHS, FRICTIONS, PANEL_HEIGHTS, PANEL_LENGTH
from alma.stats.results import _GROUP_NAMES, AnovaResult, AnovaRow

__all__ = [
    "BLOCK_LENGTH_MM",
    "CHAIN_FACTOR",
    "FACTORS",
    "FACTOR_LEVELS",
    "PANEL_HEIGHT_MM",
    "PANEL_LENGTH_MM",
    "RESULT_COLUMNS",
    "AnovaResult",
    "AnovaRow",
    "anova",
    "fit_model",
    "load_results",
    "press_balanced",
    "press_from_leverage",
    "r2_pred_balanced",
    "varying_factors",
]

# CSV column -> source name used in Table 2, in the paper's order (Table 1: A, B, C, D).
FACTORS: tuple[tuple[str, str], ...] = (
    ("panel_ratio", "Panel"),
    ("block_ratio", "Block"),
    ("bond", "Bond"),
    ("friction", "Friction"),
)

# Levels of Table 1 (alma.geometry.panels), bonds in the order the paper's figures show them
# (used for validation and for plot axes).
FACTOR_LEVELS: dict[str, tuple[Any, ...]] = {
    "panel_ratio": tuple(PANEL_HEIGHTS),
    "block_ratio": tuple(BLOCK_LENGTHS),
    "bond": ("running", "flemish", "english", "stack"),
    "friction": FRICTIONS,
}

#: The factor a design file may add (a chain across the top course, kN): not one of Table 1.
CHAIN_FACTOR: tuple[str, str] = ("chain", "Chain")
_ALL_FACTORS: tuple[tuple[str, str], ...] = (*FACTORS, CHAIN_FACTOR)
#: Numeric factors: categorical levels written from their values.
_NUMERIC_FACTORS = ("Friction", "Chain")

RESULT_COLUMNS: tuple[str, ...] = ("panel_ratio", "block_ratio", "bond", "friction", "alpha_c")

# Geometry of Table 1 (SPEC section 4): B fixed, H from the panel ratio B:H, b from the block
# ratio b:h with h = 60 mm. Used for the scale factors H/b and B/b of Figures 9 and 10.
PANEL_LENGTH_MM: float = PANEL_LENGTH
PANEL_HEIGHT_MM: dict[str, float] = dict(PANEL_HEIGHTS)
BLOCK_LENGTH_MM: dict[str, float] = dict(BLOCK_LENGTHS)

_TERM_SEP = "*"
_MAX_ORDER = 3  # order 4 is saturated for a single replicate: no error DoF left


# --------------------------------------------------------------------------------------------
# Input
# --------------------------------------------------------------------------------------------


def load_results(path: str | PathLike[str]) -> pd.DataFrame:
    """Read a results CSV with (at least) the columns of Table 5.

    Extra columns are kept. Raises ``ValueError`` naming the missing column, the bad level or
    the bad value (first offending row, 1-based data row as in a spreadsheet without header).
    """
    try:
        raw = pd.read_csv(path, dtype={"panel_ratio": str, "block_ratio": str, "bond": str})
    except pd.errors.EmptyDataError as exc:
        raise ValueError(f"{path}: empty results file") from exc
    missing = [c for c in RESULT_COLUMNS if c not in raw.columns]
    if missing:
        raise ValueError(
            f"{path}: missing column {missing[0]!r} (a results CSV needs columns {', '.join(RESULT_COLUMNS)})"
        )
    if len(raw) == 0:
        raise ValueError(f"{path}: no data rows")
    df = raw.copy()
    for col in ("panel_ratio", "block_ratio", "bond"):
        values = df[col].astype("string").str.strip()
        if col == "bond":
            values = values.str.lower()  # Table 5 prints "Running", the CSV "running"
        allowed = FACTOR_LEVELS[col]
        bad = ~values.isin(allowed) | values.isna()
        if bad.any():
            i = int(np.flatnonzero(bad.to_numpy())[0])
            raise ValueError(
                f"{path}: bad level {raw[col].iloc[i]!r} in column {col!r} (row {i + 1}); "
                f"allowed: {', '.join(map(str, allowed))}"
            )
        df[col] = values.astype(str)
    numeric = ("friction", "alpha_c", "chain") if "chain" in df.columns else ("friction", "alpha_c")
    for col in numeric:
        num = pd.to_numeric(df[col], errors="coerce")
        bad = ~np.isfinite(num.to_numpy(dtype=float)) | (num.to_numpy(dtype=float) < 0)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            what = "bad value" if col == "alpha_c" else "bad level"
            raise ValueError(
                f"{path}: {what} {raw[col].iloc[i]!r} in column {col!r} (row {i + 1}); "
                "expected a finite, non-negative number"
            )
        df[col] = num.astype(float)
    return df


# --------------------------------------------------------------------------------------------
# ANOVA
# --------------------------------------------------------------------------------------------


def _factor_pairs(factors: Sequence[str] | None) -> list[tuple[str, str]]:
    """(column, source name) of the chosen factor columns, in Table 1 order, the chain last
    (the four of Table 1 by default)."""
    if factors is None:
        return list(FACTORS)
    known = {col for col, _ in _ALL_FACTORS}
    unknown = [f for f in factors if f not in known]
    if unknown:
        raise ValueError(f"unknown factor {unknown[0]!r}; factors are {', '.join(sorted(known))}")
    chosen = [(col, name) for col, name in _ALL_FACTORS if col in set(factors)]
    if not chosen:
        raise ValueError("at least one factor is needed")
    return chosen


def varying_factors(df: pd.DataFrame) -> list[str]:
    """Factor columns of ``df`` with at least two levels (a sub-design may fix some factors)."""
    return [col for col, _ in _ALL_FACTORS if col in df.columns and df[col].nunique() >= 2]


def default_factors(df: pd.DataFrame) -> list[str]:
    """The four factors of Table 1, and the chain when ``df`` has several chain levels."""
    cols = [col for col, _ in FACTORS]
    if CHAIN_FACTOR[0] in df.columns and df[CHAIN_FACTOR[0]].nunique() >= 2:
        cols.append(CHAIN_FACTOR[0])
    return cols


def _sources(order: int, factors: Sequence[str] | None = None) -> list[tuple[str, ...]]:
    """Model terms up to ``order`` as tuples of source names, in Table 2 order."""
    names = [name for _, name in _factor_pairs(factors)]
    terms: list[tuple[str, ...]] = []
    for k in range(1, order + 1):
        terms.extend(itertools.combinations(names, k))
    return terms


def _patsy_term(term: tuple[str, ...]) -> str:
    # Sum (effect) coding: each term's coefficients are orthogonal to lower-order terms in a
    # balanced design, and the Wald tests are Minitab's "adjusted" (Type III) tests.
    return ":".join(f"C({name}, Sum)" for name in term)


def _prepare(df: pd.DataFrame, response: str, factors: Sequence[str] | None = None) -> pd.DataFrame:
    pairs = _factor_pairs(factors)
    missing = [c for c, _ in pairs if c not in df.columns]
    if response not in df.columns:
        missing.append(response)
    if missing:
        raise ValueError(f"missing column {missing[0]!r}")
    data = pd.DataFrame({name: df[col].to_numpy() for col, name in pairs})
    for col, name in pairs:
        if data[name].isna().any():
            raise ValueError(f"column {col!r} has missing values")
        if data[name].nunique() < 2:
            raise ValueError(f"column {col!r} has a single level; it cannot be a factor")
    # Friction (3 levels) and the chain strength are factors, not covariates: categorical.
    for name in _NUMERIC_FACTORS:
        if name in data.columns:
            data[name] = [format(float(v), ".10g") for v in data[name]]
    y = pd.to_numeric(df[response], errors="coerce").to_numpy(dtype=float)
    if not np.all(np.isfinite(y)):
        raise ValueError(f"column {response!r} has missing or non-finite values")
    data["y"] = y
    return data


def fit_model(
    df: pd.DataFrame, response: str = "alpha_c", order: int = 2, factors: Sequence[str] | None = None
) -> RegressionResultsWrapper:
    """OLS fit of the ANOVA model (main effects + interactions up to ``order``) of the
    ``factors`` columns (default: :func:`default_factors`, the four of Table 1 and a varying
    chain)."""
    if order not in range(1, _MAX_ORDER + 1):
        raise ValueError(
            f"order must be 1, 2 or 3 (got {order!r}); order 4 leaves no error DoF in a single-replicate design"
        )
    if factors is None:
        factors = default_factors(df)
    data = _prepare(df, response, factors)
    formula = "y ~ " + " + ".join(_patsy_term(t) for t in _sources(order, factors))
    return smf.ols(formula, data=data).fit()


def anova(
    df: pd.DataFrame, response: str = "alpha_c", order: int = 2, factors: Sequence[str] | None = None
) -> AnovaResult:
    """ANOVA table of Table 2 (paper, Appendix A, Eqs. 14-16) via statsmodels.

    Factors are categorical with sum contrasts; terms are tested with adjusted (Type III)
    sums of squares — for the balanced 108-panel design identical to the sequential ones and
    to the closed forms of Eq. 16. Interactions above ``order`` are pooled into Error.
    Group rows (Linear, Two-Way Interactions, ...) and Model are joint tests of all their
    coefficients, as Minitab reports them. ``factors`` restricts the model to some of the
    factor columns (e.g. :func:`varying_factors` of a sub-design that fixes the others); by
    default the four of Table 1, and ``chain`` when the results have several chain levels.
    """
    if factors is None:
        factors = default_factors(df)
    if factors is not None and order > len(_factor_pairs(factors)):
        raise ValueError(f"order {order} needs at least {order} factors (got {len(factors)})")
    res = fit_model(df, response, order, factors)
    exog = np.asarray(res.model.exog)
    rank = int(np.linalg.matrix_rank(exog))
    if rank < exog.shape[1]:
        # An unbalanced subset can leave a combination of levels without a panel: its
        # interaction is then not estimable and the adjusted sums of squares are meaningless.
        raise ValueError(
            f"the order-{order} model is not estimable on these panels "
            f"(design matrix rank {rank} < {exog.shape[1]} coefficients)"
        )
    n = int(res.nobs)
    dfe = int(round(res.df_resid))
    if dfe <= 0:
        raise ValueError(f"no error degrees of freedom left (n = {n}, order = {order})")
    sse, sst = float(res.ssr), float(res.centered_tss)
    mse = sse / dfe
    rows = _table_rows(res, order, factors, mse, dfe)
    rows += [AnovaRow("Error", dfe, sse, mse, None, None), AnovaRow("Total", n - 1, sst, None, None, None)]
    influence = res.get_influence()
    leverage = np.asarray(influence.hat_matrix_diag, dtype=float)
    resid = np.asarray(res.resid, dtype=float)
    press = press_from_leverage(resid, leverage)
    std_resid = np.asarray(influence.resid_studentized_internal, dtype=float)
    return AnovaResult(
        response=response,
        order=order,
        n=n,
        rows=tuple(rows),
        r2=1.0 - sse / sst,
        r2_adj=1.0 - mse / (sst / (n - 1)),
        r2_pred=1.0 - press / sst,
        press=press,
        dfe=dfe,
        mse=mse,
        n_params=int(round(res.df_model)) + 1,
        fitted=tuple(float(v) for v in np.asarray(res.fittedvalues)),
        residuals=tuple(float(v) for v in resid),
        leverage=tuple(float(v) for v in leverage),
        std_residuals=tuple(float(v) for v in std_resid),
    )


def _table_rows(
    res: RegressionResultsWrapper, order: int, factors: Sequence[str] | None, mse: float, dfe: int
) -> list[AnovaRow]:
    """Model, the group rows (Linear, Two-Way Interactions, ...) and every term's row."""
    table = anova_lm(res, typ=3)
    columns = _term_columns(res.model.exog_names)

    def term_row(term: tuple[str, ...]) -> AnovaRow:
        key = _patsy_term(term)
        return _row(_TERM_SEP.join(term), int(round(table.loc[key, "df"])), float(table.loc[key, "sum_sq"]), mse, dfe)

    def group_row(name: str, terms: Sequence[tuple[str, ...]]) -> AnovaRow:
        # Joint Wald test of all coefficients of the group = extra SS of dropping the group.
        cols = np.concatenate([columns[t] for t in terms])
        restriction = np.zeros((len(cols), len(res.params)))
        restriction[np.arange(len(cols)), cols] = 1.0
        test = res.f_test(restriction)
        dof = int(round(float(test.df_num)))
        return _row(name, dof, float(np.squeeze(test.fvalue)) * dof * mse, mse, dfe)

    terms = _sources(order, factors)
    rows = [_row("Model", int(round(res.df_model)), float(res.centered_tss) - float(res.ssr), mse, dfe)]
    for k in range(1, order + 1):
        group = [t for t in terms if len(t) == k]
        rows.append(group_row(_GROUP_NAMES[k], group))
        rows.extend(term_row(t) for t in group)
    return rows


_COLUMN_FACTOR = re.compile(r"C\((\w+), Sum\)")


def _term_columns(exog_names: Sequence[str]) -> dict[tuple[str, ...], np.ndarray]:
    """Design-matrix columns of each term, keyed by the term's factor names.

    Parsed from the column names (e.g. ``C(Panel, Sum)[S.1:1]:C(Block, Sum)[S.2:1]``) rather
    than from the formula engine's term metadata, which differs between patsy and formulaic.
    """
    out: dict[tuple[str, ...], list[int]] = {}
    for i, name in enumerate(exog_names):
        factors = tuple(_COLUMN_FACTOR.findall(name))
        if factors:
            out.setdefault(factors, []).append(i)
    return {k: np.asarray(v, dtype=int) for k, v in out.items()}


def _row(source: str, dof: int, ss: float, mse: float, dfe: int) -> AnovaRow:
    ms = ss / dof
    f = ms / mse
    # sf, not 1 - cdf: keeps tiny p-values (needed by the Pareto chart's equivalent t).
    p = float(scipy.stats.f.sf(f, dof, dfe))
    return AnovaRow(source, dof, ss, ms, f, p)


# --------------------------------------------------------------------------------------------
# Prediction: PRESS and R-sq(pred)
# --------------------------------------------------------------------------------------------


def press_from_leverage(residuals: Iterable[float], leverage: Iterable[float]) -> float:
    """PRESS = sum (e_i / (1 - h_ii))^2, the leave-one-out prediction error sum of squares."""
    e = np.asarray(list(residuals), dtype=float)
    h = np.asarray(list(leverage), dtype=float)
    if np.any(h >= 1.0 - 1e-12):
        # A point with leverage 1 is fitted exactly and cannot be predicted from the others.
        return math.inf
    return float(np.sum((e / (1.0 - h)) ** 2))


def press_balanced(sse: float, n: int, p: int) -> float:
    """Closed-form PRESS of a balanced design, where every leverage equals p/n.

    PRESS = SSE / (1 - p/n)^2 = SSE * (n / (n - p))^2; for Table 2, p = 40, n = 108.
    """
    if not 0 < p < n:
        raise ValueError(f"need 0 < p < n (got p = {p}, n = {n})")
    return sse * (n / (n - p)) ** 2


def r2_pred_balanced(sse: float, sst: float, n: int, p: int) -> float:
    """R-sq(pred) = 1 - PRESS/SST with the balanced-design PRESS of :func:`press_balanced`."""
    return 1.0 - press_balanced(sse, n, p) / sst


# --------------------------------------------------------------------------------------------
# Pareto chart of standardized effects (Figure 7)
# --------------------------------------------------------------------------------------------
