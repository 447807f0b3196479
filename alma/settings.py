"""Every tuned number of alma, in frozen dataclasses with a one-line reason each.

``alma.solve(scene, settings=Settings(...))`` takes them; the study keys hash them together
with the package version, so a change of any of them is never served from an old results file.
The evidence behind each default is in ``docs/decisions.md``.  The interior point's
:class:`~alma.engine.types.IPMSettings` are defined with the engine (plain data: the engine
imports nothing of alma) and reached here as :attr:`AssociativeSettings.ipm`.

No setting is a share of the wall clock: the searches spend work budgets (iterations, LP
solves, branch-and-bound nodes), so the same input gives the same answer on any machine.  The
only clock is :attr:`Settings.time_limit`, a user's hard cap whose cut is reported as
``limit_reached``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field
from typing import Any, Literal, get_args

# The settings that change no result (pictures, reading drawings) live apart, reached here too.
from alma.display_settings import (
    DRAWING as DRAWING,
    DrawingSettings as DrawingSettings,
    PictureSettings as PictureSettings,
)

# The interior point's settings are plain data of alma.engine, which imports nothing of alma.
from alma.engine.types import FACTORISATIONS as FACTORISATIONS, IPMSettings

#: The associative LP's engines: Clarabel, alma's interior point (alma.engine), or by size.
Engine = Literal["clarabel", "ipm", "auto"]
ENGINES: tuple[str, ...] = get_args(Engine)
#: The non-associative search's efforts ("auto": thorough on small scenes, fast on large ones).
Effort = Literal["auto", "fast", "thorough"]
EFFORTS: tuple[str, ...] = get_args(Effort)
#: The MIP solvers of the certification.
CertifyBackend = Literal["highs", "scip"]
CERTIFY_BACKENDS: tuple[str, ...] = get_args(CertifyBackend)


def _check_choice(owner: object, name: str, allowed: tuple[str, ...]) -> None:
    """A clear error when the field ``name`` of ``owner`` is not one of ``allowed``."""
    value = getattr(owner, name)
    if value not in allowed:
        raise ValueError(f"{type(owner).__name__}.{name} must be one of {', '.join(map(repr, allowed))}, got {value!r}")


@dataclass(frozen=True)
class CrushingSettings:
    """The cone program of finite compressive strength (``alma.associative.crushing``) and its
    certificate.  Forces are in mean block weights; the cones read 2 c N_p ≥ N², c = σ_c l t."""

    #: Absolute room (block weights) the solver's cones keep, 2 c ((1 − κ) N_p − margin) ≥ N²: the
    #: equilibrium repair's corrections (~1e-9) stay inside, at a cost in α below 1e-9 relative.
    cone_margin: float = 1e-8
    #: Room κ in proportion to the point's force, for the joints at the base of the tall panels
    #: (N ~ 150 block weights, where 1e-8 absolute is round-off).
    cone_relative_margin: float = 5e-8
    #: A crushing joint whose generator powers are all below this share of the largest is at rest
    #: (the interior point's blend leaves ~1e-9 there; a moving joint's are ≥ 1e-4).
    rest: float = 1e-7
    #: Anchor solve (when the repaired field stays outside a cone): the joints it left are given
    #: this many times their missing force as extra room, so the anchor is strictly inside there.
    anchor_factor: float = 10.0
    #: ... plus this absolute room (block weights): a violation of round-off size still gets room.
    anchor_margin: float = 1e-8
    #: ... plus this share of the joint's N: the solver's error grows with N (4.8e-8 N on the 5,005-block wall's base).
    anchor_load_margin: float = 1e-7


@dataclass(frozen=True)
class AssociativeSettings:
    """The associative LP (Eq. 10) and its certificate."""

    #: Clarabel's gap and feasibility tolerances: the certificate closes from 1e-10 on the largest walls.
    tolerance: float = 1e-11
    #: Clarabel's iteration cap: the certified paper panels and walls need 40-80.
    max_iter: int = 200
    #: f_Lᵀu = normalisation · n_free: block velocities of this order balance Clarabel's residuals.
    normalisation: float = 1000.0
    #: Relative gap (upper − lower) / max(1, |upper|) under which the bounds count as closed.
    gap_tolerance: float = 1e-7
    #: Largest admissibility residual (equilibrium, flow rule) of a field that counts as proof.
    residual_tolerance: float = 1e-9
    #: ... or, for the static field, this × machine ε × its largest force term |H||μ| when that is
    #: larger: equilibrium cannot be evaluated below round-off, and at 100,000 blocks forces reach
    #: 2e4 mean block weights, where the repaired residual is 580 ε × that (docs/decisions.md).
    residual_roundoff: float = 1e4
    #: "clarabel", "ipm" (alma.engine; Clarabel if it does not converge) or "auto" (the interior
    #: point from :attr:`auto_min_blocks` free blocks, :attr:`auto_min_blocks_bounded` with
    #: cohesion or ties, when a fast factorisation is installed).
    engine: Engine = "auto"
    #: "auto" takes the interior point from this many free blocks: on this project's 2-core machine Clarabel is faster
    #: on the paper panels (≤ 1,752 blocks: 0.59 s against 0.80 s), the interior point from the 5,005-block wall on
    #: (5.6 s against 12.3 s); the panels' crossover is near 700 blocks, and the threshold stays above it because the
    #: crisp mechanism needs Clarabel's sharper final partition on two of those panels (docs/engine.md, decisions.md).
    auto_min_blocks: int = 3000
    #: ... and from this many with bounded forces (cohesion, ties), which take no crisp mechanism:
    #: with 5 kPa on every joint of the 108 panels Clarabel/ipm is 0.95 below 700 free blocks and
    #: 1.08-1.26 from 700 on (studies/bench_engine_crossover.py --cohesion 5; docs/engine.md).
    auto_min_blocks_bounded: int = 700
    #: The interior point's own numbers (used when the engine is "ipm", or "auto" on large scenes).
    ipm: IPMSettings = field(default_factory=IPMSettings)
    #: The certificate's Gram matrices of at least this order go to feral when it is installed: 3 rows per free block,
    #: i.e. walls of 5,000 blocks and more, where feral's certificate is 1.1× faster (0.76× at 1,000 blocks, 2.4× at
    #: 20,000; studies/bench_certificate.py); every paper panel (≤ 5,256 rows) stays on QDLDL.
    feral_min_rows: int = 15_000
    #: Re-solve for a HiGHS vertex (crossover, else dual simplex) when the interior point's pair does not certify: a
    #: vertex is exact on the degenerate faces (noisy drawings of walls sliding at α = f) where it is not.
    simplex_fallback: bool = True
    #: A falling mode proves "no equilibrium" after a failed interior point when its weights' work exceeds its
    #: round-off breach by this × n_free: no field with forces below a million block weights (alma.associative.falling).
    falling_margin: float = 1e6
    #: Show one crisp mechanism of the optimal face (a vertex, alma.associative.crisp) instead of the interior point's
    #: blend of all of them; off by default: it costs 4.6x the solve over the 108 paper panels (HiGHS's interior point
    #: with crossover), and the blend is the same mechanism wherever the optimal face is a single one.
    crisp_mechanism: bool = False
    #: Free blocks up to which the crisp LP may fall back to its capped form (tens of solves on the biggest panels).
    crisp_capped_blocks: int = 1000
    #: Iterative refinement in Clarabel's cone program of finite compressive strength: with it the
    #: single block recovers b/h to 7e-10 at σ_c = 1e7 MPa (3e-9 without; docs/compressive.md).
    cone_refinement: bool = True
    #: Clarabel's tolerances on the cone program: at 1e-9 it ends "Solved" on the paper's panels
    #: with its stress field inside the cones (their margin, alma.associative.crushing); at
    #: 1e-10 and below it stops "AlmostSolved" with cone violations of 4e-8 (docs/compressive.md).
    cone_tolerance: float = 1e-9
    #: The cone program's margins and its anchor solve (docs/compressive.md).
    crushing: CrushingSettings = field(default_factory=CrushingSettings)

    def __post_init__(self) -> None:
        _check_choice(self, "engine", ENGINES)


@dataclass(frozen=True)
class CertifySettings:
    """The mixed-integer certification of the non-associative lower bound (``alma.certify``)."""

    #: Branch-and-bound nodes of HiGHS's MIP: the 12-block scenes prove within ~10^4.
    node_limit: int = 200_000
    #: Simplex iterations of each LP that derives a big-M constant (a stall guard).
    bound_lp_iterations: int = 200_000
    #: Velocity bound U as a multiple of the largest candidate mechanism's |u|∞.
    velocity_factor: float = 10.0
    #: Above this many contact points, one global normal-force bound replaces the per-point LPs.
    per_point_bounds: int = 400
    #: "highs" (big-M binaries, always installed) or "scip" (SOS1 pairs, the extra alma[scip]).
    backend: CertifyBackend = "highs"
    #: Absolute MIP gap of the SCIP path: the proven bound is within this of the best state found.
    absolute_gap: float = 1e-7
    #: SCIP's feasibility tolerance: its default 1e-6 lets equilibrium drift by 1e-6 block weights
    #: (α by as much); 1e-9 ended in unresolved LP trouble on a 14-block running wall, 1e-8 did not.
    scip_feasibility: float = 1e-8
    #: SCIP: add the exact energy balance (bilinear in N and the slips) as a quadratic equality.
    scip_energy: bool = True
    #: Further SCIP parameters (name, value), set last.  Bipartite SOS1 branching: at 2,000 nodes its
    #: bound was higher on 3 of 7 scenes of 14-20 blocks (x1.16-x1.9), equal on 3, 1 % lower on 1.
    scip_parameters: tuple[tuple[str, object], ...] = (("constraints/SOS1/branchingrule", "b"),)

    def __post_init__(self) -> None:
        _check_choice(self, "backend", CERTIFY_BACKENDS)


@dataclass(frozen=True)
class StateTolerances:
    """When a candidate is a collapse state of Eq. 9 (``alma.nonassociative.states.verify``) and
    how an active set is read; dimensionless: residuals relative to the largest force or velocity."""

    #: Equilibrium residual per largest force: the definition of a verified state (docs/accuracy.md).
    equilibrium: float = 1e-7
    #: Yield violation (N < 0, |T| > f N) per largest force: the same definition.
    yield_violation: float = 1e-7
    #: Interpenetration, force on an opening point, friction or bounded force not mobilised on a
    #: slip, relative to the largest velocity and force: the same definition.
    kinematic: float = 1e-7
    #: Energy balance α f_Lᵀu + f₀ᵀu = dissipation, relative to its largest term: the same definition.
    energy: float = 1e-6
    #: A relative velocity below this share of the largest counts as zero when an active set is
    #: read from a mechanism: well above the LPs' round-off, below any motion a state keeps.
    active: float = 1e-6
    #: A force below this share of the largest normal force counts as zero (or at its limit) when the
    #: widest set a static field allows is read: a vertex's forces are exact to round-off.
    force: float = 1e-9
    #: A mechanism whose relative velocities are all below this share of its largest centroid velocity is a linkage
    #: of point hinges: they are round-off (1e-16 to 1e-8 of the blocks'), and velocities are scaled by the centroids'.
    linkage: float = 1e-6


@dataclass(frozen=True)
class SearchSettings:
    """The non-associative search (Eq. 9): which starts run and the work each may spend, counted in
    solver units (LP solves, simplex and interior-point iterations, nodes, seeds), never seconds."""

    #: "fast", "thorough", or "auto" (thorough up to :attr:`thorough_blocks` free blocks).
    effort: Effort = "auto"
    #: Free blocks up to which "auto" means "thorough".
    thorough_blocks: int = 200
    #: The search runs on the canonical drawing (:mod:`alma.geometry.canonical`), its model's data
    #: rounded to canonical_bits significant bits (3.7e-9): close enough to the drawing's model
    #: that its states carry back (105 of the 108 panels; 97 at 24 bits), coarse enough that a
    #: rewritten drawing's round-off (to 1.5e-12, 100 m away) rounded alike in 40 of 40 rewrites.
    canonical_bits: int = 28
    #: When no canonical state verifies on the drawing's own model, a second search on the
    #: canonical data rounded to this many bits (52: as computed). None (no second run) by
    #: default: its answer moves with round-off of the input (a perturbed panel lost its state).
    fallback_bits: int | None = None
    #: Above this many free blocks a verified ``rocking`` state ends a "fast" search: on 6 runs of the 108 panels no
    #: Gilbert or turned start improved on one there (a third of the search).
    rocking_ends_blocks: int | None = 500
    #: A capped (Gilbert) LP stops once its α is proven below −this × max(1, |α_LP|): far below any state met.
    capped_alpha_floor: float = 100.0
    #: Canonical states (lowest α first) tried on the drawing's own model before giving up.
    carry_back_tries: int = 4
    #: States whose α are this close (relative) are one answer: the earliest start's is kept.
    same_alpha: float = 1e-9
    #: Gilbert starts of "fast": (N̄ as a multiple of N_LP, relaxation of N̄, slope-halving steps).
    gilbert_fast: tuple[tuple[float, float, int], ...] = ((0.0, 1.0, 1), (1.0, 0.5, 0))
    #: Gilbert starts of "thorough": with those below, the starts that reach the lowest state of each of 271
    #: searches (panels, walls, drawings, the walls' pushes: docs/decisions.md); the other 9 only repeated them.
    gilbert_thorough: tuple[tuple[float, float, int], ...] = ((0.0, 1.0, 1), (1.0, 0.5, 0), (2.0, 1.0, 1))
    #: Gilbert starts of "thorough" whose sloped LP keeps the yield conditions as rows (``…, rows``).
    gilbert_thorough_rows: tuple[tuple[float, float, int], ...] = ((1.0, 0.5, 4), (0.5, 0.5, 1), (2.0, 1.0, 1))
    #: Turned-table starts (alma.nonassociative.tilted): the table's turn in degrees, each running Gilbert's
    #: (0.5, 0.5, 1) on the turned problem; Ferris & Tin-Loi's wall 6 reaches its lowest state only at 10°.
    tilt_degrees: tuple[float, ...] = (10.0,)
    #: "thorough": turned tables run with the yield conditions as rows (none reached a lowest state alone).
    tilt_degrees_rows: tuple[float, ...] = ()
    #: The turns of "fast" (large scenes, where each start costs most): 10° gave 3 of the 4 lower
    #: states that the turned starts found on the 108 panels.
    tilt_degrees_fast: tuple[float, ...] = (10.0,)
    #: "thorough": restarts of restart_start from N_LP, each point's force scaled by its own factor within
    #: 1 ± restart_spread (alma.nonassociative.spread): the path turns on N_LP's last digits. 6 took 3 of 33
    #: small scenes lower (Ferris & Tin-Loi wall 6 to 0.295769) for 40 % more search on them.
    thorough_restarts: int = 6
    #: The restarts' start (as in gilbert_thorough): the cheapest start that went lower when restarted.
    restart_start: tuple[float, float, int] = (1.0, 0.5, 0)
    #: The restarts' relative spread: far above round-off, and N̄ stays near N_LP.
    restart_spread: float = 1e-3
    #: Capped-LP solves of one fixed Gilbert start.
    gilbert_iterations: int = 40
    #: "fast": simplex iterations of one fixed Gilbert start while no state is verified.
    gilbert_pivots: int = 20_000
    #: "fast": simplex iterations of one fixed Gilbert start once a state is verified.
    gilbert_pivots_verified: int = 10_000
    #: Capped-LP solves (each with one projection QP) of the projected Gilbert iteration.
    projected_iterations: int = 400
    #: Its iterations times the free blocks: the projection QP's cost grows with the scene.
    projected_block_iterations: int = 60_000
    #: Simplex iterations of the projected Gilbert iteration's capped LPs.
    projected_pivots: int = 100_000
    #: Projected iterations without settling after which it restarts once from the LP field.
    projected_restart_after: int = 60
    #: Plain (vertex) iterations before projecting again, after that restart.
    projected_restart_plain_steps: int = 20
    #: Simplex iterations of one static or kinematic LP of an exact state (a stall guard).
    lp_pivots: int = 200_000
    #: HiGHS iterations (interior point, crossover) of a widest-set vertex: lp and rocking starts, carry-back.
    vertex_pivots: int = 20_000
    #: Simplex iterations of each LP of the exact state a Gilbert start makes of its last iterate.
    last_state_pivots: int = 2_000
    #: Interior-point iterations of Clarabel's fixed-active-set LP.
    interior_iterations: int = 200
    #: Above this many contact points the exact states of Gilbert iterates take Clarabel's field
    #: (a HiGHS vertex only when the widest set is read): HiGHS's interior point with crossover
    #: took 1.2 s a solve on a 792-block panel; with the field the 108 panels' search is 85 ×
    #: the associative solves instead of 98 ×, no panel higher.
    exact_ipm_points: int = 1000
    #: Scenes up to this many contact points take the ``lp`` start's static LP from HiGHS's simplex.
    lp_vertex_points: int = 1000
    #: Above this many contact points the ``lp`` start takes the associative active set only, not the widest set of a
    #: simplex vertex: on the 108 panels it took 11 % of the search and its state was never the lowest alone.
    lp_widest_points: int = 1000
    #: Above this many contact points the Gilbert LPs are solved by Clarabel, not warm HiGHS.
    interior_points: int = 6000
    #: LP solves of a fixed Gilbert start on Clarabel's path (above :attr:`interior_points`).
    gilbert_interior_iterations: int = 8
    #: Above this many contact points a fast search skips the fixed Gilbert and turned-table starts (Clarabel's path):
    #: in 14 runs of the 108 panels they never gave the answer on the three such panels (130 s of one run).
    fixed_starts_points: int | None = 6000
    #: Macro-block rotations made exact by the ``rocking`` start, lowest lifting bound first.
    rocking_tries: int = 4
    #: Seeds (block, pivot) the rocking generator grows into macro-blocks, in block order.
    rocking_seeds: int = 20_000
    #: "thorough": scenes up to this many free blocks get the IPOPT polish (0: none; raise it to
    #: polish): it cost 95 % of the search on the Ferris & Tin-Loi walls and never went lower.
    ipopt_blocks: int = 0
    #: IPOPT iterations of each relaxed solve of the polish.
    ipopt_iterations: int = 300
    #: "thorough": scenes up to this many free blocks get the MILP of ``alma.certify`` as a start.
    milp_start_blocks: int = 12
    #: Branch-and-bound nodes × (free blocks + bounded columns) of that MILP start (a node costs more on a larger
    #: scene): 200 nodes on 12 dry blocks, 33 on 12 cohesive ones, where 20,000 nodes found nothing in 18 minutes.
    milp_start_work: int = 2_400
    #: When a candidate is a verified collapse state, and how active sets are read.
    states: StateTolerances = field(default_factory=StateTolerances)

    def __post_init__(self) -> None:
        _check_choice(self, "effort", EFFORTS)


@dataclass(frozen=True)
class PushSettings:
    """The incremental large-displacement analysis (``alma.push``): steps, budgets, accuracy.

    Lengths are relative to √(total area of the free blocks), so that the same structure drawn
    in other units or elsewhere takes the same steps."""

    #: Steps from α_c to α = 0 (after the probe): 40 draws a smooth curve of a rocking panel.
    steps: int = 40
    #: The probe step that estimates d₀ by a secant: small enough to stay on the first mechanism.
    probe: float = 1e-3
    #: The step when α does not fall over the probe (a sliding mechanism): the longest step, since
    #: where α starts to fall is located to ``turn_tolerance`` whatever the step.
    flat_step: float = 0.05
    #: Width to which a flat walk's end (where α starts to fall) is located: the mechanism that follows
    #: starts there whatever the flat step, to a ten-thousandth of the structure's size.
    turn_tolerance: float = 1e-4
    #: The longest step: a secant through a nearly flat start would otherwise leap past the structure.
    max_step: float = 0.05
    #: Main steps the analysis may take, as a multiple of ``steps`` (a work budget).
    max_steps_factor: int = 4
    #: Trials landing a step where blocks first touch (alma.push.landing), which also stops when its
    #: bracket is ``d0_tolerance`` × L wide: 40 bisections reach 1e-12 of the step.
    landing_iterations: int = 40
    #: Re-solves of a step holding the points it drove into a neighbour (each round holds all).
    unilateral_rounds: int = 5
    #: Re-linearisations of the unilateral step (alma.push.projection): its gaps are quadratic in the step.
    projection_rounds: int = 8
    #: Width of the bracket of d₀ that ends its refinement: d₀ is stated to this accuracy.
    d0_tolerance: float = 1e-7
    #: LP solves the refinement of d₀ may spend (each halves the bracket at worst).
    refine_solves: int = 40
    #: Newton iterations of the closure corrector that keeps hinges closed over a finite step.
    corrector_iterations: int = 30
    #: Residual of the corrector (relative to the length scale): the hinges meet to round-off.
    corrector_tolerance: float = 1e-12
    #: A Newton step shrinks the corrector's residual by this, else it has stalled (quadratic is far below).
    corrector_contraction: float = 0.5
    #: Unknowns (3 per body) up to which a corrector step is a dense SVD least squares: none, since
    #: LAPACK rounds by the CPU's BLAS kernel and QDLDL does not (the same curve on every CPU).
    dense_columns: int = 0
    #: A tie shorter than its rest length by more than this (relative to the length scale) is slack:
    #: far above the round-off of rigid motions (1e-16 of the coordinates), far below a step.
    tie_slack: float = 1e-9
    #: The settlement crack pattern: an optimal-face vertex whose dead-load work is within this of
    #: the optimum (above the interior point's 1e-10, below any two distinct patterns' difference).
    settlement_vertex_slack: float = 1e-8


@dataclass(frozen=True)
class Settings:
    """All settings of one analysis.  ``time_limit`` (s) is a user's cap, not a budget."""

    associative: AssociativeSettings = field(default_factory=AssociativeSettings)
    search: SearchSettings = field(default_factory=SearchSettings)
    certify: CertifySettings = field(default_factory=CertifySettings)
    #: Wall-clock cap in seconds (None: none).  Hitting it gives ``limit_reached``.
    time_limit: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """Plain nested dict (JSON-ready) of every setting."""
        return dataclasses.asdict(self)

    def digest(self) -> str:
        """A short hash of every setting that changes a result (the time cap excluded)."""
        data = self.to_dict()
        data.pop("time_limit")
        text = json.dumps(data, sort_keys=True, default=repr)
        return hashlib.sha256(text.encode()).hexdigest()[:16]
