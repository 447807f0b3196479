"""Table 2 of the paper (ANOVA of the 108-panel design) from its own Table 5.

Every printed digit of Table 2 must come out of ``alma.stats.anova`` applied to the published
collapse multipliers (Appendix B, Table 5): Adj SS and Adj MS to 4 decimals, F to 2, P to 3,
R-sq = 96.75 % and R-sq(pred) = 91.81 %, and the Pareto reference line 1.995 (Figure 7).
Values are compared after rounding to the printed digits, never with a widened tolerance.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import scipy.stats

from alma.stats.anova import anova, fit_model, load_results, press_balanced, r2_pred_balanced
from alma.stats.effects import equivalent_t, pareto_reference, standardized_effects

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "verification" / "data"
TABLE5 = DATA / "table5_collapse_multipliers.csv"
TABLE2 = DATA / "table2_anova.csv"

DECIMALS = {"adj_ss": 4, "adj_ms": 4, "f_value": 2, "p_value": 3}


@pytest.fixture(scope="module")
def result():
    return anova(load_results(TABLE5), order=2)


@pytest.fixture(scope="module")
def table2() -> pd.DataFrame:
    return pd.read_csv(TABLE2, dtype={"source": str})


def _printed(x: float, decimals: int) -> str:
    return f"{x:.{decimals}f}"


def test_sources_and_order_match_table2(result, table2):
    assert [r.source for r in result.rows] == list(table2["source"])


def test_every_printed_digit_of_table2(result, table2):
    mismatches = []
    for (_, expected), row in zip(table2.iterrows(), result.rows, strict=True):
        assert row.dof == int(expected["dof"]), row.source
        for col, dec in DECIMALS.items():
            want = expected[col]
            got = getattr(row, col)
            if pd.isna(want):
                # Blank in Table 2 (Error F/P, Total MS/F/P) must be blank here too.
                assert got is None, f"{row.source}.{col} should be blank, got {got}"
                continue
            assert got is not None, f"{row.source}.{col} is blank, Table 2 prints {want}"
            if _printed(got, dec) != _printed(float(want), dec):
                mismatches.append((row.source, col, _printed(got, dec), _printed(float(want), dec)))
    assert not mismatches, f"digits differing from Table 2: {mismatches}"


def test_r_squared_as_printed(result):
    # Paper, Results and discussion: R-sq = 96.75 %, R-sq(pred) = 91.81 %.
    assert f"{100 * result.r2:.2f}" == "96.75"
    assert f"{100 * result.r2_pred:.2f}" == "91.81"
    assert 0.0 < result.r2_pred < result.r2_adj < result.r2 < 1.0


def test_dof_bookkeeping_of_appendix_a(result):
    # Table 4: DoF_Total = abcd - 1 = 107, DoF_Model = 9 + 30 = 39, DoF_Error = 68.
    assert result.n == 108 and result.dfe == 68 and result.n_params == 40
    model = result.row("Model").dof
    assert model == result.row("Linear").dof + result.row("Two-Way Interactions").dof
    ss = {r.source: r.adj_ss for r in result.rows}
    # Balanced design: the adjusted SS add up (Eq. 15).
    assert math.isclose(ss["Model"] + ss["Error"], ss["Total"], rel_tol=1e-12)
    assert math.isclose(ss["Linear"], ss["Panel"] + ss["Block"] + ss["Bond"] + ss["Friction"], rel_tol=1e-10)


def test_adjusted_equals_sequential_ss_in_balanced_design(result):
    from statsmodels.stats.anova import anova_lm

    seq = anova_lm(fit_model(load_results(TABLE5)), typ=1)
    for term in result.terms:
        key = ":".join(f"C({n}, Sum)" for n in term.source.split("*"))
        assert math.isclose(term.adj_ss, float(seq.loc[key, "sum_sq"]), rel_tol=1e-9), term.source


def test_press_equals_balanced_closed_form(result):
    # Every leverage of a balanced full factorial is p/n = 40/108.
    assert np.allclose(result.leverage, result.n_params / result.n, rtol=0, atol=1e-12)
    sse = result.row("Error").adj_ss
    sst = result.row("Total").adj_ss
    assert math.isclose(result.press, press_balanced(sse, result.n, result.n_params), rel_tol=1e-10)
    assert math.isclose(result.r2_pred, r2_pred_balanced(sse, sst, result.n, result.n_params), rel_tol=1e-10)


def test_pareto_reference_is_1995(result):
    # Figure 7: "the reference value, in this case 1.995".
    assert f"{pareto_reference(result.dfe):.3f}" == "1.995"


def test_pareto_ranking_as_in_figure7(result):
    effects = standardized_effects(result)
    names = [e.source for e in effects]
    # Text under Figure 7: main effects and Panel*Friction lead; then Block*Friction,
    # Panel*Block, Bond*Friction, Panel*Bond; Block*Bond alone below the reference line.
    assert set(names[:5]) == {"Panel", "Block", "Bond", "Friction", "Panel*Friction"}
    assert names[5:] == ["Block*Friction", "Panel*Block", "Bond*Friction", "Panel*Bond", "Block*Bond"]
    assert [e.source for e in effects if not e.significant] == ["Block*Bond"]
    # Each multi-DoF effect reproduces its term's p-value as a two-sided t-test p-value.
    for e in effects:
        assert math.isfinite(e.effect)
        assert math.isclose(2 * scipy.stats.t.sf(e.effect, result.dfe), e.p_value, rel_tol=1e-6)


def test_multi_dof_effect_finite_for_tiny_p(result):
    p = 1e-30
    assert not math.isfinite(scipy.stats.t.ppf(1 - p / 2, result.dfe))  # why isf is used
    t = equivalent_t(p, result.dfe)
    assert math.isfinite(t) and t > 10
    assert math.isclose(2 * scipy.stats.t.sf(t, result.dfe), p, rel_tol=1e-6)
    # The Friction term's p (~3e-36) is far below 1e-16, and its effect is finite too.
    friction = next(e for e in standardized_effects(result) if e.source == "Friction")
    assert friction.p_value < 1e-30 and math.isfinite(friction.effect)
