"""alma.engine: the normal-matrix pattern, the factorisation backends, the interior point for
Eq. 10, and the hook in ``solve_lp`` (the certificate, not the engine, decides every status)."""

from __future__ import annotations

import ast
import dataclasses
import pickle
import warnings
from pathlib import Path
from typing import TypedDict

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings, strategies as st

import alma
from alma.associative.lp import NORMALISATION, solve_lp  # NORMALISATION: the default's value
from alma.engine import (
    IPMSettings,
    PatternCache,
    available_backends,
    make_factoriser,
    normal_pattern,
    select,
    solve_eq10,
    structure_key,
)
from alma.settings import AssociativeSettings


class Thresholds(TypedDict):  # the keyword arguments of select.choose that set engine="auto"'s sizes
    min_blocks: int
    min_blocks_bounded: int


#: The default thresholds of engine="auto".
AUTO = AssociativeSettings()
THRESHOLDS: Thresholds = {"min_blocks": AUTO.auto_min_blocks, "min_blocks_bounded": AUTO.auto_min_blocks_bounded}

ENGINE_DIR = Path(alma.__file__).parent / "engine"


def _rect(x0, y0, x1, y1):
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


def _wall(courses: int, per_course: int, friction: float = 0.6, live=(1.0, 0.0)) -> alma.Model:
    scene = alma.wall("running", 240.0 * per_course, 60.0 * courses, 240.0).with_friction(friction)
    if live != (1.0, 0.0):
        data = scene.to_dict()
        data["live_load"] = {"direction": list(live)}
        scene = alma.Scene.from_dict(data)
    return alma.build_model(scene)


@pytest.fixture(scope="module")
def wall() -> alma.Model:
    return _wall(6, 5)


def test_engine_imports_nothing_of_alma():
    """The engine takes plain data: its modules import numpy, scipy and backends only."""
    for path in ENGINE_DIR.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                assert node.level <= 1, (path.name, node.module)  # "from .x" inside the engine only
                assert not (node.module or "").startswith("alma"), (path.name, node.module)
            if isinstance(node, ast.Import):
                assert not any(a.name.startswith("alma") for a in node.names), path.name


def test_pattern_values_equal_h_d_ht(wall):
    H = wall.equilibrium
    pattern = normal_pattern(H)
    d = np.random.default_rng(1).uniform(0.1, 10.0, H.shape[1])
    expected = sp.triu(H @ sp.diags(d) @ H.T).toarray()
    got = pattern.matrix(d, shift=0.5).toarray()
    assert np.allclose(got, expected + 0.5 * np.eye(H.shape[0]), rtol=1e-13, atol=1e-12)
    stored = (expected != 0) | np.eye(H.shape[0], dtype=bool)
    assert pattern.nnz == np.count_nonzero(np.triu(np.ones_like(expected)) * stored)


def test_pattern_depends_on_geometry_not_friction(wall):
    a, b = normal_pattern(wall.equilibrium), normal_pattern(wall.with_friction(1.3).equilibrium)
    assert np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)


@pytest.mark.parametrize("friction", [0.27, 1.0, 1.3])
def test_a_pattern_is_reused_at_another_friction(wall, friction):
    """Issue 16, item 1: the pattern built at one f serves the others; its map D → K is the
    product H D Hᵀ of the new H, entries that cancel at this f included."""
    pattern = normal_pattern(wall.equilibrium)
    H = wall.with_friction(friction).equilibrium
    assert pattern.fits(H)
    d = np.random.default_rng(3).uniform(0.1, 10.0, H.shape[1])
    expected = sp.triu(H @ sp.diags(d) @ H.T).toarray()
    assert np.allclose(pattern.with_values(H).matrix(d).toarray(), expected, rtol=1e-13, atol=1e-12)


def test_a_pattern_is_not_reused_for_another_structure(wall):
    pattern = normal_pattern(wall.equilibrium)
    assert not pattern.fits(wall.with_friction(0.0).equilibrium)  # half the entries: its own pattern
    other = _wall(6, 5).equilibrium
    assert not pattern.fits(other) or other.shape == wall.equilibrium.shape
    assert not pattern.fits(wall.equilibrium[:, :-1].tocsc())
    with pytest.raises(ValueError, match="outside the structure"):
        normal_pattern(wall.equilibrium[:, :-4].tocsc()).with_values(wall.equilibrium)


def _same(a, b) -> bool:
    """Two LP solutions equal bit for bit (α, bounds, u, μ, iterations)."""
    return (
        a.status == b.status
        and a.iterations == b.iterations
        and a.alpha == b.alpha
        and a.lower == b.lower
        and a.upper == b.upper
        and np.array_equal(a.mechanism, b.mechanism)
        and np.array_equal(a.multipliers, b.multipliers)
    )


def test_the_frictions_of_a_geometry_share_one_pattern(wall):
    """A caller's PatternCache keeps the pattern of the structure solved; a model at another f
    reuses it, and the answer is the one of a fresh pattern bit for bit."""
    patterns = PatternCache()
    first = solve_lp(wall, engine="ipm", patterns=patterns)
    assert (len(patterns), patterns.hits, patterns.misses) == (1, 0, 1)
    other = wall.with_friction(0.4)
    again = solve_lp(other, engine="ipm", patterns=patterns)
    assert (len(patterns), patterns.hits, patterns.misses) == (1, 1, 1)
    fresh = solve_lp(alma.build_model(other.scene), engine="ipm")
    assert first.status == again.status == fresh.status == "optimal"
    assert _same(again, fresh)


def test_a_pattern_serves_only_its_own_structure(wall):
    """At f = 0 half of H's entries vanish: another structure, another key, its own pattern."""
    patterns = PatternCache()
    solve_lp(wall, engine="ipm", patterns=patterns)
    zero = wall.with_friction(0.0)
    assert structure_key(zero.equilibrium, zero.equilibrium.shape[0]) != structure_key(
        wall.equilibrium, wall.equilibrium.shape[0]
    )
    cached = solve_lp(zero, engine="ipm", patterns=patterns)
    assert (len(patterns), patterns.hits) == (2, 0)
    assert _same(cached, solve_lp(zero, engine="ipm"))
    # the key is the structure, not the values: the same H at another friction has the same key
    H1, H2 = wall.equilibrium, wall.with_friction(1.3).equilibrium
    assert not np.array_equal(H1.data, H2.data)
    assert structure_key(H1, H1.shape[0]) == structure_key(H2, H2.shape[0])
    assert structure_key(H1, H1.shape[0]) != structure_key(H1, H1.shape[0] - 3)


def test_solve_lp_writes_nothing_into_the_model(wall):
    """The solver reads its model: every field and H are the same, bit for bit, after a solve
    (scipy sorts an unsorted matrix in place on first use, even through a transposed view:
    H is built sorted), so a second solve of the same model gives the first one's answer."""
    model = wall.with_friction(0.5)

    def state() -> bytes:
        return pickle.dumps(
            [*(getattr(model, f.name) for f in dataclasses.fields(model)), model.equilibrium, model.equilibrium.indices]
        )

    before = state()
    first = solve_lp(model, engine="ipm", patterns=PatternCache())
    solve_lp(model, engine="clarabel")
    assert state() == before
    assert not hasattr(model, "derived")
    assert _same(solve_lp(model, engine="ipm"), first)


@settings(max_examples=8, deadline=None)
@given(friction=st.floats(0.05, 2.0))
def test_a_warm_cache_never_changes_the_answer(wall, friction):
    """Property: whatever was solved before, the answer at f is the fresh one, bit for bit."""
    patterns = PatternCache()
    solve_lp(wall, engine="ipm", patterns=patterns)
    model = wall.with_friction(friction)
    assert _same(solve_lp(model, engine="ipm", patterns=patterns), solve_lp(model, engine="ipm"))


@pytest.mark.parametrize("backend", available_backends())
def test_backend_solves_k(wall, backend):
    H = wall.equilibrium
    pattern = normal_pattern(H)
    rng = np.random.default_rng(2)
    d = 10.0 ** rng.uniform(-4, 4, H.shape[1])
    full = (H @ sp.diags(d) @ H.T + 1e-8 * sp.eye(H.shape[0])).tocsc()
    factoriser = make_factoriser(pattern, backend)
    rhs = rng.standard_normal((H.shape[0], 2))
    for _ in range(2):  # the second factorisation reuses the symbolic analysis
        factoriser.factor(pattern.values(d, 1e-8))
        x = factoriser.solve(rhs)
        assert np.abs(full @ x - rhs).max() <= 1e-8 * np.abs(rhs).max() * max(1.0, float(np.abs(full).max()))
    factoriser.close()


@pytest.mark.parametrize("backend", available_backends())
def test_backend_solves_the_bordered_system(wall, backend):
    """[K f_L; f_Lᵀ 0] [x; a] = [g; h]: by the Schur complement, or (feral) by factorising the
    bordered matrix, one right-hand side per solve after the first factorisation's K⁻¹ f_L."""
    H, f = wall.equilibrium, wall.live
    pattern = normal_pattern(H)
    rng = np.random.default_rng(3)
    d = 10.0 ** rng.uniform(-4, 4, H.shape[1])
    K = (H @ sp.diags(d) @ H.T + 1e-8 * sp.eye(H.shape[0])).tocsc()
    factoriser = make_factoriser(pattern, backend, border=f)
    for _ in range(2):
        factoriser.factor(pattern.values(d, 1e-8))
        g, h = rng.standard_normal(H.shape[0]), float(rng.standard_normal())
        x, a = factoriser.solve_bordered(g, h)
        scale = max(1.0, float(np.abs(K).max())) * max(1.0, float(np.abs(f).max()))
        assert np.abs(K @ x + f * a - g).max() <= 1e-8 * scale * max(1.0, abs(a), float(np.abs(x).max()))
        assert abs(f @ x - h) <= 1e-8 * scale * max(1.0, float(np.abs(x).max()))
    factoriser.close()


def test_unknown_backend_and_engine_are_refused(wall):
    with pytest.raises(ValueError):
        make_factoriser(normal_pattern(wall.equilibrium), "nonesuch")
    with pytest.raises(ValueError):
        select.choose("nonesuch", 10, **THRESHOLDS)


@pytest.mark.parametrize("backend", available_backends())
def test_ipm_agrees_with_clarabel_and_is_certified(wall, backend):
    clarabel = solve_lp(wall, engine="clarabel")
    raw = solve_eq10(wall.equilibrium, wall.dead, wall.live, NORMALISATION * wall.n_free, IPMSettings(backend=backend))
    assert raw.status == "optimal" and raw.backend == backend
    assert abs(raw.alpha - clarabel.alpha) <= 1e-7 * max(1.0, abs(clarabel.alpha))
    assert float(raw.mu.min()) >= 0.0
    assert abs(float(wall.live @ raw.u) - NORMALISATION * wall.n_free) <= 1e-8 * NORMALISATION * wall.n_free
    ipm = solve_lp(wall, engine="ipm")
    assert ipm.status == "optimal", ipm.message
    assert "alma-ipm" in ipm.message and "Clarabel used" not in ipm.message
    assert ipm.lower <= clarabel.upper + 1e-9 and clarabel.lower <= ipm.upper + 1e-9


def test_iteration_budget_is_a_count(wall):
    """max_iter stops the iteration at that count whatever the machine (no clock)."""
    raw = solve_eq10(wall.equilibrium, wall.dead, wall.live, NORMALISATION * wall.n_free, IPMSettings(max_iter=3))
    assert raw.status == "max_iterations" and raw.iterations == 3


def test_no_collapse_falls_back_to_clarabel_and_says_so():
    """Live load pushing down into the ground: no mechanism does positive live work."""
    model = _wall(2, 2, live=(0.0, -1.0))
    result = solve_lp(model, engine="ipm")
    assert result.status == "no_collapse"
    assert "Clarabel used" in result.message


def test_no_equilibrium_falls_back_to_clarabel_and_says_so():
    """Gravity pulling the blocks up off the ground: no stress field for any α."""
    scene = alma.wall("running", 480.0, 120.0, 240.0)
    data = scene.to_dict()
    data["gravity"] = [0.0, 1.0]
    model = alma.build_model(alma.Scene.from_dict(data))
    result = solve_lp(model, engine="ipm")
    assert result.status == "no_equilibrium"
    assert "Clarabel used" in result.message


def test_auto_without_fast_backend_warns_once_and_uses_clarabel(monkeypatch, wall):
    monkeypatch.setattr(select, "available_backends", lambda: ("qdldl",))
    assert select.choose("auto", AUTO.auto_min_blocks - 1, **THRESHOLDS) == "clarabel"  # small: no warning
    assert select.choose("auto", AUTO.auto_min_blocks - 1, **THRESHOLDS) == "clarabel"  # small: no warning needed
    with pytest.warns(RuntimeWarning, match="Clarabel"):
        assert select.choose("auto", 10_000, **THRESHOLDS) == "clarabel"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert select.choose("auto", 10_000, **THRESHOLDS) == "clarabel"  # said once only
    result = solve_lp(wall, engine="auto")
    assert result.status == "optimal" and "Clarabel" in result.message and "alma-ipm" not in result.message


def test_auto_chooses_by_size(monkeypatch):
    monkeypatch.setattr(select, "available_backends", lambda: ("feral", "qdldl"))
    assert select.choose("auto", AUTO.auto_min_blocks - 1, **THRESHOLDS) == "clarabel"
    assert select.choose("auto", AUTO.auto_min_blocks, **THRESHOLDS) == "ipm"
    assert select.choose("clarabel", 10**6, **THRESHOLDS) == "clarabel"
    assert select.choose("ipm", 1, **THRESHOLDS) == "ipm"
    assert select.choose("auto", AUTO.auto_min_blocks_bounded - 1, bounded=True, **THRESHOLDS) == "clarabel"
    assert select.choose("auto", AUTO.auto_min_blocks_bounded, bounded=True, **THRESHOLDS) == "ipm"


def test_crossed_bounds_are_not_certified():
    """A lower bound above the upper one (measured on test_mixed_tiny_and_huge through a trial
    engine setting: [0.011901605, 0.011899563], relative gap −2.0e-6) proves nothing."""
    from alma.associative.lp_forms import _judge
    from alma.settings import AssociativeSettings
    from alma.status import Status

    s = AssociativeSettings()
    status, _, _, _ = _judge(s, Status.OPTIMAL, "trial", 0.011901605, 0.011899563, 0.0, 0.0)
    assert status != Status.OPTIMAL
    status, _, _, _ = _judge(s, Status.OPTIMAL, "trial", 0.2736352830, 0.2736352834, 0.0, 0.0)
    assert status == Status.OPTIMAL


def _bounded_wall() -> alma.Model:
    """A small wall with cohesion on every joint and one tie between two end blocks."""
    data = alma.wall("running", 720.0, 180.0, 240.0).with_friction(0.6).to_dict()
    free = [b for b in data["blocks"] if not b.get("fixed")]
    a, b = free[0], free[-1]
    data["cohesion"] = 2.0
    data["ties"] = [
        {
            "id": "t",
            "from": {"block": a["id"], "point": a["vertices"][0]},
            "to": {"block": b["id"], "point": b["vertices"][2]},
            "strength": 0.5,
        }
    ]
    return alma.build_model(alma.Scene.from_dict(data))


def test_auxiliary_elimination_is_the_exact_schur_complement():
    """U diag(d_eff) Uᵀ equals the Schur complement of the v block of H_aug D H_augᵀ, and
    reduce → solve → expand solves the augmented system."""
    from alma.associative.lp_forms import _engine_form
    from alma.engine.auxiliary import auxiliary_rows

    model = _bounded_wall()
    H_aug, _, _ = _engine_form(model, model.equilibrium)
    n = model.equilibrium.shape[0]
    aux = auxiliary_rows(H_aug, n)
    assert aux.n_aux == H_aug.shape[0] - n > 1
    d = np.exp(np.random.default_rng(3).uniform(-8, 8, H_aug.shape[1]))  # D spans 7 orders
    K = (H_aug @ sp.diags(d) @ H_aug.T).toarray()
    A, B, C = K[:n, :n], K[:n, n:], K[n:, n:]
    assert np.allclose(C, np.diag(np.diag(C)), rtol=0, atol=0)  # the v block is diagonal
    c, s, d_eff = aux.weights(d)
    reduced = (aux.U @ sp.diags(d_eff) @ aux.U.T).toarray()
    schur = A - B @ np.diag(1.0 / np.diag(C)) @ B.T
    assert np.allclose(reduced, schur, rtol=1e-10, atol=1e-10 * np.abs(A).max())
    g = np.random.default_rng(4).normal(size=H_aug.shape[0])
    x = aux.expand(np.linalg.solve(reduced + 1e-12 * np.eye(n), aux.reduce(g, c, s)), g, c, s)
    assert np.allclose(K @ x, g, rtol=1e-6, atol=1e-6 * np.abs(g).max())


def test_auxiliary_rows_must_hold_parallel_columns():
    from alma.engine.auxiliary import auxiliary_rows

    U = sp.csc_matrix(np.array([[1.0, 0.0], [0.0, 1.0]]))
    V = sp.csc_matrix(np.array([[1.0, 1.0]]))  # two columns on one v row, not parallel on u
    with pytest.raises(ValueError, match="not parallel"):
        auxiliary_rows(sp.vstack([U, V]).tocsc(), 2)
    with pytest.raises(ValueError, match="more than one auxiliary row"):
        auxiliary_rows(sp.vstack([U, sp.csc_matrix(np.ones((2, 2)))]).tocsc(), 2)


def test_the_interior_point_takes_cohesion_and_ties_without_clarabel():
    model = _bounded_wall()
    ipm, clarabel = solve_lp(model, engine="ipm"), solve_lp(model, engine="clarabel")
    assert "alma-ipm" in ipm.message and "Clarabel used" not in ipm.message, ipm.message
    assert ipm.status == clarabel.status == "optimal"
    assert ipm.alpha == pytest.approx(clarabel.alpha, rel=1e-7)
    assert ipm.bounded_forces.shape == clarabel.bounded_forces.shape == (model.n_bounded,)


@pytest.mark.skipif("feral" not in available_backends(), reason="feral-solver is not installed here")
def test_certificate_gram_solves_agree_between_qdldl_and_feral(monkeypatch, wall):
    """The certificate's Gram solves go to feral on large walls (alma.backends.gram_backend): on
    a small wall forced there, the solution and the certified bounds match QDLDL's."""
    from alma.backends import gram_backend
    from alma.backends.qdldl_backend import regularised_solver as qdldl_solver

    H = wall.equilibrium
    gram = (H @ H.T).tocsc()
    b = np.random.default_rng(1).standard_normal(gram.shape[0])
    reference = solve_lp(wall, engine="ipm")
    x = gram_backend.regularised_solver(gram, feral_min_rows=1)(b)
    assert np.abs(x - qdldl_solver(gram)(b)).max() <= 1e-9 * np.abs(x).max()
    forced = solve_lp(wall, AssociativeSettings(feral_min_rows=1), engine="ipm")
    assert forced.status == reference.status == alma.Status.OPTIMAL
    assert forced.lower == pytest.approx(reference.lower, abs=1e-11)
    assert forced.upper == pytest.approx(reference.upper, abs=1e-11)


def test_auto_backend_takes_qdldl_below_its_size(monkeypatch, wall):
    """``auto``: QDLDL for K below ``IPMSettings.qdldl_max_rows`` rows (faster there), feral above."""
    from alma.engine import cholesky

    monkeypatch.setattr(cholesky, "available_backends", lambda: ("feral", "qdldl"))
    pattern = normal_pattern(wall.equilibrium)
    assert pattern.n < IPMSettings().qdldl_max_rows
    if "feral" in available_backends():
        assert make_factoriser(pattern, "auto").name == "qdldl"
        assert make_factoriser(pattern, "auto", qdldl_max_rows=pattern.n).name == "feral"
    monkeypatch.setattr(cholesky, "available_backends", lambda: ("pardiso", "feral", "qdldl"))
    monkeypatch.setattr(cholesky, "PardisoFactoriser", lambda p, b=None: type("P", (), {"name": "pardiso"})())
    monkeypatch.setitem(cholesky._BACKENDS, "pardiso", ("pypardiso", cholesky.PardisoFactoriser))
    assert make_factoriser(pattern, "auto").name == "pardiso"  # Pardiso is not displaced
