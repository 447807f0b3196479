"""The same commit gives the same friction answer on another CPU (issue 30).

NumPy hands dense products to OpenBLAS, which picks its kernels by the CPU: with FMA or not,
four or eight lanes, the sums round differently.  Before ``alma.floats`` the search's starting
field (the associative LP's certificate) went through such sums, and english 2:1 2:1 f = 0.6
gave α_NL 0.445940 with this machine's kernel (SkylakeX), 0.444576 with the Haswell and Zen
kernels and 0.446495 with Sandybridge's.  Here each run is a fresh interpreter with OpenBLAS
forced to another kernel (``OPENBLAS_CORETYPE``) and NumPy's own vector code limited to older
instruction sets (``NPY_DISABLE_CPU_FEATURES``), as on an older CPU; the α, status and winning
start of each scene must be the same bits, and so must the associative LP's field it starts from
and the end of ``examples/portal.json``'s capacity curve (whose last α differed in its last bits
while the push's corrector used LAPACK and SuperLU).
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Paper panels whose answers differed between OpenBLAS kernels before the dense sums left BLAS.
PANELS = [("english", "2:1", "2:1", 0.6), ("running", "2:1", "1:1", 0.6), ("stack", "1:2", "4:1", 1.0)]

#: One interpreter's answers: a BLAS probe (it must differ between kernels, or the test proves
#: nothing), the canonical associative field's hash, and each panel's α, status and start.
_RUN = """
import hashlib, json, sys
import numpy as np
import alma
from alma.associative.lp import solve_lp
from alma.geometry.canonical import canonical_scene
from alma.mechanics.canonical import snapped
from alma.mechanics.model import build_model
from alma.settings import Settings

rng = np.random.default_rng(7)
x, y = rng.normal(size=1001), rng.normal(size=1001)
out = {"probe": repr(float(x @ y)), "panels": []}
for bond, panel, block, friction in json.loads(sys.argv[1]):
    scene = alma.paper_panel(bond, panel, block, friction)
    canonical = snapped(build_model(canonical_scene(scene)[0]), Settings().search.canonical_bits)
    field = solve_lp(canonical).multipliers
    result = alma.solve(scene, model="nonassociative")
    out["panels"].append(
        [repr(result.alpha), str(result.status), result.start, hashlib.sha256(field.tobytes()).hexdigest()]
    )
curve = alma.push(alma.load_scene("examples/portal.json"))
out["push"] = [repr(curve.curve[-1].d), repr(curve.curve[-1].alpha), curve.end["reason"]]
print(json.dumps(out))
"""


def _cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    line = next((line for line in text.splitlines() if line.startswith("flags")), "")
    return set(line.partition(":")[2].split())


def _numpy_features(older: tuple[str, ...]) -> str:
    """The ones of ``older`` that NumPy found on this CPU (it refuses to disable others)."""
    found = np._core._multiarray_umath.__cpu_features__  # type: ignore[attr-defined]
    return " ".join(f for f in older if found.get(f))


def _variants() -> list[dict[str, str]]:
    """This machine as it is, and as older CPUs: OpenBLAS kernels this CPU can run."""
    flags = _cpu_flags()
    variants: list[dict[str, str]] = [{}]
    if {"avx2", "fma"} <= flags:
        variants.append(
            {
                "OPENBLAS_CORETYPE": "Haswell",
                "NPY_DISABLE_CPU_FEATURES": _numpy_features(("X86_V4", "AVX512_ICL", "AVX512_SPR")),
            }
        )
    if "sse4_2" in flags:
        variants.append(
            {
                "OPENBLAS_CORETYPE": "Nehalem",
                "NPY_DISABLE_CPU_FEATURES": _numpy_features(("X86_V3", "X86_V4", "AVX512_ICL", "AVX512_SPR")),
            }
        )
    return variants


def _answers(variant: dict[str, str]) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_CORETYPE", "NPY_DISABLE_CPU_FEATURES")}
    env.update({k: v for k, v in variant.items() if v})
    done = subprocess.run(
        [sys.executable, "-c", _RUN, json.dumps(PANELS)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        check=False,
        timeout=600,
    )
    assert done.returncode == 0, f"{variant}: {done.stderr[-2000:]}"
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.slow
@pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"), reason="OpenBLAS's x86 kernels are forced here")
def test_friction_answers_do_not_depend_on_the_blas_kernel() -> None:
    variants = _variants()
    runs = [_answers(v) for v in variants]
    if len({r["probe"] for r in runs}) < 2:
        pytest.skip("OpenBLAS gave one rounding under every kernel tried: nothing to compare")
    first = runs[0]
    for variant, run in zip(variants[1:], runs[1:], strict=True):
        for panel, mine, other in zip(PANELS, first["panels"], run["panels"], strict=True):
            assert other == mine, f"{panel} under {variant}: {other} against {mine}"
        assert run["push"] == first["push"], f"the portal's capacity curve under {variant}"
