"""The non-associative search with cohesion and ties against the same panels without them.

For each paper panel (f = 0.6) the search runs without cohesion, with c kPa on every joint, and
with an anchored top chain of S kN (``alma.with_chain``): α of Eq. 10, Radenkovic's bound, the
lowest verified state of Eq. 9 and its start, the verified candidates, the search's seconds and
LP solves.  Times are noisy on a shared machine; the LP solves are not.

    python -m studies.bench_nonassociative_bounded [--cohesion 5] [--chain 2]
"""

from __future__ import annotations

import argparse
import dataclasses

import alma
from alma.geometry.chains import with_chain

PANELS = (("running", "2:1", "4:1"), ("english", "2:1", "2:1"), ("running", "1:1", "2:1"))


def row(label: str, scene: alma.Scene) -> str:
    both = alma.solve(scene, model="both")
    assert isinstance(both, alma.Comparison)
    nl, lp = both.nonassociative, both.associative
    verified = sum(1 for c in nl.candidates if c["verified"])
    lower = nl.search["radenkovic_lower_bound"]
    starts = ", ".join(
        f"{s['start']}={s['alpha']:.6f}" if s["alpha"] is not None else f"{s['start']}=-" for s in nl.starts
    )
    return (
        f"{label:34s} LP {lp.alpha:.6f}  Radenkovic {lower if lower is None else round(lower, 6)}  "
        f"NL {nl.alpha:.6f} ({nl.status}, {nl.start})  verified {verified}/{len(nl.candidates)}  "
        f"search {nl.timings['nonassociative_s']:.2f} s\n      {starts}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cohesion", type=float, default=5.0, help="kPa")
    parser.add_argument("--chain", type=float, default=2.0, help="kN, anchored chain at 90 %% of the height")
    args = parser.parse_args()
    for bond, panel, block in PANELS:
        scene = alma.paper_panel(bond, panel, block, 0.6)
        name = f"{bond} {panel} {block}"
        print(row(f"{name} plain", scene))
        print(row(f"{name} c = {args.cohesion:g} kPa", dataclasses.replace(scene, cohesion=args.cohesion)))
        top = max(float(v[1]) for b in scene.blocks for v in b.vertices)
        print(row(f"{name} chain {args.chain:g} kN", with_chain(scene, 0.9 * top, args.chain, anchored=True)))


if __name__ == "__main__":
    main()
