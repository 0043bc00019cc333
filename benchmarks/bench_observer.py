"""Observer kernel speed (issue 5): ns per cell-step per start, starts in one pass, twin ratio.

Run: ``python benchmarks/bench_observer.py`` — prints a Markdown table for
docs/performance.md. All ratios are measured in one run (shared, noisy machines: compare
ratios, not absolute times across runs). 500 cells, the A&S drill pipe on a build-and-hold
well, 60 s of 100 Hz stick-slip data from the plant.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from drillfric.estimation.observer import Measurements, ObserverState, observe  # noqa: E402
from tests.synthetic import build_and_hold, noisy, simulate  # noqa: E402
from tests.test_observer import config, make_observer  # noqa: E402


def best_of(fn, repeat: int = 3) -> float:
    """Best wall time of ``repeat`` calls [s]."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    case = simulate(build_and_hold(1500.0, 60.0, 2500.0), 2500.0, 0.6, 0.187, 60.0, 60.0)
    obs = make_observer(case, config(), cells=500)
    w, q = noisy(case.record)
    meas = Measurements.from_samples(case.record.time_s, w, q)
    n_cells = obs.plant.grid.n_cells
    dt = obs.plant.grid.dt_s
    starts3 = [[0.3, 0.2], [0.6, 0.4], [0.9, 0.1]]

    def run(starts, t_end, backend="numba"):
        st = ObserverState.from_starts(obs, starts)
        return lambda: observe(obs, meas, st, t_end_s=t_end, backend=backend)

    run(starts3[:1], 1.0)()  # compile
    t_end = 60.0
    steps = int(t_end / dt)
    one = three = float("inf")
    for _ in range(7):  # interleaved, best of 7: single runs of ~20 ms are noisy
        one = min(one, best_of(run(starts3[:1], t_end), repeat=1))
        three = min(three, best_of(run(starts3, t_end), repeat=1))
    twin_end = 2.0
    twin_steps = int(twin_end / dt)
    twin = best_of(run(starts3[:1], twin_end, "numpy"), repeat=1)
    fast_short = best_of(run(starts3[:1], twin_end))
    ns = lambda seconds, n_steps, n_starts: seconds / (n_steps * n_cells * n_starts) * 1e9  # noqa: E731
    print("| quantity | value | target |\n|---|---|---|")
    print(f"| cells, Δt | {n_cells}, {dt * 1e3:.3f} ms | 500 |")
    print(f"| 1 start, ns per cell-step | {ns(one, steps, 1):.2f} | ≤ 2.5 |")
    print(f"| 3 starts, ns per cell-step per start | {ns(three, steps, 3):.2f} | ≤ 2.5 |")
    print(f"| 3 starts / 1 start (same window) | {three / one:.2f} | < 2.5 |")
    print(f"| NumPy twin / numba (1 start, {twin_end:.0f} s) | {twin / fast_short:.0f}× | ≥ 30× |")
    print(f"| real-time factor, 3 starts | {t_end / three:.0f}× | |")
    del twin_steps


if __name__ == "__main__":
    main()
