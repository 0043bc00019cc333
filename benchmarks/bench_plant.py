"""Throughput of the torsional plant kernel (docs/theory.md §3.1, §3.2), numba vs its NumPy twin.

Case: A&S 2018 Well B at 2500 m in off-bottom stick-slip (40 RPM, μ_s 0.885, μ_k 0.425),
500 requested cells, one thread, recording at 100 Hz, started from a stick-slip state. Rows:
the step law (the default), the Stribeck law with δ = 1, 2 and 1.5 (v_s = 0.8 rad/s), the
step law with a fixed (cased) part of the friction profile above 1600 m, and the step law
while the pipe reams at 0.3 m/s (the axial variant, docs/theory.md §3.3). All numba rows are
timed interleaved (A B C … A B C …, best of ``--repeats``) so they share the machine's state;
the NumPy twin runs the step law on a shorter window. Times are the thread's CPU time. The
machine may be shared: compare the ratios, and quote the load. Targets (issue 17):
≤ 0.65 ns per cell-step for the step law, ≥ 30× the NumPy twin.

Usage: python benchmarks/bench_plant.py [--cells N] [--seconds S] [--repeats R]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from drillfric import torsional as T  # noqa: E402
from drillfric.sim.well_b import well_b_plant, well_b_string  # noqa: E402
from drillfric.units import RPM_TO_RAD_S as RPM  # noqa: E402


def variants(plant: T.Plant) -> dict[str, T.Plant]:
    """The benchmarked friction variants of ``plant`` (docs/theory.md §3.2)."""
    cased = plant.grid.x_m < 1600.0
    fc = plant.fc_Nm_m
    profile = dataclasses.replace(plant, fc_Nm_m=np.where(cased, 0.0, fc),
                                  fc_fixed_k_Nm_m=np.where(cased, 0.25 * fc, 0.0),
                                  fc_fixed_s_Nm_m=np.where(cased, 0.35 * fc, 0.0))
    reaming = dataclasses.replace(plant, contact_radius_m=T.contact_radius(well_b_string(),
                                                                           plant.grid))
    out = {"step law": plant, "step law + fixed part": profile,
           f"step law, reaming at {REAMING_M_S:g} m/s": reaming}
    for delta in (1.0, 2.0, 1.5):
        out[f"Stribeck δ = {delta:g}"] = dataclasses.replace(
            plant, stribeck_speed_rad_s=0.8, stribeck_exponent=delta)
    return out


#: The reaming row: the pipe moving at this axial speed [m/s] (docs/theory.md §3.3).
REAMING_M_S = 0.3


def timed(plant, drive, seconds, state, backend="numba") -> float:
    """CPU time of this thread for one run of ``seconds`` simulated from ``state`` [s] (the
    run is single-threaded: CPU time is its wall time without the preemption a shared
    machine adds). A plant with a contact radius reams at :data:`REAMING_M_S`."""
    axial = None if plant.contact_radius_m is None else T.Axial(np.array([REAMING_M_S]), 1.0)
    t0 = time.thread_time()
    T.run(plant, drive, seconds, 100.0, state, backend=backend, axial=axial)
    return time.thread_time() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=500)
    parser.add_argument("--seconds", type=float, default=120.0)
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args()
    base = well_b_plant(cells=args.cells)
    drive = T.Drive("pi", np.array([0.0, 40 * RPM]), 10.0)
    _, state = T.run(base, drive, 30.0, 10.0)  # start in stick-slip
    plants = variants(base)
    for plant in plants.values():
        timed(plant, drive, 1.0, state)  # compile / load the cached variant
    best = dict.fromkeys(plants, np.inf)
    for _ in range(args.repeats):
        for name, plant in plants.items():
            best[name] = min(best[name], timed(plant, drive, args.seconds, state))
    slow_s = 2.0
    slow = min(timed(base, drive, slow_s, state, "numpy") for _ in range(3))
    n, dt = base.grid.n_cells, base.grid.dt_s
    ns = lambda wall, seconds: wall / (seconds / dt) / n * 1e9  # noqa: E731
    print(f"cells {n}, dt {dt * 1e3:.3f} ms, {args.seconds / dt:.0f} steps per "
          f"{args.seconds:g} s simulated, best of {args.repeats} interleaved, load "
          f"{os.getloadavg()[0]:.1f}")
    print("| variant | ns per cell-step | real-time factor |\n|---|---|---|")
    for name, wall in best.items():
        print(f"| {name} | {ns(wall, args.seconds):.3f} | {args.seconds / wall:.0f}× |")
    print(f"| NumPy twin, step law ({slow_s:g} s) | {ns(slow, slow_s):.1f} | |")
    print(f"twin / numba (step law): {ns(slow, slow_s) / ns(best['step law'], args.seconds):.0f}×"
          "  (targets: ≤ 0.65 ns per cell-step, ≥ 30×)")


if __name__ == "__main__":
    main()
