"""Benchmark: batch refinement of a 10-minute 100-Hz record on one core (issue 5: ≤ 5 s).

Records: the paper's case (docs/reference_cases.md, μ_k = 0.187, μ_s = 0.6, build-and-hold to 2500
m,
six-section BHA) simulated by the 1500-cell plant in PI mode, noise 0.5 RPM / 200 N·m:
(a) stick-slip at 40 RPM after a normal start (μ_k fit + onset scan),
(b) steady rotation at 100 RPM (μ_k fit only),
(c) a creep start then 40 RPM (μ_k fit + creep fit at ≥ MD/1000 with the grid check).
Times are wall-clock of :func:`drillfric.estimation.batch.refine` after a warm-up call (numba caches
compiled), best of ``--repeat``; the machine may be shared, so the single-run cost of the
500-cell model is printed alongside to compare ratios measured in the same run.

    NUMBA_NUM_THREADS=1 python benchmarks/bench_batch.py [--repeat 2]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from test_batch import estimate, make_case, sample  # noqa: E402

from drillfric import torsional  # noqa: E402


def _time(fn, repeat):
    best = float("inf")
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--duration", type=float, default=600.0)
    args = ap.parse_args(argv)
    cases = {"stick-slip 40 RPM": (0.6, 0.187, "normal", 40.0),
             "steady 100 RPM": (0.6, 0.187, "normal", 100.0),
             "creep start, 40 RPM": (0.6, 0.187, "creep", 40.0)}
    print(f"batch refinement, {args.duration:.0f}-s record at 100 Hz, estimator 500 cells")
    print(f"{'record':<22} {'time_s':>7} {'runs':>5} {'mu_k':>7} {'mu_s':>7} {'bound':>7} flags")
    for name, (mu_s, mu_k, kind, rpm) in cases.items():
        string, fc, rec = make_case(mu_s, mu_k, kind, args.duration, rpm)
        data = sample(rec, 100.0, seed=0)
        estimate(string, fc, *(x[:2000] for x in data))  # warm-up (compilation cache)
        sec, res = _time(lambda: estimate(string, fc, *data), args.repeat)  # noqa: B023

        def show(x):
            return f"{'—':>7}" if x is None else f"{x:7.4f}"
        print(f"{name:<22} {sec:7.2f} {res.runs:5d} {show(res.mu_k)} {show(res.mu_s)} "
              f"{show(res.mu_s_lower_bound)} {','.join(res.flags) or '-'}")
    grid = torsional.make_grid(string, 500)
    plant = torsional.Plant(grid, fc(grid.x_m), 0.6, 0.187, 1.0, 0.1, 2900.0)
    drive = torsional.Drive("speed", data[1], 0.01)
    sec, _ = _time(lambda: torsional.run(plant, drive, args.duration, 100.0), args.repeat)
    steps = args.duration / grid.dt_s
    print(f"one speed-driven run of {args.duration:.0f} s, {grid.n_cells} cells: {sec:.3f} s "
          f"({1e9 * sec / (steps * grid.n_cells):.2f} ns per cell-step)")


if __name__ == "__main__":
    main()
