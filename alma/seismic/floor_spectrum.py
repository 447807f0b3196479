"""The peak floor acceleration at a height z of the main structure (Circolare 2019 §C7.2.3).

Source: Circolare 21 gennaio 2019, n. 7 C.S.LL.PP., §C7.2.3 "Formulazione semplificata, a
diverse quote, per elementi non strutturali, impianti, eventuali meccanismi locali" (pp. 199–200
of the printed text), to which §C8.7.1.2.1.4 sends the check of a local mechanism at a height z,
read from a public transcription of the official PDF (``docs/seismic.md`` names it).  The
rigid mechanism's linear check (§C8.7.1.2.1.7: "attraverso le equazioni [C8.7.1.8] e [C7.2.8]")
needs the peak acceleration at z only, first mode only ("è, in genere, sufficiente riferirsi al
solo primo modo di vibrare nella direzione di verifica"):

- a_{Z,1}(z) = S_e(T_1, ξ_1) |γ_1 ψ_1(z)| √(1 + 0.0004 ξ_1²)   (Eq. C7.2.7),
  a_Z(z) = √(Σ_k a_{Z,k}(z)²) = a_{Z,1}(z) with the first mode alone   (Eq. C7.2.8);
- S_e(T, ξ) the ground's elastic spectrum (NTC 2018 Eq. 3.2.2) at the period T_1 and the
  equivalent viscous damping ξ_1 (percent, η of NTC Eq. 3.2.4) of the main structure's first
  mode; §C8.7.1.2.1.4 asks for T_1 and ξ_1 compatible with the main structure's nonlinearity
  (masonry at the ultimate limit state: the period 50–100 % longer, ξ from 10 % to 20 %): the
  user gives them;
- ψ_1(z) = z/H and γ_1 = 3n/(2n + 1) (Eq. C7.2.10), the linear first mode normalised to the top
  of a building of n storeys with its masses spread evenly over its height;
- T_1 the user's, or "in assenza di tali valutazioni" the estimate of NTC 2018 Eq. 7.3.6,
  T_1 = C_1 H^¾ with C_1 = 0.050 for masonry.

The floor spectrum S_eZ(T, ξ, z) of Eqs. C7.2.5–6 and C7.2.9, which the displacement checks at
z > 0 need (Eq. C8.7.1.12), is not implemented: read with ξ_k in percent as the text says, its
peak 1.1 ξ_k^−0.5 η(ξ) a_{Z,k} is below a_{Z,k} (0.49 a_{Z,k} at ξ_k = 5 %) and the denominator
of its third branch vanishes at a finite period when 1.1 ξ_k^−0.5 η(ξ) < 1 (``docs/seismic.md``).

Units: accelerations in m/s², periods in s, heights in m, damping in percent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from alma.seismic.spectrum import Spectrum

#: C₁ of T₁ = C₁ H^¾ for masonry buildings (NTC 2018 Eq. 7.3.6).
C1_MASONRY = 0.050
#: The coefficient of ξ_k² in the correction √(1 + 0.0004 ξ_k²) of Eq. C7.2.7 (ξ_k in percent).
MODAL_DAMPING_TERM = 0.0004


@dataclass(frozen=True)
class FirstMode:
    """The main structure's first mode at the mechanism's height (Circolare 2019 §C7.2.3)."""

    #: Period T_1 (s): the user's, or C_1 H^¾ (NTC 2018 Eq. 7.3.6).
    T1: float
    #: Equivalent viscous damping ξ_1 of the first mode (percent).
    xi1: float
    #: Participation factor γ_1 = 3n/(2n + 1) (Eq. C7.2.10).
    gamma: float
    #: Modal shape ψ_1(z) = z/H (the linear first mode, 1 at the top).
    psi: float
    #: True when T_1 is the estimate of NTC 2018 Eq. 7.3.6 (the user gave none).
    T1_estimated: bool


def first_mode(Z: float, H: float, storeys: int, xi1: float, T1: float | None = None) -> FirstMode:
    """The first mode at the height ``Z`` (m) of a building ``H`` (m) tall with ``storeys`` storeys.

    Parameters
    ----------
    Z, H
        The mechanism's height and the building's, from the foundation (m), 0 < Z <= H.
    storeys
        n of γ_1 = 3n/(2n + 1) (Circolare 2019 Eq. C7.2.10).
    xi1
        ξ_1 (percent).
    T1
        T_1 (s); None takes C_1 H^¾ (NTC 2018 Eq. 7.3.6, §C7.2.3 "in assenza di tali valutazioni").
    """
    period = C1_MASONRY * H**0.75 if T1 is None else T1
    return FirstMode(T1=period, xi1=xi1, gamma=3 * storeys / (2 * storeys + 1), psi=Z / H, T1_estimated=T1 is None)


def floor_acceleration(spec1: Spectrum, mode: FirstMode) -> float:
    """a_Z(z) = S_e(T_1, ξ_1) |γ_1 ψ_1(z)| √(1 + 0.0004 ξ_1²) (m/s², Eqs. C7.2.7–8, first mode).

    ``spec1`` is the ground's spectrum at the damping ξ_1 (η of NTC 2018 Eq. 3.2.4).
    """
    correction = math.sqrt(1 + MODAL_DAMPING_TERM * mode.xi1**2)
    return spec1.Se(mode.T1) * abs(mode.gamma * mode.psi) * correction


def floor_terms(spec1: Spectrum, mode: FirstMode) -> dict[str, float | bool]:
    """The terms of a_Z(z) for the JSON (module docstring)."""
    return {
        "T1": mode.T1,
        "T1_estimated": mode.T1_estimated,
        "xi1": mode.xi1,
        "eta1": spec1.eta,
        "gamma1": mode.gamma,
        "psi1": mode.psi,
        "Se_T1": spec1.Se(mode.T1),
        "a_Z": floor_acceleration(spec1, mode),
    }
