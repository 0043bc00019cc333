"""Observer kernel speed (issue 17): ns per member per cell-step, serial vs parallel members, twin.

Run: ``python benchmarks/bench_observer.py`` — prints a Markdown table for
docs/performance.md. Case: 500 requested cells, the A&S drill pipe on a build-and-hold well,
60 s of 100 Hz stick-slip data from the plant, Kalman gains. Serial runs (one thread) are
timed by the thread's CPU time, parallel ones (ranges of members on threads, nogil kernel) by
wall time; all configurations are timed interleaved (A B C … A B C …, best of
``--repeats``) in one process, so their ratios share the machine's state — quote the load.
Targets: ≤ 0.8 ns per member per cell-step (serial); ≥ 30× the NumPy twin.

Usage: python benchmarks/bench_observer.py [--repeats R] [--seconds S]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numba  # noqa: E402
import numpy as np  # noqa: E402

from drillfric.estimation.observer import Measurements, ObserverState, observe  # noqa: E402
from tests.synthetic import build_and_hold, noisy, simulate  # noqa: E402
from tests.test_observer import config, make_observer  # noqa: E402

STARTS = [[0.3, 0.2], [0.6, 0.4], [0.9, 0.1], [0.5, 0.3], [0.7, 0.2]]


def profiled(obs):
    """The observer with a cased zone above 1200 m in the fixed part of the profile and the
    Stribeck law (docs/theory.md §3.2): the cost of the general kernel variant."""
    cased = obs.plant.grid.x_m < 1200.0
    fc = obs.plant.fc_Nm_m
    plant = dataclasses.replace(obs.plant, fc_Nm_m=np.where(cased, 0.0, fc),
                                fc_fixed_k_Nm_m=np.where(cased, 0.25 * fc, 0.0),
                                fc_fixed_s_Nm_m=np.where(cased, 0.35 * fc, 0.0),
                                stribeck_speed_rad_s=1.0, stribeck_exponent=2.0)
    return dataclasses.replace(obs, plant=plant)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--seconds", type=float, default=59.0)
    args = parser.parse_args()
    case = simulate(build_and_hold(1500.0, 60.0, 2500.0), 2500.0, 0.6, 0.187, 60.0, 60.0)
    obs = make_observer(case, config(), cells=500)
    w, q = noisy(case.record)
    meas = Measurements.from_samples(case.record.time_s, w, q)
    n_cells, dt = obs.plant.grid.n_cells, obs.plant.grid.dt_s

    def run(observer, members, parallel, t_end, backend="numba"):
        """(wall, CPU time of this thread) of one call [s]."""
        start = ObserverState.from_starts(observer, STARTS[:members])
        wall, cpu = time.perf_counter(), time.thread_time()
        observe(observer, meas, start, t_end_s=t_end, backend=backend, parallel=parallel)
        return time.perf_counter() - wall, time.thread_time() - cpu

    configs = {"1 member": (obs, 1, False), "3 members": (obs, 3, False),
               "5 members": (obs, 5, False), "3 members, parallel": (obs, 3, True),
               "5 members, parallel": (obs, 5, True),
               "3 members, fixed part + Stribeck δ = 2": (profiled(obs), 3, False)}
    for observer, members, parallel in configs.values():
        run(observer, members, parallel, 1.0)  # compile / load the cached variants
    wall = dict.fromkeys(configs, np.inf)
    cpu = dict.fromkeys(configs, np.inf)
    for _ in range(args.repeats):
        for name, cfg in configs.items():
            w_s, c_s = run(*cfg, args.seconds)
            wall[name], cpu[name] = min(wall[name], w_s), min(cpu[name], c_s)
    twin_s = 2.0
    twin = run(obs, 1, False, twin_s, "numpy")[1]
    fast = min(run(obs, 1, False, twin_s)[1] for _ in range(5))
    steps = args.seconds / dt

    def ns(name):
        """Serial: the thread's CPU time; parallel: wall time (members × cells × steps)."""
        seconds = wall[name] if configs[name][2] else cpu[name]
        return seconds / (steps * n_cells * configs[name][1]) * 1e9

    print(f"cells {n_cells}, Δt {dt * 1e3:.3f} ms, {args.seconds:g} s of data, "
          f"best of {args.repeats} interleaved, numba threads {numba.get_num_threads()}, "
          f"load {os.getloadavg()[0]:.1f}")
    print("| configuration | ns per member per cell-step | real-time factor (wall) |")
    print("|---|---|---|")
    for name in configs:
        print(f"| {name} | {ns(name):.3f} | {args.seconds / wall[name]:.0f}× |")
    for members in (3, 5):
        ratio = wall[f"{members} members"] / wall[f"{members} members, parallel"]
        print(f"| serial / parallel wall time, {members} members | {ratio:.2f}× | |")
    print(f"| NumPy twin / numba, 1 member ({twin_s:g} s) | {twin / fast:.0f}× | |")


if __name__ == "__main__":
    main()
