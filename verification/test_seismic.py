"""The NTC 2018 elastic spectra and the Circolare's kinematic check on closed-form cases.

Spectrum values are computed by hand here, term by term, from NTC 2018 §3.2.3.2 (Eq. 3.2.2,
Tab. 3.2.IV for S_S and C_C, Tab. 3.2.V for S_T); the kinematic check from the Circolare 2019
§C8.7.1: for one rigid block rocking about its toe every weight moves with the block, so
e* = 1, M* = its mass and a₀* = α₀ g / FC = (b/h) g / FC.

A published worked example of a façade's overturning is in test_seismic_published.py.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import alma
from alma.seismic import Site, elastic_spectrum
from alma.seismic.spectrum import G

from helpers import SiteArgs, number

# site 1: a_g = 0.20 g, F0 = 2.4, T_C* = 0.30 s, soil B, flat (T1)
#   S_S = 1.40 − 0.40 · 2.4 · 0.20 = 1.208 → capped at 1.20;  C_C = 1.10 · 0.30^−0.20 = 1.399486
#   T_C = C_C T_C* = 0.419846 s, T_B = 0.139949 s, T_D = 4 · 0.20 + 1.6 = 2.40 s
#   plateau a_g S F0 = 0.20 · 9.80665 · 1.20 · 2.4 = 5.648630 m/s²
SITE1: SiteArgs = dict(ag=0.20, F0=2.4, Tc_star=0.30, soil="B", topography="T1")
# site 2: a_g = 0.25 g, F0 = 2.5, T_C* = 0.35 s, soil C, ridge (T2: S_T = 1.2)
#   S_S = 1.70 − 0.60 · 2.5 · 0.25 = 1.325;  C_C = 1.05 · 0.35^−0.33 = 1.05 · 1.414027 = 1.484728;  S = 1.59
#   T_C = 0.519655 s, T_B = 0.173218 s, T_D = 4 · 0.25 + 1.6 = 2.60 s
#   plateau 0.25 · 9.80665 · 1.59 · 2.5 = 9.745358 m/s²
SITE2: SiteArgs = dict(ag=0.25, F0=2.5, Tc_star=0.35, soil="C", topography="T2")


def test_site_one_spectrum_by_hand():
    s = elastic_spectrum(**SITE1)
    assert s.S_S == 1.20 and s.S_T == 1.0
    assert s.C_C == pytest.approx(1.10 * 0.30**-0.20, rel=1e-12) and s.C_C == pytest.approx(1.399486, abs=1e-6)
    assert s.TC == pytest.approx(0.419846, abs=1e-6) and s.TB == pytest.approx(0.139949, abs=1e-6)
    assert s.TD == pytest.approx(2.40)
    assert s.Se(0.0) == pytest.approx(0.20 * G * 1.20, rel=1e-12)  # a_g S at T = 0
    assert s.Se(0.3) == pytest.approx(5.648630, abs=1e-6)  # plateau
    assert s.Se(1.0) == pytest.approx(5.648630 * 0.419846 / 1.0, abs=1e-5)  # T_C ≤ T < T_D
    assert s.Se(3.0) == pytest.approx(5.648630 * 0.419846 * 2.4 / 9.0, abs=1e-5)  # T ≥ T_D
    assert s.SDe(1.0) == pytest.approx(s.Se(1.0) / (2 * math.pi) ** 2, rel=1e-12)
    # T_E = 5 s < T = 7 s ≤ T_F = 10 s (soil B): d_g [F0 + (1 − F0)(T − T_E)/(T_F − T_E)]
    dg = 0.025 * 0.20 * G * 1.20 * 0.419846 * 2.4
    assert s.SDe(7.0) == pytest.approx(dg * (2.4 + (1 - 2.4) * 2 / 5), rel=1e-5)


def test_site_two_spectrum_by_hand():
    s = elastic_spectrum(**SITE2)
    assert s.S_S == pytest.approx(1.325) and s.S_T == 1.2 and s.S == pytest.approx(1.59)
    assert s.C_C == pytest.approx(1.484728, abs=1e-6)
    assert s.TC == pytest.approx(0.519655, abs=1e-6) and s.TD == pytest.approx(2.60)
    assert s.Se(0.4) == pytest.approx(9.745358, abs=1e-6)
    t = 0.1  # rising branch: a_g S η F0 [T/T_B + (1 − T/T_B)/(η F0)]
    assert s.Se(t) == pytest.approx(0.25 * G * 1.59 * 2.5 * (t / 0.173218 + (1 - t / 0.173218) / 2.5), rel=1e-5)


def test_soil_amplification_bounds():
    assert elastic_spectrum(0.05, 2.4, 0.3, "D").S_S == pytest.approx(1.80)  # 2.40 − 0.18 = 2.22 → 1.80
    assert elastic_spectrum(0.35, 2.6, 0.3, "E").S_S == pytest.approx(1.0)  # 2.00 − 1.001 = 0.999 → 1.00
    assert elastic_spectrum(0.2, 2.4, 0.3, "A").S_S == 1.0


def test_single_block_kinematic_check():
    b, h = 240.0, 600.0
    scene = alma.Scene.from_dict(
        {
            "thickness": 120,
            "unit_weight": 18,
            "friction": 0.8,
            "blocks": [
                {"id": "ground", "vertices": [[-500, -100], [800, -100], [800, 0], [-500, 0]], "fixed": True},
                {"id": "wall", "vertices": [[0, 0], [b, 0], [b, h], [0, h]]},
            ],
        }
    )
    site = Site(**SITE1, FC=1.35)
    check = alma.seismic(scene, site, edition="2009", steps=20)
    mass = b * h * 120 * 1e-9 * 18 / G * 1e3  # kg
    assert check.e_star == pytest.approx(1.0, abs=1e-9)
    assert check.M_star == pytest.approx(mass, rel=1e-9)
    assert check.a0_star == pytest.approx((b / h) * G / 1.35, rel=1e-9)
    demand = 0.20 * G * 1.20 / 2.0  # a_g S / q at Z = 0
    assert check.linear["demand"] == pytest.approx(demand, rel=1e-12)
    assert check.linear["safety_index"] == pytest.approx((b / h) * G / 1.35 / demand, rel=1e-9)
    nl = check.nonlinear
    # one block: d* = d (e* = 1, the control is the block), d₀* = b/2
    assert nl["d0_star"] == pytest.approx(b / 2 * 1e-3, rel=1e-6)
    assert nl["du_star"] == pytest.approx(0.4 * b / 2 * 1e-3, rel=1e-6)
    assert nl["Ts"] == pytest.approx(2 * math.pi * math.sqrt(number(nl, "ds_star") / number(nl, "as_star")), rel=1e-12)
    assert nl["demand"] == pytest.approx(check.spectrum.SDe(number(nl, "Ts")), rel=1e-12)


def test_elevated_mechanism_takes_the_larger_demand():
    b, h = 240.0, 600.0
    scene = alma.Scene.from_dict(
        {
            "thickness": 120,
            "unit_weight": 18,
            "friction": 0.8,
            "blocks": [
                {"id": "ground", "vertices": [[-500, -100], [800, -100], [800, 0], [-500, 0]], "fixed": True},
                {"id": "wall", "vertices": [[0, 0], [b, 0], [b, h], [0, h]]},
            ],
        }
    )
    site = Site(**SITE1, Z=6.0, H=9.0, storeys=3)
    check = alma.seismic(scene, site, edition="2009", steps=10)
    s = check.spectrum
    T1 = 0.050 * 9.0**0.75
    upper = s.Se(T1) * (6.0 / 9.0) * (9 / 7) / 2.0
    assert check.linear["demand"] == pytest.approx(max(0.20 * G * 1.20 / 2.0, upper), rel=1e-12)


@pytest.mark.parametrize(
    "bad, word",
    [
        ({"ag": -0.1}, "ag"),
        ({"soil": "F"}, "soil"),
        ({"topography": "T9"}, "topography"),
        ({"Z": 3.0}, "H"),
        ({"colour": 1}, "unknown"),
    ],
)
def test_bad_site_is_refused_by_name(bad, word):
    with pytest.raises(ValueError, match=word):
        Site.from_dict({**SITE1, **bad})


def test_a_curve_that_loses_equilibrium_bounds_the_ultimate_displacement():
    # Circolare §C8.7.1.2: d_u* is the smaller of 0.4 d₀* and the displacement incompatible with
    # the stability of the elements; the arch's curve stops at a loss of equilibrium with α > 0,
    # d₀* is then the secant's zero through its last two points
    arch = alma.load_scene(Path(__file__).resolve().parents[1] / "examples" / "arch.json")
    check = alma.seismic(arch, SITE1, edition="2009")
    nl, curve = check.nonlinear, check.push.curve
    assert check.push.end["reason"] == "no_equilibrium" and nl["d0_extrapolated"] is True
    (d1, a1), (d2, a2) = [(p.d, p.alpha) for p in curve[-2:]]
    factor = curve[-1].d and check.curve_star[-1][0] / (curve[-1].d * 1e-3)
    assert nl["d0_star"] == pytest.approx((d2 + (d2 - d1) * a2 / (a1 - a2)) * factor * 1e-3, rel=1e-12)
    assert nl["d_lost_star"] == pytest.approx(check.push.end["bracket"][0] * factor * 1e-3, rel=1e-12)
    assert nl["du_star"] == pytest.approx(min(0.4 * number(nl, "d0_star"), number(nl, "d_lost_star")), rel=1e-12)
    assert math.isfinite(number(nl, "safety_index"))
