"""The solver layer does not move an answer: α_NL, its status and its winning start, and the
associative α, as the code gave them before every solver call went through ``alma/backends/``.

The friction search (Eq. 9) branches on LP vertices, so its answer hangs on the last bits of
every solve; these values were recorded at commit 7051f4d (before issue 35's solver layer) with
the solver releases below (those of constraints.txt), and the refactored code reproduced them
exactly (repr-identical on 21 scenes: docs/decisions.md, "One solver layer").  Another solver
release may pick other vertices of degenerate LPs (docs/decisions.md, "Still open: the solver's
release"), so the check runs only with the releases it was recorded with.  These are alma's own
earlier answers, not published values.
"""

from __future__ import annotations

import importlib.metadata

import pytest
from test_friction_invariance import stack_with_cohesion, tied_pier

import alma
from alma.geometry.scene import Scene

RELEASES = {"highspy": "1.15.1", "scipy": "1.17.1", "clarabel": "0.11.1"}
REL = 1e-12

WALL_1 = [[0.5, 1, 1, 1, 1, 0.5] if i % 2 == 0 else [1] * 5 for i in range(6)]
SCENES = {
    "stack panel": lambda: alma.paper_panel("stack", "2:1", "4:1", 0.6),
    "stack 3x4 with cohesion": lambda: Scene.from_dict(stack_with_cohesion()),
    "tied portal with a point load": lambda: Scene.from_dict(tied_pier()),
    "Ferris & Tin-Loi wall 1": lambda: alma.coursed_wall(
        WALL_1, 400.0, 175.0, friction=0.65, thickness=1000.0, unit_weight=10.0
    ),
}
#: (α_NL, status, start kept, associative α), recorded at 7051f4d.
RECORDED = {
    "stack panel": (0.33333333333057613, "feasible", "rocking", 0.41912002594745845),
    "stack 3x4 with cohesion": (0.5644765770336546, "feasible", "gilbert(N̄=0·N_LP, r=1, steps=1)", 0.6143468737571647),
    "tied portal with a point load": (0.48141891891891886, "feasible", "lp", 0.4814189189193672),
    "Ferris & Tin-Loi wall 1": (0.6389818336852203, "feasible", "gilbert(N̄=0·N_LP, r=1, steps=1)", 0.6428590033278915),
}


def _other_releases() -> list[str]:
    return [
        f"{name} {importlib.metadata.version(name)} (recorded with {pinned})"
        for name, pinned in RELEASES.items()
        if importlib.metadata.version(name) != pinned
    ]


@pytest.mark.parametrize("name", sorted(SCENES))
def test_answer_is_the_one_recorded_before_the_solver_layer(name):
    other = _other_releases()
    if other:
        pytest.skip("recorded with other solver releases: " + ", ".join(other))
    alpha_nl, status, start, alpha_assoc = RECORDED[name]
    result = alma.solve(SCENES[name](), model="both")
    nl = result.nonassociative
    assert nl.alpha == pytest.approx(alpha_nl, rel=REL, abs=0.0)
    assert (str(nl.status), nl.start) == (status, start)
    assert str(result.associative.status) == "optimal"
    assert result.associative.alpha == pytest.approx(alpha_assoc, rel=REL, abs=0.0)
