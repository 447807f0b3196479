"""``alma wall`` and ``alma arch`` (SPEC §3): generate a structure, write it, solve it."""

from __future__ import annotations

import argparse
from collections.abc import Callable

from alma.cli.scene_options import finite_float, non_negative_float, positive_float
from alma.geometry.generators import KINDS, arch, coursed_wall, wall
from alma.geometry.panels import BONDS
from alma.geometry.scene import Scene, SceneError


def register(sub, add_common: Callable, run: Callable, export: Callable, invalid: Callable) -> None:
    """Add the two generator commands to the ``alma`` parser."""
    p = sub.add_parser("wall", help="a bonded wall with openings and lintels (SPEC §3)")
    p.add_argument("--bond", choices=BONDS, help="required unless --courses is given")
    p.add_argument("--width", type=positive_float, help="mm (required unless --courses is given)")
    p.add_argument(
        "--height", type=positive_float, help="mm, a whole number of courses (required unless --courses is given)"
    )
    p.add_argument(
        "--courses",
        metavar="FILE",
        help="lay the wall from a text file instead: one course per line, "
        "top course first as drawn, block lengths in units of the block length, negative for a gap",
    )
    p.add_argument("--block", required=True, metavar="LxH", help="block length x height, mm (e.g. 240x60)")
    p.add_argument(
        "--opening",
        action="append",
        default=[],
        metavar="X,Y,W,H",
        help="a rectangular opening (mm, on course lines; repeatable); a lintel spans each",
    )
    p.add_argument(
        "--overburden", type=non_negative_float, default=0.0, metavar="KPA", help="pre-compression on the top course"
    )
    p.add_argument("--thickness", type=positive_float, default=120.0, help="mm")
    p.add_argument("--friction", type=non_negative_float, default=0.6)
    p.add_argument("--export-scene", metavar="OUT.json|OUT.dxf", help="write the wall as a scene file")
    add_common(p)
    p.set_defaults(func=lambda args: _generated(args, _wall, run, export, invalid))

    p = sub.add_parser("arch", help="a semicircular, segmental or pointed arch (SPEC §3)")
    p.add_argument("--span", required=True, type=positive_float, help="of the centre line, mm")
    p.add_argument("--rise", required=True, type=positive_float, help="of the centre line, mm")
    p.add_argument("--thickness", required=True, type=positive_float, help="radial, mm")
    p.add_argument("--voussoirs", required=True, type=int)
    p.add_argument("--kind", default="semicircular", choices=KINDS)
    p.add_argument("--springing", default="fixed", choices=("fixed", "piers"))
    p.add_argument("--pier-height", type=non_negative_float, default=0.0, help="mm (with --springing piers)")
    p.add_argument("--pier-width", type=positive_float, default=None, help="mm (default 1.5 x thickness)")
    p.add_argument("--pier-courses", type=int, default=1)
    p.add_argument("--depth", type=positive_float, default=120.0, help="out-of-plane thickness, mm")
    p.add_argument("--friction", type=non_negative_float, default=0.6)
    p.add_argument("--export-scene", metavar="OUT.json|OUT.dxf", help="write the arch as a scene file")
    add_common(p)
    p.set_defaults(func=lambda args: _generated(args, _arch, run, export, invalid))


def _generated(args: argparse.Namespace, build: Callable, run: Callable, export: Callable, invalid: Callable) -> int:
    try:
        scene = build(args).validate()
    except (SceneError, ValueError) as exc:
        return invalid(exc, args)
    if args.export_scene:
        export(scene, args.export_scene)
    return run(scene, args)


def _wall(args: argparse.Namespace) -> Scene:
    length, height = block_size(args.block)
    if args.courses:
        return coursed_wall(
            read_courses(args.courses),
            length,
            height,
            thickness=args.thickness,
            friction=args.friction,
            name=f"coursed wall {args.courses}",
        )
    missing = [
        flag
        for flag, value in (("--bond", args.bond), ("--width", args.width), ("--height", args.height))
        if value is None
    ]
    if missing:
        raise SceneError(f"alma wall: give {', '.join(missing)} (or --courses FILE)")
    openings = []
    for text in args.opening:
        try:
            opening = tuple(finite_float(v) for v in text.split(","))
        except argparse.ArgumentTypeError as exc:
            raise SceneError(f"--opening: give X,Y,W,H in mm; got {text!r}") from exc
        if len(opening) != 4 or not (opening[2] > 0 and opening[3] > 0):
            raise SceneError(f"--opening: give X,Y,W,H in mm with W, H > 0; got {text!r}")
        openings.append(opening)
    return wall(
        args.bond,
        args.width,
        args.height,
        length,
        height,
        openings=openings,
        overburden_kpa=args.overburden,
        thickness=args.thickness,
        friction=args.friction,
    )


def block_size(text: str) -> tuple[float, float]:
    """``LENGTHxHEIGHT`` (mm, both finite and > 0) of ``--block``."""
    try:
        length, height = (positive_float(v) for v in text.lower().split("x"))
    except (ValueError, argparse.ArgumentTypeError) as exc:
        raise SceneError(f"--block: give LENGTHxHEIGHT in mm, both > 0, e.g. 240x60; got {text!r}") from exc
    return length, height


def read_courses(path: str) -> list[list[float]]:
    """Courses of :func:`alma.coursed_wall` from a text file drawn top course first.

    Numbers are separated by spaces or commas; ``#`` starts a comment; blank lines are skipped.
    """
    try:
        with open(path, encoding="utf-8") as fh:
            lines = fh.readlines()
    except OSError as exc:
        raise SceneError(f"--courses: cannot read {path}: {exc.strerror}") from exc
    except UnicodeDecodeError as exc:
        raise SceneError(f"--courses: {path} is not UTF-8 text (byte {exc.start})") from exc
    rows = []
    for number, line in enumerate(lines, 1):
        text = line.split("#", 1)[0].replace(",", " ").split()
        if not text:
            continue
        try:
            rows.append([float(v) for v in text])
        except ValueError as exc:
            raise SceneError(f"{path}, line {number}: not a list of numbers: {line.strip()!r}") from exc
    return rows[::-1]


def _arch(args: argparse.Namespace) -> Scene:
    return arch(
        args.span,
        args.rise,
        args.thickness,
        args.voussoirs,
        kind=args.kind,
        springing=args.springing,
        pier_height=args.pier_height,
        pier_width=args.pier_width,
        pier_courses=args.pier_courses,
        depth=args.depth,
        friction=args.friction,
    )
