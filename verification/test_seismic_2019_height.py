"""The Circolare 2019's linear check at a height Z > 0 and its SLC check, against hand computations.

Formulas (Circolare 21 gennaio 2019 n. 7, read from a public transcription of the official PDF;
docs/seismic.md names it):

- Eq. C7.2.7–8, first mode: a_Z(z) = S_e(T_1, ξ_1) |γ_1 ψ_1(z)| √(1 + 0.0004 ξ_1²), with
  ψ_1 = z/H, γ_1 = 3n/(2n + 1) (Eq. C7.2.10), T_1 the user's or C_1 H^¾ (NTC 2018 Eq. 7.3.6),
  S_e at the damping ξ_1 (η = √(10/(5 + ξ_1)), NTC Eq. 3.2.4);
- §C8.7.1.2.1.7 with Eqs. C8.7.1.8 and C7.2.8: a_{Z,SLD} = α₀ g / (e* FC) reached by a_Z(z)
  at the ground acceleration a_{g,SLD} = a_g a_{Z,SLD} / a_Z(z); a_{g,SLV} = q a_{g,SLD} ≥ a_g;
- §C8.7.1.2.1.6: d_SLC = 60 % of d₀; Eq. C8.7.1.11: T_SLC = 1.56 π √(d_SLC / a(d_SLC));
  §C8.7.1.2.1.8: ξ = 10 % and "un'espressione analoga alla [C8.7.1.12]" at the ground:
  demand = max S_De over [0, T_SLC] of the SLC's spectrum, a_{g,SLC} = a_g,SLC d_SLC / demand.

Two sites for each check, every term written out.
"""

from __future__ import annotations

import math
from typing import TypedDict

import pytest
from hypothesis import given, settings, strategies as st

import alma
from alma.seismic import Site
from alma.seismic.floor_spectrum import first_mode, floor_acceleration
from alma.seismic.spectrum import G, elastic_spectrum

from helpers import SiteArgs


class HeightArgs(TypedDict, total=False):
    """A mechanism's height and its building (keys of :class:`Site`; ``T1`` may be left out)."""

    Z: float
    H: float
    storeys: int
    xi1: float
    T1: float


class SlcArgs(TypedDict):
    """The hazard at the SLC's return period (keys of :class:`Site`)."""

    ag_SLC: float
    F0_SLC: float
    Tc_star_SLC: float


B, H = 240.0, 600.0  # mm
T = 120.0  # mm
SITE1: SiteArgs = dict(ag=0.20, F0=2.4, Tc_star=0.30, soil="B", topography="T1")
S1, TB1, TC1 = 1.20, 0.419846 / 3, 0.419846  # verification/test_seismic.py
SITE2: SiteArgs = dict(ag=0.25, F0=2.5, Tc_star=0.35, soil="C", topography="T2")
# site 2 by hand: S_S = 1.70 − 0.60 · 2.5 · 0.25 = 1.325 (within [1.0, 1.5]), S_T = 1.2 (T2),
# C_C = 1.05 · 0.35^−0.33 = 1.484728, T_C = C_C T_C* = 0.5196547 s, T_D = 4 · 0.25 + 1.6 = 2.6 s
S2, TC2, TD2 = 1.325 * 1.2, 0.5196547, 2.6


def _block(k=1.0):
    b, h = k * B, k * H
    return alma.Scene.from_dict(
        {
            "thickness": T,
            "unit_weight": 18.0,
            "friction": 0.8,
            "blocks": [
                {"id": "ground", "vertices": [[-2 * b, -100], [3 * b, -100], [3 * b, 0], [-2 * b, 0]], "fixed": True},
                {"id": "wall", "vertices": [[0, 0], [b, 0], [b, h], [0, h]]},
            ],
        }
    )


def _floor_site1() -> float:
    """Site 1, Z = 6 m of H = 9 m, n = 3, ξ_1 = 10 %, T_1 = 0.050 · 9^0.75 = 0.259808 s."""
    t1 = 0.050 * 9**0.75
    assert TB1 < t1 < TC1  # the plateau: S_e = a_g S η F0
    eta = math.sqrt(10 / 15)  # 0.816497
    se = 0.20 * G * S1 * eta * 2.4
    gamma, psi = 3 * 3 / (2 * 3 + 1), 6.0 / 9.0  # 9/7, 2/3
    return se * gamma * psi * math.sqrt(1 + 0.0004 * 10.0**2)


def _floor_site2() -> float:
    """Site 2, Z = 4 m of H = 12 m, n = 4, ξ_1 = 15 %, T_1 = 0.9 s given."""
    assert TC2 < 0.9 < TD2  # the branch a_g S η F0 T_C / T
    eta = math.sqrt(10 / 20)  # 0.707107
    se = 0.25 * G * S2 * eta * 2.5 * TC2 / 0.9
    gamma, psi = 3 * 4 / (2 * 4 + 1), 4.0 / 12.0  # 4/3, 1/3
    return se * gamma * psi * math.sqrt(1 + 0.0004 * 15.0**2)


HEIGHT1: HeightArgs = dict(Z=6.0, H=9.0, storeys=3, xi1=10.0)
HEIGHT2: HeightArgs = dict(Z=4.0, H=12.0, storeys=4, xi1=15.0, T1=0.9)


def test_site2_spectrum_by_hand():
    s = elastic_spectrum(**SITE2)
    assert s.S == pytest.approx(S2, rel=1e-12)
    assert s.TC == pytest.approx(TC2, abs=1e-6) and s.TD == pytest.approx(TD2, rel=1e-12)


@pytest.mark.parametrize(
    ("site", "height", "by_hand"), [(SITE1, HEIGHT1, _floor_site1), (SITE2, HEIGHT2, _floor_site2)]
)
def test_floor_acceleration_by_hand(site, height, by_hand):
    mode = first_mode(height["Z"], height["H"], height["storeys"], height["xi1"], height.get("T1"))
    assert mode.T1_estimated is ("T1" not in height)
    spec1 = elastic_spectrum(**site, damping=height["xi1"])
    assert floor_acceleration(spec1, mode) == pytest.approx(by_hand(), rel=1e-6)


@pytest.mark.parametrize(
    ("site", "height", "by_hand"), [(SITE1, HEIGHT1, _floor_site1), (SITE2, HEIGHT2, _floor_site2)]
)
def test_linear_check_at_height_by_hand(site, height, by_hand):
    check = alma.seismic(_block(), Site(**site, **height, FC=1.35), steps=6)
    lin, a_floor = check.linear, by_hand()
    a_z_sld = (B / H) * G / 1.35  # Eq. C8.7.1.8, one block: e* = 1
    assert lin["governs"] == "floor"
    assert lin["a_Z"] == pytest.approx(a_floor, rel=1e-6)
    assert lin["a_Z_SLD"] == pytest.approx(a_z_sld, rel=1e-9)
    ag = site["ag"] * G
    assert lin["a_g_SLD"] == pytest.approx(ag * a_z_sld / a_floor, rel=1e-6)
    assert lin["a_g_SLV"] == pytest.approx(2.0 * ag * a_z_sld / a_floor, rel=1e-6)  # q = 2
    assert lin["safety_index"] == pytest.approx(2.0 * a_z_sld / a_floor, rel=1e-6)
    assert lin["verified"] is (2.0 * a_z_sld >= a_floor)
    assert lin["a0_star_required"] == pytest.approx(a_floor / 2.0, rel=1e-6)
    data = check.to_dict()
    assert data["safety_index"] == lin["safety_index"] and data["linear"]["T1"] == pytest.approx(
        height.get("T1", 0.050 * height["H"] ** 0.75), rel=1e-12
    )


def test_the_displacement_checks_at_height_are_refused_with_the_reason():
    check = alma.seismic(_block(), Site(**SITE1, **HEIGHT1, ag_SLC=0.25, F0_SLC=2.5, Tc_star_SLC=0.32), steps=6)
    data = check.to_dict()
    assert "C7.2.5" in check.nonlinear["refused"] and check.nonlinear["verified"] is None
    assert data["du_star"] is None and data["Ts"] is None
    assert data["d0_star"] == pytest.approx(B / 2 * 1e-3, rel=1e-6)  # the curve's d₀ is still given
    assert data["slc"]["verified"] is None and "refused" in data["slc"]
    assert "not done" in check.message


SLC1: SlcArgs = dict(ag_SLC=0.25, F0_SLC=2.5, Tc_star_SLC=0.32)
# SLC 1 on soil B by hand: S = 1.40 − 0.40 · 2.5 · 0.25 = 1.15, C_C = 1.10 · 0.32^−0.2 = 1.381538,
# T_C = 0.442092 s, T_D = 2.6 s
SLC1_S, SLC1_TC, SLC1_TD = 1.15, 0.442092, 2.6
SLC2: SlcArgs = dict(ag_SLC=0.30, F0_SLC=2.45, Tc_star_SLC=0.36)
# SLC 2 on soil C, T2: S_S = 1.70 − 0.60 · 2.45 · 0.30 = 1.259, S = 1.259 · 1.2 = 1.5108,
# C_C = 1.05 · 0.36^−0.33 = 1.470989, T_C = 0.529556 s, T_D = 4 · 0.30 + 1.6 = 2.8 s
SLC2_S, SLC2_TC, SLC2_TD = 1.259 * 1.2, 0.529556, 2.8
ETA10 = math.sqrt(10 / 15)  # ξ = 10 %


def _angle_at(d: float, k: float) -> float:
    """θ with b/2 (1 − cos θ) + h/2 sin θ = d (mm) for the block k b × k h, by bisection."""
    b, h = k * B, k * H
    lo, hi = 0.0, math.atan(b / h)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if b / 2 * (1 - math.cos(mid)) + h / 2 * math.sin(mid) < d else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize(
    ("base", "slc", "k", "s", "tc", "td"),
    [(SITE1, SLC1, 1.0, SLC1_S, SLC1_TC, SLC1_TD), (SITE2, SLC2, 5.0, SLC2_S, SLC2_TC, SLC2_TD)],
)
def test_slc_check_by_hand(base, slc, k, s, tc, td):
    spec = elastic_spectrum(slc["ag_SLC"], slc["F0_SLC"], slc["Tc_star_SLC"], base["soil"], base["topography"])
    assert spec.S == pytest.approx(s, rel=1e-12) and spec.TC == pytest.approx(tc, abs=1e-6)
    check = alma.seismic(_block(k), Site(**base, **slc, FC=1.35), steps=20)
    out = check.slc
    assert out is not None
    d_slc = 0.6 * k * B / 2 * 1e-3  # 60 % of d₀ = b/2 (one block: d* = d), m
    assert out["d_SLC"] == pytest.approx(d_slc, rel=1e-6)
    theta = _angle_at(d_slc * 1e3, k)
    a = (B * math.cos(theta) - H * math.sin(theta)) / (H * math.cos(theta) + B * math.sin(theta)) * G / 1.35
    # read on the computed curve between its points: within 1e-4 of the closed form (as at SLV)
    assert out["a_SLC"] == pytest.approx(a, rel=1e-4)
    t_slc = 1.56 * math.pi * math.sqrt(out["d_SLC"] / out["a_SLC"])  # Eq. C8.7.1.11
    assert out["T_SLC"] == pytest.approx(t_slc, rel=1e-12)
    ag = slc["ag_SLC"] * G
    top = ag * s * ETA10 * slc["F0_SLC"]
    if t_slc < td:  # S_De = a_g S η F0 T_C / T · T²/4π² (T_C < T < T_D)
        assert tc < t_slc
        demand = top * tc / t_slc * t_slc**2 / (4 * math.pi**2)
    else:  # S_De = a_g S η F0 T_C T_D / T² · T²/4π² (T_D <= T < T_E = 5 or 6 s)
        demand = top * tc * td / (4 * math.pi**2)
    assert out["xi"] == 10.0 and out["eta"] == pytest.approx(ETA10, rel=1e-12)
    assert out["displacement_demand"] == pytest.approx(demand, rel=1e-5)
    assert out["a_g_SLC"] == pytest.approx(ag * out["d_SLC"] / demand, rel=1e-5)
    assert out["safety_index"] == pytest.approx(out["d_SLC"] / demand, rel=1e-5)
    assert out["verified"] is (out["d_SLC"] >= demand)
    as_dict = check.to_dict()["slc"]
    assert as_dict is not None and as_dict["T_SLC"] == out["T_SLC"]


def test_both_slc_branches_are_met():
    """The two cases above read the two branches of S_e (T_SLC below and above T_D)."""
    small = alma.seismic(_block(1.0), Site(**SITE1, **SLC1), steps=8).slc
    large = alma.seismic(_block(5.0), Site(**SITE2, **SLC2), steps=8).slc
    assert small is not None and large is not None
    assert small["T_SLC"] < SLC1_TD < SLC2_TD < large["T_SLC"]


def test_slc_keys_leave_the_slv_checks_unchanged():
    plain = alma.seismic(_block(), Site(**SITE1), steps=8)
    with_slc = alma.seismic(_block(), Site(**SITE1, **SLC1), steps=8)
    assert plain.slc is None and plain.to_dict()["slc"] is None
    assert with_slc.linear == plain.linear and with_slc.nonlinear == plain.nonlinear


@settings(max_examples=40, deadline=None)
@given(
    z=st.floats(0.05, 1.0),
    n=st.integers(1, 12),
    xi1=st.floats(2.0, 25.0),
    t1=st.one_of(st.none(), st.floats(0.05, 3.0)),
)
def test_the_floor_acceleration_grows_as_the_linear_mode(z, n, xi1, t1):
    """a_Z(z) = a_Z(H) z/H (ψ_1 = z/H), and 1 <= γ_1 = 3n/(2n + 1) < 1.5."""
    spec1 = elastic_spectrum(**SITE2, damping=xi1)
    at_z = floor_acceleration(spec1, first_mode(z * 12.0, 12.0, n, xi1, t1))
    top = floor_acceleration(spec1, first_mode(12.0, 12.0, n, xi1, t1))
    assert at_z == pytest.approx(top * z, rel=1e-12)
    assert 1.0 <= first_mode(6.0, 12.0, n, xi1, t1).gamma < 1.5
