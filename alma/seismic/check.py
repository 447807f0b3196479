"""The kinematic seismic check of a local mechanism (NTC 2018 with Circolare n. 7/2019, §C8.7.1).

The mechanism is the one alma's limit analysis finds (not a catalogue's): α₀ is the collapse
multiplier of the horizontal load proportional to the weights, the virtual displacements δx,i
are its blocks' centroids' horizontal velocities, and the capacity curve is ``alma.push``'s
α(d) on the displaced geometry.  Formulas (Circolare 2019 §C8.7.1.2, as in the Circolare 2009
§C8A.4 they come from), with P_i the weights of the n moving blocks (kN):

- participating mass and fraction: M* = (Σ P_i δx,i)² / (g Σ P_i δx,i²),
  e* = g M* / Σ P_i;
- spectral acceleration of activation: a₀* = α₀ Σ P_i / (M* FC) = α₀ g / (e* FC);
- linear check: a₀* ≥ a_g S / q for a mechanism at the ground (Z = 0), and, for a mechanism
  whose base is at height Z > 0, also a₀* ≥ S_e(T₁) ψ(Z) γ / q with T₁ = C₁ H^¾ (C₁ = 0.050,
  NTC 2018 Eq. 7.3.6 for masonry), ψ(Z) = Z / H and γ = 3N / (2N + 1) (N storeys); the demand is
  the larger, the safety index a₀* / demand;
- nonlinear check: the capacity curve in spectral coordinates d* = d_k Σ P_i δx,i² /
  (δx,k Σ P_i δx,i) (d_k the control point's displacement) and a* = α g / (e* FC) (FC divides the
  accelerations as it does a₀*; the displacements are not divided); d₀* where a* = 0;
  d_u* = 0.4 d₀*, or the displacement where the curve loses equilibrium when that is smaller
  (the code's "situations incompatible with the stability of the elements"; d₀* is then
  extrapolated on the secant of the curve's last two points); d_s* = 0.4 d_u*,
  a_s* = a*(d_s*), T_s = 2π √(d_s*/a_s*); demand Δ = S_De(T_s) at Z = 0, and for Z > 0 also
  S_De(T₁) ψ(Z) γ (T_s/T₁)² / √((1 − T_s/T₁)² + 0.02 T_s/T₁); the safety index d_u* / demand.

Units: masses in kg, accelerations in m/s², displacements in m (the scene's mm converted),
periods in s.
"""
from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

import numpy as np

from alma.geometry.contacts import block_areas_and_centroids
from alma.geometry.scene import Scene
from alma.push import PushResult, push
from alma.results.types import finite
from alma.seismic.spectrum import G, Spectrum, elastic_spectrum
from alma.status import Status

#: kN per (mm³ · kN/m³)
_MM3_TO_M3 = 1e-9
#: C₁ of T₁ = C₁ H^¾ for masonry buildings (NTC 2018 Eq. 7.3.6).
C1_MASONRY = 0.050
#: Ultimate and secant displacements as fractions of d₀* and d_u* (Circolare §C8.7.1.2).
ULTIMATE_FRACTION = 0.4
SECANT_FRACTION = 0.4
_SITE_KEYS = {"ag", "F0", "Tc_star", "soil", "topography", "FC", "q", "Z", "H", "storeys"}


@dataclass(frozen=True)
class Site:
    """A site's parameters (SPEC §3 site file): a_g in g, T_C* in s, Z and H in m."""

    ag: float
    F0: float
    Tc_star: float
    soil: str
    topography: str = "T1"
    #: Confidence factor: 1.35 (knowledge level LC1) unless the user's survey earns less.
    FC: float = 1.35
    #: Behaviour factor of the linear check: 2.0 as the Circolare sets it.
    q: float = 2.0
    Z: float = 0.0
    H: float | None = None
    storeys: int | None = None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Site:
        """The site of a TOML table (keys of SPEC §3), checked key by key."""
        unknown = set(data) - _SITE_KEYS
        if unknown:
            raise ValueError(f"site: unknown key(s) {sorted(unknown)}; allowed: {sorted(_SITE_KEYS)}")
        missing = {"ag", "F0", "Tc_star", "soil"} - set(data)
        if missing:
            raise ValueError(f"site: missing key(s) {sorted(missing)}")
        site = cls(**{k: data[k] for k in data})
        for name in ("ag", "F0", "Tc_star", "FC", "q"):
            value = getattr(site, name)
            if (isinstance(value, bool) or not isinstance(value, (int, float))
                    or not (math.isfinite(value) and value > 0)):
                raise ValueError(f"site: {name} must be a positive number, got {value!r}")
        if (isinstance(site.Z, bool) or not isinstance(site.Z, (int, float))
                or not (math.isfinite(site.Z) and site.Z >= 0)):
            raise ValueError(f"site: Z must be a number >= 0 (m), got {site.Z!r}")
        if site.Z > 0:
            if not (isinstance(site.H, (int, float)) and site.H >= site.Z and site.H > 0):
                raise ValueError(f"site: a mechanism at Z = {site.Z} m needs the building's height H >= Z (m)")
            if not (isinstance(site.storeys, int) and not isinstance(site.storeys, bool) and site.storeys >= 1):
                raise ValueError("site: a mechanism at Z > 0 needs 'storeys', a positive integer")
        elastic_spectrum(site.ag, site.F0, site.Tc_star, site.soil, site.topography)  # checks soil, topography
        return site


def load_site(path: str | Path) -> Site:
    """Read a site file (TOML, SPEC §3)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except OSError as exc:
        raise ValueError(f"site file '{path}': cannot be read ({exc.strerror})") from exc
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"site file '{path}': not valid TOML ({exc})") from exc
    try:
        return Site.from_dict(data)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"site file '{path}': {exc}") from exc


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
    linear: dict[str, float | bool | None]
    nonlinear: dict[str, float | bool | None]
    #: The capacity curve in spectral coordinates: (d* m, a* m/s²) per point of the push curve.
    curve_star: tuple[tuple[float, float], ...]
    push: PushResult = field(repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        clean = lambda d: {k: (finite(v) if isinstance(v, float) else v) for k, v in d.items()}  # noqa: E731
        nl = clean(self.nonlinear)
        return {"status": str(self.status), "message": self.message, "control": self.push.control,
                "alpha0": finite(self.alpha0), "M_star": finite(self.M_star), "e_star": finite(self.e_star),
                "a0_star": finite(self.a0_star), "demand": finite(self.linear["demand"]),
                "safety_index": finite(self.linear["safety_index"]), "linear": clean(self.linear),
                "d0_star": nl.get("d0_star"), "du_star": nl.get("du_star"), "Ts": nl.get("Ts"),
                "nonlinear": nl, "spectrum": self.spectrum.to_dict(),
                "site": {k: getattr(self.site, k) for k in sorted(_SITE_KEYS)},
                "curve_star": [[finite(d), finite(a)] for d, a in self.curve_star],
                "push": self.push.to_dict()}


def seismic(scene: Scene, site: Site | Mapping[str, Any], *, curve: PushResult | None = None,
            **push_options: Any) -> SeismicResult:
    """The linear and nonlinear kinematic checks of ``scene``'s collapse mechanism at ``site``.

    ``curve``: a capacity curve already computed for ``scene`` (else ``alma.push(scene,
    **push_options)`` runs).  The live load must be the weights in a horizontal direction (the
    code's seismic action on masses proportional to the weights).
    """
    site = site if isinstance(site, Site) else Site.from_dict(site)
    if not scene.validated:
        scene = scene.validate()
    if not (scene.live_self_weight and not scene.loads and abs(scene.live_load_direction[1]) < 1e-12
            and abs(scene.gravity[0]) < 1e-12):
        raise ValueError("the kinematic check needs gravity along -y and the live load the weights along ±x "
                         "(no extra point loads): the code's action is proportional to the masses")
    spec = elastic_spectrum(site.ag, site.F0, site.Tc_star, site.soil, site.topography)
    pushed = curve if curve is not None else push(scene, **push_options)
    if not pushed.curve:
        nan = math.nan
        return SeismicResult(pushed.status, pushed.message, site, spec, nan, nan, nan, nan,
                             {"demand": _linear_demand(site, spec), "safety_index": nan, "verified": None},
                             {}, (), pushed)
    weights, dx, k = _virtual(scene, pushed)
    alpha0 = pushed.curve[0].alpha
    sum_p = float(weights.sum())
    m_star = float((weights @ dx) ** 2 / (G * (weights @ dx ** 2))) * 1e3  # kN → N, so kg
    e_star = G * m_star / (sum_p * 1e3)
    a0_star = alpha0 * G / (e_star * site.FC)
    demand = _linear_demand(site, spec)
    linear: dict[str, float | bool | None] = {"demand": demand, "safety_index": a0_star / demand,
                                              "verified": bool(a0_star >= demand)}
    factor = float((weights @ dx ** 2) / (dx[k] * (weights @ dx)))  # d* = d_k · factor
    d_star = np.array([p.d for p in pushed.curve]) * factor * 1e-3
    a_star = np.array([p.alpha for p in pushed.curve]) * G / (e_star * site.FC)
    curve_star = tuple(zip(d_star.tolist(), a_star.tolist(), strict=True))
    nonlinear = _nonlinear(site, spec, pushed, d_star, a_star, factor)
    status, message = pushed.status, pushed.message
    safety = cast(float, nonlinear.get("safety_index", math.nan))  # a number when present
    if not math.isfinite(safety):
        message = f"{message}; the nonlinear check needs d0 (the curve must reach α = 0)"
    return SeismicResult(status, message, site, spec, alpha0, m_star, e_star, a0_star, linear, nonlinear,
                         curve_star, pushed)


def _virtual(scene: Scene, pushed: PushResult) -> tuple[np.ndarray, np.ndarray, int]:
    """Weights P_i (kN) and horizontal virtual displacements δx,i (along the curve's sense) of the
    moving blocks of the collapse mechanism, and the control block's row."""
    areas, _ = block_areas_and_centroids(scene)
    index = {b.id: i for i, b in enumerate(scene.blocks)}
    ids = [b.id for b in pushed.first.blocks]
    u = np.array([b.u for b in pushed.first.blocks], dtype=float).reshape(-1, 3)
    rows = np.array([index[i] for i in ids])
    own = np.array([scene.blocks[i].weight if scene.blocks[i].weight is not None else np.nan for i in rows])
    weights = np.where(np.isnan(own), np.abs(areas[rows]) * scene.thickness * scene.unit_weight * _MM3_TO_M3, own)
    moving = set().union(*(m.blocks for m in pushed.first.macro_blocks)) if pushed.first.macro_blocks else set(ids)
    keep = np.array([i in moving for i in ids])
    dx = u[:, 0] * pushed.sense
    k = int(np.flatnonzero(np.array(ids)[keep] == pushed.control)[0])
    return weights[keep], dx[keep], k


def _linear_demand(site: Site, spec: Spectrum) -> float:
    """a_g S / q, and at Z > 0 the larger of it and S_e(T₁) ψ(Z) γ / q (m/s²)."""
    ground = spec.ag * spec.S / site.q
    if site.Z <= 0:
        return ground
    T1, psi, gamma = _building(site)
    return max(ground, spec.Se(T1) * psi * gamma / site.q)


def _building(site: Site) -> tuple[float, float, float]:
    """T₁ = C₁ H^¾ (s), ψ(Z) = Z/H and γ = 3N/(2N + 1)."""
    # Only at Z > 0, where Site.from_dict requires H and storeys.
    n, H = cast(int, site.storeys), cast(float, site.H)
    return C1_MASONRY * H ** 0.75, site.Z / H, 3 * n / (2 * n + 1)


def _nonlinear(site: Site, spec: Spectrum, pushed: PushResult, d_star: np.ndarray, a_star: np.ndarray,
               factor: float) -> dict[str, float | bool | None]:
    """d₀*, d_u*, d_s*, a_s*, T_s and the displacement check (module docstring)."""
    d0, lost = pushed.d0, math.nan
    if not math.isfinite(d0) and pushed.end.get("reason") == "no_equilibrium" and len(pushed.curve) >= 2:
        # the curve stops at a loss of equilibrium with α > 0: d₀ is extrapolated on the secant of
        # its last two points, and the stop itself bounds d_u* (the Circolare's "displacement
        # incompatible with the stability of the elements")
        (d1, a1), (d2, a2) = [(p.d, p.alpha) for p in pushed.curve[-2:]]
        d0 = d2 + (d2 - d1) * a2 / (a1 - a2) if a1 > a2 > 0 else math.nan
        lost = pushed.end["bracket"][0] * factor * 1e-3
    if not math.isfinite(d0):
        return {"d0_star": math.nan, "du_star": math.nan, "ds_star": math.nan, "as_star": math.nan,
                "Ts": math.nan, "demand": math.nan, "safety_index": math.nan, "verified": None}
    d0_star = d0 * factor * 1e-3
    du_star = min(ULTIMATE_FRACTION * d0_star, lost) if math.isfinite(lost) else ULTIMATE_FRACTION * d0_star
    ds_star = SECANT_FRACTION * du_star
    as_star = float(np.interp(ds_star, d_star, a_star))
    Ts = 2 * math.pi * math.sqrt(ds_star / as_star)
    demand = spec.SDe(Ts)
    if site.Z > 0:
        T1, psi, gamma = _building(site)
        r = Ts / T1
        demand = max(demand, spec.SDe(T1) * psi * gamma * r ** 2 / math.sqrt((1 - r) ** 2 + 0.02 * r))
    return {"d0_star": d0_star, "du_star": du_star, "ds_star": ds_star, "as_star": as_star, "Ts": Ts,
            "demand": demand, "safety_index": du_star / demand, "verified": bool(du_star >= demand),
            "d0_extrapolated": bool(math.isfinite(lost)), "d_lost_star": lost}
