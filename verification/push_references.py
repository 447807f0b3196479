"""Closed forms of rigid-block statics at finite rotation, and their scenes, for the capacity
curves of ``alma.push`` (``test_push.py``, ``test_push_friction.py``).

- a block b × h rocking about its toe under αW at its centroid (horizontal) and W (vertical):
  α(θ) = (b cos θ − h sin θ)/(h cos θ + b sin θ) (Housner's rocking block);
- a portal frame (two piers, a lintel) swaying about four hinges: α = Σ W v_y / Σ W v_x with v
  the bodies' virtual velocities at the displaced configuration.
"""

from __future__ import annotations

import math

import numpy as np

import alma


def rect(x0, y0, w, h):
    return [[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]


def scene(blocks, friction=0.8):
    return alma.Scene.from_dict(
        {
            "thickness": 120,
            "unit_weight": 18,
            "friction": friction,
            "blocks": [{"id": "ground", "vertices": rect(-2000, -100, 5000, 100), "fixed": True}, *blocks],
        }
    )


def rocking_alpha(b, h, theta):
    return (b * math.cos(theta) - h * math.sin(theta)) / (h * math.cos(theta) + b * math.sin(theta))


def theta_of_d(d, b, h):
    """The block's rotation that moves its centroid horizontally by d (toe at the right)."""
    r, beta = 0.5 * math.hypot(b, h), math.atan2(h, b)
    return math.acos((r * math.cos(beta) - d) / r) - beta


# ------------------------------------------------------------------ portal frame (4 hinges)
PB, PH, SPAN, LT = 200.0, 1000.0, 1000.0, 200.0
PORTAL = scene(
    [
        {"id": "pier_l", "vertices": rect(0, 0, PB, PH)},
        {"id": "pier_r", "vertices": rect(SPAN - PB, 0, PB, PH)},
        {"id": "lintel", "vertices": rect(-100, PH, SPAN + 200, LT)},
    ]
)


def portal_alpha(theta):
    """Sway of the portal: each pier turns clockwise by θ about its right toe, hinged to the lintel
    at its top-left corner; the lintel translates with those corners (a parallelogram)."""
    weights, vx, vy = [], [], []
    for x0 in (0.0, SPAN - PB):
        toe = np.array([x0 + PB, 0.0])
        c, s = math.cos(theta), math.sin(theta)
        rot = np.array([[c, s], [-s, c]])  # clockwise by θ
        centroid = toe + rot @ np.array([-PB / 2, PH / 2])
        corner = toe + rot @ np.array([-PB, PH])
        for point, w in ((centroid, PB * PH), (corner, None)):
            r = point - toe
            v = np.array([r[1], -r[0]])  # clockwise unit rate
            if w is None:
                lintel_v = v
            else:
                weights.append(w)
                vx.append(v[0])
                vy.append(v[1])
    weights.append((SPAN + 200) * LT)
    vx.append(lintel_v[0])
    vy.append(lintel_v[1])
    weight = np.array(weights)
    return float(weight @ np.array(vy) / (weight @ np.array(vx)))


def portal_theta(d):
    """θ that moves the lintel (its control centroid) by d: d = b(1 − cos θ) + h sin θ."""
    lo, hi = 0.0, 1.5
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if PB * (1 - math.cos(mid)) + PH * math.sin(mid) < d else (lo, mid)
    return 0.5 * (lo + hi)
