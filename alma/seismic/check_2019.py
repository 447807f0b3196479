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

Linear check of a mechanism at a height z > 0 (§C8.7.1.2.1.7: "attraverso le equazioni
[C8.7.1.8] e [C7.2.8], nel caso di meccanismi locali rigidamente vincolati alla struttura
principale"): the mechanism activates when the peak floor acceleration a_Z(z) of Eq. C7.2.8
(:mod:`alma.seismic.floor_spectrum`, first mode) reaches a_{Z,SLD}; a_Z(z) is proportional to
a_g with the spectrum's shape held at the site's, so a_{g,SLD} = a_g a_{Z,SLD} / a_Z(z) and
a_{g,SLV} = q a_{g,SLD}.  The displacement checks at z > 0 (Eq. C8.7.1.12 on the floor spectrum
S_eZ of Eqs. C7.2.5–6) are not done: ``nonlinear`` says why (``refused``).

SLC (§C8.7.1.2.1.6 and .8), when the site gives its hazard at the SLC's return period
(a_g, F₀, T_C* there): d_SLC is the smaller of 60 % of d₀ and the displacement "localmente
incompatibile con la stabilità degli elementi" (the curve's loss of equilibrium);
T_SLC = 1.56 π √(d_SLC / a(d_SLC)) (Eq. C8.7.1.11); "un'espressione analoga alla [C8.7.1.12]"
at the ground: the largest S_De over [0, T_SLC] of the SLC spectrum at ξ = 10 %, and
a_{g,SLC} = a_{g,SLC site} d_SLC / demand, compared with the SLC's a_g.  The text does not carry
the floor a_{g,SLD} over to the SLC (it says so of the SLV only), so none is applied.

Units: accelerations in m/s², displacements in m, periods in s.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from alma.push import PushResult
from alma.push.result import STOPPED_ENDS
from alma.seismic.spectrum import Spectrum

#: A check's named terms (numbers, verdicts, names) as the JSON gives them.
Terms = dict[str, Any]
#: d_SLV as a fraction of d₀ (Circolare 2019 §C8.7.1.2.1.6).
SLV_FRACTION = 0.4
#: The coefficient of π in T_SLV = 1.68 π √(d_SLV / a(d_SLV)) (Eq. C8.7.1.10).
T_SLV_COEFFICIENT = 1.68
#: Equivalent viscous damping of the local mechanism at SLV, percent (§C8.7.1.2.1.8).
XI_SLV = 8.0
#: d_SLC as a fraction of d₀ (Circolare 2019 §C8.7.1.2.1.6).
SLC_FRACTION = 0.6
#: The coefficient of π in T_SLC = 1.56 π √(d_SLC / a(d_SLC)) (Eq. C8.7.1.11).
T_SLC_COEFFICIENT = 1.56
#: Equivalent viscous damping of the local mechanism at SLC, percent (§C8.7.1.2.1.8).
XI_SLC = 10.0
#: Why the displacement checks at z > 0 are not done (docs/seismic.md).
HEIGHT_REFUSED = (
    "the 2019 displacement checks at Z > 0 need the floor spectrum S_eZ of Eqs. C7.2.5-6, whose "
    "text (xi_k in percent) gives a peak below the floor's peak acceleration and a vanishing "
    "denominator; alma does not implement it (docs/seismic.md)"
)


def d0_star_of(pushed: PushResult, factor: float) -> tuple[float, float]:
    """d₀* (m) of the curve and the spectral displacement where it stops with α > 0 (m, NaN if not).

    When the curve stops with α > 0 (:data:`~alma.push.result.STOPPED_ENDS`: a loss of equilibrium
    beyond its last point, or a mechanism at its last point that the control block does not
    follow), d₀ is extrapolated on the secant of its last two points, and the stop itself bounds
    the ultimate displacement (the Circolare's "displacement incompatible with the stability of
    the elements").  d₀* is NaN when the curve gives neither.
    """
    d0, lost = pushed.d0, math.nan
    reason = pushed.end.get("reason")
    if not math.isfinite(d0) and reason in STOPPED_ENDS and len(pushed.curve) >= 2:
        (d1, a1), (d2, a2) = [(p.d, p.alpha) for p in pushed.curve[-2:]]
        d0 = d2 + (d2 - d1) * a2 / (a1 - a2) if a1 > a2 > 0 else math.nan
        stop = pushed.end["bracket"][0] if reason == "no_equilibrium" else pushed.end["d"]
        lost = stop * factor * 1e-3
    return d0 * factor * 1e-3, lost


def linear_2019(site_q: float, spec: Spectrum, a0_star: float, floor: dict[str, float | bool] | None = None) -> Terms:
    """The linear check of §C8.7.1.2.1.7 (module docstring): a_{g,SLV} = q a_{g,SLD} >= a_g.

    At z = 0 ``floor`` is None and a_{g,SLD} = a_{Z,SLD} / S; at z > 0 ``floor`` holds the terms
    of a_Z(z) (Eqs. C7.2.7–8, :func:`alma.seismic.floor_spectrum.floor_terms`) at the site's a_g
    and a_{g,SLD} = a_g a_{Z,SLD} / a_Z(z).  ``governs`` names the demand: "ground" or "floor".
    """
    a_z = a0_star  # Eq. C8.7.1.8: a_{Z,SLD} = α₀ g / (e* FC)
    if floor is None:
        a_g_sld = a_z / spec.S
        required = spec.ag * spec.S / site_q
    else:
        a_floor = float(floor["a_Z"])
        a_g_sld = spec.ag * a_z / a_floor  # a_Z(z) is proportional to a_g (Eq. C7.2.7)
        required = a_floor / site_q
    a_g_slv = site_q * a_g_sld
    terms: Terms = {
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
        "a0_star_required": required,
        "governs": "ground" if floor is None else "floor",
    }
    if floor is not None:
        terms.update(floor)
    return terms


def _nan_check(spec: Spectrum, xi: float, state: str) -> Terms:
    """The displacement check's fields at limit state ``state`` ("SLV", "SLC") when the curve gives no d₀."""
    nan = math.nan
    return {
        "d0_star": nan,
        f"d_{state}": nan,
        f"a_{state}": nan,
        f"T_{state}": nan,
        "xi": xi,
        "eta": spec.eta,
        "displacement_demand": nan,
        f"a_g_{state}": nan,
        "capacity": nan,
        "demand": spec.ag,
        "safety_index": nan,
        "verified": None,
    }


def _displacement_check(
    d_ls: float, d_star: np.ndarray, a_star: np.ndarray, coefficient: float, spec: Spectrum
) -> tuple[float, float, float, float]:
    """a(d), T = c π √(d / a(d)) (Eqs. C8.7.1.10–11), the demand max S_De over [0, T] and
    a_g d / demand (Eq. C8.7.1.12 at the ground, the spectrum's shape held): m/s², s, m, m/s²."""
    a_ls = float(np.interp(d_ls, d_star, a_star))
    t_ls = coefficient * math.pi * math.sqrt(d_ls / a_ls)
    demand = spec.SDe_max(t_ls)
    return a_ls, t_ls, demand, spec.ag * d_ls / demand


def _limit_state(
    state: str,
    xi: float,
    fraction: float,
    coefficient: float,
    pushed: tuple[float, float],
    curve: tuple[np.ndarray, np.ndarray],
    spec: Spectrum,
) -> tuple[Terms, float]:
    """The displacement check's terms at ``state`` ("SLV", "SLC") up to its demand, and
    a_g d / demand (m/s²).  ``pushed`` is (d₀*, the loss of equilibrium), d = min(``fraction``
    d₀*, the loss); ``curve`` the curve (d*, a*) of Eqs. C8.7.1.3–4 (m, m/s²)."""
    d0_star, lost = pushed
    d_ls = min(fraction * d0_star, lost) if math.isfinite(lost) else fraction * d0_star
    a_ls, t_ls, demand, by_displacement = _displacement_check(d_ls, *curve, coefficient, spec)
    terms: Terms = {
        "d0_star": d0_star,
        f"d_{state}": d_ls,
        f"a_{state}": a_ls,
        f"T_{state}": t_ls,
        "xi": xi,
        "eta": spec.eta,
        "displacement_demand": demand,
    }
    return terms, by_displacement


def _verdict(capacity: float, spec: Spectrum, lost: float) -> Terms:
    """The check's last terms: the capacity a_g (m/s²) against the site's, and the curve's end."""
    return {
        "capacity": capacity,
        "demand": spec.ag,
        "safety_index": capacity / spec.ag,
        "verified": bool(capacity >= spec.ag),
        "d0_extrapolated": bool(math.isfinite(lost)),
        "d_lost_star": lost,
    }


def nonlinear_2019(
    pushed: PushResult, d_star: np.ndarray, a_star: np.ndarray, factor: float, spec8: Spectrum, a_g_sld: float
) -> Terms:
    """The displacement check at SLV of §C8.7.1.2.1.8 at z = 0 (module docstring).

    ``spec8`` is the site's spectrum at ξ = 8 %; ``d_star``, ``a_star`` the curve of
    Eqs. C8.7.1.3–4 (m, m/s²); ``a_g_sld`` the linear check's a_{g,SLD} (m/s²).  ``governs``
    says whether the displacement or a_{g,SLD} gave a_{g,SLV}.
    """
    d0_star, lost = d0_star_of(pushed, factor)
    if not math.isfinite(d0_star):
        return _nan_check(spec8, XI_SLV, "SLV")
    curve = (d_star, a_star)
    terms, by_displacement = _limit_state("SLV", XI_SLV, SLV_FRACTION, T_SLV_COEFFICIENT, (d0_star, lost), curve, spec8)
    a_g_slv = max(by_displacement, a_g_sld)
    return {
        **terms,
        "a_g_SLD": a_g_sld,
        "a_g_SLV": a_g_slv,
        **_verdict(a_g_slv, spec8, lost),
        "governs": "displacement" if by_displacement >= a_g_sld else "a_g_SLD",
    }


def nonlinear_at_height(pushed: PushResult, factor: float) -> Terms:
    """The displacement check at z > 0, not done (module docstring): d₀* and the reason."""
    d0_star, lost = d0_star_of(pushed, factor)
    return {"d0_star": d0_star, "d_lost_star": lost, "verified": None, "refused": HEIGHT_REFUSED}


def slc_2019(pushed: PushResult, d_star: np.ndarray, a_star: np.ndarray, factor: float, spec10: Spectrum) -> Terms:
    """The displacement check at SLC of §C8.7.1.2.1.6 and .8 at z = 0 (module docstring).

    ``spec10`` is the spectrum of the SLC's hazard (a_g, F₀, T_C* at its return period) at
    ξ = 10 %; ``d_star``, ``a_star`` the curve of Eqs. C8.7.1.3–4 (m, m/s²).
    """
    d0_star, lost = d0_star_of(pushed, factor)
    if not math.isfinite(d0_star):
        return _nan_check(spec10, XI_SLC, "SLC")
    curve = (d_star, a_star)
    terms, a_g_slc = _limit_state("SLC", XI_SLC, SLC_FRACTION, T_SLC_COEFFICIENT, (d0_star, lost), curve, spec10)
    return {**terms, "a_g_SLC": a_g_slc, **_verdict(a_g_slc, spec10, lost), "spectrum": spec10.to_dict()}
