"""The kinematic seismic check of a local mechanism (NTC 2018 with the Circolare 2019 or 2009).

The mechanism is the one alma's limit analysis finds (not a catalogue's): α₀ is the collapse
multiplier of the horizontal load proportional to the weights, the virtual displacements δx,i
are the horizontal velocities of its masses in the collapse mechanism (blocks' self-weights and
carried loads: :mod:`alma.seismic.masses`), and the capacity curve is ``alma.push``'s α(d) on
the displaced geometry.  ``edition`` chooses the form of the checks: ``"2019"`` (the default,
Circolare n. 7/2019 §C8.7.1.2.1.5–8: :mod:`alma.seismic.check_2019`; at a height Z > 0 its
linear check reads the floor acceleration of Eqs. C7.2.7–8, :mod:`alma.seismic.floor_spectrum`,
and its displacement checks are refused; the SLC check when the site gives the SLC's hazard)
or ``"2009"`` (Circolare n. 617/2009 §C8A.4, below), with P_i the weights of the n moving
masses (kN):

- participating mass and fraction (both editions; 2019 Eq. C8.7.1.5):
  M* = (Σ P_i δx,i)² / (g Σ P_i δx,i²), e* = g M* / Σ P_i;
- spectral acceleration of activation: a₀* = α₀ Σ P_i / (M* FC) = α₀ g / (e* FC)
  (2019: a_{Z,SLD} of Eq. C8.7.1.8);
- capacity curve (both editions; 2019 Eqs. C8.7.1.3–4): d* = d_k Σ P_i δx,i² / (δx,k Σ P_i δx,i)
  (d_k the control point's displacement) and a* = α g / (e* FC) (FC divides the accelerations as
  it does a₀*; the displacements are not divided);
- 2009 linear check: a₀* ≥ a_g S / q for a mechanism at the ground (Z = 0), and, for a mechanism
  whose base is at height Z > 0, also a₀* ≥ S_e(T₁) ψ(Z) γ / q with T₁ = C₁ H^¾ (C₁ = 0.050,
  NTC 2018 Eq. 7.3.6 for masonry), ψ(Z) = Z / H and γ = 3N / (2N + 1) (N storeys); the demand is
  the larger, the safety index a₀* / demand;
- 2009 nonlinear check: d₀* where a* = 0; d_u* = 0.4 d₀*, or the displacement where the curve
  loses equilibrium when that is smaller (the code's "situations incompatible with the stability
  of the elements"; d₀* is then extrapolated on the secant of the curve's last two points);
  d_s* = 0.4 d_u*, a_s* = a*(d_s*), T_s = 2π √(d_s*/a_s*); demand Δ = S_De(T_s) at Z = 0, and for
  Z > 0 also S_De(T₁) ψ(Z) γ (T_s/T₁)² / √((1 − T_s/T₁)² + 0.02 T_s/T₁); the safety index
  d_u* / demand.

Units: masses in kg, accelerations in m/s², displacements in m (the scene's mm converted),
periods in s.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np

from alma.geometry.scene import Scene
from alma.push import PushResult, push
from alma.results.types import finite
from alma.seismic.check_2019 import (
    XI_SLC,
    XI_SLV,
    d0_star_of,
    linear_2019,
    nonlinear_2019,
    nonlinear_at_height,
    slc_2019,
)
from alma.seismic.floor_spectrum import C1_MASONRY, first_mode, floor_terms
from alma.seismic.masses import MassPoints, check_loads, mass_points
from alma.seismic.site import EDITIONS, SITE_KEYS, SLC_KEYS, Site
from alma.seismic.spectrum import G, Spectrum, elastic_spectrum
from alma.status import Status

#: Ultimate and secant displacements as fractions of d₀* and d_u* (Circolare 2009 §C8A.4).
ULTIMATE_FRACTION = 0.4
SECANT_FRACTION = 0.4
#: The JSON fields ``du_star`` and ``Ts`` (SPEC §3) are these terms of each edition's nonlinear check.
_TOP_FIELDS = {"2009": ("du_star", "Ts"), "2019": ("d_SLV", "T_SLV")}


@dataclass(frozen=True)
class SeismicResult:
    """The kinematic check of SPEC §3 ``alma seismic`` (units in the module docstring)."""

    status: Status
    message: str
    site: Site
    spectrum: Spectrum
    alpha0: float
    M_star: float
    e_star: float
    a0_star: float
    linear: dict[str, Any]
    nonlinear: dict[str, Any]
    #: The capacity curve in spectral coordinates: (d* m, a* m/s²) per point of the push curve.
    curve_star: tuple[tuple[float, float], ...]
    push: PushResult = field(repr=False, compare=False)
    #: The Circolare whose form of the checks was applied ("2019" or "2009").
    edition: str = EDITIONS[0]
    #: The moving masses and their virtual displacements (None when there is no curve).
    masses: MassPoints | None = field(default=None, repr=False, compare=False)
    #: The 2019 displacement check at SLC (None unless the site gives the SLC's hazard).
    slc: dict[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        clean = lambda d: {k: (finite(v) if isinstance(v, float) else v) for k, v in d.items()}  # noqa: E731
        nl = clean(self.nonlinear)
        du, ts = _TOP_FIELDS[self.edition]
        masses = self.masses
        carried = [{"load": i, "block": b, "weight": w, "dx": d} for i, b, w, d in masses.carried] if masses else []
        return {
            "status": str(self.status),
            "message": self.message,
            "edition": self.edition,
            "control": self.push.control,
            "alpha0": finite(self.alpha0),
            "M_star": finite(self.M_star),
            "e_star": finite(self.e_star),
            "a0_star": finite(self.a0_star),
            "demand": finite(self.linear["demand"]),
            "safety_index": finite(self.linear["safety_index"]),
            "linear": clean(self.linear),
            "d0_star": nl.get("d0_star"),
            "du_star": nl.get(du),
            "Ts": nl.get(ts),
            "nonlinear": nl,
            "slc": clean(self.slc) if self.slc is not None else None,
            "spectrum": self.spectrum.to_dict(),
            "site": {k: getattr(self.site, k) for k in sorted(SITE_KEYS)},
            "carried_loads": carried,
            "external_forces": list(masses.forces) if masses else [],
            "curve_star": [[finite(d), finite(a)] for d, a in self.curve_star],
            "push": self.push.to_dict(),
        }


def _site_for(site: Site | Mapping[str, Any], edition: str | None) -> Site:
    """The site checked as a site file is, with ``edition`` (None: the site's own) applied."""
    if isinstance(site, Site):
        site.check()  # a Site built directly is checked as a site file is
    else:
        site = Site.from_dict(site)
    edition = site.edition if edition is None else edition
    if edition not in EDITIONS:
        raise ValueError(f"edition must be one of {list(EDITIONS)}, got {edition!r}")
    if edition != site.edition:
        site = dataclasses.replace(site, edition=edition)
    site.needs_for(edition)
    return site


def _checked_scene(scene: Scene) -> Scene:
    """``scene`` validated, its actions those the code's check assumes (else a ValueError naming them)."""
    if not scene.validated:
        scene = scene.validate()
    if not (scene.live_self_weight and abs(scene.live_load_direction[1]) < 1e-12 and abs(scene.gravity[0]) < 1e-12):
        raise ValueError(
            "the kinematic check needs gravity along -y and the live load the weights along ±x: "
            "the code's action is proportional to the masses"
        )
    check_loads(scene)
    return scene


def _participation(masses: MassPoints) -> tuple[float, float, float]:
    """M* (kg), e* and d*/d_k of the mass points (module docstring; weights in kN, δ in mm)."""
    weights, dx, k = masses.weight, masses.dx, masses.control
    m_star = float((weights @ dx) ** 2 / (G * (weights @ dx**2))) * 1e3  # kN → N, so kg
    e_star = G * m_star / (float(weights.sum()) * 1e3)
    factor = float((weights @ dx**2) / (dx[k] * (weights @ dx)))  # d* = d_k · factor
    return m_star, e_star, factor


def seismic(
    scene: Scene,
    site: Site | Mapping[str, Any],
    *,
    edition: str | None = None,
    curve: PushResult | None = None,
    **push_options: Any,
) -> SeismicResult:
    """The linear and nonlinear kinematic checks of ``scene``'s collapse mechanism at ``site``.

    Parameters
    ----------
    scene
        The structure (mm, kN): gravity along −y, the live load the free blocks' weights along ±x
        (the code's action on the masses, α P_k), point loads either carried masses (their live
        part their mass's weight along the same direction) or external forces F_k (no live part):
        :mod:`alma.seismic.masses`.
    site
        The site's parameters (SPEC §3 site file keys).
    edition
        ``"2019"`` or ``"2009"``: the Circolare whose form of the checks applies (module
        docstring); None takes the site's ``edition`` (default "2019").
    curve
        A capacity curve already computed for ``scene`` (else ``alma.push(scene,
        **push_options)`` runs).

    Returns
    -------
    SeismicResult
        Both checks' terms under the edition's names; ``edition`` says which applied.
    """
    site = _site_for(site, edition)
    edition = site.edition
    scene = _checked_scene(scene)
    spec = elastic_spectrum(site.ag, site.F0, site.Tc_star, site.soil, site.topography)
    pushed = curve if curve is not None else push(scene, **push_options)
    if not pushed.curve:
        nan = math.nan
        demand = _linear_demand(site, spec) if edition == "2009" else spec.ag
        return SeismicResult(
            pushed.status,
            pushed.message,
            site,
            spec,
            nan,
            nan,
            nan,
            nan,
            {"demand": demand, "safety_index": nan, "verified": None},
            {},
            (),
            pushed,
            edition,
        )
    masses = mass_points(scene, pushed)
    alpha0 = pushed.curve[0].alpha
    m_star, e_star, factor = _participation(masses)
    a0_star = alpha0 * G / (e_star * site.FC)
    d_star = np.array([p.d for p in pushed.curve]) * factor * 1e-3
    a_star = np.array([p.alpha for p in pushed.curve]) * G / (e_star * site.FC)
    curve_star = tuple(zip(d_star.tolist(), a_star.tolist(), strict=True))
    if edition == "2009":
        demand = _linear_demand(site, spec)
        linear: dict[str, Any] = {
            "demand": demand,
            "safety_index": a0_star / demand,
            "verified": bool(a0_star >= demand),
        }
        nonlinear: dict[str, Any] = _nonlinear(site, spec, pushed, d_star, a_star, factor)
        slc = None
    else:
        linear, nonlinear, slc = _checks_2019(site, spec, a0_star, pushed, d_star, a_star, factor)
    status, message = pushed.status, pushed.message
    safety = cast(float, nonlinear.get("safety_index", math.nan))  # a number when present
    if "refused" in nonlinear:
        message = f"{message}; not done: {nonlinear['refused']}"
    elif not math.isfinite(safety):
        message = f"{message}; the nonlinear check needs d0 (the curve must reach α = 0)"
    return SeismicResult(
        status,
        message,
        site,
        spec,
        alpha0,
        m_star,
        e_star,
        a0_star,
        linear,
        nonlinear,
        curve_star,
        pushed,
        edition,
        masses,
        slc,
    )


def _checks_2019(
    site: Site,
    spec: Spectrum,
    a0_star: float,
    pushed: PushResult,
    d_star: np.ndarray,
    a_star: np.ndarray,
    factor: float,
) -> tuple[dict[str, Any], dict[str, Any], dict[str, Any] | None]:
    """The 2019 linear, SLV displacement and SLC displacement checks (:mod:`alma.seismic.check_2019`).

    At Z > 0 the linear check reads the floor acceleration a_Z(z) of Eqs. C7.2.7–8 (first mode,
    the ground spectrum at ξ_1) and the displacement checks are not done (their ``refused``).
    """
    if site.Z > 0:
        n, H, xi1 = cast(int, site.storeys), cast(float, site.H), cast(float, site.xi1)
        mode = first_mode(site.Z, H, n, xi1, site.T1)
        spec1 = elastic_spectrum(site.ag, site.F0, site.Tc_star, site.soil, site.topography, damping=xi1)
        linear = linear_2019(site.q, spec, a0_star, floor_terms(spec1, mode))
        refused = nonlinear_at_height(pushed, factor)
        return linear, refused, (dict(refused) if site.ag_SLC is not None else None)
    linear = linear_2019(site.q, spec, a0_star)
    spec8 = elastic_spectrum(site.ag, site.F0, site.Tc_star, site.soil, site.topography, damping=XI_SLV)
    nonlinear = nonlinear_2019(pushed, d_star, a_star, factor, spec8, cast(float, linear["a_g_SLD"]))
    if site.ag_SLC is None:
        return linear, nonlinear, None
    ag, f0, tc = (cast(float, getattr(site, k)) for k in SLC_KEYS)
    spec10 = elastic_spectrum(ag, f0, tc, site.soil, site.topography, damping=XI_SLC)
    return linear, nonlinear, slc_2019(pushed, d_star, a_star, factor, spec10)


def _linear_demand(site: Site, spec: Spectrum) -> float:
    """a_g S / q, and at Z > 0 the larger of it and S_e(T₁) ψ(Z) γ / q (m/s², Circolare 2009)."""
    ground = spec.ag * spec.S / site.q
    if site.Z <= 0:
        return ground
    T1, psi, gamma = _building(site)
    return max(ground, spec.Se(T1) * psi * gamma / site.q)


def _building(site: Site) -> tuple[float, float, float]:
    """T₁ = C₁ H^¾ (s), ψ(Z) = Z/H and γ = 3N/(2N + 1)."""
    # Only at Z > 0, where Site.from_dict requires H and storeys.
    n, H = cast(int, site.storeys), cast(float, site.H)
    return C1_MASONRY * H**0.75, site.Z / H, 3 * n / (2 * n + 1)


def _nonlinear(
    site: Site, spec: Spectrum, pushed: PushResult, d_star: np.ndarray, a_star: np.ndarray, factor: float
) -> dict[str, float | bool | None]:
    """d₀*, d_u*, d_s*, a_s*, T_s and the displacement check of the Circolare 2009 (module docstring)."""
    d0_star, lost = d0_star_of(pushed, factor)
    if not math.isfinite(d0_star):
        return {
            "d0_star": math.nan,
            "du_star": math.nan,
            "ds_star": math.nan,
            "as_star": math.nan,
            "Ts": math.nan,
            "demand": math.nan,
            "safety_index": math.nan,
            "verified": None,
        }
    du_star = min(ULTIMATE_FRACTION * d0_star, lost) if math.isfinite(lost) else ULTIMATE_FRACTION * d0_star
    ds_star = SECANT_FRACTION * du_star
    as_star = float(np.interp(ds_star, d_star, a_star))
    Ts = 2 * math.pi * math.sqrt(ds_star / as_star)
    demand = spec.SDe(Ts)
    if site.Z > 0:
        T1, psi, gamma = _building(site)
        r = Ts / T1
        demand = max(demand, spec.SDe(T1) * psi * gamma * r**2 / math.sqrt((1 - r) ** 2 + 0.02 * r))
    return {
        "d0_star": d0_star,
        "du_star": du_star,
        "ds_star": ds_star,
        "as_star": as_star,
        "Ts": Ts,
        "demand": demand,
        "safety_index": du_star / demand,
        "verified": bool(du_star >= demand),
        "d0_extrapolated": bool(math.isfinite(lost)),
        "d_lost_star": lost,
    }
