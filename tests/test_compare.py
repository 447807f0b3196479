"""``alma compare``: the associative/non-associative report on top of the resumable study.

A tiny design (stack bond, panel 2:1, blocks 4:1, three frictions: 72 blocks, well under a
second per non-associative solve with ``--effort fast``) goes through the real command line;
the ANOVA of the ratio and the "which factors change" paragraph are checked on a synthetic
balanced 108-panel table whose answer is known by construction.
"""

from __future__ import annotations

import csv
import json
import pathlib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from alma.cli.main import main
from alma.stats.anova import anova, varying_factors
from alma.study import compare as compare_mod, compare_report, compare_stats
from alma.study.doe import COLUMNS, PAPER_DESIGN, Design, read_results, run_doe

ROOT = Path(__file__).resolve().parents[1]
TINY = 'panel_ratio = ["2:1"]\nblock_ratio = ["4:1"]\nbond = ["stack"]\nfriction = [0.27, 0.6, 1.0]\n'


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    base = tmp_path_factory.mktemp("compare")
    design = base / "tiny.toml"
    design.write_text(TINY)
    out = base / "out"
    argv = ["compare", "--out", str(out), "--design", str(design), "--workers", "2", "--effort", "fast", "--quiet"]
    code = main(argv)
    return out, argv, code


def test_compare_cli_writes_table_report_and_figures(tiny_run):
    out, _, code = tiny_run
    assert code == 0
    table = pd.read_csv(
        out / "compare.csv",
        dtype={"panel_ratio": str, "block_ratio": str},
        keep_default_na=False,
        na_values={"alpha_lp_start": [""], "lp_start_gain": [""]},
    )
    assert list(table.columns) == list(compare_mod.COMPARE_COLUMNS)
    assert len(table) == 3
    assert sorted(table["friction"]) == [0.27, 0.6, 1.0]
    assert (table["status_lp"] == "optimal").all() and table["status_nl"].isin(["feasible", "optimal"]).all()
    for r in table.itertuples():
        assert r.alpha_nl <= r.alpha_lp + 1e-7, r
        assert r.ratio == pytest.approx(r.alpha_nl / r.alpha_lp, rel=1e-15)
        assert r.mechanism_lp in ("sliding", "rocking", "mixed") and r.mechanism_nl in ("sliding", "rocking", "mixed")
        assert r.time_lp_s > 0 and r.time_nl_s > 0
        assert r.start_nl and r.effort == "fast" and r.n_blocks == 72
        assert r.n_verified >= 1 and r.n_candidates >= r.n_verified
        if r.lp_start_verified == "True":  # the LP-started candidate can only be above the best
            assert r.alpha_lp_start >= r.alpha_nl - 1e-9 and r.lp_start_gain >= -1e-9
    # The table agrees with the study rows it is built from.
    rows = read_results(out / "results.csv")
    assert list(rows.columns) == list(COLUMNS) and len(rows) == 6
    lp = rows[rows["model"] == "associative"].set_index("friction")["alpha_c"]
    nl = rows[rows["model"] == "nonassociative"].set_index("friction")
    for r in table.itertuples():
        assert r.alpha_lp == lp[r.friction] and r.alpha_nl == nl.loc[r.friction, "alpha_c"]
        assert nl.loc[r.friction, "ratio"] == pytest.approx(r.ratio, rel=1e-12)
        assert nl.loc[r.friction, "alpha_associative"] == r.alpha_lp
    # Stack, f = 0.6: without dilatancy the panel is clearly weaker (0.4191 vs 1/3).
    row = table[table["friction"] == 0.6].iloc[0]
    assert row.ratio < 0.9

    md = (out / "compare.md").read_text()
    for text in (
        "## Summary",
        "| Panels | 3 |",
        "Largest gap",
        "Median gap",
        "LP-started candidate",
        "Failures (status error) | 0",
        "Wall time",
        "### ANOVA of α_NL",
        "### ANOVA of α_NL/α_LP",
        "Which factors change their effect",
        "## All panels",
    ):
        assert text in md, text
    assert f"{1 - table['ratio'].min():.4f}" in md  # the largest gap, printed
    # Where the search time goes: every start that ran is recorded, the winner among them.
    assert "## Where the search time goes" in md
    runs = compare_mod.start_times(table)
    assert set(runs["start"]) >= {"lp", "rocking"} and (runs["time_s"] >= 0).all()
    for r in table.itertuples():
        names = [run[0] for run in json.loads(r.starts_nl)]
        assert r.start_nl in names and names[0] == "lp"
        # effort fast: the projected iteration runs last, and only when no other start verified
        before = [run[2] for run in json.loads(r.starts_nl) if run[0] != "gilbert-projected"]
        assert ("gilbert-projected" in names) == (not any(before))
        for name, _, verified, alpha in json.loads(r.starts_nl):  # every start's α is kept
            if verified:
                assert alpha >= r.alpha_nl - 1e-12
            if name == r.start_nl:
                assert verified and alpha == pytest.approx(r.alpha_nl, rel=1e-12)
    assert runs["won"].sum() == len(table)
    assert runs["time_s"].sum() <= table["time_nl_s"].sum() + 1e-3 * len(runs)  # JSON keeps ms
    figures = out / "figures"
    for name in ("main_effects_alpha_nl.png", "main_effects_ratio.png", "main_effects_lp_vs_nl.png"):
        assert (figures / name).stat().st_size > 5_000, name
    pairs = sorted(figures.glob("mechanisms_*.png"))
    differ = table[table["ratio"] < 1 - compare_mod.DIFFER_TOLERANCE]
    assert len(pairs) == min(6, len(differ)) >= 1
    assert all(p.stat().st_size > 10_000 for p in pairs)
    assert "mechanisms_stack_panel2-1_blocks4-1_f0.60.png" in {p.name for p in pairs}


def test_compare_resume_adds_no_rows(tiny_run, capsys):
    out, argv, _ = tiny_run
    before = (out / "results.csv").read_bytes()
    table_before = pd.read_csv(out / "compare.csv")
    assert main(argv) == 0
    assert (out / "results.csv").read_bytes() == before
    pd.testing.assert_frame_equal(pd.read_csv(out / "compare.csv"), table_before)
    assert "(6 rows, 6 resumed" in (out / "compare.md").read_text()


def test_every_row_keeps_its_mechanism_and_the_figures_are_drawn_from_them(tiny_run, monkeypatch):
    out, argv, _ = tiny_run
    from alma.report.plot import MechanismPicture
    from alma.study.doe import picture_path

    rows = read_results(out / "results.csv")
    for r in rows.itertuples():
        picture = MechanismPicture.load(picture_path(out, r.key))
        assert picture.model == r.model and picture.status == r.status
        assert picture.alpha == r.alpha_c  # the state of the row, not another one
        assert len(picture.blocks) == 72 and all(len(b.u) == 3 for b in picture.blocks)
        assert picture.joints and all(j.state in ("hinging", "sliding", "separating") for j in picture.joints)
    # Redrawing the figures solves nothing: they come from the kept mechanisms.
    import alma

    def no_build(*args, **kwargs):
        raise AssertionError("the report built a panel's model to solve it again")

    # (alma.solve itself is not patched: its signature is part of the rows' keys)
    monkeypatch.setattr(alma, "build_model", no_build)
    for p in (out / "figures").glob("mechanisms_*"):
        p.unlink()
    (out / "figures" / "mechanisms.json").unlink(missing_ok=True)
    assert main(argv) == 0
    assert len(list((out / "figures").glob("mechanisms_*.png"))) >= 1
    assert "failed" not in (out / "compare.md").read_text().split("## Summary")[0]


def test_a_stale_or_missing_picture_is_not_drawn(tiny_run):
    """A picture that does not match its row (left from another run) or cannot be read sends the
    report back to solving the panel."""
    import dataclasses

    from alma.report.plot import MechanismPicture
    from alma.study.doe import picture_path

    out = tiny_run[0]
    row = next(pd.read_csv(out / "compare.csv", keep_default_na=False, na_values={"alpha_nl": [""]}).itertuples())
    assert compare_mod._stored_pictures(row, out) is not None
    path = picture_path(out, row.key_nl)
    kept = MechanismPicture.load(path)
    try:
        dataclasses.replace(kept, alpha=kept.alpha + 1e-3).save(path)
        assert compare_mod._stored_pictures(row, out) is None
        path.write_bytes(b"not an npz")
        assert compare_mod._stored_pictures(row, out) is None
    finally:
        kept.save(path)
    assert compare_mod._stored_pictures(row, out) is not None


def test_mechanism_picture_round_trip(tmp_path):
    import alma
    from alma.report.plot import MechanismPicture, plot_mechanism

    scene = alma.paper_panel("stack", "2:1", "4:1", 0.6)
    result = alma.solve(alma.build_model(scene, alma.find_joints(scene)), model="associative")
    picture = MechanismPicture.from_result(result)
    again = MechanismPicture.load(picture.save(tmp_path / "p.npz"))
    assert again == picture
    assert [b.u for b in again.blocks] == [b.u for b in result.blocks]
    assert len(again.joints) == sum(j.state != "rest" for j in result.joints)
    assert plot_mechanism(scene, again, tmp_path / "p.png").stat().st_size > 10_000


def test_a_results_file_of_other_columns_is_refused_with_a_message(tmp_path):
    design = Design(panel_ratio=("2:1",), block_ratio=("4:1",), bond=("stack",), friction=(0.6,))
    run_doe(tmp_path, design=design, workers=1, progress=False)
    path = tmp_path / "results.csv"
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    n_old = COLUMNS.index("key") + 1
    with open(path, "w", newline="") as fh:
        csv.writer(fh, lineterminator="\n").writerows(r[:n_old] for r in rows)
    with pytest.raises(ValueError, match="choose another --out folder"):
        run_doe(tmp_path, design=design, workers=1, progress=False)


def test_effort_is_part_of_the_nonassociative_key_only(tmp_path):
    design = Design(panel_ratio=("2:1",), block_ratio=("4:1",), bond=("stack",), friction=(0.27,))
    fast = run_doe(tmp_path, model="both", design=design, workers=1, progress=False, effort="fast")
    auto = run_doe(tmp_path, model="both", design=design, workers=1, progress=False)
    assert set(fast["model"]) == {"associative", "nonassociative"}
    key = dict(zip(fast["model"], fast["key"], strict=True))
    key_auto = dict(zip(auto["model"], auto["key"], strict=True))
    assert key["associative"] == key_auto["associative"]
    assert key["nonassociative"] != key_auto["nonassociative"]
    assert list(auto["effort"]) == ["", "auto"] and list(fast["effort"]) == ["", "fast"]
    with pytest.raises(ValueError, match="effort"):
        run_doe(tmp_path, design=design, workers=1, progress=False, effort="quick")


def test_time_limit_is_part_of_the_nonassociative_key_and_reaches_the_search(tmp_path, monkeypatch):
    import alma

    design = Design(panel_ratio=("2:1",), block_ratio=("4:1",), bond=("stack",), friction=(0.27,))
    limits = []
    real_solve = alma.solve

    def spy(*args, **kwargs):
        if kwargs.get("model") != "associative":
            limits.append((kwargs.get("model"), kwargs["settings"].time_limit))
        return real_solve(*args, **kwargs)

    monkeypatch.setattr(alma, "solve", spy)
    limited = run_doe(tmp_path, model="both", design=design, workers=1, progress=False, time_limit=7.5)
    default = run_doe(tmp_path, model="both", design=design, workers=1, progress=False)
    # Each solved once with its own cap: both models in one solve first, then only the
    # non-associative row (the associative one is shared: its key does not hold the cap).
    assert limits == [("both", 7.5), ("nonassociative", None)]
    key = dict(zip(limited["model"], limited["key"], strict=True))
    key_default = dict(zip(default["model"], default["key"], strict=True))
    assert key["associative"] == key_default["associative"]
    assert key["nonassociative"] != key_default["nonassociative"]
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="time_limit"):
            run_doe(tmp_path, design=design, workers=1, progress=False, time_limit=bad)


def test_compare_bad_design_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('bond = ["herringbone"]\n')
    assert main(["compare", "--out", str(tmp_path / "o"), "--design", str(bad)]) == 2
    assert "herringbone" in capsys.readouterr().err
    assert not (tmp_path / "o" / "results.csv").exists()


# ------------------------------------------------------------------- statistics (synthetic)


def synthetic_table(seed: int = 7) -> pd.DataFrame:
    """108 panels: α_LP from friction and panel ratio; α_NL = α_LP except stack (×0.7)."""
    rng = np.random.default_rng(seed)
    rows = []
    for p, b, bond, f in PAPER_DESIGN.panels():
        a_lp = f * {"2:1": 0.9, "1:1": 0.7, "1:2": 0.5}[p] + rng.normal(0, 0.01)
        a_nl = a_lp * (0.7 if bond == "stack" else 1.0) * (1 + rng.normal(0, 0.005))
        rows.append(
            {
                "panel_ratio": p,
                "block_ratio": b,
                "bond": bond,
                "friction": f,
                "alpha_lp": a_lp,
                "alpha_nl": a_nl,
                "ratio": a_nl / a_lp,
            }
        )
    return pd.DataFrame(rows)


def test_anova_of_the_ratio_on_a_balanced_table():
    df = synthetic_table()
    res = anova(df, response="ratio")
    assert res.n == 108 and res.dfe == 68  # the model of Table 2
    assert [r.source for r in res.rows][:6] == ["Model", "Linear", "Panel", "Block", "Bond", "Friction"]
    bond = res.row("Bond")
    assert bond.p_value is not None and bond.f_value is not None
    assert bond.p_value < 1e-20  # the only real effect on the ratio
    for name in ("Panel", "Block", "Friction"):
        f_value = res.row(name).f_value
        assert f_value is not None and f_value < bond.f_value / 100
    assert 0.9 < res.r2 <= 1 and res.r2_pred < res.r2_adj < res.r2
    # A sub-design that fixes factors: only the varying ones enter the model.
    sub = df[(df["panel_ratio"] == "2:1") & (df["block_ratio"] == "4:1")]
    factors = varying_factors(sub)
    assert factors == ["bond", "friction"]
    r2 = anova(sub, response="ratio", order=1, factors=factors)
    assert [r.source for r in r2.rows] == ["Model", "Linear", "Bond", "Friction", "Error", "Total"]
    assert r2.dfe == 12 - 1 - 3 - 2
    with pytest.raises(ValueError, match="single level"):
        anova(sub, response="ratio", order=1)  # all four factors: panel ratio is constant


def test_changes_paragraph_is_computed_from_the_numbers():
    df = synthetic_table()
    stats = {
        key: compare_stats._run_anova(df, key, label)
        for key, label in (("alpha_lp", "α_LP"), ("alpha_nl", "α_NL"), ("ratio", "α_NL/α_LP"))
    }
    assert all(a.result is not None and a.order == 2 for a in stats.values())
    (text,) = compare_report._changes_paragraph(df, stats)
    changed, _, unchanged = text.partition("It is unchanged for")
    assert "**Bond**" in changed and "significant for the ratio" in changed
    for name in ("Panel (", "Block (", "Friction ("):
        assert name in unchanged, name
    # Same α in both models: the ratio ANOVA is undefined and no factor changes.
    same = df.assign(alpha_nl=df["alpha_lp"], ratio=1.0)
    stats = {
        key: compare_stats._run_anova(same, key, label)
        for key, label in (("alpha_lp", "α_LP"), ("alpha_nl", "α_NL"), ("ratio", "α_NL/α_LP"))
    }
    assert stats["ratio"].result is None and "same on every panel" in stats["ratio"].note
    (text,) = compare_report._changes_paragraph(same, stats)
    assert "no factor changes its effect" in text


def test_anova_with_unverified_panels_is_unbalanced_and_says_so():
    df = synthetic_table()
    # The largest panels fail in practice: leave out every 1:2 panel with 1:1 blocks in flemish
    # bond and a few scattered ones.
    lost = ((df["panel_ratio"] == "1:2") & (df["block_ratio"] == "1:1") & (df["bond"] == "flemish")) | df.index.isin(
        [5, 40, 77]
    )
    df.loc[lost, ["alpha_nl", "ratio"]] = np.nan
    stats = {
        "alpha_nl": compare_stats._run_anova(df, "alpha_nl", "α_NL"),
        "ratio": compare_stats._run_anova(df, "ratio", "α_NL/α_LP"),
    }
    for a in stats.values():
        assert a.result is not None and a.order == 2
        assert a.result.n == 108 - int(lost.sum()) and a.result.dfe == a.result.n - 40
        assert a.note.startswith(f"unbalanced: {a.result.n} of 108 panels")
    assert stats["ratio"].result.row("Bond").p_value < 1e-10
    # Unbalanced: the adjusted sums of squares no longer add up to the model's.
    res = stats["ratio"].result
    terms = sum(r.adj_ss for r in res.rows if r.source in ("Panel", "Block", "Bond", "Friction"))
    assert abs(terms - res.row("Linear").adj_ss) > 1e-12 * res.row("Linear").adj_ss
    # α_LP restricted to the same panels.
    keep = np.isfinite(df["ratio"].to_numpy())
    lp = compare_stats._run_anova(df, "alpha_lp", "α_LP", keep=keep, why="those with α_NL")
    assert lp.result.n == int(keep.sum()) and "those with α_NL" in lp.note


def test_anova_falls_back_to_main_effects_when_a_cell_is_empty():
    df = synthetic_table()
    # No 1:2 panel with 1:1 blocks at all: the Panel*Block interaction is not estimable.
    empty = (df["panel_ratio"] == "1:2") & (df["block_ratio"] == "1:1")
    df.loc[empty, ["alpha_nl", "ratio"]] = np.nan
    with pytest.raises(ValueError, match="not estimable"):
        anova(df[~empty], response="ratio", order=2)
    a = compare_stats._run_anova(df, "ratio", "α_NL/α_LP")
    assert a.result is not None and a.order == 1
    assert "main effects only" in a.note and a.result.dfe == int((~empty).sum()) - 1 - 9


def test_paper_nonassociative_option_reaches_make_paper(monkeypatch, tmp_path, capsys):
    import alma.paper.tables as tables

    def fake_make_paper(out, published, workers=None, **kw):
        pathlib.Path(out).mkdir(parents=True, exist_ok=True)
        pathlib.Path(out, "kw.json").write_text(json.dumps(kw))
        pathlib.Path(out, "published.txt").write_text(str(published))
        return {"report": "r.md", "compare_report": "c.md", "compare_failed": kw.get("fail", 0)}

    monkeypatch.setattr(tables, "make_paper", fake_make_paper)
    data = tmp_path / "data"
    data.mkdir()
    assert (
        main(["paper", "--out", str(tmp_path / "p"), "--published", str(data), "--nonassociative", "--effort", "fast"])
        == 0
    )
    assert (tmp_path / "p" / "kw.json").read_text() == '{"nonassociative": true, "effort": "fast"}'
    assert (tmp_path / "p" / "published.txt").read_text() == str(data)
    assert "non-associative comparison: c.md" in capsys.readouterr().out
    assert main(["paper", "--out", str(tmp_path / "q"), "--published", str(data)]) == 0
    assert (tmp_path / "q" / "kw.json").read_text() == "{}"  # unchanged call without the option
