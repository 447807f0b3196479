"""Settings: every tuned number in one place, choices checked on construction, all of them hashed
and reachable from ``alma.solve`` (issue 35, item 3)."""

from __future__ import annotations

import dataclasses
import types

import pytest

import alma
import alma.nonassociative.starts as starts
from alma.engine import types as engine_types
from alma.nonassociative.policy import parse_kind, plan, resolve_effort, rows_kind
from alma.settings import (
    CERTIFY_BACKENDS,
    EFFORTS,
    ENGINES,
    FACTORISATIONS,
    AssociativeSettings,
    CertifySettings,
    IPMSettings,
    SearchSettings,
    Settings,
    StateTolerances,
)
from alma.status import Status
from alma.study.keys import panel_key


def _column(k: int, f: float = 0.6) -> alma.Scene:
    """k square blocks stacked on the ground."""
    blocks = [{"id": "ground", "vertices": [[-200, -100], [300, -100], [300, 0], [-200, 0]], "fixed": True}]
    blocks += [
        {"id": f"c{i}", "vertices": [[0, 100 * i], [100, 100 * i], [100, 100 * i + 100], [0, 100 * i + 100]]}
        for i in range(k)
    ]
    return alma.Scene.from_dict({"thickness": 100, "unit_weight": 20, "friction": f, "blocks": blocks})


@pytest.mark.parametrize(
    ("make", "field", "allowed"),
    [
        (lambda v: AssociativeSettings(engine=v), "AssociativeSettings.engine", ENGINES),
        (lambda v: SearchSettings(effort=v), "SearchSettings.effort", EFFORTS),
        (lambda v: CertifySettings(backend=v), "CertifySettings.backend", CERTIFY_BACKENDS),
        (lambda v: IPMSettings(backend=v), "IPMSettings.backend", FACTORISATIONS),
    ],
)
def test_choices_are_checked_on_construction(make, field, allowed):
    for value in allowed:
        make(value)
    with pytest.raises(ValueError, match=f"{field} must be one of .*got 'nonsense'"):
        make("nonsense")
    with pytest.raises(ValueError, match=field):
        dataclasses.replace(make(allowed[0]), **{field.split(".")[1]: "nonsense"})


def test_efforts_are_one_constant():
    assert EFFORTS == ("auto", "fast", "thorough")
    for effort in EFFORTS:
        assert resolve_effort(effort, SearchSettings(), 10) in ("fast", "thorough")
    with pytest.raises(ValueError, match="effort must be one of"):
        alma.solve(_column(1), "nonassociative", effort="slow")


def test_the_interior_point_settings_are_alma_settings():
    assert engine_types.IPMSettings is IPMSettings
    assert AssociativeSettings().ipm == IPMSettings()


@pytest.mark.parametrize(
    "changed",
    [
        {"associative": AssociativeSettings(ipm=IPMSettings(backend="qdldl"))},
        {"associative": AssociativeSettings(ipm=IPMSettings(qdldl_max_rows=1))},
        {"associative": AssociativeSettings(auto_min_blocks=10)},
        {"associative": AssociativeSettings(auto_min_blocks_bounded=10)},
        {"associative": AssociativeSettings(feral_min_rows=10)},
        {"search": SearchSettings(states=StateTolerances(active=1e-5))},
        {"search": SearchSettings(states=StateTolerances(energy=1e-5))},
    ],
)
def test_every_moved_number_is_hashed(changed):
    """A change of any number moved into the settings changes the digest and the study key."""
    other = Settings(**changed)
    assert other.digest() != Settings().digest()
    model = "associative" if "associative" in changed else "nonassociative"
    assert panel_key("2:1", "4:1", "stack", 0.6, model, version="x", revision="y", settings=other) != panel_key(
        "2:1", "4:1", "stack", 0.6, model, version="x", revision="y", settings=Settings()
    )


def test_ipm_settings_reach_the_interior_point_from_solve():
    """With one interior-point iteration allowed the engine stops and Clarabel answers."""
    scene = _column(2)
    short = Settings(associative=AssociativeSettings(engine="ipm", ipm=IPMSettings(max_iter=1, backend="qdldl")))
    result = alma.solve(scene, settings=short)
    assert "after 1 iterations, Clarabel used" in result.message
    full = alma.solve(
        scene, settings=Settings(associative=AssociativeSettings(engine="ipm", ipm=IPMSettings(backend="qdldl")))
    )
    assert "Clarabel used" not in full.message and "alma-ipm/qdldl" in full.message
    assert result.alpha == pytest.approx(full.alpha, rel=1e-7)


def test_the_milp_start_takes_the_users_certify_settings(monkeypatch):
    """Its node budget is the search's work, capped by the user's; the other numbers are the user's."""
    seen = []

    def fake_certify(model, alpha, mechanisms, *, settings, alpha_best=None, time_limit=None):
        seen.append(settings)
        return types.SimpleNamespace(mechanism=None, nodes=0)

    monkeypatch.setattr(starts, "certify", fake_certify)
    user = CertifySettings(velocity_factor=7.0, node_limit=3, per_point_bounds=5)
    alma.solve(_column(2), "nonassociative", effort="thorough", settings=Settings(certify=user))
    assert len(seen) == 1
    assert dataclasses.replace(seen[0], node_limit=user.node_limit) == user and seen[0].node_limit <= 3
    seen.clear()
    alma.solve(_column(2), "nonassociative", effort="thorough")
    assert seen[0].velocity_factor == CertifySettings().velocity_factor
    assert seen[0].node_limit == SearchSettings().milp_start_work // 2  # its own work on 2 free blocks


def test_state_tolerances_decide_every_verification():
    """No start may verify a state against a tolerance nobody can meet: every path reads them."""
    scene = _column(3)
    assert alma.solve(scene, "nonassociative", effort="thorough").status == Status.FEASIBLE
    impossible = Settings(search=SearchSettings(states=StateTolerances(equilibrium=-1.0)))
    result = alma.solve(scene, "nonassociative", effort="thorough", settings=impossible)
    assert result.status == Status.NOT_CONVERGED


def test_start_kinds_are_parsed_in_one_place():
    for effort in ("fast", "thorough"):
        for kind in plan(SearchSettings(), effort):
            family, index = parse_kind(kind)
            rows = ":rows" if rows_kind(kind) else ""
            assert kind == (family if index is None else f"{family}:{index}{rows}")
    assert parse_kind("gilbert:3") == ("gilbert", 3) and parse_kind("milp") == ("milp", None)
    assert parse_kind("tilt:1:rows") == ("tilt", 1) and rows_kind("tilt:1:rows") and not rows_kind("tilt:1")


def test_a_verified_rocking_state_ends_the_fast_search_of_a_large_scene():
    """``rocking_ends_blocks``: above it (here 0 free blocks) the Gilbert and turned-table starts
    do not run once ``rocking`` has verified a state; "thorough" and ``None`` run every start."""
    panel = alma.paper_panel(bond="stack", panel_ratio="2:1", block_ratio="4:1", friction=0.6)

    def starts(**search):
        result = alma.solve(panel, "nonassociative", settings=Settings(search=SearchSettings(**search)))
        return result, [s["start"].split("(")[0] for s in result.to_dict()["starts"]]

    ended, ran = starts(effort="fast", rocking_ends_blocks=0)
    assert ran == ["lp", "rocking"] and ended.to_dict()["start"] == "rocking"
    full, ran_all = starts(effort="fast", rocking_ends_blocks=None)
    assert ran_all == ["lp", "rocking", "gilbert", "gilbert", "tilt"]
    assert full.alpha == ended.alpha and full.status == ended.status == Status.FEASIBLE
    _, thorough = starts(effort="thorough", rocking_ends_blocks=0)
    assert "gilbert" in thorough and "tilt" in thorough


def test_a_fast_search_of_many_contact_points_skips_the_fixed_starts():
    """``fixed_starts_points``: above it (here 0 contact points) a fast search runs no fixed
    Gilbert or turned-table start; "thorough" and ``None`` run them."""
    panel = alma.paper_panel(bond="running", panel_ratio="2:1", block_ratio="4:1", friction=0.27)

    def starts(**search):
        result = alma.solve(panel, "nonassociative", settings=Settings(search=SearchSettings(**search)))
        return result, [s["start"].split("(")[0] for s in result.to_dict()["starts"]]

    _, ran = starts(effort="fast", fixed_starts_points=0)
    assert "gilbert" not in ran and "tilt" not in ran and ran[:2] == ["lp", "rocking"]
    _, ran_all = starts(effort="fast", fixed_starts_points=None)
    assert "gilbert" in ran_all and "tilt" in ran_all
    _, thorough = starts(effort="thorough", fixed_starts_points=0)
    assert "gilbert" in thorough and "tilt" in thorough
