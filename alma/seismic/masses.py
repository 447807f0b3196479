"""The masses of a local mechanism and their virtual displacements (Circolare 2019 §C8.7.1.2.1.1).

The Circolare's P_k is "the resultant of the weights applied to the k-th block (its self-weight
at its centroid, plus the other weights it carries)", Q_k the weights that do not bear on the
block but whose mass pushes on it, and F_k the external forces independent of the seismic action
(a vault's thrust); the seismic action is α (P_k + Q_k) along the horizontal (Eq. C8.7.1.1).
In a scene (SPEC §2) these are:

- the free blocks' self-weights (``live_load.self_weight``: the live load is each weight along
  ``live_load.direction``);
- a point load whose ``live`` part is m g along ``live_load.direction`` (m g ≥ 0): a carried
  mass of weight m g (kN) at the load's point, a P_k share when its ``dead`` part is that weight
  downwards, a Q_k when its weight bears elsewhere;
- a point load with no ``live`` part: an external force F_k (its ``dead`` part, any direction).

The dead parts of all of them do work in the collapse mechanism and alma's limit analysis puts
that work in α₀ (Eq. C8.7.1.1's numerator: Σ P_k δ_{P_y,k} − Σ F_k δ_{F,k}); the live parts do
the work of the denominator.  The terms of e* and d* (Eqs. C8.7.1.4–5) are summed over mass
*points*: each block's self-weight at its centroid and each carried mass at its own point, with
δx the horizontal virtual displacement of that point in the collapse mechanism.  (Lumping a
block's weights at the centroid of its forces gives the same Σ P δ but a larger Σ P δ², since δx
varies along a rotating block; the point sum is the kinetic-energy form and the one published
worked examples use.)

Units: weights in kN, virtual displacements in mm (the mechanism's velocities, any scale).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from alma.geometry.contacts import block_areas_and_centroids
from alma.geometry.scene import Scene
from alma.push import PushResult

#: kN per (mm³ · kN/m³)
_MM3_TO_M3 = 1e-9
#: A live part is "along the live direction" when its normal component is at most this fraction.
_PARALLEL = 1e-9


@dataclass(frozen=True)
class MassPoints:
    """The moving mass points of a collapse mechanism (module docstring).

    ``weight`` (kN) and ``dx`` (mm, along the curve's sense) per point: first the moving blocks'
    self-weights in the mechanism's block order, then the carried masses in the scene's load
    order; ``control`` the row of the control block's centroid.
    """

    weight: np.ndarray
    dx: np.ndarray
    control: int
    #: Per carried mass: (load index, block, weight kN, δx mm).
    carried: tuple[tuple[int, str, float, float], ...] = ()
    #: Indices of the scene's loads that are external forces F_k (no live part).
    forces: tuple[int, ...] = ()


def check_loads(scene: Scene) -> None:
    """Refuse point loads whose live part is not a mass's weight along the live direction.

    Raises
    ------
    ValueError
        Naming the load: its live part has a component across ``live_load.direction`` or
        points against it (the code's action is α times the masses' weights, along one sense).
    """
    if not scene.loads:
        return
    e = np.asarray(scene.live_load_direction, dtype=float)
    e = e / np.linalg.norm(e)
    live = np.array([load.live for load in scene.loads], dtype=float)
    along = live @ e
    across = np.abs(live @ np.array([-e[1], e[0]]))
    size = np.linalg.norm(live, axis=1)
    bad = (across > _PARALLEL * size) | (along < -_PARALLEL * size)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"load #{i} on block '{scene.loads[i].block}': its live part {list(scene.loads[i].live)} "
            f"is not a weight along the live load direction {list(scene.live_load_direction)} "
            "(the kinematic check's action is α times the carried masses' weights; "
            "an external force F_k has no live part)"
        )


def mass_points(scene: Scene, pushed: PushResult) -> MassPoints:
    """Weights and horizontal virtual displacements of the mechanism's moving masses.

    The virtual displacement of a point (x, y) of a block is the horizontal velocity of the
    collapse mechanism there: u − θ (y − c_y), with (u, v, θ) the block's velocity at its
    centroid c; along the capacity curve's sense (``pushed.sense``).
    """
    areas, centroids = block_areas_and_centroids(scene)
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    ids = [b.id for b in pushed.first.blocks]
    u = np.array([b.u for b in pushed.first.blocks], dtype=float).reshape(-1, 3)
    rows = np.array([index[i] for i in ids])
    own = np.array([scene.blocks[i].weight if scene.blocks[i].weight is not None else np.nan for i in rows])
    weights = np.where(np.isnan(own), np.abs(areas[rows]) * scene.thickness * scene.unit_weight * _MM3_TO_M3, own)
    macro = pushed.first.macro_blocks
    moving = set().union(*(m.blocks for m in macro)) if macro else set(ids)
    keep = np.array([i in moving for i in ids])
    dx = u[:, 0] * pushed.sense
    k = int(np.flatnonzero(np.array(ids)[keep] == pushed.control)[0])
    carried, forces = _carried(scene, ids, u, centroids, moving, pushed.sense)
    if not carried:
        return MassPoints(weights[keep], dx[keep], k, (), forces)
    extra_w = np.array([c[2] for c in carried])
    extra_dx = np.array([c[3] for c in carried])
    return MassPoints(
        np.concatenate([weights[keep], extra_w]), np.concatenate([dx[keep], extra_dx]), k, tuple(carried), forces
    )


def _carried(
    scene: Scene, ids: list[str], u: np.ndarray, centroids: np.ndarray, moving: set[str], sense: float
) -> tuple[list[tuple[int, str, float, float]], tuple[int, ...]]:
    """The carried masses on moving blocks (load index, block, m g kN, δx mm) and the F_k loads."""
    if not scene.loads:
        return [], ()
    e = np.asarray(scene.live_load_direction, dtype=float)
    e = e / np.linalg.norm(e)
    row = {b: i for i, b in enumerate(ids)}
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    live = np.array([load.live for load in scene.loads], dtype=float)
    weight = live @ e
    on = np.array([load.block in moving for load in scene.loads])
    block_row = np.array([row.get(load.block, 0) for load in scene.loads])
    centre = centroids[[index[load.block] for load in scene.loads]]
    point = np.array(
        [load.point if load.point is not None else centre[i] for i, load in enumerate(scene.loads)], dtype=float
    )
    velocity = u[block_row, 0] - u[block_row, 2] * (point[:, 1] - centre[:, 1])
    mass = (weight > 0) & on
    carried = [
        (int(i), scene.loads[i].block, float(weight[i]), float(velocity[i] * sense)) for i in np.flatnonzero(mass)
    ]
    forces = tuple(int(i) for i in np.flatnonzero(weight <= 0))
    return carried, forces
