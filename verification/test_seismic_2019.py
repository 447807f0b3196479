"""The Circolare 2019's form of the kinematic checks (§C8.7.1.2.1.5–8) against hand computations.

Formulas (Circolare 21 gennaio 2019 n. 7, read from a public transcription of the official PDF;
docs/seismic.md names it):

- Eq. C8.7.1.8: a_{Z,SLD} = α₀ g / (e* FC); at the ground a_{g,SLD} = a_{Z,SLD} / S (the ground
  motion's peak acceleration is S_e(0) = a_g S, NTC 2018 Eq. 3.2.2);
- §C8.7.1.2.1.7: a_{g,SLV} = q a_{g,SLD}, compared with a_g;
- §C8.7.1.2.1.6: d_SLV = 0.4 d₀ (or the loss of equilibrium, if smaller);
- Eq. C8.7.1.10: T_SLV = 1.68 π √(d_SLV / a(d_SLV));
- Eq. C8.7.1.12 at the ground: the demand is the largest S_De over [0, T_SLV] at ξ = 8 %
  (η = √(10 / (5 + ξ)), NTC 2018 Eq. 3.2.4), a_{g,SLV} = a_g d_SLV / demand, not below a_{g,SLD}.

Carried loads (§C8.7.1.2.1.1: P_k includes the weights a block carries): a block rocking about
its toe with a mass on its top, against the closed form of α(θ) with the load's point turning
with the block, and e*, M* summed over the block's centroid and the load's point.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import alma
from alma.seismic import Site, elastic_spectrum
from alma.seismic.spectrum import G
from alma.status import Status

from helpers import SiteArgs, number

B, H = 240.0, 600.0  # mm
T = 120.0  # mm
GAMMA = 18.0  # kN/m³
W = B * H * T * 1e-9 * GAMMA  # kN, the block's weight
SITE1: SiteArgs = dict(ag=0.20, F0=2.4, Tc_star=0.30, soil="B", topography="T1")
# site 1 by hand (verification/test_seismic.py): S = 1.20, T_C = 0.419846 s, T_D = 2.40 s, T_E = 5 s
S1, TC1, TD1 = 1.20, 0.419846, 2.40
ETA8 = math.sqrt(10 / 13)  # ξ = 8 %: 0.877058


def _block(loads=(), k=1.0):
    """The b × h block (scaled by k) on a fixed ground."""
    b, h = k * B, k * H
    return alma.Scene.from_dict(
        {
            "thickness": T,
            "unit_weight": GAMMA,
            "friction": 0.8,
            "blocks": [
                {"id": "ground", "vertices": [[-2 * b, -100], [3 * b, -100], [3 * b, 0], [-2 * b, 0]], "fixed": True},
                {"id": "wall", "vertices": [[0, 0], [b, 0], [b, h], [0, h]]},
            ],
            "loads": list(loads),
        }
    )


@pytest.fixture(scope="module")
def block_2019():
    return alma.seismic(_block(), Site(**SITE1, FC=1.35), steps=20)


def test_eta_at_eight_percent_damping():
    s = elastic_spectrum(**SITE1, damping=8.0)
    assert s.eta == pytest.approx(0.877058, abs=1e-6)
    # plateau a_g S η F0 = 0.20 · 9.80665 · 1.20 · 0.877058 · 2.4
    assert s.Se(0.3) == pytest.approx(0.20 * G * 1.20 * 0.877058 * 2.4, rel=1e-6)
    assert elastic_spectrum(**SITE1, damping=100.0).eta == 0.55  # the lower bound of Eq. 3.2.4


def test_largest_displacement_over_the_periods():
    s = elastic_spectrum(**SITE1, damping=8.0)
    # up to T_E = 5 s S_De is non-decreasing: the maximum over [0, T] is S_De(T)
    assert s.SDe_max(0.7) == s.SDe(0.7)
    # beyond T_E it falls (F0 η > 1): the maximum stays S_De(T_E) = S_e(T_E) T_E²/4π²
    # = a_g S η F0 T_C T_D / 4π² (T_E ≥ T_D)
    top = 0.20 * G * S1 * ETA8 * 2.4 * TC1 * TD1 / (4 * math.pi**2)
    assert s.SDe(5.0) == pytest.approx(top, rel=1e-5)
    assert s.SDe_max(7.0) == pytest.approx(top, rel=1e-5) and s.SDe(7.0) < top


def test_linear_check_in_ground_accelerations(block_2019):
    check = block_2019
    assert check.edition == "2019" and check.to_dict()["edition"] == "2019"
    lin = check.linear
    a_z = (B / H) * G / 1.35  # Eq. C8.7.1.8 with e* = 1 (one block) and FC = 1.35
    assert lin["a_Z_SLD"] == pytest.approx(a_z, rel=1e-9)
    assert lin["S"] == S1
    assert lin["a_g_SLD"] == pytest.approx(a_z / S1, rel=1e-9)
    assert lin["a_g_SLV"] == pytest.approx(2.0 * a_z / S1, rel=1e-9)  # q = 2
    assert lin["demand"] == pytest.approx(0.20 * G, rel=1e-12)  # a_g in m/s²
    assert lin["safety_index"] == pytest.approx(2.0 * a_z / S1 / (0.20 * G), rel=1e-9)
    assert lin["verified"] is (2.0 * a_z / S1 >= 0.20 * G)


def test_nonlinear_check_at_slv(block_2019):
    check = block_2019
    nl = check.nonlinear
    d_slv = 0.4 * B / 2 * 1e-3  # 40 % of d₀ = b/2 (one block: d* = d)
    assert nl["d0_star"] == pytest.approx(B / 2 * 1e-3, rel=1e-6)
    assert nl["d_SLV"] == pytest.approx(d_slv, rel=1e-6)
    # a(d_SLV) on the closed form: d = b/2 (1 − cos θ) + h/2 sin θ, a = α(θ) g / FC
    theta = _angle_at(d_slv * 1e3)
    a = (B * math.cos(theta) - H * math.sin(theta)) / (H * math.cos(theta) + B * math.sin(theta)) * G / 1.35
    # the curve is read between its points (20 steps): the chord of α(d) differs from the closed form
    # by less than 1e-4 relative here (α(d) is almost straight; measured 6.7e-5)
    assert nl["a_SLV"] == pytest.approx(a, rel=1e-4)
    t_slv = 1.68 * math.pi * math.sqrt(nl["d_SLV"] / nl["a_SLV"])  # Eq. C8.7.1.10
    assert nl["T_SLV"] == pytest.approx(t_slv, rel=1e-12)
    assert TC1 < t_slv < TD1  # the branch a_g S η F0 T_C / T of S_e
    demand = 0.20 * G * S1 * ETA8 * 2.4 * (TC1 / t_slv) * t_slv**2 / (4 * math.pi**2)
    assert nl["displacement_demand"] == pytest.approx(demand, rel=1e-5)
    a_g_sld = check.linear["a_g_SLD"]
    a_g_slv = max(0.20 * G * nl["d_SLV"] / demand, a_g_sld)
    assert 0.20 * G * nl["d_SLV"] / demand < a_g_sld  # this small block: a_{g,SLD} governs
    assert nl["a_g_SLV"] == pytest.approx(a_g_slv, rel=1e-5)
    assert nl["safety_index"] == pytest.approx(a_g_slv / (0.20 * G), rel=1e-5)
    data = check.to_dict()  # SPEC's du_star and Ts are the 2019 check's d_SLV and T_SLV
    assert data["du_star"] == nl["d_SLV"] and data["Ts"] == nl["T_SLV"]


def test_a_large_block_is_governed_by_its_displacement():
    """The block 5 times larger: a_{g,SLD} does not depend on the size, the displacement
    capacity grows as k and T_SLV as √k, so a_g d_SLV / demand exceeds a_{g,SLD}."""
    check = alma.seismic(_block(k=5.0), Site(**SITE1, FC=1.35), steps=10)
    nl, lin = check.nonlinear, check.linear
    assert nl["d_SLV"] == pytest.approx(0.4 * 5 * B / 2 * 1e-3, rel=1e-6)
    t_slv = 1.68 * math.pi * math.sqrt(number(nl, "d_SLV") / number(nl, "a_SLV"))
    assert TC1 < t_slv < TD1
    demand = 0.20 * G * S1 * ETA8 * 2.4 * TC1 * t_slv / (4 * math.pi**2)
    assert nl["displacement_demand"] == pytest.approx(demand, rel=1e-5)
    by_displacement = 0.20 * G * number(nl, "d_SLV") / demand
    assert by_displacement > number(lin, "a_g_SLD")
    assert nl["a_g_SLV"] == pytest.approx(by_displacement, rel=1e-5)
    assert nl["verified"] is (by_displacement >= 0.20 * G)


def _angle_at(d: float) -> float:
    """θ with b/2 (1 − cos θ) + h/2 sin θ = d (mm), by bisection."""
    lo, hi = 0.0, math.atan(B / H)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if B / 2 * (1 - math.cos(mid)) + H / 2 * math.sin(mid) < d else (lo, mid)
    return 0.5 * (lo + hi)


TOP = 10.0  # kN carried on the block's top at x = 60 mm, its mass pushed along +x with the block's


def test_a_carried_mass_rocks_with_its_block():
    """α(θ) of the block with a mass P on its top at (x_p, h), turning about the toe (b, 0) by θ:
    α = [W (b/2 cos θ − h/2 sin θ) + P ((b − x_p) cos θ − h sin θ)]
        / [W (b/2 sin θ + h/2 cos θ) + P ((b − x_p) sin θ + h cos θ)]."""
    xp = 60.0
    scene = _block([{"block": "wall", "point": [xp, H], "dead": [0.0, -TOP], "live": [TOP, 0.0]}])
    check = alma.seismic(scene, SITE1, steps=10)
    curve = check.push
    assert curve.status == Status.OPTIMAL, curve.message
    for point in curve.curve:
        theta = -point.pose.angle[1]
        c, s = math.cos(theta), math.sin(theta)
        alpha = (W * (B / 2 * c - H / 2 * s) + TOP * ((B - xp) * c - H * s)) / (
            W * (B / 2 * s + H / 2 * c) + TOP * ((B - xp) * s + H * c)
        )
        assert point.alpha == pytest.approx(alpha, abs=1e-6)
    # e*, M*: the block's weight at its centroid (δ = h/2 θ), the mass at its point (δ = h θ)
    num, den = W * H / 2 + TOP * H, W * (H / 2) ** 2 + TOP * H**2
    assert check.M_star == pytest.approx(num**2 / (G * den) * 1e3, rel=1e-9)
    assert check.e_star == pytest.approx(num**2 / ((W + TOP) * den), rel=1e-9)
    assert check.alpha0 == pytest.approx((W * B / 2 + TOP * (B - xp)) / (W * H / 2 + TOP * H), rel=1e-7)
    assert check.to_dict()["carried_loads"][0]["weight"] == TOP
    # d* = d_C Σ P δ² / (δ_C Σ P δ) with the control the block's centroid (δ_C = h/2 θ)
    d_ratio = den / (H / 2 * num)
    assert check.curve_star[-1][0] == pytest.approx(curve.curve[-1].d * 1e-3 * d_ratio, rel=1e-9)


def test_an_external_force_is_not_a_mass():
    """A dead horizontal thrust F (no live part) does work in α₀ (Eq. C8.7.1.1's −Σ F δ_F) but
    takes no seismic action: e* = 1 still, α₀ = (W b/2 − F y_F)/(W h/2)."""
    f, y = 0.05, 400.0
    scene = _block([{"block": "wall", "point": [0.0, y], "dead": [f, 0.0]}])
    check = alma.seismic(scene, SITE1, steps=10)
    assert check.alpha0 == pytest.approx((W * B / 2 - f * y) / (W * H / 2), rel=1e-7)
    assert check.e_star == pytest.approx(1.0, abs=1e-12)
    assert check.to_dict()["external_forces"] == [0] and check.to_dict()["carried_loads"] == []


@pytest.mark.parametrize("live", [[0.0, 5.0], [-5.0, 0.0], [3.0, 1.0]])
def test_a_live_load_that_is_not_a_mass_is_refused_by_name(live):
    scene = _block([{"block": "wall", "point": [60.0, H], "dead": [0.0, -5.0], "live": live}])
    with pytest.raises(ValueError, match="load #0 on block 'wall'"):
        alma.seismic(scene, SITE1, steps=4)


def test_edition_2019_refuses_a_mechanism_at_height_by_name():
    with pytest.raises(ValueError, match="Z > 0"):
        alma.seismic(_block(), {**SITE1, "Z": 6.0, "H": 9.0, "storeys": 3}, steps=4)
    with pytest.raises(ValueError, match="edition"):
        alma.seismic(_block(), SITE1, edition="2018", steps=4)
    with pytest.raises(ValueError, match="edition"):
        Site.from_dict({**SITE1, "edition": "1999"})


@pytest.mark.slow  # four CLI runs with a capacity curve each: 7 s here; make test-slow (CI) runs it
def test_edition_from_the_site_file_and_the_command_line(tmp_path):
    assert Site.from_dict({**SITE1, "edition": 2009}).edition == "2009"  # a TOML number is read too
    (tmp_path / "scene.json").write_text(json.dumps(_block().to_dict()))
    (tmp_path / "site.toml").write_text('ag = 0.2\nF0 = 2.4\nTc_star = 0.3\nsoil = "B"\nedition = "2009"\n')

    def run(*extra):
        out = subprocess.run(
            [
                sys.executable,
                "-m",
                "alma.cli",
                "seismic",
                "scene.json",
                "--site",
                "site.toml",
                "--steps",
                "4",
                "--json",
                *extra,
            ],
            capture_output=True,
            text=True,
            cwd=tmp_path,
        )
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)

    from_file, from_option = run(), run("--edition", "2019")
    assert from_file["edition"] == "2009" and "Ts" in from_file["nonlinear"]
    assert from_option["edition"] == "2019" and "T_SLV" in from_option["nonlinear"]
    assert from_option["site"]["edition"] == "2019"
    assert from_file["M_star"] == from_option["M_star"] and from_file["safety_index"] == pytest.approx(
        from_option["safety_index"], rel=1e-12
    )  # at Z = 0 the two linear checks are one inequality
    assert np.isfinite(from_option["nonlinear"]["a_g_SLV"])
    text = subprocess.run(
        [
            sys.executable,
            "-m",
            "alma.cli",
            "seismic",
            "scene.json",
            "--site",
            "site.toml",
            "--steps",
            "4",
            "--edition",
            "2019",
            "--plot",
            "check.png",
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert text.returncode == 0 and "Circolare 2019" in text.stdout and "a_g,SLV" in text.stdout, text.stderr
    assert (tmp_path / "check.png").stat().st_size > 0
    (tmp_path / "high.toml").write_text(
        'ag = 0.2\nF0 = 2.4\nTc_star = 0.3\nsoil = "B"\nZ = 6.0\nH = 9.0\nstoreys = 3\n'
    )
    refused = subprocess.run(
        [sys.executable, "-m", "alma.cli", "seismic", "scene.json", "--site", "high.toml", "--json"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert refused.returncode == 2 and "Z > 0" in refused.stderr and "Traceback" not in refused.stderr
    assert json.loads(refused.stdout)["status"] == "invalid_input"
