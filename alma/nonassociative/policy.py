"""Which starts the search runs for each effort, in which order, and with what work.

- every effort runs the turned-table starts (``tilt(θ°)``, :mod:`alma.nonassociative.tilted`)
  after its Gilbert starts;
- ``"fast"`` (large scenes): ``lp``, ``rocking``, the fast Gilbert starts (each within
  :attr:`~alma.settings.SearchSettings.gilbert_pivots`, or the smaller
  :attr:`~alma.settings.SearchSettings.gilbert_pivots_verified` once a state is verified),
  then ``gilbert-projected`` only when no start verified a state: when the fixed starts verify
  at all they do so early, and the projected iteration settles where their vertex iterates jump.
  Above :attr:`~alma.settings.SearchSettings.rocking_ends_blocks` free blocks a verified
  ``rocking`` state ends the search before the Gilbert and turned-table starts, and above
  :attr:`~alma.settings.SearchSettings.fixed_starts_points` contact points those starts do not
  run (``gilbert-projected`` follows ``rocking``).
- ``"thorough"`` (small scenes): ``lp``, ``rocking``, the thorough Gilbert starts (their
  iterations only) and turned tables, then the Gilbert starts of
  :attr:`~alma.settings.SearchSettings.gilbert_thorough_rows` and the turned tables of
  :attr:`~alma.settings.SearchSettings.tilt_degrees_rows` (none by default), their sloped LP
  written with the yield conditions as rows (``…, rows``): the same LP as the generators' form of
  :class:`~alma.nonassociative.cap_lp.CapLP`, whose other vertices lead the iteration to other
  states, at the price of a few small LPs; :attr:`~alma.settings.SearchSettings.thorough_restarts`
  restarts of :attr:`~alma.settings.SearchSettings.restart_start` from N_LP spread point by point
  (:mod:`alma.nonassociative.spread`); ``gilbert-projected`` when no start other
  than ``rocking`` verified (it can go below a rocking state); ``ipopt`` up to
  :attr:`~alma.settings.SearchSettings.ipopt_blocks` free blocks (none by default: the polish
  runs when asked for); and ``milp`` up to :attr:`~alma.settings.SearchSettings.milp_start_blocks`
  free blocks, within :attr:`~alma.settings.SearchSettings.milp_start_work` / (free blocks +
  bounded columns) branch-and-bound nodes.

Every start takes cohesion and ties (bounded forces): ``ipopt`` (:mod:`alma.nonassociative.nlp`)
and ``milp`` (:mod:`alma.certify.rows`) write them as bounded columns with their flow rule.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from alma.backends.linprog_backend import LPMethod
from alma.nonassociative.limits import Work
from alma.nonassociative.starts import (
    Context,
    GilbertStart,
    IpoptStart,
    LpStart,
    MilpStart,
    ProjectedStart,
    RockingStart,
    Start,
)
from alma.nonassociative.tilted import TiltStart
from alma.settings import EFFORTS, SearchSettings


def resolve_effort(effort: str, settings: SearchSettings, n_free: int) -> str:
    """ "fast" or "thorough"; "auto" is thorough up to ``settings.thorough_blocks`` free blocks."""
    if effort == "auto":
        return "thorough" if n_free <= settings.thorough_blocks else "fast"
    if effort not in EFFORTS:  # "auto" is resolved above
        raise ValueError(f"effort must be 'auto', 'fast' or 'thorough', got {effort!r}")
    return effort


def _work(settings: SearchSettings, iterations: int, pivots: int | None, points: int) -> Work:
    method = LPMethod.CLARABEL if points > settings.exact_ipm_points else LPMethod.SIMPLEX
    return Work(
        iterations=iterations,
        pivots=pivots,
        lp_pivots=settings.lp_pivots,
        floor_pivots=settings.last_state_pivots,
        interior_iterations=settings.interior_iterations,
        exact_method=method,
        tolerances=settings.states,
    )


def gilbert_work(settings: SearchSettings, effort: str, verified: bool, points: int) -> Work:
    """A fixed Gilbert start's budget: its LP solves (fewer on Clarabel's path, where each is a
    cold interior-point solve), and with "fast" a total of simplex iterations."""
    iterations = settings.gilbert_iterations
    if points > settings.interior_points:
        iterations = min(iterations, settings.gilbert_interior_iterations)
    if effort == "thorough":
        return _work(settings, iterations, None, points)
    pivots = settings.gilbert_pivots_verified if verified else settings.gilbert_pivots
    return _work(settings, iterations, pivots, points)


def projected_work(settings: SearchSettings, n_free: int, points: int) -> Work:
    """The projected iteration's budget: LP solves (each with a projection QP), fewer on larger
    scenes (:attr:`~alma.settings.SearchSettings.projected_block_iterations`), and simplex iterations."""
    iterations = min(settings.projected_iterations, settings.projected_block_iterations // max(n_free, 1))
    return _work(settings, max(iterations, 1), settings.projected_pivots, points)


def plan(settings: SearchSettings, effort: str) -> list[str]:
    """The starts of an effort in the order they run (names of kinds; see :func:`make_start`)."""
    turns = [f"tilt:{k}" for k in range(len(_turns(settings, effort, rows=False)))]
    gilbert = [f"gilbert:{k}" for k in range(len(_gilbert(settings, effort, rows=False)))]
    rows = [f"gilbert:{k}:rows" for k in range(len(_gilbert(settings, effort, rows=True)))]
    rows += [f"tilt:{k}:rows" for k in range(len(_turns(settings, effort, rows=True)))]
    restarts = [f"restart:{k}" for k in range(settings.thorough_restarts if effort == "thorough" else 0)]
    return ["lp", "rocking", *gilbert, *turns, *rows, *restarts, "projected", "ipopt", "milp"]


def parse_kind(kind: str) -> tuple[str, int | None]:
    """A kind of :func:`plan` as (family, index): "gilbert:3" → ("gilbert", 3), "gilbert:3:rows"
    → ("gilbert", 3), "lp" → ("lp", None)."""
    family, colon, index = kind.partition(":")
    return family, (int(index.split(":")[0]) if colon else None)


def rows_kind(kind: str) -> bool:
    """Whether a kind's sloped LP keeps the yield conditions as rows."""
    return kind.endswith(":rows")


def _gilbert(settings: SearchSettings, effort: str, rows: bool) -> tuple[tuple[float, float, int], ...]:
    """The fixed Gilbert starts of an effort, those written with the yield rows when ``rows``
    (none for "fast")."""
    if effort == "fast":
        return () if rows else settings.gilbert_fast
    return settings.gilbert_thorough_rows if rows else settings.gilbert_thorough


def _turns(settings: SearchSettings, effort: str, rows: bool) -> tuple[float, ...]:
    """The turned-table starts' angles (degrees) of an effort, those written with the yield rows
    when ``rows`` (none for "fast")."""
    if effort == "fast":
        return () if rows else settings.tilt_degrees_fast
    return settings.tilt_degrees_rows if rows else settings.tilt_degrees


def wanted(kind: str, ctx: Context, polish: bool | None = None) -> bool:
    """Whether a start of this kind runs now, given the candidates so far."""
    s, thorough = ctx.settings, ctx.effort == "thorough"
    if kind == "projected":
        others = [c for c in ctx.verified() if not thorough or c.start != "rocking"]
        return not others
    if parse_kind(kind)[0] in ("gilbert", "tilt", "restart") and (_rocking_ends(ctx) or _too_many_points(ctx)):
        return False
    if kind == "ipopt":
        return (thorough and ctx.model.n_free <= s.ipopt_blocks) if polish is None else polish
    if kind == "milp":
        alpha = ctx.associative_alpha
        return (
            thorough
            and ctx.model.n_free <= s.milp_start_blocks
            and alpha is not None
            and bool(np.isfinite(alpha))
            and alpha >= 0
        )
    return True


def _rocking_ends(ctx: Context) -> bool:
    """Whether a verified ``rocking`` state ends a fast search of a large scene
    (:attr:`~alma.settings.SearchSettings.rocking_ends_blocks`)."""
    limit = ctx.settings.rocking_ends_blocks
    return (
        ctx.effort == "fast"
        and limit is not None
        and ctx.model.n_free > limit
        and any(c.start == "rocking" for c in ctx.verified())
    )


def _too_many_points(ctx: Context) -> bool:
    """Whether a fast search skips its fixed Gilbert and turned-table starts, whose LPs are
    Clarabel's on a scene this large (:attr:`~alma.settings.SearchSettings.fixed_starts_points`)."""
    limit = ctx.settings.fixed_starts_points
    return ctx.effort == "fast" and limit is not None and ctx.points.count > limit


def _floored(work: Work, ctx: Context) -> Work:
    """``work`` whose capped LPs stop once their α is proven below
    −:attr:`~alma.settings.SearchSettings.capped_alpha_floor` × max(1, |α_LP|): a cut, not a proof
    (an iterate there is given up), far below every state met, where such LPs can run for minutes."""
    alpha = ctx.associative_alpha
    if alpha is None or not np.isfinite(alpha):
        return work
    return replace(work, alpha_floor=-ctx.settings.capped_alpha_floor * max(1.0, abs(float(alpha))))


def _gilbert_start(kind: str, index: int, settings: SearchSettings, effort: str, work: Work) -> GilbertStart:
    """The fixed Gilbert start or the restart of this kind (``gilbert:k[:rows]``, ``restart:k``),
    ``index`` its k."""
    if parse_kind(kind)[0] == "restart":
        scale, relaxation, steps = settings.restart_start
        return GilbertStart(scale, relaxation, steps, work, restart=index, spread=settings.restart_spread)
    scale, relaxation, steps = _gilbert(settings, effort, rows_kind(kind))[index]
    return GilbertStart(scale, relaxation, steps, work, yield_rows=rows_kind(kind))


def make_start(kind: str, ctx: Context) -> Start:
    """The start of this kind, with the work the policy gives it now."""
    s = ctx.settings
    family, index = parse_kind(kind)
    if kind == "lp":
        return LpStart()
    if kind == "rocking":
        return RockingStart()
    if family in ("gilbert", "restart") and index is not None:
        work = _floored(gilbert_work(s, ctx.effort, bool(ctx.verified()), ctx.points.count), ctx)
        return _gilbert_start(kind, index, s, ctx.effort, work)
    if family == "tilt" and index is not None:
        return TiltStart(
            _turns(s, ctx.effort, rows_kind(kind))[index],
            _floored(gilbert_work(s, ctx.effort, bool(ctx.verified()), ctx.points.count), ctx),
            ipm_above=s.interior_points,
            yield_rows=rows_kind(kind),
        )
    if kind == "projected":
        return ProjectedStart(_floored(projected_work(s, ctx.model.n_free, ctx.points.count), ctx))
    if kind == "ipopt":
        return IpoptStart()
    if kind == "milp":
        return MilpStart()
    raise ValueError(f"unknown start {kind!r}")


def start_name(kind: str, settings: SearchSettings, effort: str) -> str:
    """The name a start of this kind reports (for the list of skipped starts)."""
    family, index = parse_kind(kind)
    if family in ("gilbert", "restart") and index is not None:
        return _gilbert_start(kind, index, settings, effort, Work()).name
    if family == "tilt" and index is not None:
        return TiltStart(_turns(settings, effort, rows_kind(kind))[index], Work(), yield_rows=rows_kind(kind)).name
    return {"lp": "lp", "rocking": "rocking", "projected": "gilbert-projected", "ipopt": "ipopt", "milp": "milp"}[kind]
