"""The projection of Gilbert's projected iteration (`alma.nonassociative.cap_lp.ClosestField`):
the closest static field to N̄ among those that carry the capped LP's α (Eqs. 3 and 5)."""

from __future__ import annotations

import alma


def test_closest_field_returns_a_field_that_is_already_admissible():
    """The projection of an admissible field onto the fields carrying the same α is the field itself."""
    import numpy as np

    from alma.associative.lp import solve_lp
    from alma.mechanics.contact_points import ContactPoints
    from alma.mechanics.model import build_model
    from alma.nonassociative.cap_lp import CapLP
    from alma.nonassociative.closest_field import ClosestField

    model = build_model(alma.paper_panel("running", "2:1", "2:1", 0.6))
    points = ContactPoints.from_model(model)
    lp = solve_lp(model)
    cap = points.friction * lp.multipliers.reshape(-1, 2).sum(axis=1)
    vertex = CapLP(model, points).solve(np.zeros(points.count), cap)
    # The QP stops when ½‖N − N̄‖² is within its gap tolerance of the optimum 0, so N is resolved
    # only to about the square root of it: at the search's 1e-10, 4.7e-5 (1.1e-6 of the largest N)
    # from the vertex the caps-as-bounds model returns since 2026-11-23.  The projection itself is
    # checked here at 1e-12.
    closest = ClosestField(model, points, tolerance=1e-12)
    solved = closest.solve(vertex.alpha, cap, vertex.normal)
    assert solved is not None
    normal, shear, tau = solved
    assert tau.size == 0  # no cohesion, no ties
    scale = float(np.abs(vertex.normal).max())
    assert np.abs(normal - vertex.normal).max() <= 1e-6 * scale
    equilibrium = points.normal @ normal + points.tangent @ shear + model.dead + vertex.alpha * model.live
    assert np.abs(equilibrium).max() <= 1e-7 * scale
    assert normal.min() >= 0 and (np.abs(shear) - cap).max() <= 1e-7 * scale
    # Another target: the result is at least as close to it as the vertex is.
    target = 0.5 * vertex.normal
    solved = closest.solve(vertex.alpha, cap, target)
    assert solved is not None
    normal2, _, _ = solved
    assert np.linalg.norm(normal2 - target) <= np.linalg.norm(vertex.normal - target) + 1e-7 * scale


def test_closest_field_on_the_lps_face_is_the_projection_onto_that_face():
    """The QP written on the capped LP's face (N = 0 where its mechanism opens, T at the cap where
    it slips) gives the field the QP over every force gives at the LP's α less a hair (the face),
    complementary to the mechanism, balanced and admissible."""
    import numpy as np

    from alma.associative.lp import solve_lp
    from alma.mechanics.contact_points import ContactPoints
    from alma.mechanics.model import build_model
    from alma.nonassociative.cap_lp import CapLP
    from alma.nonassociative.closest_field import ClosestField
    from alma.nonassociative.states import active_set

    model = build_model(alma.paper_panel("running", "2:1", "2:1", 0.6))
    points = ContactPoints.from_model(model)
    cap = points.friction * solve_lp(model).multipliers.reshape(-1, 2).sum(axis=1)
    vertex = CapLP(model, points).solve(np.zeros(points.count), cap)
    assert vertex.mechanism is not None
    open_points, slip_sign = face = active_set(model, points, vertex.mechanism)
    assert open_points.any() and slip_sign.any()
    alpha, target = vertex.alpha - 1e-9 * abs(vertex.alpha), 0.5 * vertex.normal
    closest = ClosestField(model, points, tolerance=1e-12)
    on_face, everywhere = closest.solve(alpha, cap, target, face), closest.solve(alpha, cap, target)
    assert on_face is not None and everywhere is not None
    normal, shear, _ = on_face
    scale = float(np.abs(vertex.normal).max())
    # The full QP reaches the sliver beyond the face that the hair opens: 2.6e-6 of the largest N
    # apart here, and never closer to the target on the face, which is the smaller set.
    assert np.abs(normal - everywhere[0]).max() <= 1e-5 * scale
    assert np.linalg.norm(normal - target) >= np.linalg.norm(everywhere[0] - target) - 1e-9 * scale
    assert np.all(normal[open_points] == 0.0)
    slipping = slip_sign != 0
    assert np.array_equal(shear[slipping], -slip_sign[slipping] * cap[slipping])
    equilibrium = points.normal @ normal + points.tangent @ shear + model.dead + alpha * model.live
    assert np.abs(equilibrium).max() <= 1e-7 * scale
    assert normal.min() >= 0 and (np.abs(shear) - cap).max() <= 1e-7 * scale
