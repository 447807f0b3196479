"""Command line (SPEC §3): ``alma solve``, ``panel``, ``settle``, ``tilt`` and the study commands."""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from pathlib import Path
from typing import NoReturn, cast

from alma.backends import scip_backend
from alma.cli import generate, push as push_cli, study as study_cli
from alma.cli.common_options import add_common_options
from alma.cli.json_output import dumps
from alma.cli.outputs import OutputPathError, check_outputs
from alma.cli.scene_options import add_scene_options, scene_from_args, with_compressive_strength
from alma.geometry.chains import parse_chain, with_chain
from alma.geometry.dxf import write_dxf
from alma.geometry.panels import BLOCK_LENGTHS, BONDS, PANEL_HEIGHTS, paper_panel
from alma.geometry.scene import Scene, SceneError
from alma.report.html import write_html, write_settlement_html, write_tilt_html
from alma.report.picture import StillPicture
from alma.report.plot import plot_mechanism
from alma.settings import AssociativeSettings, CertifyBackend, CertifySettings, Settings
from alma.settle import SettleError, after_settlement, settle
from alma.solve import solve
from alma.tilt import tilt, tilted


class UsageError(Exception):
    """A command line argparse refuses (unknown option, a value of the wrong kind): exit 2."""

    def __init__(self, parser: argparse.ArgumentParser, message: str) -> None:
        super().__init__(f"{parser.prog}: {message}")
        self.parser = parser


class _Parser(argparse.ArgumentParser):
    """argparse, with its refusals raised to :func:`main` (which says them, as JSON too with --json)."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(self, message)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = _build_parser()
    try:
        args = parser.parse_args(argv)
    except UsageError as exc:
        exc.parser.print_usage(sys.stderr)
        return _invalid(exc, argparse.Namespace(json="--json" in argv))
    try:
        check_outputs(args)  # before any work: a result is never lost to an unwritable path
    except OutputPathError as exc:
        return _invalid(exc, args)
    return int(args.func(args) or 0)


def _build_parser() -> argparse.ArgumentParser:
    """The ``alma`` parser with every subcommand (SPEC §3), in the order ``alma --help`` lists them."""
    parser = _Parser(
        prog="alma",
        description="Limit analysis of masonry block structures.",
        epilog="Scene files, commands and the JSON output: docs/scenes.md of alma's repository; "
        "worked examples in examples/.",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    _add_solve(sub)
    _add_panel(sub)
    _add_settle(sub)
    _add_tilt(sub)
    generate.register(sub, add_common_options, _run, export_scene, _invalid)
    push_cli.register(sub, _invalid)

    study_cli.register(sub)
    return parser


def _add_solve(sub: argparse._SubParsersAction) -> None:
    """Add ``alma solve``: the collapse load of a scene file."""
    p_solve = sub.add_parser("solve", help="solve a scene file (SPEC §2)")
    p_solve.add_argument("scene", help="scene file: JSON (SPEC §2) or a DXF drawing (one polyline per block)")
    add_scene_options(p_solve)
    p_solve.add_argument(
        "--after-settlement",
        action="store_true",
        help="solve the settled structure: cohesion lost on every joint its settlement opens",
    )
    add_common_options(p_solve)
    p_solve.set_defaults(func=_cmd_solve)


def _add_panel(sub: argparse._SubParsersAction) -> None:
    """Add ``alma panel``: the collapse load of one of the paper's panels (Table 1)."""
    p_panel = sub.add_parser("panel", help="solve one of the paper's panels")
    p_panel.add_argument("--bond", required=True, choices=BONDS)
    p_panel.add_argument("--panel-ratio", required=True, choices=sorted(PANEL_HEIGHTS))
    p_panel.add_argument("--block-ratio", required=True, choices=sorted(BLOCK_LENGTHS))
    p_panel.add_argument("--friction", required=True, type=float)
    p_panel.add_argument(
        "--export-scene", metavar="OUT.json|OUT.dxf", help="write the panel as a scene file (JSON) or a drawing (DXF)"
    )
    p_panel.add_argument(
        "--chain",
        action="append",
        default=[],
        metavar="HEIGHT:STRENGTH",
        help="a horizontal chain at HEIGHT mm of STRENGTH kN across the panel, anchored on its "
        "two end blocks (repeatable)",
    )
    p_panel.add_argument(
        "--anchored", action="store_true", help="tie each chain's ends to fixed anchors outside the panel instead"
    )
    add_common_options(p_panel)
    p_panel.set_defaults(func=_cmd_panel)


def _add_settle(sub: argparse._SubParsersAction) -> None:
    """Add ``alma settle``: the crack pattern of a prescribed support settlement."""
    p_settle = sub.add_parser("settle", help="the crack pattern a prescribed support settlement opens (SPEC §3)")
    p_settle.add_argument("scene", help="scene file (JSON or DXF) with a 'settlement' on a fixed block")
    add_scene_options(p_settle)
    p_settle.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p_settle.add_argument("--plot", metavar="OUT.png", help="write a picture of the settlement mechanism")
    p_settle.add_argument(
        "--html",
        metavar="OUT.html",
        help="write a self-contained page: the settlement "
        "mechanism in SVG, the crack pattern, the work and the reactions in words",
    )
    push_cli.add_capacity_options(p_settle)
    p_settle.set_defaults(func=_cmd_settle)


def _add_tilt(sub: argparse._SubParsersAction) -> None:
    """Add ``alma tilt``: the critical tilt angle θ_c (degrees) on a tilting table."""
    p_tilt = sub.add_parser("tilt", help="the critical tilt angle on a tilting table (SPEC §3)")
    p_tilt.add_argument("scene", help="scene file: JSON or a DXF drawing")
    add_scene_options(p_tilt)
    p_tilt.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p_tilt.add_argument("--plot", metavar="OUT.png", help="write a picture of the collapse on the table tilted to θ_c")
    p_tilt.add_argument(
        "--html",
        metavar="OUT.html",
        help="write a self-contained page: the collapse on the tilted table in SVG and the critical angle in words",
    )
    p_tilt.set_defaults(func=_cmd_tilt)


def _cmd_solve(args: argparse.Namespace) -> int:
    try:
        scene = scene_from_args(args)
        if args.after_settlement:
            scene = after_settlement(scene)
    except (SceneError, ValueError) as exc:
        return _invalid(exc, args)
    return _run(scene, args)


def _cmd_settle(args: argparse.Namespace) -> int:
    if args.capacity:
        return push_cli.run_capacity(args, _invalid)
    try:
        if args.model is not None or args.steps is not None:
            raise ValueError("--model and --steps apply to --capacity only (the settlement capacity)")
        scene = scene_from_args(args)
        result = settle(scene)
    except (SceneError, SettleError, ValueError) as exc:
        return _invalid(exc, args)
    if args.plot:
        plot_mechanism(
            scene,
            StillPicture.of(result),
            args.plot,
            title=scene.name or None,
            settling=True,
            caption_text=f"settlement mechanism: {len(result.opened)} joints open",
        )
    if args.html:
        write_settlement_html(scene, result, args.html)
    if args.json:
        print(dumps(result.to_dict()))
        return 0
    b = result.bounds
    print(f"{scene.name or 'scene'}")
    print(f"  status     {result.status} — {result.message}")
    print(f"  work       {result.work:.6g} kN·mm  (bounds [{b.lower:.9g}, {b.upper:.9g}])")
    for r in result.reactions:
        print(
            f"  reaction   {r['block']}: force [{r['force'][0]:.6g}, {r['force'][1]:.6g}] kN, "
            f"moment {r['moment']:.6g} kN·mm"
        )
    print(f"  opened     {len(result.opened)} joints")
    return 0


def _cmd_tilt(args: argparse.Namespace) -> int:
    try:
        scene = scene_from_args(args)
        result = tilt(scene)
    except SceneError as exc:
        return _invalid(exc, args)
    if args.plot or args.html:
        _tilt_pictures(scene, result, args)
    if args.json:
        print(dumps(result.to_dict()))
        return 0
    lo, hi = result.bounds_deg
    print(f"{scene.name or 'scene'}")
    print(f"  status     {result.status} — {result.message}")
    print(
        f"  angle      {result.angle_deg:.6f}°  (bounds [{lo:.6f}°, {hi:.6f}°], {result.method}, "
        f"{result.steps} LP solves)"
    )
    return 0


def _tilt_pictures(scene: Scene, result, args: argparse.Namespace) -> None:
    """The collapse on the table tilted to the proven standing angle θ_c⁻ (α ≥ 0 there, ≈ 0)."""
    lower = result.bounds_deg[0]
    on_table = tilted(scene, lower) if result.status == "optimal" and math.isfinite(lower) else None
    collapse = solve(on_table) if on_table is not None else None
    if args.plot:
        words = (
            f"collapse on the table tilted to θ_c = {result.angle_deg:.4g}°"
            if collapse is not None
            else f"{result.status}: {result.message}"
        )
        plot_mechanism(
            scene if on_table is None else on_table,
            collapse or StillPicture.of(result),
            args.plot,
            title=scene.name or None,
            gravity_deg=lower if math.isfinite(lower) else 0.0,
            caption_text=words,
        )
    if args.html:
        write_tilt_html(scene if on_table is None else on_table, result, collapse, args.html)


def _cmd_panel(args: argparse.Namespace) -> int:
    try:
        scene = paper_panel(args.bond, args.panel_ratio, args.block_ratio, args.friction)
        for k, text in enumerate(args.chain):
            height, strength = parse_chain(text)
            scene = with_chain(scene, height, strength, anchored=args.anchored, name=f"chain{k + 1}")
        if args.chain:
            scene = scene.validate()
        scene = with_compressive_strength(scene, args.compressive_strength)  # exported with it
    except SceneError as exc:
        return _invalid(exc, args)
    if args.export_scene:
        export_scene(scene, args.export_scene)
    return _run(scene, args)


def _run(scene: Scene, args: argparse.Namespace) -> int:
    if args.certify and args.model == "associative":
        print("alma: --certify applies to the non-associative model (--model nonassociative|both)", file=sys.stderr)
        return 2
    certify = _certify_settings(args)
    if isinstance(certify, str):
        print(f"alma: {certify}", file=sys.stderr)
        if args.json:
            print(json.dumps({"status": "invalid_input", "message": certify}))
        return 2
    try:
        scene = with_compressive_strength(scene, getattr(args, "compressive_strength", None))
        settings = Settings(associative=AssociativeSettings(crisp_mechanism=bool(args.crisp)), certify=certify)
        result = solve(
            scene,
            model=args.model,
            settings=settings,
            effort=args.effort,
            certify=args.certify,
            time_limit=args.time_limit,
        )
    except SceneError as exc:
        return _invalid(exc, args)
    for warning in result.warnings:
        print(f"alma: warning: {warning}", file=sys.stderr)
    if args.plot:
        plot_mechanism(scene, result, args.plot, title=scene.name or None, line_of_thrust=args.thrust)
    if args.html:
        write_html(scene, result, args.html, thrust=args.thrust)
    if args.json:
        print(dumps(result.to_dict()))
    else:
        _print_text(scene, result, args.plot)
    return 0


def _certify_settings(args: argparse.Namespace) -> CertifySettings | str:
    """The certificate's settings from --certify-backend and --certify-nodes, or what is wrong."""
    backend = getattr(args, "certify_backend", "highs")
    nodes = getattr(args, "certify_nodes", None)
    if backend == "scip" and not scip_backend.available():
        return f"--certify-backend scip: {scip_backend.INSTALL_HINT}"
    if nodes is not None and nodes < 1:
        return f"--certify-nodes must be a positive number of nodes, got {nodes}"
    base = CertifySettings(backend=cast(CertifyBackend, backend))  # one of CERTIFY_BACKENDS (argparse's choices)
    return base if nodes is None else dataclasses.replace(base, node_limit=int(nodes))


def _print_text(scene: Scene, result, picture: str | None) -> None:
    """The human-readable summary: one line per fact, every timing of the analysis."""
    b = result.bounds
    print(f"{scene.name or 'scene'}")
    print(f"  model      {result.model}")
    print(f"  status     {result.status} — {result.message}")
    print(f"  alpha      {result.alpha:.6f}")
    if result.model != "associative":
        print(f"  assoc. α   {result.alpha_associative:.6f}")
        print(f"  start      {result.extra.get('start')}  (the search's start that gave α)")
        if "certificate" in result.extra:
            print(f"  certified  {result.extra['certificate']['message']}")
    print(f"  bounds     {b.describe()}")
    print(
        f"  mechanism  {result.mechanism_class}  ({result.extra['n_blocks']} blocks, {result.extra['n_joints']} joints)"
    )
    names = {
        "joints_s": "joints",
        "build_s": "build",
        "solve_s": "LP solve",
        "certify_s": "LP certificate",
        "nonassociative_s": "search",
        "certification_s": "MILP certification",
    }
    parts = [f"{label} {result.timings[key]:.3f} s" for key, label in names.items() if key in result.timings]
    print(f"  time       {', '.join(parts)}")
    if picture:
        print(f"  picture    {picture}")


def export_scene(scene: Scene, path: str) -> None:
    """Write ``scene`` as JSON (SPEC §2) or, for a ``.dxf`` path, as a drawing."""
    if path.lower().endswith(".dxf"):
        write_dxf(scene, path)
    else:
        Path(path).write_text(json.dumps(scene.to_dict(), indent=1))


def _invalid(exc: Exception, args: argparse.Namespace) -> int:
    print(f"alma: invalid input: {exc}", file=sys.stderr)
    if getattr(args, "json", False):
        print(dumps({"status": "invalid_input", "message": str(exc)}))
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
