"""``alma push`` and ``alma seismic`` (SPEC §3): the capacity curve and the kinematic check."""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import cast

from alma.cli.scene_options import add_compressive_strength, add_scene_options, scene_from_args
from alma.geometry.scene import Scene, SceneError
from alma.push import PUSH_MODELS, PushResult, push
from alma.push.settlement import settlement_capacity
from alma.report.capacity import plot_capacity
from alma.report.capacity_html import write_capacity_html
from alma.seismic import EDITIONS, SeismicResult, load_site, seismic
from alma.settle import SettleError


def register(sub, invalid: Callable) -> None:
    """Add the two commands to the ``alma`` parser; ``invalid`` reports bad input (exit 2)."""
    p = sub.add_parser("push", help="the capacity curve α(d): incremental large-displacement analysis")
    p.add_argument("scene", help="scene file: JSON (SPEC §2) or a DXF drawing")
    p.add_argument("--model", default="associative", choices=PUSH_MODELS)
    p.add_argument(
        "--control",
        metavar="BLOCK",
        help="block whose centroid's horizontal displacement is d (default: the block that moves most horizontally)",
    )
    p.add_argument("--steps", type=int, default=None, help="steps from α_c to α = 0 (default 40)")
    _outputs(p)
    add_compressive_strength(add_scene_options(p))
    p.set_defaults(func=lambda args: _run(args, invalid, None))

    p = sub.add_parser("seismic", help="the kinematic seismic check (NTC 2018, Circolare 2019 §C8.7.1)")
    p.add_argument("scene", help="scene file: JSON (SPEC §2) or a DXF drawing")
    p.add_argument("--site", required=True, metavar="SITE.toml", help="the site's parameters (SPEC §3 keys)")
    p.add_argument(
        "--edition",
        choices=EDITIONS,
        default=None,
        help="the Circolare whose form of the checks applies (default: the site file's 'edition', else 2019)",
    )
    p.add_argument(
        "--model",
        default="associative",
        choices=PUSH_MODELS,
        help="the capacity curve by the associative LP (default) or the friction search (nonassociative)",
    )
    p.add_argument("--control", metavar="BLOCK", help="the control block of the capacity curve")
    p.add_argument("--steps", type=int, default=None, help="steps of the capacity curve (default 40)")
    _outputs(p)
    add_compressive_strength(add_scene_options(p))
    p.set_defaults(func=lambda args: _run(args, invalid, args.site))


def add_capacity_options(p: argparse.ArgumentParser) -> None:
    """``alma settle --capacity [--steps N]``: the settlement capacity instead of one mechanism."""
    p.add_argument(
        "--capacity",
        action="store_true",
        help="grow the settlement until the structure can no "
        "longer carry its dead load (settlement capacity s_u, the curve α(s), large displacements)",
    )
    p.add_argument("--steps", type=int, default=None, help="with --capacity: steps from s = 0 to s_u (default 40)")
    p.add_argument(
        "--model",
        choices=PUSH_MODELS,
        default=None,
        help="with --capacity: α(s) by the associative LP (default) or the friction search (nonassociative)",
    )


def run_capacity(args: argparse.Namespace, invalid: Callable) -> int:
    """``alma settle SCENE --capacity``: s_u, α(s) and the crack pattern at each step."""
    try:
        for out in (args.plot, args.html):
            if out:
                _check_output(out, (args.scene,))
        if args.steps is not None and args.steps < 1:
            raise ValueError(f"--steps must be a positive integer, got {args.steps}")
        scene = scene_from_args(args)
        result = settlement_capacity(scene, steps=args.steps, model=args.model or "associative")
    except (SceneError, SettleError, ValueError) as exc:
        return invalid(exc, args)
    name = "s: rotation" if result.unit == "rad" else "s: settlement"
    abscissa = (f"{name} of {result.support} [{result.unit}]", "s_u", result.unit)
    curve = dataclasses.replace(result.curve, d0=result.s_u)
    if args.plot and result.curve.curve:
        plot_capacity(scene, curve, args.plot, title=scene.name or None, abscissa=abscissa)
    if args.html and result.curve.curve:
        rows = [(k, v if isinstance(v, str) else json.dumps(v)) for k, v in result.to_dict().items() if k != "curve"]
        rows += [
            (f"cracked at s = {p.d:.6g} {result.unit}", ", ".join("|".join(j) for j in c) or "none")
            for p, c in zip(result.curve.curve, result.cracks, strict=True)
        ]
        write_capacity_html(
            curve, args.html, title=scene.name or "settlement capacity", scene=scene, abscissa=abscissa, rows=rows
        )
    if args.json:
        print(json.dumps(result.to_dict()))
        return 0
    print(f"{scene.name or 'scene'}")
    print(f"  status     {result.status} — {result.message}")
    print(f"  support    {result.support} (s in {result.unit})")
    if result.curve.curve:
        print(f"  alpha(0)   {result.curve.alpha_c:.6f}")
        last = result.curve.curve[-1].d
        print(
            f"  s_u        {result.s_u:.6g} {result.unit}  (bracket [{result.bracket[0]:.9g}, "
            f"{result.bracket[1]:.9g}]; {result.factor_u:.6g} x the scene's settlement)"
            if result.s_u == result.s_u
            else f"  s_u        not reached: the structure stands at s = {last:.6g} {result.unit}, the last tried"
        )
        print(
            f"  curve      {len(result.curve.curve)} points, {result.curve.solves} configurations solved; "
            f"cracked while standing: {', '.join('|'.join(j) for j in result.cracked_u) or 'none'}"
        )
    if args.plot:
        print(f"  picture    {args.plot}")
    sys.stdout.flush()
    return 0


def _outputs(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p.add_argument("--plot", metavar="OUT.png", help="write the capacity curve and the displaced geometry")
    p.add_argument("--html", metavar="OUT.html", help="write a standalone page: the curve(s) in SVG and the numbers")


def _run(args: argparse.Namespace, invalid: Callable, site_path: str | None) -> int:
    try:
        for out in (args.plot, args.html):
            if out:
                _check_output(out, (args.scene, site_path))
        scene = scene_from_args(args)
        site = load_site(site_path) if site_path else None
        if args.steps is not None and args.steps < 1:
            raise ValueError(f"--steps must be a positive integer, got {args.steps}")
        options = {"control": args.control, "steps": args.steps, "model": args.model}
        if site is None:
            result: PushResult | SeismicResult = push(scene, **options)
        else:
            result = seismic(scene, site, edition=args.edition, **options)
    except (SceneError, ValueError) as exc:
        return invalid(exc, args)
    curve = result if isinstance(result, PushResult) else result.push
    if args.plot and curve.curve:
        plot_capacity(
            scene,
            curve,
            args.plot,
            check=result if isinstance(result, SeismicResult) else None,
            title=scene.name or None,
        )
    if args.html and curve.curve:
        write_capacity_html(
            curve,
            args.html,
            check=result if isinstance(result, SeismicResult) else None,
            title=scene.name or "capacity curve",
            scene=scene,
        )
    if args.json:
        print(json.dumps(result.to_dict()))
    else:
        _print_text(scene, result, args.plot)
    return 0


def _verdict(check: dict) -> str:
    return f"safety index {check['safety_index']:.3f} ({'verified' if check['verified'] else 'NOT verified'})"


def _lines_2009(result: SeismicResult) -> list[str]:
    lin, nl = result.linear, result.nonlinear
    lines = [f"  linear     a0* = {result.a0_star:.4g} m/s² vs demand {lin['demand']:.4g} m/s²: {_verdict(lin)}"]
    if nl.get("verified") is not None:  # the check ran: its values are numbers
        du, demand = cast(float, nl["du_star"]), cast(float, nl["demand"])
        lines.append(
            f"  nonlinear  du* = {du * 1e3:.4g} mm vs demand {demand * 1e3:.4g} mm "
            f"(Ts = {nl['Ts']:.3f} s): {_verdict(nl)}"
        )
    return lines


def _lines_2019(result: SeismicResult) -> list[str]:
    lin, nl, slc = result.linear, result.nonlinear, result.slc
    formula = "q a_g a_Z,SLD / a_Z(z)" if lin.get("governs") == "floor" else "q a_Z,SLD / S"
    lines = [
        f"  linear     a_g,SLV = {formula} = {lin['a_g_SLV']:.4g} m/s² vs a_g {lin['demand']:.4g} m/s²: {_verdict(lin)}"
    ]
    if lin.get("governs") == "floor":
        lines.append(
            f"  floor      a_Z(z) = {lin['a_Z']:.4g} m/s² at Z = {result.site.Z:g} m (T1 = {lin['T1']:.3f} s"
            f"{', NTC Eq. 7.3.6' if lin['T1_estimated'] else ''}, ξ1 = {lin['xi1']:g} %)"
        )
    if "refused" in nl:
        lines.append(f"  nonlinear  not done: {nl['refused']}")
    elif nl.get("verified") is not None:
        d, demand = cast(float, nl["d_SLV"]), cast(float, nl["displacement_demand"])
        lines.append(
            f"  nonlinear  d_SLV = {d * 1e3:.4g} mm vs demand {demand * 1e3:.4g} mm (T_SLV = "
            f"{nl['T_SLV']:.3f} s, ξ = 8 %): a_g,SLV = {nl['a_g_SLV']:.4g} m/s², {_verdict(nl)}"
        )
    if slc is not None and slc.get("verified") is not None:
        d, demand = cast(float, slc["d_SLC"]), cast(float, slc["displacement_demand"])
        lines.append(
            f"  SLC        d_SLC = {d * 1e3:.4g} mm vs demand {demand * 1e3:.4g} mm (T_SLC = "
            f"{slc['T_SLC']:.3f} s, ξ = 10 %): a_g,SLC = {slc['a_g_SLC']:.4g} m/s² vs "
            f"{slc['demand']:.4g} m/s², {_verdict(slc)}"
        )
    return lines


def _check_output(path: str, inputs: tuple[str | None, ...]) -> None:
    out = Path(path).resolve()
    if any(i is not None and Path(i).resolve() == out for i in inputs):
        raise ValueError(f"{path}: refusing to write over an input file")
    if not out.parent.is_dir():
        raise ValueError(f"{path}: the directory {out.parent} does not exist")


def _print_text(scene: Scene, result: PushResult | SeismicResult, picture: str | None) -> None:
    curve = result if isinstance(result, PushResult) else result.push
    print(f"{scene.name or 'scene'}")
    print(f"  status     {result.status} — {result.message}")
    if curve.curve:
        print(f"  control    {curve.control}")
        print(f"  alpha_c    {curve.alpha_c:.6f}")
        stop = f"d0 {curve.d0:.6g} mm" if curve.d0 == curve.d0 else f"ends: {curve.end.get('reason', '?')}"
        print(
            f"  {stop}  ({len(curve.curve)} points, {curve.solves} LP solves, "
            f"{sum(p.mechanism_changed for p in curve.curve)} mechanism changes)"
        )
    if isinstance(result, SeismicResult) and curve.curve:
        print(f"  M*, e*     {result.M_star:.6g} kg, {result.e_star:.4f}  (Circolare {result.edition})")
        for line in (_lines_2019 if result.edition == "2019" else _lines_2009)(result):
            print(line)
    if picture:
        print(f"  picture    {picture}")
    sys.stdout.flush()
