"""Benchmark: broomstick of 100 bit depths × 5 friction factors × 4 load cases, 5000 m well.

Issue 3 part 6 target: < 1 s on one core at 1 m elements. Prints the wall time of the
broomstick (best of several runs, after a warm-up that loads the numba cache), of one
profile, and of the plain-Python oracle march for the same profile (the ratio is the
meaningful number on a shared, noisy machine: both are measured in the same run).

Run: python benchmarks/bench_torque_drag.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from drillfric.config import load_config
from drillfric.drillstring import build_string
from drillfric.torque_drag import broomstick, solve
from drillfric.wellpath import minimum_curvature

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_torque_drag import naive_march  # noqa: E402  (the test oracle)


def well_5000m():
    """Build-and-turn well to 5000 m MD: kick-off 600 m, 3°/30 m to 65°, turn, hold."""
    md = np.array([0.0, 600.0, 1250.0, 1900.0, 2600.0, 5000.0])
    inc = np.radians([0.0, 0.0, 35.0, 65.0, 68.0, 68.0])
    azi = np.radians([0.0, 0.0, 20.0, 40.0, 55.0, 55.0])
    return minimum_curvature(md, inc, azi)


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times), float(np.median(times))


def main() -> None:
    path = well_5000m()
    cfg = load_config()
    depths = np.linspace(300.0, 5000.0, 100)
    frictions = [0.1, 0.2, 0.3, 0.4, 0.5]
    cases = ["rotating_off_bottom", "rotating_on_bottom", "pick_up", "slack_off"]

    def run():
        return broomstick(path, cfg.sections, depths, frictions, cases, wob_N=100e3,
                          bit_torque_Nm=3e3, element_length_m=1.0)

    t0 = time.perf_counter()
    table = run()
    first = time.perf_counter() - t0
    best, median = best_of(run, 5)
    n_el = sum(int(np.ceil(d)) for d in depths)
    print(f"broomstick 100 depths x 5 frictions x 4 cases, 1 m elements, 5000 m well: "
          f"{len(table)} rows, {n_el * 20 / 1e6:.1f} M element steps")
    print(f"  first call (numba cache load/compile): {first:.3f} s")
    print(f"  best of 5: {best:.3f} s   median: {median:.3f} s   (target < 1 s)")

    string = build_string(cfg.sections, 5000.0)
    one = lambda: solve(path, string, friction=0.3, load_case="pick_up",  # noqa: E731
                        element_length_m=1.0)
    t_one, _ = best_of(one, 5)
    res = one()
    md = res.md_m
    mid = 0.5 * (md[1:] + md[:-1])
    n = mid.size
    args = (md, path.tangent(md), string.buoyed_weight_N_m(mid, 1200.0, 1200.0),
            string.along("contact_radius_m", mid), np.full(n, 0.3), np.ones(n), np.zeros(n),
            0.0, 0.0)
    t_naive, _ = best_of(lambda: naive_march(*args), 1)
    print(f"one profile at 5000 m ({n} elements): compiled solve {t_one * 1e3:.2f} ms, "
          f"plain-Python oracle march {t_naive * 1e3:.0f} ms (x{t_naive / t_one:.0f})")


if __name__ == "__main__":
    main()
