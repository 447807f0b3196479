"""Table 2 of the paper from alma's own 108 collapse multipliers (associative LP, Eq. 10).

The study runs with ``alma.study.run_doe`` (2 worker processes, ~20-40 s). Table 2 is the ANOVA
of Table 5 *as printed* (4 decimals): ``test_table2_anova.py`` shows the published Table 5
gives every printed digit. Here alma's multipliers, rounded to the same 4 decimals, are the
input, and every printed cell is compared after rounding to the printed digits (SS and MS 4
decimals, F 2, P 3) — never with a widened tolerance.

alma agrees with Table 5 to 4 decimals in 106 of the 108 panels. The two others (english
bond, panel 1:2, blocks 2:1, f = 0.60 and 1.00) lie 1.5e-6 and 8.6e-6 beyond the values that
print as the published ones (alma: 0.3518515 and 0.4172586, certified bounds; published
0.3518 and 0.4172). Those two 4th-decimal steps move the last digit of three cells of
Table 2; those cells are strict xfails carrying the measured values. With the published
values for those two panels, alma's printed Table 5 *is* the published Table 5.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from alma.stats.anova import anova, load_results
from alma.study.doe import run_doe

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "verification" / "data"
TABLE5 = DATA / "table5_collapse_multipliers.csv"
TABLE2 = DATA / "table2_anova.csv"
DECIMALS = {"dof": 0, "adj_ss": 4, "adj_ms": 4, "f_value": 2, "p_value": 3}
FACTORS = ["panel_ratio", "block_ratio", "bond", "friction"]

# The two panels whose 4-decimal value differs from Table 5 (published, alma exact).
KNOWN_TABLE5 = {
    ("1:2", "2:1", "english", 0.60): ("0.3518", 0.3518515),
    ("1:2", "2:1", "english", 1.00): ("0.4172", 0.4172586),
}
# Cells of Table 2 that these two values change (measured with alma 0.1.0).
KNOWN_TABLE2 = {
    ("Panel", "adj_ms"): "alma 0.3786 (0.378641) vs printed 0.3787",
    ("Panel", "f_value"): "alma 126.82 (126.8244) vs printed 126.83",
    ("Block", "f_value"): "alma 141.11 (141.1148) vs printed 141.12",
}
_REASON = (
    "caused by alma's α of english 1:2 2:1 at f = 0.60 / 1.00 (0.3519 / 0.4173 at 4 "
    "decimals, published 0.3518 / 0.4172, ~1e-5 beyond the rounding boundary): "
)


@pytest.fixture(scope="module")
def alma_table5(tmp_path_factory) -> pd.DataFrame:
    """alma's 108 multipliers in the row order of Table 5 (unrounded)."""
    results = run_doe(tmp_path_factory.mktemp("doe"), model="associative", workers=2, progress=False)
    assert len(results) == 108 and results["key"].is_unique
    assert (results["status"] == "optimal").all(), results[results["status"] != "optimal"]
    t5 = load_results(TABLE5)
    mine = results.set_index(FACTORS)["alpha_c"]
    out = t5[FACTORS].copy()
    out["alpha_c"] = [float(mine.loc[(r.panel_ratio, r.block_ratio, r.bond, r.friction)]) for r in t5.itertuples()]
    out["published"] = t5["alpha_c"].to_numpy()
    return out


@pytest.fixture(scope="module")
def printed_input(alma_table5) -> pd.DataFrame:
    df = alma_table5[FACTORS].copy()
    df["alpha_c"] = [float(f"{a:.4f}") for a in alma_table5["alpha_c"]]
    return df


@pytest.fixture(scope="module")
def result(printed_input):
    return anova(printed_input, order=2)


def test_table5_to_printed_digits(alma_table5):
    differ = {}
    for r in alma_table5.itertuples():
        if f"{r.alpha_c:.4f}" != f"{r.published:.4f}":
            differ[(r.panel_ratio, r.block_ratio, r.bond, r.friction)] = (f"{r.published:.4f}", r.alpha_c)
    assert set(differ) == set(KNOWN_TABLE5), differ
    for k, (pub, exact) in differ.items():
        assert pub == KNOWN_TABLE5[k][0]
        assert abs(exact - KNOWN_TABLE5[k][1]) < 5e-7, (k, exact)
        # Off by one unit of the 4th decimal, and within 1e-5 of the rounding boundary.
        assert abs(float(f"{exact:.4f}") - float(pub)) == pytest.approx(1e-4)
        assert abs(exact - (float(pub) + 5e-5)) < 1e-5


def test_known_differences_are_the_only_cause(printed_input, alma_table5):
    # With the published value for the two known panels, alma's printed Table 5 is Table 5.
    patched = printed_input.copy()
    for i, r in enumerate(alma_table5.itertuples()):
        if (r.panel_ratio, r.block_ratio, r.bond, r.friction) in KNOWN_TABLE5:
            patched.loc[i, "alpha_c"] = r.published
    assert (patched["alpha_c"].to_numpy() == alma_table5["published"].to_numpy()).all()


def _cells():
    t2 = pd.read_csv(TABLE2, dtype={"source": str})
    for _, row in t2.iterrows():
        for col, dec in DECIMALS.items():
            if pd.isna(row[col]):
                continue
            marks: pytest.MarkDecorator | tuple[()] = ()
            if (row["source"], col) in KNOWN_TABLE2:
                marks = pytest.mark.xfail(strict=True, reason=_REASON + KNOWN_TABLE2[(row["source"], col)])
            yield pytest.param(row["source"], col, dec, float(row[col]), marks=marks, id=f"{row['source']}-{col}")


@pytest.mark.parametrize("source, column, decimals, printed", list(_cells()))
def test_table2_cell_from_alma(result, source, column, decimals, printed):
    got = getattr(result.row(source), column)
    assert got is not None
    assert f"{got:.{decimals}f}" == f"{printed:.{decimals}f}", f"{source} {column}: alma {got!r}"


def test_blank_cells_stay_blank(result):
    assert result.row("Error").f_value is None and result.row("Error").p_value is None
    assert result.row("Total").adj_ms is None


def test_r_squared_as_printed(result, alma_table5):
    # Paper, Results and discussion / Table 3: R-sq = 96.75 %, R-sq(pred) = 91.81 %.
    assert f"{100 * result.r2:.2f}" == "96.75"
    assert f"{100 * result.r2_pred:.2f}" == "91.81"
    # The same from alma's unrounded multipliers.
    exact = anova(alma_table5[[*FACTORS, "alpha_c"]], order=2)
    assert f"{100 * exact.r2:.2f}" == "96.75"
    assert f"{100 * exact.r2_pred:.2f}" == "91.81"
