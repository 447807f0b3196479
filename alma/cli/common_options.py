"""The options every collapse-load command shares (``solve``, ``panel``, ``wall``, ``arch``;
SPEC §3): the contact model, the certificate of the non-associative α, the search effort and
time limit, the blocks' compressive strength and the outputs (``--json``, ``--plot``,
``--html``, ``--thrust``).
"""

from __future__ import annotations

import argparse

from alma.cli.scene_options import positive_float
from alma.settings import CERTIFY_BACKENDS, EFFORTS, CertifySettings
from alma.solve import MODELS

__all__ = ["add_common_options"]


def add_common_options(p: argparse.ArgumentParser) -> None:
    """Add the model, certificate, effort and output options of a collapse-load command to ``p``."""
    p.add_argument("--model", default="associative", choices=MODELS)
    p.add_argument(
        "--certify", action="store_true", help="prove a lower bound of the non-associative α by mixed-integer LP"
    )
    p.add_argument(
        "--certify-backend",
        default="highs",
        choices=CERTIFY_BACKENDS,
        help="the MIP solver of --certify: highs (big-M binaries, the default) or scip (SOS1 "
        "pairs, no big-M; needs the extra alma[scip])",
    )
    p.add_argument(
        "--certify-nodes",
        type=int,
        default=None,
        metavar="N",
        help=f"branch-and-bound node budget of --certify (default {CertifySettings().node_limit:,}); "
        "when it stops the proof, the bound reached is reported",
    )
    p.add_argument(
        "--effort",
        default="auto",
        choices=EFFORTS,
        help="non-associative search effort (auto: thorough up to 200 blocks)",
    )
    p.add_argument(
        "--time-limit",
        type=positive_float,
        default=None,
        help="a hard wall-clock cap in seconds (default: none); the searches spend work budgets, "
        "so the answer does not depend on the machine unless the cap cuts it (status "
        "limit_reached)",
    )
    p.add_argument(
        "--crisp",
        action="store_true",
        help="show one crisp mechanism of the associative optimal face (a vertex) instead of the "
        "interior point's blend of all of them (about 1-5x the solve)",
    )
    p.add_argument(
        "--compressive-strength",
        type=float,
        default=None,
        metavar="MPA",
        help="σ_c of every joint in MPa (overrides the scene's compressive_strength; default: the "
        "scene's, else infinitely strong blocks); associative model only",
    )
    _add_outputs(p)


def _add_outputs(p: argparse.ArgumentParser) -> None:
    """Add the outputs of a collapse-load command: ``--json``, ``--plot``, ``--html``, ``--thrust``."""
    p.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p.add_argument("--plot", metavar="OUT.png", help="write a picture of the collapse mechanism")
    p.add_argument(
        "--html",
        metavar="OUT.html",
        help="write a self-contained page: the result in words, the "
        "mechanism in SVG (loads, supports, rigid parts, crack, hinges) with a displacement slider, "
        "hover details, bounds and timings folded (both models side by side for --model both)",
    )
    p.add_argument(
        "--thrust",
        action="store_true",
        help="draw the line of thrust on --plot and show it from the start on --html (a switch on the page)",
    )
