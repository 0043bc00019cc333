"""The creep fit's twist-noise uncertainty against the scatter it predicts (docs/theory.md
§6.3, check 2; docs/batch_refinement.md).

One noise-free creep record of a validate_batch truth (2 cells per metre), logged at RATE
with 0.5 RPM / 200 N·m of noise under N seeds: the spread of the fitted μ_s (claimed or
withheld) against the median predicted 1-σ (``CreepChecks.twist_noise``, with the
torque-noise term 10 %/sensitivity beside it).

    python benchmarks/validate_twist_noise.py ["paper 2500 m"] [RATE_HZ] [SEEDS]
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_batch import estimate, make_case, sample  # noqa: E402
from validate_batch import TRUTH_CELLS_PER_M, TRUTHS  # noqa: E402

WITHHELD = re.compile(r"μ_s = ([0-9.]+) of the creep fit not reported")


def fitted_mu_s(res) -> float | None:
    """The creep fit's μ_s, claimed or withheld (from its message)."""
    if res.mu_s is not None:
        return res.mu_s
    for message in res.messages:
        found = WITHHELD.search(message)
        if found:
            return float(found.group(1))
    return None


def main() -> None:
    name = sys.argv[1] if len(sys.argv) > 1 else "paper 2500 m"
    rate = float(sys.argv[2]) if len(sys.argv) > 2 else 5.0
    seeds = int(sys.argv[3]) if len(sys.argv) > 3 else 12
    mu_s, mu_k, md, kop, hold, _, rpm, _ = TRUTHS[name]
    string, fc, rec = make_case(mu_s, mu_k, "creep", 120.0, rpm, md_m=md,
                                cells=int(TRUTH_CELLS_PER_M * md), kop_m=kop, hold_deg=hold)
    errors, twist, torque = [], [], []
    for seed in range(seeds):
        res = estimate(string, fc, *sample(rec, rate, seed=seed))
        mu, checks = fitted_mu_s(res), res.details.creep_checks
        if mu is None or checks is None:
            continue
        errors.append(mu / mu_s - 1.0)
        twist.append(checks.twist_noise)
        torque.append(0.1 / checks.sensitivity)
        print(f"seed {seed:2d}: μ_s {mu:.3f} ({100 * errors[-1]:+.1f} %), claimed "
              f"{res.mu_s_identifiable}, twist ±{100 * twist[-1]:.1f} %, torque "
              f"±{100 * torque[-1]:.1f} %", flush=True)
    e = np.array(errors)
    print(f"{name}, {rate:g} Hz, {e.size} fits: mean {100 * e.mean():+.1f} %, sd "
          f"{100 * e.std(ddof=1):.1f} % (range {100 * e.min():+.1f} … {100 * e.max():+.1f} %); "
          f"predicted 1-σ: twist {100 * np.median(twist):.1f} %, torque "
          f"{100 * np.median(torque):.1f} %")


if __name__ == "__main__":
    main()
