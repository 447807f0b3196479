"""The starts of the non-associative search, one class each behind the :class:`Start` protocol.

A start turns what the search knows so far (:class:`Context`) into one candidate collapse
state, spending the work its settings allow; :mod:`alma.nonassociative.policy` decides which
starts run, and :mod:`alma.nonassociative.search` runs them in turn.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Protocol, cast

import numpy as np

from alma.backends.linprog_backend import LPMethod
from alma.certify.milp import certify
from alma.mechanics.contact_points import ContactPoints
from alma.mechanics.model import Model
from alma.nonassociative.exact_states import exact_state, fast_exact_state
from alma.nonassociative.fixed_set_lps import FixedSetLPs
from alma.nonassociative.gilbert import gilbert, projected_gilbert
from alma.nonassociative.limits import Cap, Work, no_cap
from alma.nonassociative.nlp import ipopt_polish
from alma.nonassociative.rocking import rocking_candidates
from alma.nonassociative.spread import spread_factors
from alma.nonassociative.states import CollapseState, ExactLimits, Tally, lowest
from alma.settings import CertifySettings, SearchSettings


@dataclass
class Context:
    """What every start sees: the scene, the associative solution, the candidates so far."""

    model: Model
    points: ContactPoints
    settings: SearchSettings
    effort: str  # "fast" | "thorough"
    cap: Cap
    associative_mechanism: np.ndarray | None
    associative_normal: np.ndarray  # N of the associative static field at each contact point
    associative_alpha: float | None
    candidates: list[CollapseState] = field(default_factory=list)
    #: The user's certification settings, for the ``milp`` start (its nodes are the search's work).
    certify: CertifySettings = field(default_factory=CertifySettings)
    #: The fixed-set LPs of ``model`` solved so far, shared by the starts.
    lps: FixedSetLPs = field(init=False)

    def __post_init__(self) -> None:
        self.lps = FixedSetLPs(self.model, self.points)

    def verified(self) -> list[CollapseState]:
        """The verified candidates so far."""
        return [c for c in self.candidates if c.verified]

    def best(self) -> CollapseState | None:
        """The verified candidate with the lowest α, if any (the earliest of those within
        :attr:`~alma.settings.SearchSettings.same_alpha` of it: round-off does not choose)."""
        return lowest(self.verified(), self.settings.same_alpha)

    def exact_limits(self, vertex: bool = False) -> ExactLimits:
        """Iteration caps of an exact state (``vertex``: HiGHS's vertex within ``vertex_pivots``)."""
        s = self.settings
        return ExactLimits(s.lp_pivots, s.vertex_pivots if vertex else s.lp_pivots, s.interior_iterations, s.states)


class Start(Protocol):
    """One way of finding a collapse state."""

    @property
    def name(self) -> str:
        """The start's name in the search's records (read-only: the starts are frozen)."""
        ...

    def run(self, ctx: Context, tally: Tally) -> tuple[CollapseState | None, int]:
        """The start's best state (None: none) and its iterations, its work counted in ``tally``."""
        ...


@dataclass(frozen=True)
class LpStart:
    """The active set of the associative mechanism (Eq. 10), its dilatant openings read as slips."""

    name: str = "lp"

    def run(self, ctx: Context, tally: Tally) -> tuple[CollapseState | None, int]:
        if ctx.associative_mechanism is None:
            return None, 0
        if ctx.points.count <= ctx.settings.lp_vertex_points:  # HiGHS's vertex: exact to the last digit
            return exact_state(
                ctx.model,
                ctx.points,
                ctx.associative_mechanism,
                self.name,
                dilatant=True,
                limits=ctx.exact_limits(),
                tally=tally,
                lps=ctx.lps,
            ), 0
        if ctx.points.count > ctx.settings.lp_widest_points:  # the associative set itself, by Clarabel
            return exact_state(
                ctx.model,
                ctx.points,
                ctx.associative_mechanism,
                self.name,
                dilatant=True,
                method=LPMethod.CLARABEL,
                limits=ctx.exact_limits(vertex=True),
                tally=tally,
                widest=False,
                lps=ctx.lps,
            ), 0
        return fast_exact_state(
            ctx.model,
            ctx.points,
            ctx.associative_mechanism,
            self.name,
            dilatant=True,
            limits=ctx.exact_limits(vertex=True),
            tally=tally,
            lps=ctx.lps,
        ), 0


def rocking_start(
    model: Model,
    points: ContactPoints,
    verified: list[CollapseState],
    *,
    tries: int = 4,
    upper: float | None = None,
    max_seeds: int | None = None,
    limits: ExactLimits = ExactLimits(),
    cap: Cap | None = None,
    tally: Tally | None = None,
    lps: FixedSetLPs | None = None,
) -> tuple[CollapseState | None, int]:
    """The lowest verified exact state among macro-block rotations (:mod:`alma.nonassociative.rocking`).

    Candidates are made exact in the order of their lifting bound (a lower bound on the α of any
    state with that mechanism) while the bound is below the best verified α so far and below
    ``upper`` (the associative α: Radenkovic's theorem puts the minimum below it).  At most
    ``tries`` candidates; returns the state (None if none verified) and the candidates tried.
    ``lps``: the search's store of ``model``'s fixed-set LPs (None: each candidate its own).
    """
    cap = cap or no_cap()
    ceilings = [c.alpha for c in verified] + ([upper] if upper is not None and np.isfinite(upper) else [])
    best_alpha, best, tried = min(ceilings, default=np.inf), None, 0
    for candidate in rocking_candidates(model, points, keep=tries, max_seeds=max_seeds, cap=cap):
        if tried >= tries or candidate.lifting_bound >= best_alpha - 1e-12 or cap.expired():
            break
        tried += 1
        state = fast_exact_state(model, points, candidate.mechanism, "rocking", limits=limits, tally=tally, lps=lps)
        if state is not None and state.verified and state.alpha < best_alpha:
            best, best_alpha = state, state.alpha
    return best, tried


@dataclass(frozen=True)
class RockingStart:
    """Macro-blocks turning about a support point (:func:`rocking_start`); iterations: candidates tried."""

    name: str = "rocking"

    def run(self, ctx: Context, tally: Tally) -> tuple[CollapseState | None, int]:
        s = ctx.settings
        return rocking_start(
            ctx.model,
            ctx.points,
            ctx.verified(),
            tries=s.rocking_tries,
            upper=ctx.associative_alpha,
            max_seeds=s.rocking_seeds,
            limits=ctx.exact_limits(vertex=True),
            cap=ctx.cap,
            tally=tally,
            lps=ctx.lps,
        )


@dataclass(frozen=True)
class GilbertStart:
    """Gilbert's iteration from N̄ = scale · N_LP with relaxation r and slope-halving steps;
    a restart (``restart`` not None) scales each point's N_LP by its factor 1 ± ``spread``
    (:func:`~alma.nonassociative.spread.spread_factors`), to take another path."""

    scale: float
    relaxation: float
    slope_steps: int
    work: Work
    #: The sloped LP with its yield conditions as rows (:class:`~alma.nonassociative.cap_lp.CapLP`).
    yield_rows: bool = False
    restart: int | None = None
    spread: float = 0.0

    @property
    def name(self) -> str:
        rows = ", rows" if self.yield_rows else ""
        field = f"{self.scale:g}·N_LP"
        if self.restart is not None:
            field += f"·(1±{self.spread:g})#{self.restart}"
        return f"gilbert(N̄={field}, r={self.relaxation:g}, steps={self.slope_steps}{rows})"

    def run(self, ctx: Context, tally: Tally) -> tuple[CollapseState | None, int]:
        initial = self.scale * ctx.associative_normal
        if self.restart is not None:
            initial = initial * spread_factors(initial.size, self.restart, self.spread)
        return gilbert(
            ctx.model,
            ctx.points,
            initial,
            start=self.name,
            relaxation=self.relaxation,
            slope_steps=self.slope_steps,
            ipm_above=ctx.settings.interior_points,
            yield_rows=self.yield_rows,
            work=self.work,
            cap=ctx.cap,
            tally=tally,
            lps=ctx.lps,
        )


@dataclass(frozen=True)
class ProjectedStart:
    """Gilbert's iteration at slope zero with the closest static field (:func:`projected_gilbert`)."""

    work: Work
    name: str = "gilbert-projected"

    def run(self, ctx: Context, tally: Tally) -> tuple[CollapseState | None, int]:
        s = ctx.settings
        return projected_gilbert(
            ctx.model,
            ctx.points,
            ctx.associative_normal,
            start=self.name,
            restart_after=s.projected_restart_after,
            restart_plain_steps=s.projected_restart_plain_steps,
            work=self.work,
            cap=ctx.cap,
            tally=tally,
            lps=ctx.lps,
        )


@dataclass(frozen=True)
class IpoptStart:
    """A CasADi/IPOPT polish of Eq. 9 (:mod:`alma.nonassociative.nlp`) from the best state so far."""

    name: str = "ipopt"

    def run(self, ctx: Context, tally: Tally) -> tuple[CollapseState | None, int]:
        seed = ctx.best()
        mechanism = seed.mechanism if seed is not None else ctx.associative_mechanism
        if mechanism is None:
            return None, 0
        return ipopt_polish(
            ctx.model,
            ctx.points,
            mechanism,
            seed,
            max_iter=ctx.settings.ipopt_iterations,
            cap=ctx.cap,
            limits=ctx.exact_limits(),
        ), 0


@dataclass(frozen=True)
class MilpStart:
    """The MILP of :mod:`alma.certify` capped at the best verified α: a lower state if one exists.

    Its state goes through the same exact-state verification as every other candidate.
    Iterations: branch-and-bound nodes.
    """

    name: str = "milp"

    def run(self, ctx: Context, tally: Tally) -> tuple[CollapseState | None, int]:
        best = ctx.best()
        mechanisms = [c.mechanism for c in ctx.candidates]
        if ctx.associative_mechanism is not None:
            mechanisms.append(ctx.associative_mechanism)
        nodes = max(1, ctx.settings.milp_start_work // max(ctx.model.n_free + ctx.model.n_bounded, 1))
        settings = replace(ctx.certify, node_limit=min(nodes, ctx.certify.node_limit))
        # The policy runs this start only with a finite associative α (policy.wanted).
        certificate = certify(
            ctx.model,
            float(cast(float, ctx.associative_alpha)),
            mechanisms,
            settings=settings,
            alpha_best=best.alpha if best is not None else None,
            time_limit=ctx.cap.remaining() if ctx.cap.seconds is not None else None,
        )
        if certificate.mechanism is None:
            return None, certificate.nodes
        return exact_state(
            ctx.model, ctx.points, certificate.mechanism, self.name, limits=ctx.exact_limits(), tally=tally, lps=ctx.lps
        ), certificate.nodes
