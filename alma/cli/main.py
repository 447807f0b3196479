"""Command line (SPEC §3): ``alma solve``, ``panel``, ``settle``, ``tilt`` and the study commands."""
from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import types
from pathlib import Path

from alma.backends import scip_backend
from alma.certify.milp import BACKENDS
from alma.geometry.chains import parse_chain, with_chain
from alma.geometry.panels import BLOCK_LENGTHS, BONDS, PANEL_HEIGHTS, paper_panel
from alma.geometry.scene import Scene, SceneError, load_scene
from alma.settle import after_settlement, settle
from alma.settings import AssociativeSettings, CertifySettings, Settings
from alma.solve import MODELS, solve
from alma.tilt import tilt


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="alma", description="Limit analysis of masonry block structures.",
        epilog="Scene files, commands and the JSON output: docs/scenes.md of alma's repository; "
               "worked examples in examples/.")
    sub = parser.add_subparsers(dest="command", required=True)

    p_solve = sub.add_parser("solve", help="solve a scene file (SPEC §2)")
    p_solve.add_argument("scene", help="scene file: JSON (SPEC §2) or a DXF drawing (one polyline per block)")
    dxf = p_solve.add_argument_group("DXF drawings (materials of the scene; ignored for JSON)")
    dxf.add_argument("--thickness", type=float, default=None, help="mm (default 120)")
    dxf.add_argument("--unit-weight", type=float, default=None, help="kN/m³ (default 18)")
    dxf.add_argument("--friction", type=float, default=None, help="(default 0.6)")
    dxf.add_argument("--cohesion", type=float, default=None, help="kPa (default 0)")
    dxf.add_argument("--supports", choices=("layers", "lowest"), default=None,
                     help="supports from layer names (fixed/support/ground, the default) or every block "
                          "reaching the lowest y")
    p_solve.add_argument("--after-settlement", action="store_true",
                         help="solve the settled structure: cohesion lost on every joint its settlement opens")
    p_solve.add_argument("--contact-tolerance", type=float, metavar="REL",
                         help="gaps and overlaps snapped to a joint, relative to the median block size "
                              "(default 1e-4; overrides the scene's contact_tolerance)")
    _add_common(p_solve)
    p_solve.set_defaults(func=_cmd_solve)

    p_panel = sub.add_parser("panel", help="solve one of the paper's panels")
    p_panel.add_argument("--bond", required=True, choices=BONDS)
    p_panel.add_argument("--panel-ratio", required=True, choices=sorted(PANEL_HEIGHTS))
    p_panel.add_argument("--block-ratio", required=True, choices=sorted(BLOCK_LENGTHS))
    p_panel.add_argument("--friction", required=True, type=float)
    p_panel.add_argument("--export-scene", metavar="OUT.json|OUT.dxf",
                         help="write the panel as a scene file (JSON) or a drawing (DXF)")
    p_panel.add_argument("--chain", action="append", default=[], metavar="HEIGHT:STRENGTH",
                         help="a horizontal chain at HEIGHT mm of STRENGTH kN across the panel, anchored on its "
                              "two end blocks (repeatable)")
    p_panel.add_argument("--anchored", action="store_true",
                         help="tie each chain's ends to fixed anchors outside the panel instead")
    _add_common(p_panel)
    p_panel.set_defaults(func=_cmd_panel)

    p_settle = sub.add_parser("settle", help="the crack pattern a prescribed support settlement opens (SPEC §3)")
    p_settle.add_argument("scene", help="scene JSON file with a 'settlement' on a fixed block")
    p_settle.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p_settle.add_argument("--plot", metavar="OUT.png", help="write a picture of the settlement mechanism")
    p_settle.set_defaults(func=_cmd_settle)

    p_tilt = sub.add_parser("tilt", help="the critical tilt angle on a tilting table (SPEC §3)")
    p_tilt.add_argument("scene", help="scene JSON file")
    p_tilt.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p_tilt.set_defaults(func=_cmd_tilt)

    from alma.cli import generate

    generate.register(sub, _add_common, _run, export_scene, _invalid)

    try:
        from alma.cli import study as study_cli
    except ImportError:  # pragma: no cover — the study commands are optional extras
        study_cli = None
    if study_cli is not None:
        study_cli.register(sub)

    args = parser.parse_args(argv)
    return int(args.func(args) or 0)


def _add_common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--model", default="associative", choices=MODELS)
    p.add_argument("--certify", action="store_true",
                   help="prove a lower bound of the non-associative α by mixed-integer LP")
    p.add_argument("--certify-backend", default="highs", choices=BACKENDS,
                   help="the MIP solver of --certify: highs (big-M binaries, the default) or scip (SOS1 "
                        "pairs, no big-M; needs the extra alma[scip])")
    p.add_argument("--certify-nodes", type=int, default=None, metavar="N",
                   help=f"branch-and-bound node budget of --certify (default {CertifySettings().node_limit:,}); "
                        "when it stops the proof, the bound reached is reported")
    p.add_argument("--effort", default="auto", choices=("auto", "fast", "thorough"),
                   help="non-associative search effort (auto: thorough up to 200 blocks)")
    p.add_argument("--time-limit", type=float, default=None,
                   help="a hard wall-clock cap in seconds (default: none); the searches spend work budgets, "
                        "so the answer does not depend on the machine unless the cap cuts it (status "
                        "limit_reached)")
    p.add_argument("--crisp", action="store_true",
                   help="show one crisp mechanism of the associative optimal face (a vertex) instead of the "
                        "interior point's blend of all of them (about 1-5x the solve)")
    p.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p.add_argument("--plot", metavar="OUT.png", help="write a picture of the collapse mechanism")
    p.add_argument("--html", metavar="OUT.html", help="write a self-contained page: the mechanism in SVG with a "
                   "displacement slider and animation, joint states, the line of thrust, hover details, bounds "
                   "and timings (both models side by side for --model both)")


def _cmd_solve(args: argparse.Namespace) -> int:
    try:
        scene = load_scene(args.scene, **_dxf_options(args))
        if args.contact_tolerance is not None:
            scene = dataclasses.replace(scene, contact_tolerance=args.contact_tolerance, validated=False)
            scene.validate()
        if args.after_settlement:
            scene = after_settlement(scene)
    except (SceneError, ValueError) as exc:
        return _invalid(exc, args)
    return _run(scene, args)


def _dxf_options(args: argparse.Namespace) -> dict[str, object]:
    """The material options of a DXF scene (none for JSON, which holds its own)."""
    if not str(args.scene).lower().endswith(".dxf"):
        return {}
    return {"thickness": args.thickness, "unit_weight": args.unit_weight, "friction": args.friction,
            "cohesion": args.cohesion, "supports": args.supports}


def _loaded(args: argparse.Namespace) -> Scene | int:
    """The scene file of ``args``, or the exit code of its refusal."""
    try:
        return load_scene(args.scene)
    except SceneError as exc:
        return _invalid(exc, args)


def _cmd_settle(args: argparse.Namespace) -> int:
    scene = _loaded(args)
    if isinstance(scene, int):
        return scene
    result = settle(scene)
    if args.plot:
        from alma.report.plot import plot_mechanism

        picture = types.SimpleNamespace(blocks=result.blocks, joints=result.joints, status=result.status,
                                        alpha=float("nan"), model="settlement", mechanism_class="settlement")
        plot_mechanism(scene, picture, args.plot, title=scene.name or None)
    if args.json:
        print(json.dumps(result.to_dict()))
        return 0
    b = result.bounds
    print(f"{scene.name or 'scene'}")
    print(f"  status     {result.status} — {result.message}")
    print(f"  work       {result.work:.6g} kN·mm  (bounds [{b.lower:.9g}, {b.upper:.9g}])")
    for r in result.reactions:
        print(f"  reaction   {r['block']}: force [{r['force'][0]:.6g}, {r['force'][1]:.6g}] kN, "
              f"moment {r['moment']:.6g} kN·mm")
    print(f"  opened     {len(result.opened)} joints")
    return 0


def _cmd_tilt(args: argparse.Namespace) -> int:
    scene = _loaded(args)
    if isinstance(scene, int):
        return scene
    result = tilt(scene)
    if args.json:
        print(json.dumps(result.to_dict()))
        return 0
    lo, hi = result.bounds_deg
    print(f"{scene.name or 'scene'}")
    print(f"  status     {result.status} — {result.message}")
    print(f"  angle      {result.angle_deg:.6f}°  (bounds [{lo:.6f}°, {hi:.6f}°], {result.method}, "
          f"{result.steps} LP solves)")
    return 0


def _cmd_panel(args: argparse.Namespace) -> int:
    try:
        scene = paper_panel(args.bond, args.panel_ratio, args.block_ratio, args.friction)
        for k, text in enumerate(args.chain):
            height, strength = parse_chain(text)
            scene = with_chain(scene, height, strength, anchored=args.anchored, name=f"chain{k + 1}")
        if args.chain:
            scene.validate()
    except SceneError as exc:
        return _invalid(exc, args)
    if args.export_scene:
        export_scene(scene, args.export_scene)
    return _run(scene, args)


def _run(scene: Scene, args: argparse.Namespace) -> int:
    if args.certify and args.model == "associative":
        print("alma: --certify applies to the non-associative model (--model nonassociative|both)",
              file=sys.stderr)
        return 2
    certify = _certify_settings(args)
    if isinstance(certify, str):
        print(f"alma: {certify}", file=sys.stderr)
        if args.json:
            print(json.dumps({"status": "invalid_input", "message": certify}))
        return 2
    try:
        settings = Settings(associative=AssociativeSettings(crisp_mechanism=bool(args.crisp)), certify=certify)
        result = solve(scene, model=args.model, settings=settings, effort=args.effort, certify=args.certify,
                       time_limit=args.time_limit)
    except SceneError as exc:
        return _invalid(exc, args)
    for warning in result.warnings:
        print(f"alma: warning: {warning}", file=sys.stderr)
    if args.plot:
        from alma.report.plot import plot_mechanism

        plot_mechanism(scene, result, args.plot, title=scene.name or None)
    if args.html:
        from alma.report.html import write_html

        write_html(scene, result, args.html)
    if args.json:
        print(json.dumps(result.to_dict()))
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
    base = CertifySettings(backend=backend)
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
    print(f"  mechanism  {result.mechanism_class}  ({result.extra['n_blocks']} blocks, "
          f"{result.extra['n_joints']} joints)")
    names = {"joints_s": "joints", "build_s": "build", "solve_s": "LP solve", "certify_s": "LP certificate",
             "nonassociative_s": "search", "certification_s": "MILP certification"}
    parts = [f"{label} {result.timings[key]:.3f} s" for key, label in names.items() if key in result.timings]
    print(f"  time       {', '.join(parts)}")
    if picture:
        print(f"  picture    {picture}")


def export_scene(scene: Scene, path: str) -> None:
    """Write ``scene`` as JSON (SPEC §2) or, for a ``.dxf`` path, as a drawing."""
    if path.lower().endswith(".dxf"):
        from alma.geometry.dxf import write_dxf

        write_dxf(scene, path)
    else:
        Path(path).write_text(json.dumps(scene.to_dict(), indent=1))


def _invalid(exc: Exception, args: argparse.Namespace) -> int:
    print(f"alma: invalid input: {exc}", file=sys.stderr)
    if getattr(args, "json", False):
        print(json.dumps({"status": "invalid_input", "message": str(exc)}))
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
