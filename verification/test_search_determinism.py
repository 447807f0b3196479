"""The non-associative search spends work budgets, not seconds: the same answer under any load.

Issue 15: with wall-clock shares, `make test` failed on another machine because the starts got
other shares of the clock under load.  These tests run the search with and without a CPU hog
beside it and demand the same states bit for bit, check that solver output never reaches
stdout (``--json`` must print JSON only), and that the user's time cap is reported.
"""

from __future__ import annotations

import json
import multiprocessing
import os

import pytest

import alma
from alma.associative.lp import solve_lp
from alma.cli.main import main
from alma.mechanics.model import build_model
from alma.nonassociative.fixed_set_lps import FixedSetLPs
from alma.nonassociative.search import solve_nonassociative
from benchmarks.bench_friction import stack_with_cohesion

#: Small-to-medium paper panels (78 to 228 blocks) whose searches run Gilbert starts to their
#: budgets: english 1:1 4:1 f = 1 verifies only with its second fixed start.
PANELS = [("english", "1:1", "4:1", 1.0), ("stack", "2:1", "2:1", 0.6), ("flemish", "2:1", "4:1", 0.27)]


def _spin() -> None:  # pragma: no cover - runs in a child process
    while True:
        pass


def _fingerprint(bond: str, panel: str, block: str, friction: float) -> tuple:
    """α, the candidates (start, α, verified) and the work of every start, exactly as floats."""
    model = build_model(alma.paper_panel(bond, panel, block, friction))
    lp = solve_lp(model)
    solution = solve_nonassociative(model, lp.mechanism, lp.multipliers, effort="fast", associative_alpha=lp.alpha)
    assert not solution.stopped_by_limit
    candidates = tuple((c.start, c.alpha.hex(), c.verified) for c in solution.candidates)
    work = tuple((r.start, r.iterations, r.pivots, r.lp_solves) for r in solution.starts)
    return solution.best.alpha.hex() if solution.best is not None else None, candidates, work


@pytest.mark.slow  # spins every core for the length of three searches, stalling the other xdist worker
def test_same_states_with_a_cpu_hog_beside_the_search():
    """Three panels, once plainly and once with every core spinning: identical α, identical
    candidate lists (start names, α bit for bit, verified flags) and identical work per start."""
    plain = [_fingerprint(*panel) for panel in PANELS]
    context = multiprocessing.get_context("spawn")
    hogs = [context.Process(target=_spin, daemon=True) for _ in range(os.cpu_count() or 2)]
    try:
        for hog in hogs:
            hog.start()
        loaded = [_fingerprint(*panel) for panel in PANELS]
    finally:
        for hog in hogs:
            hog.terminate()
        for hog in hogs:
            hog.join()
    assert loaded == plain
    assert all(alpha is not None for alpha, _, _ in plain)


def test_a_nonassociative_solve_prints_nothing_on_stdout(capfd):
    """No solver (HiGHS, Clarabel, IPOPT) writes to file descriptor 1 during a search, the
    certification included."""
    scene = alma.paper_panel("stack", "2:1", "4:1", 0.6)
    capfd.readouterr()
    result = alma.solve(scene, model="nonassociative", effort="thorough", certify=False)
    assert result.status == "feasible"
    small = alma.Scene.from_dict(
        {
            "friction": 1.0,
            "blocks": [
                {"id": "g", "vertices": [[-1, -1], [4, -1], [4, 0], [-1, 0]], "fixed": True},
                {"id": "a", "vertices": [[0, 0], [1, 0], [1, 2], [0, 2]]},
                {"id": "b", "vertices": [[1, 0], [2, 0], [2, 2], [1, 2]]},
                {"id": "c", "vertices": [[2, 0], [3, 0], [3, 2], [2, 2]]},
            ],
        }
    )
    certified = alma.solve(small, model="nonassociative", certify=True)
    assert certified.extra["certificate"]["status"] == "proven"
    out, _ = capfd.readouterr()
    assert out == ""


def test_json_output_is_json_only(capfd):
    """``alma panel ... --model nonassociative --json`` prints exactly one JSON object on fd 1."""
    code = main(
        [
            "panel",
            "--bond",
            "stack",
            "--panel-ratio",
            "2:1",
            "--block-ratio",
            "4:1",
            "--friction",
            "0.6",
            "--model",
            "nonassociative",
            "--json",
        ]
    )
    assert code == 0
    out, _ = capfd.readouterr()
    assert json.loads(out)["model"] == "nonassociative"


def test_a_tiny_time_limit_is_reported_as_stopped_by_limit():
    """A cap far below the search's work stops it: the flag is set and the cut starts are named."""
    model = build_model(alma.paper_panel("english", "1:1", "4:1", 1.0))
    lp = solve_lp(model)
    solution = solve_nonassociative(
        model, lp.mechanism, lp.multipliers, effort="fast", time_limit=1e-3, associative_alpha=lp.alpha
    )
    assert solution.stopped_by_limit
    assert solution.skipped and "gilbert(N̄=1·N_LP, r=0.5, steps=0)" in solution.skipped


@pytest.mark.parametrize("effort", ["fast", "thorough"])
def test_no_limit_means_not_stopped(effort):
    model = build_model(alma.paper_panel("running", "2:1", "4:1", 0.6))
    lp = solve_lp(model)
    solution = solve_nonassociative(model, lp.mechanism, lp.multipliers, effort=effort, associative_alpha=lp.alpha)
    assert not solution.stopped_by_limit and solution.skipped == ()
    assert solution.status == "feasible"


def _wall_fingerprint(scene: alma.Scene) -> tuple:
    """α, candidates and per-start work of a thorough search, exactly as floats."""
    model = build_model(scene)
    lp = solve_lp(model)
    solution = solve_nonassociative(model, lp.mechanism, lp.multipliers, effort="thorough", associative_alpha=lp.alpha)
    candidates = tuple((c.start, c.alpha.hex(), c.verified) for c in solution.candidates)
    work = tuple((r.start, r.iterations, r.pivots, r.lp_solves) for r in solution.starts)
    return solution.best.alpha.hex() if solution.best is not None else None, candidates, work


@pytest.mark.parametrize("name", [pytest.param("stack panel", marks=pytest.mark.slow), "cohesive stack"])
def test_the_store_of_fixed_set_lps_changes_no_answer(monkeypatch, name):
    """The search's store of fixed-set LPs (:class:`FixedSetLPs`) serves repeats, and the search
    without it (every LP solved anew) gives the same α, candidates and work bit for bit: a paper
    panel (144 blocks) and the 12-block stack with cohesion and weaker joints (bounded forces)."""
    scene = alma.paper_panel("stack", "2:1", "2:1", 0.6) if name == "stack panel" else stack_with_cohesion()
    served = []
    stored = FixedSetLPs._stored

    def counting(self, key, cap):
        hit = stored(self, key, cap)
        served.append(hit is not None)
        return hit

    monkeypatch.setattr(FixedSetLPs, "_stored", counting)
    with_store = _wall_fingerprint(scene)
    assert any(served), "no fixed-set LP repeated: the test no longer exercises the store"
    monkeypatch.setattr(FixedSetLPs, "_stored", lambda self, key, cap: None)
    assert _wall_fingerprint(scene) == with_store
