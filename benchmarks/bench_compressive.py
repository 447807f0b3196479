"""Cost of finite compressive strength: Clarabel's cone program against the rigid LP (issue 34).

Cases: the largest paper panel (english bond, 1440 × 2880 mm, 60 × 60 blocks, 1,752 blocks) and a
running-bond wall of about 5,000 blocks (the generator of bench_scaling.py), each solved rigid
(alma's default associative path) and with σ_c = 2 MPa on every joint, in the same process, so
the ratio of the two is meaningful on a shared machine.  Prints one line per solve: status, α,
iterations, solve and certificate seconds.

    python benchmarks/bench_compressive.py [--sigma 2] [--wall 5000] [--skip-wall]
"""

from __future__ import annotations

import argparse
import dataclasses

import alma
from alma.geometry.contacts import find_joints
from alma.geometry.panels import paper_panel
from benchmarks.bench_scaling import wall_shape


def measure(name: str, scene: alma.Scene, sigma: float) -> None:
    """Solve ``scene`` rigid and at ``sigma`` MPa; one line each and their time ratio."""
    joints = find_joints(scene)
    rows = []
    for label, s in (
        ("rigid LP", scene),
        (f"cone σ_c={sigma:g} MPa", dataclasses.replace(scene, compressive_strength=sigma)),
    ):
        r = alma.solve(s, joints=joints)
        t = r.timings
        rows.append(t["solve_s"] + t["certify_s"])
        print(
            f"{name:28s} {label:20s} {r.n_blocks:6d} blocks  {r.status!s:14s} α = {r.alpha:.9f}  "
            f"{r.iterations:4d} it  solve {t['solve_s']:7.2f} s  certificate {t['certify_s']:6.2f} s",
            flush=True,
        )
    print(f"{name:28s} cone / LP (solve + certificate): {rows[1] / rows[0]:.1f}x", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sigma", type=float, default=2.0, help="MPa")
    parser.add_argument("--wall", type=int, default=5000, help="blocks of the running-bond wall")
    parser.add_argument("--skip-wall", action="store_true")
    args = parser.parse_args()
    measure("largest panel (english 1:2 1:1)", paper_panel("english", "1:2", "1:1", 0.6), args.sigma)
    if not args.skip_wall:
        courses, per_course = wall_shape(args.wall)
        measure(
            f"running wall ~{args.wall}", alma.wall("running", 240.0 * per_course, 60.0 * courses, 240.0), args.sigma
        )


if __name__ == "__main__":
    main()
