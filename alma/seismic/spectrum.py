"""The NTC 2018 elastic response spectra of a site (D.M. 17/01/2018, §3.2.3.2), 5 % damping unless told.

The user gives the site's parameters (no hazard database): a_g (in g), F₀, T_C* (s), the soil
category A–E and the topographic category T1–T4, in a TOML file with the keys of SPEC §3.

Formulas, written from the code's text:

- soil amplification S_S and the coefficient C_C (Tab. 3.2.IV):
  A: S_S = 1.00, C_C = 1.00;
  B: S_S = 1.40 − 0.40 F₀ a_g/g within [1.00, 1.20], C_C = 1.10 (T_C*)^−0.20;
  C: S_S = 1.70 − 0.60 F₀ a_g/g within [1.00, 1.50], C_C = 1.05 (T_C*)^−0.33;
  D: S_S = 2.40 − 1.50 F₀ a_g/g within [0.90, 1.80], C_C = 1.25 (T_C*)^−0.50;
  E: S_S = 2.00 − 1.10 F₀ a_g/g within [1.00, 1.60], C_C = 1.15 (T_C*)^−0.40;
- topographic amplification S_T (Tab. 3.2.V, the value at the top of the relief): T1 1.0,
  T2 1.2, T3 1.2, T4 1.4; S = S_S S_T (Eq. 3.2.3);
- T_C = C_C T_C*, T_B = T_C / 3, T_D = 4.0 a_g/g + 1.6 s (Eqs. 3.2.5–3.2.7);
- η = √(10 / (5 + ξ)) ≥ 0.55 with ξ in percent, so η = 1 at ξ = 5 % (Eq. 3.2.4); the
  Circolare 2019's nonlinear kinematic check reads the spectrum at ξ = 8 % (§C8.7.1.2.1.8);
- the horizontal elastic acceleration spectrum S_e(T) (Eq. 3.2.2):
  0 ≤ T < T_B:   a_g S η F₀ [T/T_B + (1 − T/T_B)/(η F₀)],
  T_B ≤ T < T_C: a_g S η F₀,
  T_C ≤ T < T_D: a_g S η F₀ T_C / T,
  T_D ≤ T:       a_g S η F₀ T_C T_D / T²;
- the elastic displacement spectrum S_De(T) (§3.2.3.2.3, Eq. 3.2.12): S_e(T) (T/2π)² up to
  T_E; between T_E and T_F, 0.025 a_g S T_C T_D [F₀ η + (1 − F₀ η)(T − T_E)/(T_F − T_E)];
  beyond T_F, d_g = 0.025 a_g S T_C T_D, with T_E, T_F of the table of §3.2.3.2.3 (A: 4.5 s, 10 s;
  B: 5.0 s, 10 s; C, D, E: 6.0 s, 10 s);
- the largest displacement over the periods [0, T] (the Circolare 2019's demand of a local
  mechanism, §C8.7.1.2.1.8: the maximum of the displacement spectrum over [T_0, T_SLV], T_0 = 0
  for a mechanism rigid until it activates): S_De is non-decreasing on [0, T_E] (each branch of
  S_e(T) T²/4π² is) and linear, then constant, beyond, so the maximum is the largest of
  S_De(min(T, T_E)), S_De just beyond T_E (d_g F₀ η) when T > T_E, and S_De(T).

Units: accelerations in m/s², displacements in m, periods in s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: Standard gravity (m/s²): a_g is given in g.
G = 9.80665
#: S_S = max(low, min(high, a − b F₀ a_g/g)) and C_C = c (T_C*)^e per soil (NTC 2018 Tab. 3.2.IV).
SOILS = {
    "A": (1.0, 0.0, 1.0, 1.0, 1.0, 0.0),
    "B": (1.40, 0.40, 1.00, 1.20, 1.10, -0.20),
    "C": (1.70, 0.60, 1.00, 1.50, 1.05, -0.33),
    "D": (2.40, 1.50, 0.90, 1.80, 1.25, -0.50),
    "E": (2.00, 1.10, 1.00, 1.60, 1.15, -0.40),
}
#: S_T at the top of the relief (NTC 2018 Tab. 3.2.V).
TOPOGRAPHY = {"T1": 1.0, "T2": 1.2, "T3": 1.2, "T4": 1.4}
#: The lower bound of the damping correction η (NTC 2018 Eq. 3.2.4).
ETA_MIN = 0.55
#: (T_E, T_F) in s of the displacement spectrum (NTC 2018 §3.2.3.2.3).
DISPLACEMENT_PERIODS = {"A": (4.5, 10.0), "B": (5.0, 10.0), "C": (6.0, 10.0), "D": (6.0, 10.0), "E": (6.0, 10.0)}


@dataclass(frozen=True)
class Spectrum:
    """The elastic spectra of one site at one damping (NTC 2018 §3.2.3.2; η = 1 at 5 %)."""

    ag: float  # m/s²
    F0: float
    soil: str
    S_S: float
    S_T: float
    C_C: float
    TB: float
    TC: float
    TD: float
    eta: float = 1.0

    @property
    def S(self) -> float:
        """S = S_S S_T (NTC 2018 Eq. 3.2.3)."""
        return self.S_S * self.S_T

    def Se(self, T: float) -> float:
        """Horizontal elastic acceleration S_e(T) in m/s² (NTC 2018 Eq. 3.2.2)."""
        if T < 0:
            raise ValueError(f"a period must be >= 0 s, got {T}")
        top = self.ag * self.S * self.eta * self.F0
        if T < self.TB:
            return top * (T / self.TB + (1 - T / self.TB) / (self.eta * self.F0))
        if T < self.TC:
            return top
        if T < self.TD:
            return top * self.TC / T
        return top * self.TC * self.TD / T**2

    def SDe(self, T: float) -> float:
        """Elastic displacement S_De(T) in m (NTC 2018 §3.2.3.2.3)."""
        TE, TF = DISPLACEMENT_PERIODS[self.soil]
        if T <= TE:
            return self.Se(T) * (T / (2 * math.pi)) ** 2
        dg = 0.025 * self.ag * self.S * self.TC * self.TD
        if T <= TF:
            return dg * (self.F0 * self.eta + (1 - self.F0 * self.eta) * (T - TE) / (TF - TE))
        return dg

    def SDe_max(self, T: float) -> float:
        """The largest elastic displacement over the periods [0, T] in m (module docstring)."""
        TE, _ = DISPLACEMENT_PERIODS[self.soil]
        best = max(self.SDe(min(T, TE)), self.SDe(T))
        if T > TE:
            best = max(best, 0.025 * self.ag * self.S * self.TC * self.TD * self.F0 * self.eta)
        return best

    def to_dict(self) -> dict[str, float | str]:
        return {
            "ag": self.ag,
            "F0": self.F0,
            "soil": self.soil,
            "S_S": self.S_S,
            "S_T": self.S_T,
            "S": self.S,
            "C_C": self.C_C,
            "TB": self.TB,
            "TC": self.TC,
            "TD": self.TD,
            "eta": self.eta,
        }


def elastic_spectrum(
    ag: float, F0: float, Tc_star: float, soil: str, topography: str = "T1", damping: float = 5.0
) -> Spectrum:
    """The site's spectrum from a_g (in g), F₀, T_C* (s), the soil and topographic categories, at
    the viscous damping ξ = ``damping`` (percent; η of NTC 2018 Eq. 3.2.4)."""
    if soil not in SOILS:
        raise ValueError(f"soil must be one of {sorted(SOILS)}, got {soil!r}")
    if topography not in TOPOGRAPHY:
        raise ValueError(f"topography must be one of {sorted(TOPOGRAPHY)}, got {topography!r}")
    for name, value in (("ag", ag), ("F0", F0), ("Tc_star", Tc_star), ("damping", damping)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive number, got {value!r}")
    a, b, low, high, c, e = SOILS[soil]
    s_s = min(high, max(low, a - b * F0 * ag))
    c_c = c * Tc_star**e
    tc = c_c * Tc_star
    return Spectrum(
        ag=ag * G,
        F0=F0,
        soil=soil,
        S_S=s_s,
        S_T=TOPOGRAPHY[topography],
        C_C=c_c,
        TB=tc / 3,
        TC=tc,
        TD=4.0 * ag + 1.6,
        eta=max(ETA_MIN, math.sqrt(10.0 / (5.0 + damping))),
    )
