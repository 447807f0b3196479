"""The control point of a capacity curve: which block's centroid d measures, and where the
mechanism stops moving it (SPEC §3 ``alma push``; lengths in mm)."""

from __future__ import annotations

import math

from alma.geometry.scene import Scene
from alma.push.motion import MotionError
from alma.push.result import _State
from alma.results.types import Result


class ControlLeft(MotionError):
    """The mechanism at a point leaves the control block still (``reason`` "control_still") or
    moves it backwards ("control_reverses"): the structure there collapses, at that point's α, by
    a mechanism the control point does not follow, so the curve of d ends.  A finding of the
    analysis, not a failure of the step."""

    def __init__(self, reason: str, text: str) -> None:
        super().__init__(text)
        self.reason = reason


def control_block(scene: Scene, result: Result, control: str | None) -> tuple[int, float]:
    """The control block's scene index and the sense of its horizontal motion."""
    ids = scene.block_ids
    ux = {b.id: b.u[0] for b in result.blocks}
    top = max(abs(v) for v in ux.values()) if ux else 0.0
    if control is None:
        if not top > 0:
            raise ValueError("the collapse mechanism moves no block horizontally: give --control")
        control = min((k for k, v in ux.items() if abs(v) >= top * (1 - 1e-9)))
    if control not in ids:
        raise ValueError(f"control block '{control}': no such block")
    if control not in ux:
        raise ValueError(f"control block '{control}': a fixed block does not move")
    if not abs(ux[control]) > 1e-6 * top:
        raise ValueError(
            f"control block '{control}': its centroid does not move horizontally in the collapse mechanism"
        )
    return ids.index(control), math.copysign(1.0, ux[control])


def control_end(state: _State, left: ControlLeft) -> dict:
    """The ``end`` of a curve whose last point's mechanism leaves the control block (``left``)."""
    text = (
        f"the curve ends at d = {state.d:.6g} mm with α = {state.alpha:.4g} > 0: {left}, so the "
        "structure collapses there by a mechanism the control point does not follow (d₀ is not defined)"
    )
    return {"reason": left.reason, "d": state.d, "alpha": state.alpha, "text": text}
