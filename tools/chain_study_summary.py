"""Summary of a study with a chain factor: the ANOVA, the share of the variance of α_c each term
explains, and α_c by chain level (the tables of docs/runs/doe-chain-*.md).

    alma doe --out chain_study/ --design examples/design_chain.toml --workers 2
    python tools/chain_study_summary.py chain_study/results.csv
"""

from __future__ import annotations

import sys

from alma.stats.anova import anova
from alma.study.store import read_results


def main(path: str) -> None:
    df = read_results(path)
    df = df[df["model"] == "associative"]
    result = anova(df)
    total = result.row("Total").adj_ss
    print("```\n" + result.format_table() + "\n```\n")
    chain_terms = [r for r in result.terms if "Chain" in r.source.split("*")]
    print("| term | Adj SS | share of the total SS |\n|---|---:|---:|")
    for r in sorted(result.terms, key=lambda r: -r.adj_ss):
        print(f"| {r.source} | {r.adj_ss:.4f} | {100 * r.adj_ss / total:.2f} % |")
    share = sum(r.adj_ss for r in chain_terms) / total
    print(f"\nChain and its interactions: {100 * share:.2f} % of the total sum of squares.\n")
    base = df[df["chain"] == 0].set_index(["panel_ratio", "block_ratio", "bond", "friction"])["alpha_c"]
    print("| chain (kN) | mean α_c | panels above the unchained α (+1e-6) | largest gain |\n|---:|---:|---:|---:|")
    for level, rows in df.groupby("chain"):
        alpha = rows.set_index(["panel_ratio", "block_ratio", "bond", "friction"])["alpha_c"]
        gain = alpha - base.reindex(alpha.index)
        print(f"| {level:g} | {alpha.mean():.4f} | {(gain > 1e-6).sum()} of {len(gain)} | {gain.max():.4f} |")


if __name__ == "__main__":
    main(sys.argv[1])
