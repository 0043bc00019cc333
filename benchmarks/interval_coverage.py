"""Coverage of every printed ± on the validation sweeps of both plant families (issue 33
item 5): how often each interval holds the truth.

Reads the records the sweeps write with ``--json`` — :mod:`validate_lumped` (the second,
lumped plant family), :mod:`validate_trust` and :mod:`validate_drilling` (drillfric's own
plant family) — and prints, per quantity, family and rate: the cases (a printed value with
its ±), how many intervals hold the truth, the one-sided 95 % Clopper–Pearson lower bound
of the coverage, and the median half-width relative to the value. A withheld value is no
case. The target: ≥ 95 % pooled over rates, ≥ 90 % at each rate, the median half-width no
wider than the quantity's tolerance.

Usage::

    python benchmarks/interval_coverage.py [--lumped FILE] [--trust FILE] [--drilling FILE]
"""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path

import numpy as np
from scipy.stats import beta

#: (family, quantity, rate) → list of (value, half-width, truth).
Cases = dict[tuple[str, str, str], list[tuple[float, float, float]]]


def lower_bound(covered: int, cases: int, confidence: float = 0.95) -> float:
    """One-sided Clopper–Pearson lower bound of a binomial proportion.

    >>> round(lower_bound(60, 60), 3)
    0.951
    """
    if covered == 0:
        return 0.0
    return float(beta.ppf(1.0 - confidence, covered, cases - covered + 1))


def _add(cases: Cases, key, value, half, truth) -> None:
    if value is not None and half is not None and truth is not None:
        cases[key].append((float(value), float(half), float(truth)))


def lumped(records: list[dict], cases: Cases) -> None:
    """The lumped sweep: the headline μ_k and μ_s against the effective truths."""
    for r in records:
        _add(cases, ("lumped", "headline μ_k ±", r["rate"]), r["mu_k"], r.get("mu_k_u"),
             r["mu_k_eff"])
        _add(cases, ("lumped", "μ_s ±", r["rate"]), r.get("mu_s"), r.get("mu_s_u"),
             r["mu_s_eff"])


def trust(records: list[dict], cases: Cases) -> None:
    """The trust sweep (own family): the headline μ_k and μ_s against the zone's truth."""
    for r in records:
        _add(cases, ("own", "headline μ_k ±", r["rate"]), r["mu_k"], r.get("mu_k_u"),
             r["mu_k_truth"])
        _add(cases, ("own", "μ_s ±", r["rate"]), r.get("mu_s"), r.get("mu_s_u"),
             r.get("mu_s_truth"))


def drilling(records: list[dict], truth_mu_k: float, cases: Cases) -> None:
    """The drilling sweep (own family): the headline, the friction log's μ_k and T_bit."""
    for r in records:
        rate = r["rate"]
        _add(cases, ("own", "headline μ_k ±", rate), r["well_mu_k"], r.get("well_u"),
             truth_mu_k)
        for (_, mu), half in zip(r["log"], r.get("log_u") or [], strict=False):
            _add(cases, ("own", "friction-log μ_k ±", rate), mu, half, truth_mu_k)
        for t_bit, half, _, _, _, truth in r["t_bit"]:
            _add(cases, ("own", "T_bit ±", rate), t_bit, half, truth)


def table(cases: Cases) -> list[str]:
    """Markdown rows: per (family, quantity) each rate, then all rates pooled."""
    lines = ["| quantity | family | rate | cases | covered | lower bound (95 %) | median "
             "half-width |", "|---|---|---|---|---|---|---|"]
    pooled: Cases = defaultdict(list)
    for (family, quantity, _rate), rows in cases.items():
        pooled[(family, quantity, "all rates")] += rows
    for key in sorted(cases) + sorted(pooled):
        rows = (cases | pooled)[key]
        family, quantity, rate = key
        hit = sum(abs(v - t) <= h for v, h, t in rows)
        width = float(np.median([h / abs(v) for v, h, _ in rows if v]))
        lines.append(f"| {quantity} | {family} | {rate} | {len(rows)} | {hit} "
                     f"({hit / len(rows):.0%}) | {lower_bound(hit, len(rows)):.3f} | "
                     f"{width:.1%} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lumped", type=Path)
    parser.add_argument("--trust", type=Path)
    parser.add_argument("--drilling", type=Path)
    parser.add_argument("--drilling-mu-k", type=float, default=0.25,
                        help="the drilling sweep's true μ_k (validate_drilling.MU_K)")
    args = parser.parse_args()
    cases: Cases = defaultdict(list)
    if args.lumped:
        lumped(json.loads(args.lumped.read_text())["records"], cases)
    if args.trust:
        trust(json.loads(args.trust.read_text()), cases)
    if args.drilling:
        drilling(json.loads(args.drilling.read_text()), args.drilling_mu_k, cases)
    print("\n".join(table(cases)))


if __name__ == "__main__":
    main()
