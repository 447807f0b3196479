"""The kinematic checks of a local mechanism in the form of the Circolare 2019 (§C8.7.1.2.1.5–8).

Source: Circolare 21 gennaio 2019, n. 7 C.S.LL.PP., §C8.7.1.2.1 (pp. 269–273 of the printed
text), read from a public transcription of the official PDF (``docs/seismic.md`` names it).
Both checks are framed in ground accelerations; the capacity curve is Eqs. C8.7.1.3–5,
a = α(d_C) g / (e* FC) and d = d_C Σ(P+Q)δ² / (δ_Cx Σ(P+Q)δ), as in the Circolare 2009.

Linear check (SLV with a behaviour factor, §C8.7.1.2.1.7), for a mechanism at the ground:

- the mechanism activates when the peak acceleration at its height reaches
  a_{Z,SLD} = α₀ g / (e* FC) (Eq. C8.7.1.8, §C8.7.1.2.1.5);
- at z = 0 the peak acceleration of the ground motion is S_e(0) = a_g S (NTC 2018 Eq. 3.2.2),
  so the ground acceleration of activation is a_{g,SLD} = a_{Z,SLD} / S, with S the site's
  (S_S at the site's a_g);
- a_{g,SLV} = q a_{g,SLD} (q = 2 unless the user gives another), compared with the site's a_g;
  safety index a_{g,SLV} / a_g.

Nonlinear check (displacements at SLV, §C8.7.1.2.1.6 and .8):

- d_SLV is the smaller of 40 % of d₀ (where the spectral acceleration a vanishes) and the
  displacement "incompatible with the stability of the elements" (the curve's loss of
  equilibrium, ``alma.push``'s ``no_equilibrium`` end);
- T_SLV = 1.68 π √(d_SLV / a(d_SLV)) (Eq. C8.7.1.10), a(d_SLV) read off the computed curve;
- the displacement demand is the largest elastic displacement S_De over the periods
  [T_0, T_SLV] (T_0 = 0: the mechanism is rigid until it activates) at the equivalent viscous
  damping ξ = 8 % (η = √(10/(5 + ξ)), NTC 2018 Eq. 3.2.4), for a mechanism at the ground
  (Eq. C8.7.1.12 with the ground's spectrum);
- Eq. C8.7.1.12 gives the ground acceleration a_{g,SLV} at which that demand equals d_SLV:
  with the spectrum's shape held at the site's (S_S, T_C, T_D at the given a_g) the demand is
  proportional to a_g, so a_{g,SLV} = a_g d_SLV / demand; when it is below a_{g,SLD} the
  latter is taken (§C8.7.1.2.1.8); safety index a_{g,SLV} / a_g.

A mechanism at a height z > 0 needs the floor spectrum S_eZ of Eqs. C7.2.5–C7.2.10 (the
building's modes), which is not implemented: the 2019 check refuses Z > 0.

Units: accelerations in m/s², displacements in m, periods in s.
"""

from __future__ import annotations

import math

import numpy as np

from alma.push import PushResult
from alma.seismic.spectrum import Spectrum

#: d_SLV as a fraction of d₀ (Circolare 2019 §C8.7.1.2.1.6).
SLV_FRACTION = 0.4
#: The coefficient of π in T_SLV = 1.68 π √(d_SLV / a(d_SLV)) (Eq. C8.7.1.10).
T_SLV_COEFFICIENT = 1.68
#: Equivalent viscous damping of the local mechanism at SLV, percent (§C8.7.1.2.1.8).
XI_SLV = 8.0


def d0_star_of(pushed: PushResult, factor: float) -> tuple[float, float]:
    """d₀* (m) of the curve and the spectral displacement where it loses equilibrium (m, NaN if not).

    When the curve stops at a loss of equilibrium with α > 0, d₀ is extrapolated on the secant of
    its last two points, and the stop itself bounds the ultimate displacement (the Circolare's
    "displacement incompatible with the stability of the elements").  d₀* is NaN when the curve
    gives neither.
    """
    d0, lost = pushed.d0, math.nan
    if not math.isfinite(d0) and pushed.end.get("reason") == "no_equilibrium" and len(pushed.curve) >= 2:
        (d1, a1), (d2, a2) = [(p.d, p.alpha) for p in pushed.curve[-2:]]
        d0 = d2 + (d2 - d1) * a2 / (a1 - a2) if a1 > a2 > 0 else math.nan
        lost = pushed.end["bracket"][0] * factor * 1e-3
    return d0 * factor * 1e-3, lost


def linear_2019(site_q: float, spec: Spectrum, a0_star: float) -> dict[str, float | bool | None]:
    """The linear check of §C8.7.1.2.1.7 at z = 0 (module docstring): a_{g,SLV} = q a_{Z,SLD} / S ≥ a_g."""
    a_z = a0_star  # Eq. C8.7.1.8: a_{Z,SLD} = α₀ g / (e* FC)
    a_g_sld = a_z / spec.S
    a_g_slv = site_q * a_g_sld
    return {
        "a_Z_SLD": a_z,
        "S": spec.S,
        "a_g_SLD": a_g_sld,
        "q": site_q,
        "a_g_SLV": a_g_slv,
        "capacity": a_g_slv,
        "demand": spec.ag,
        "safety_index": a_g_slv / spec.ag,
        "verified": bool(a_g_slv >= spec.ag),
        # the spectral acceleration a₀* must reach for the same verdict (for the pictures)
        "a0_star_required": spec.ag * spec.S / site_q,
    }


def nonlinear_2019(
    pushed: PushResult, d_star: np.ndarray, a_star: np.ndarray, factor: float, spec8: Spectrum, a_g_sld: float
) -> dict[str, float | bool | None]:
    """The displacement check at SLV of §C8.7.1.2.1.8 at z = 0 (module docstring).

    ``spec8`` is the site's spectrum at ξ = 8 %; ``d_star``, ``a_star`` the curve of
    Eqs. C8.7.1.3–4 (m, m/s²); ``a_g_sld`` the linear check's a_{g,SLD} (m/s²).
    """
    d0_star, lost = d0_star_of(pushed, factor)
    if not math.isfinite(d0_star):
        return {
            "d0_star": math.nan,
            "d_SLV": math.nan,
            "a_SLV": math.nan,
            "T_SLV": math.nan,
            "xi": XI_SLV,
            "eta": spec8.eta,
            "displacement_demand": math.nan,
            "a_g_SLV": math.nan,
            "capacity": math.nan,
            "demand": spec8.ag,
            "safety_index": math.nan,
            "verified": None,
        }
    d_slv = min(SLV_FRACTION * d0_star, lost) if math.isfinite(lost) else SLV_FRACTION * d0_star
    a_slv = float(np.interp(d_slv, d_star, a_star))
    t_slv = T_SLV_COEFFICIENT * math.pi * math.sqrt(d_slv / a_slv)  # Eq. C8.7.1.10
    demand = spec8.SDe_max(t_slv)  # Eq. C8.7.1.12 at the ground, over [0, T_SLV]
    a_g_slv = max(spec8.ag * d_slv / demand, a_g_sld)
    return {
        "d0_star": d0_star,
        "d_SLV": d_slv,
        "a_SLV": a_slv,
        "T_SLV": t_slv,
        "xi": XI_SLV,
        "eta": spec8.eta,
        "displacement_demand": demand,
        "a_g_SLD": a_g_sld,
        "a_g_SLV": a_g_slv,
        "capacity": a_g_slv,
        "demand": spec8.ag,
        "safety_index": a_g_slv / spec8.ag,
        "verified": bool(a_g_slv >= spec8.ag),
        "d0_extrapolated": bool(math.isfinite(lost)),
        "d_lost_star": lost,
    }
