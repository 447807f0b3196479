"""Certification of the non-associative optimum (``--certify``): the largest scenes proven.

For every scene alma's default non-associative search runs once (α_LP, the candidate
mechanisms and the best verified α), then ``alma.certify.milp.certify`` (per-joint slip states,
LP-derived big-M per point, energy balance, highspy with the verified state as cutoff) within
its node budget and a wall-clock cap of ``--time-limit`` seconds.  A family stops after two
consecutive sizes it could not prove (later rows say ``skipped``).  The first formulation
(``classic``) it was once compared with is deleted; its measurements are in ``docs/decisions.md``.

Families: k blocks 1 × 2 side by side on the ground (f = 1.0 and 0.6), stack-bond panels and
running-bond walls (``alma.wall``, blocks 120 × 60, f = 0.6) from 6 to 40 blocks.  With
``--cohesion C`` (kPa) every joint is cohesive and the side-by-side blocks are 100 × 200 mm
(their bounded shear is then 0.14 C and 0.28 C of a block's weight; a bed joint of the walls
carries 0.93 C): the MILP with bounded forces (τ, its rates and two binaries per column).

    python -m benchmarks.bench_certify [--time-limit 60] [--families side1.0,side0.6,stack,running]
                                       [--backends highs,scip] [--only NAME,...] [--overrides]
                                       [--cohesion 0] [--nodes N] [--out benchmarks/results]

Prints a table and the largest scene proven within the time limit per family and formulation;
writes ``certify[_cC][_overrides]_<backends>.csv`` (one row per scene and certificate).
``--backends highs,scip`` compares HiGHS's big-M MILP with SCIP's SOS1 form (``alma[scip]``);
``--overrides`` puts a joint override (friction 0.4, no cohesion) on every joint on the ground;
``--nodes N`` gives every certificate a budget of N nodes (with a generous ``--time-limit``, a
comparison that does not depend on the machine's load).
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd

import alma
from alma.associative.lp import solve_lp
from alma.certify.milp import certify
from alma.geometry.contacts import find_joints
from alma.mechanics.model import build_model
from alma.nonassociative.search import solve_nonassociative
from alma.settings import CertifySettings

#: The certificates compared: HiGHS on the big-M MILP, SCIP on the SOS1 form (bipartite SOS1
#: branching, the default) with and without the bilinear energy balance
#: (CertifySettings.scip_energy), and SCIP with its own neighbourhood branching (``scip-neighbourhood``,
#: the default before issue 31's second pass).
BACKENDS = {
    "highs": CertifySettings(),
    "scip": CertifySettings(backend="scip"),
    "scip-noenergy": CertifySettings(backend="scip", scip_energy=False),
    "scip-neighbourhood": CertifySettings(backend="scip", scip_parameters=()),
}


def with_overrides(scene: alma.Scene, friction: float = 0.4) -> alma.Scene:
    """The scene with a joint override on every joint touching a fixed block: friction ``friction``
    and no cohesion there (a damp-proof course at the base)."""
    joints = find_joints(scene)
    fixed = {i for i, b in enumerate(scene.blocks) if b.fixed}
    data = scene.to_dict()
    data["joints"] = [
        {"blocks": [scene.blocks[a].id, scene.blocks[b].id], "friction": friction, "cohesion": 0.0}
        for a, b in zip(joints.block_a, joints.block_b, strict=True)
        if a in fixed or b in fixed
    ]
    return alma.Scene.from_dict(data)


def side_by_side(k: int, f: float, b: float = 1.0, h: float = 2.0, cohesion: float = 0.0) -> alma.Scene:
    blocks = [{"id": "g", "vertices": [[-b, -1], [(k + 1) * b, -1], [(k + 1) * b, 0], [-b, 0]], "fixed": True}]
    blocks += [
        {"id": f"b{i}", "vertices": [[i * b, 0], [(i + 1) * b, 0], [(i + 1) * b, h], [i * b, h]]} for i in range(k)
    ]
    return alma.Scene.from_dict(
        {"friction": f, "blocks": blocks, "cohesion": cohesion, "name": f"{k} blocks side by side, f={f:g}"}
    )


def families(cohesion: float = 0.0) -> dict[str, list[tuple[str, alma.Scene]]]:
    out: dict[str, list[tuple[str, alma.Scene]]] = {}
    size = dict(b=100.0, h=200.0) if cohesion else {}
    for f in (1.0, 0.6):
        out[f"side{f:g}"] = [
            (f"side-by-side k={k} f={f:g}", side_by_side(k, f, cohesion=cohesion, **size)) for k in range(2, 21)
        ]
    out["stack"] = [
        (f"stack {c}x{r}", alma.wall("stack", c * 120.0, r * 60.0, 120.0, friction=0.6))
        for c, r in [(2, 3), (3, 3), (4, 3), (4, 4), (5, 4), (6, 4), (6, 5), (8, 5)]
    ]
    out["running"] = [
        (f"running {int(L)}x{r * 60}", alma.wall("running", L, r * 60.0, 120.0, friction=0.6))
        for L, r in [
            (360.0, 2),
            (360.0, 3),
            (360.0, 4),
            (480.0, 3),
            (480.0, 4),
            (600.0, 4),
            (480.0, 6),
            (600.0, 6),
            (600.0, 7),
        ]
    ]
    for family in ("stack", "running"):
        out[family] = [(name, dataclasses.replace(scene, cohesion=cohesion)) for name, scene in out[family]]
    return out


def search(scene: alma.Scene):
    model = build_model(scene)
    lp = solve_lp(model)
    effort = "thorough" if model.n_free <= 200 else "fast"
    sol = solve_nonassociative(model, lp.mechanism, lp.multipliers, effort=effort)
    mechanisms = [c.mechanism for c in sol.candidates] + [lp.mechanism]
    best = sol.best.alpha if sol.best is not None else None
    return model, lp.alpha, mechanisms, best


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--time-limit", type=float, default=60.0)
    parser.add_argument("--families", default="side1,side0.6,stack,running")
    parser.add_argument(
        "--formulations",
        "--backends",
        dest="formulations",
        default="highs",
        help=f"comma-separated certificates among {', '.join(BACKENDS)}",
    )
    parser.add_argument("--only", default="", help="comma-separated scene names to run (default: every size)")
    parser.add_argument(
        "--overrides", action="store_true", help="override the joints on the ground: friction 0.4, no cohesion"
    )
    parser.add_argument("--cohesion", type=float, default=0.0, help="cohesion on every joint, kPa")
    parser.add_argument(
        "--nodes",
        type=int,
        default=0,
        help="branch-and-bound node budget of every certificate (default: CertifySettings's); "
        "a budget in nodes compares backends whatever the machine's load",
    )
    parser.add_argument("--stop-after", type=int, default=2, help="unproven sizes in a row before a family stops")
    parser.add_argument("--out", default=str(Path(__file__).resolve().parent / "results"))
    args = parser.parse_args(argv)
    chosen = args.families.split(",")
    formulations = args.formulations.split(",")
    all_families = families(args.cohesion)
    rows = []
    for family in chosen:
        misses = {f: 0 for f in formulations}
        for name, scene in all_families[family]:
            if args.only and name not in args.only.split(","):
                continue
            if all(misses[f] >= args.stop_after for f in formulations):
                break
            if args.overrides:
                scene = with_overrides(scene)
            model, alpha_lp, mechanisms, best = search(scene)
            points = 2 * model.n_joints
            for formulation in formulations:
                row = dict(
                    family=family,
                    scene=name,
                    blocks=model.n_free,
                    points=points,
                    formulation=formulation,
                    alpha_best=best,
                    alpha_lp=alpha_lp,
                )
                if misses[formulation] >= args.stop_after:
                    row.update(status="skipped", lower=np.nan, upper=best, gap=np.nan, seconds=np.nan)
                else:
                    chosen_settings = BACKENDS[formulation]
                    if args.nodes:
                        chosen_settings = dataclasses.replace(chosen_settings, node_limit=args.nodes)
                    cert = certify(
                        model,
                        alpha_lp,
                        mechanisms,
                        time_limit=args.time_limit,
                        alpha_best=best,
                        settings=chosen_settings,
                    )
                    upper = min(best, cert.upper) if best is not None else cert.upper
                    proven = cert.status == "proven"
                    misses[formulation] = 0 if proven else misses[formulation] + 1
                    row.update(
                        status=cert.status,
                        lower=cert.lower,
                        upper=upper,
                        gap=upper - cert.lower,
                        seconds=cert.time_s,
                        velocity_bound_active=cert.velocity_bound_active,
                        nodes=cert.nodes,
                    )
                rows.append(row)
                print(
                    f"{name:28s} {row['blocks']:3d} blocks {points:4d} pts  {formulation:8s} {row['status']:10s} "
                    f"lower {row['lower']:.6f}  upper {row['upper']:.6f}  gap {row['gap']:.2e}  "
                    f"{row['seconds']:6.2f} s",
                    flush=True,
                )
    df = pd.DataFrame(rows)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    stem = "certify" + (f"_c{args.cohesion:g}" if args.cohesion else "") + ("_overrides" if args.overrides else "")
    csv = out / f"{stem}_{'_'.join(formulations)}.csv"
    df.to_csv(csv, index=False)

    wide = df.pivot_table(
        index=["family", "scene", "blocks", "points"],
        columns="formulation",
        values=["lower", "gap", "seconds"],
        aggfunc="first",
        sort=False,
    )
    status = df.pivot_table(
        index=["family", "scene", "blocks", "points"],
        columns="formulation",
        values="status",
        aggfunc="first",
        sort=False,
    )
    print(
        "\nscene                         blocks points | "
        + " | ".join(f"{f}: status lower upper gap seconds" for f in formulations)
    )
    for key in status.index:
        family, scene, blocks, points = key
        upper = df[(df.scene == scene)].upper.iloc[0]
        cells = []
        for f in formulations:
            cells.append(
                f"{status.loc[key, f]:10s} {wide.loc[key, ('lower', f)]:.6f} {upper:.6f} "
                f"{wide.loc[key, ('gap', f)]:.1e} {wide.loc[key, ('seconds', f)]:6.2f}"
            )
        print(f"{scene:29s} {blocks:6d} {points:6d} | " + " | ".join(cells))
    print(f"\nlargest scene proven within {args.time_limit:g} s:")
    for family in chosen:
        for f in formulations:
            proven = df[(df.family == family) & (df.formulation == f) & (df.status == "proven")]
            if proven.empty:
                print(f"  {family:10s} {f:8s} none")
            else:
                top = proven.sort_values("blocks").iloc[-1]
                print(
                    f"  {family:10s} {f:8s} {top.scene} ({top.blocks} blocks, {top.points} points, {top.seconds:.1f} s)"
                )
    print(f"\nwrote {csv}")


if __name__ == "__main__":
    main()
