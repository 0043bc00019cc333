"""Throughput of the torsional plant kernel (THEORY.md §3.1), numba vs its NumPy twin.

Case: A&S 2018 Well B at 2500 m in off-bottom stick-slip (40 RPM, μ_s 0.885, μ_k 0.425),
500 cells, one core, recording at 100 Hz. Both backends run the same plant side by side in
this process; the machine may be shared, so compare the ratio (best of several repeats)
rather than absolute times across runs. Targets (issue 4): ≤ 1.5 ns per cell-step and
≥ 30× faster than the NumPy twin.

Usage: python benchmarks/bench_plant.py [--cells N] [--seconds S] [--repeats R]
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from drillfric import torsional as T  # noqa: E402
from drillfric.simulator import well_b_plant  # noqa: E402
from drillfric.units import RPM_TO_RAD_S as RPM  # noqa: E402


def best_time(plant, drive, seconds, backend, repeats, state):
    """Best wall time of ``repeats`` runs of ``seconds`` simulated from ``state``."""
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        T.run(plant, drive, seconds, 100.0, state, backend=backend)
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=500)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    plant = well_b_plant(cells=args.cells)
    drive = T.Drive("pi", np.array([0.0, 40 * RPM]), 10.0)
    _, state = T.run(plant, drive, 30.0, 10.0)  # compile, and start in stick-slip
    n = plant.grid.n_cells
    fast = best_time(plant, drive, args.seconds, "numba", args.repeats, state)
    slow_s = max(1.0, args.seconds / 30.0)
    slow = best_time(plant, drive, slow_s, "numpy", max(1, args.repeats // 2), state)
    ns_fast = fast / (args.seconds / plant.grid.dt_s) / n * 1e9
    ns_slow = slow / (slow_s / plant.grid.dt_s) / n * 1e9
    print(f"cells {n}, dt {plant.grid.dt_s * 1e3:.3f} ms, "
          f"{args.seconds / plant.grid.dt_s:.0f} steps per {args.seconds:g} s simulated")
    print(f"numba : {ns_fast:8.3f} ns per cell-step  ({fast:.3f} s for {args.seconds:g} s, "
          f"{args.seconds / fast:.0f}x real time)")
    print(f"numpy : {ns_slow:8.3f} ns per cell-step  ({slow:.3f} s for {slow_s:g} s)")
    print(f"ratio : {ns_slow / ns_fast:8.1f}x  (targets: <= 1.5 ns, >= 30x)")


if __name__ == "__main__":
    main()
