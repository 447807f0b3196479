"""Unit tests of alma.stats: model orders, input checks, JSON shape, figures, Tukey."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pandas as pd
import pytest

from alma.stats import anova as anova_mod
from alma.stats.anova import RESULT_COLUMNS, anova, load_results, press_balanced
from alma.stats.effects import equivalent_t, tukey_bond

ROOT = Path(__file__).resolve().parents[1]
TABLE5 = ROOT / "verification" / "data" / "table5_collapse_multipliers.csv"


@pytest.fixture(scope="module")
def df() -> pd.DataFrame:
    return load_results(TABLE5)


@pytest.fixture(scope="module")
def result(df):
    return anova(df)


# ------------------------------------------------------------------------- model orders


def test_order1_pools_all_interactions(df):
    r = anova(df, order=1)
    # 107 total - 9 main-effect DoF = 98.
    assert r.dfe == 98
    assert [x.source for x in r.rows] == ["Model", "Linear", "Panel", "Block", "Bond", "Friction", "Error", "Total"]


def test_order3_error_is_the_four_way_interaction(df):
    r = anova(df, order=3)
    # Single replicate of 3x3x4x3: only the 4-way interaction is left, (2)(2)(3)(2) = 24 DoF.
    assert r.dfe == 24
    three_way = {
        "Panel*Block*Bond": 12,
        "Panel*Block*Friction": 8,
        "Panel*Bond*Friction": 12,
        "Block*Bond*Friction": 12,
    }
    for name, dof in three_way.items():
        assert r.row(name).dof == dof
    assert r.row("Three-Way Interactions").dof == 44
    assert r.row("Model").dof == 83
    assert r.row("Total").dof == 107


def test_order4_is_saturated_and_refused(df):
    with pytest.raises(ValueError, match="order"):
        anova(df, order=4)


def test_terms_do_not_depend_on_row_order(df, result):
    shuffled = df.sample(frac=1.0, random_state=1).reset_index(drop=True)
    r = anova(shuffled)
    for a, b in zip(result.rows, r.rows, strict=True):
        assert a.source == b.source and math.isclose(a.adj_ss, b.adj_ss, rel_tol=1e-9)


def test_friction_is_categorical(result):
    assert result.row("Friction").dof == 2


# ------------------------------------------------------------------------------ output


def test_to_dict_is_the_cli_json(result):
    d = json.loads(json.dumps(result.to_dict()))
    assert set(d) == {"rows", "r2", "r2_adj", "r2_pred"}
    assert set(d["rows"][0]) == {"source", "dof", "adj_ss", "adj_ms", "f_value", "p_value"}
    panel = next(r for r in d["rows"] if r["source"] == "Panel")
    assert panel["dof"] == 2 and isinstance(panel["dof"], int)
    error = next(r for r in d["rows"] if r["source"] == "Error")
    assert error["f_value"] is None and error["p_value"] is None
    total = next(r for r in d["rows"] if r["source"] == "Total")
    assert total["adj_ms"] is None
    assert 0 < d["r2_pred"] < d["r2_adj"] < d["r2"] < 1


def test_format_table_layout(result):
    text = result.format_table()
    lines = text.splitlines()
    assert lines[0].split() == ["Source", "DoF", "Adj", "SS", "Adj", "MS", "F-Value", "P-Value"]
    panel = next(line for line in lines if line.startswith("Panel "))
    assert panel.split() == ["Panel", "2", "0.7573", "0.3787", "126.83", "0.000"]
    assert "R-sq       = 96.75%" in text
    assert "R-sq(pred) = 91.81%" in text


def test_press_closed_form_checks_arguments():
    assert math.isclose(press_balanced(1.0, 4, 2), 4.0)
    with pytest.raises(ValueError):
        press_balanced(1.0, 4, 4)


def test_equivalent_t_bounds():
    assert math.isclose(equivalent_t(0.05, 68), 1.995468931, rel_tol=1e-8)
    with pytest.raises(ValueError):
        equivalent_t(1.5, 68)


# ------------------------------------------------------------------------ input checks


def _write(tmp_path: Path, frame: pd.DataFrame) -> Path:
    path = tmp_path / "results.csv"
    frame.to_csv(path, index=False)
    return path


@pytest.mark.parametrize("column", RESULT_COLUMNS)
def test_missing_column_is_named(tmp_path, df, column):
    path = _write(tmp_path, df.drop(columns=[column]))
    with pytest.raises(ValueError, match=f"missing column '{column}'"):
        load_results(path)


@pytest.mark.parametrize(
    ("column", "value"),
    [
        ("bond", "herringbone"),
        ("panel_ratio", "3:1"),
        ("block_ratio", "5:1"),
        ("friction", "rough"),
        ("alpha_c", "nan"),
    ],
)
def test_bad_level_or_value_is_named(tmp_path, df, column, value):
    bad = df.astype({column: object})
    bad.loc[5, column] = value
    path = _write(tmp_path, bad)
    with pytest.raises(ValueError, match=f"column '{column}' \\(row 6\\)"):
        load_results(path)


def test_extra_columns_and_capitalised_bond_accepted(tmp_path, df, result):
    more = df.copy()
    more["bond"] = more["bond"].str.capitalize()
    more["status"] = "optimal"
    loaded = load_results(_write(tmp_path, more))
    assert "status" in loaded.columns and set(loaded["bond"]) == set(df["bond"])
    assert math.isclose(anova(loaded).r2, result.r2, rel_tol=1e-12)


def test_anova_refuses_missing_response(df):
    with pytest.raises(ValueError, match="missing column 'alpha'"):
        anova(df, response="alpha")


# ------------------------------------------------------------------------------- Tukey


def test_tukey_stack_differs_only(df):
    # Paper, Results and discussion: stack differs from every other bond, the others do not.
    t = tukey_bond(df)
    pairs = {frozenset(p) for p in t.significant_pairs()}
    assert pairs == {frozenset({"stack", b}) for b in ("running", "english", "flemish")}
    means = dict(t.means)
    assert means["stack"] == min(means.values())


# ----------------------------------------------------------------------------- figures


def test_figures_write_png(tmp_path, df, result):
    pytest.importorskip("matplotlib")
    from alma.stats import figures

    outputs = [
        figures.pareto_chart(result, tmp_path / "fig7_pareto.png"),
        figures.main_effects_plot(df, tmp_path / "fig5_main.png"),
        figures.interaction_plot_matrix(df, tmp_path / "fig6_interactions.png"),
        figures.residual_plots(df, result, tmp_path / "fig8_residuals.png"),
        figures.residual_plots(df, None, tmp_path / "fig8_residuals_refit.png"),
        *figures.scale_factor_plots(df, tmp_path / "fig9_hb.png", tmp_path / "fig10_bb.png"),
    ]
    for out in outputs:
        out = Path(out)
        assert out.exists() and out.stat().st_size > 1000
        assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_statistics_do_not_import_matplotlib():
    # anova.py must stay usable without a plotting stack (e.g. `alma anova --json`).
    import subprocess

    # Whatever the rest of the package loads, importing the statistics adds no matplotlib.
    code = (
        "import sys; import alma; "
        "before = 'matplotlib' in sys.modules; import alma.stats.anova; "
        "print(not before and 'matplotlib' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False", anova_mod.__name__
