"""Starts that do not depend on how the load is written: the same structure on a turned table.

Eq. 9 with dead load f₀ and live load f_L is the same problem as with f₀' = c f₀ + s f_L and
f_L' = c f_L − s f₀ (c = cos θ, s = sin θ): gravity and the live load turned together by θ, as
on a tilting table.  A collapse state (N, T, u, α') of the turned problem is one of the original
with α = (s + c α') / (c − s α') = tan(θ + atan α') and forces divided by c − s α' > 0 (the
cohesionless yield domain is a cone).  The associative LP and Gilbert's iteration end on other
active sets in the turned problem, so its states are new starts: LACT³'s Portal reaches states
25 % below the horizontal posing's best this way (issue 20).  With cohesion and ties the yield
domain is no cone (their capacities do not scale with the forces), so the turned state's
mechanism is made an exact state of the original problem instead (:func:`exact_state`, verified
there).  Dimensionless, as
:mod:`alma.mechanics.model`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from alma.associative.lp import solve_lp
from alma.floats import dot
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.exact_states import exact_state_by
from alma.nonassociative.gilbert import gilbert
from alma.nonassociative.limits import Work
from alma.nonassociative.states import CollapseState, Tally, verify
from alma.settings import StateTolerances
from alma.status import Status


def turned(model: Model, degrees: float) -> Model:
    """``model`` with gravity and the live load turned together by ``degrees``."""
    t = math.radians(degrees)
    c, s = math.cos(t), math.sin(t)
    return dataclasses.replace(model, dead=c * model.dead + s * model.live, live=c * model.live - s * model.dead)


def mapped_back(
    model: Model,
    points: ContactPoints,
    state: CollapseState,
    degrees: float,
    name: str,
    tolerances: StateTolerances | None = None,
) -> CollapseState | None:
    """A state of the turned problem as a state of the original (see the module docstring),
    verified there; None when the turned α' is beyond the table's turn (c − s α' ≤ 0)."""
    t = math.radians(degrees)
    c, s = math.cos(t), math.sin(t)
    scale = c - s * state.alpha
    if not scale > 0:
        return None
    alpha = (s + c * state.alpha) / scale
    normal, shear = state.normal / scale, state.shear / scale
    mechanism = state.mechanism * (model.n_free / max(dot(model.live, state.mechanism), 1e-300))
    residuals, ok = verify(
        model,
        points,
        alpha,
        normal,
        shear,
        mechanism,
        tolerances=tolerances if tolerances is not None else StateTolerances(),
    )
    return CollapseState(
        alpha=alpha, normal=normal, shear=shear, mechanism=mechanism, start=name, residuals=residuals, verified=ok
    )


@dataclass(frozen=True)
class TiltStart:
    """Gilbert's iteration (N̄ = ``scale`` × the turned LP's N, relaxation, slope steps) on the
    structure turned by ``degrees``, its state mapped back; iterations: the turned problem's LP
    solves."""

    degrees: float
    work: Work
    scale: float = 0.5
    relaxation: float = 0.5
    slope_steps: int = 1
    ipm_above: int = 6000
    yield_rows: bool = False  # the sloped LP with its yield conditions as rows

    @property
    def name(self) -> str:
        return f"tilt({self.degrees:g}°{', rows' if self.yield_rows else ''})"

    def run(self, ctx, tally: Tally) -> tuple[CollapseState | None, int]:
        model = turned(ctx.model, self.degrees)
        lp = solve_lp(model)
        tally.add(lp.iterations)
        if lp.status != Status.OPTIMAL or not np.isfinite(lp.alpha):
            return None, 1
        normal = lp.multipliers.reshape(-1, 2).sum(axis=1)
        state, solves = gilbert(
            model,
            ctx.points,
            self.scale * normal,
            start=self.name,
            relaxation=self.relaxation,
            slope_steps=self.slope_steps,
            ipm_above=self.ipm_above,
            yield_rows=self.yield_rows,
            work=self.work,
            cap=ctx.cap,
            tally=tally,
        )
        if state is None or not state.verified:
            return None, solves + 1
        if ctx.model.n_bounded:
            return exact_state_by(
                self.work.exact_method,
                ctx.model,
                ctx.points,
                state.mechanism,
                self.name,
                limits=self.work.exact_limits(tally),
                tally=tally,
                lps=ctx.lps,
            ), solves + 1
        return mapped_back(ctx.model, ctx.points, state, self.degrees, self.name, self.work.tolerances), solves + 1
