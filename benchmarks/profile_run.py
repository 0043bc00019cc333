"""Where a `drillfric run` spends its time (issue 32): CPU and wall per named step.

Runs ``drillfric run WELL ...`` in this process with the run's steps wrapped by a timer
that keeps a stack, so each step's time excludes the steps it calls (the table adds up to the
whole run). It runs with one numba thread (``NUMBA_NUM_THREADS=1``, set before numba is
imported), so no two steps overlap and each step's CPU is its own work; the wall time of a
run on both cores is measured by ``farm-bench`` or :mod:`benchmarks.bench_compare`. CPU is
the process's (``resource.getrusage``); wall a monotonic clock. Prints a Markdown table
for docs/performance.md.

Usage: ``python benchmarks/profile_run.py WELL [run options ...]``
(e.g. ``/tmp/drillfric-24h/well24.parquet --out /tmp/p --no-report``).
The first run in a fresh environment compiles the numba kernels: profile a second one.
"""

from __future__ import annotations

import os
import resource
import sys
import time
from importlib import import_module
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
os.environ["NUMBA_NUM_THREADS"] = "1"  # before numba is imported: steps never overlap

#: (module, attribute, step label): the steps of a run, callers and callees alike. A class
#: attribute is written "Class.method".
STEPS = [
    ("drillfric.runner.engine", "Engine.segment_raw", "read, check, classify, accumulate"),
    ("drillfric.runner.estimator", "SegmentEstimator.segment", "segment bookkeeping"),
    ("drillfric.estimation.chain", "build_models", "models: string, T&D, gains"),
    ("drillfric.estimation.chain", "starts_pass", "observer starts pass"),
    ("drillfric.estimation.chain", "batch_fit", "batch fit (μ_k, creep, onset)"),
    ("drillfric.estimation.chain", "decide", "verdict"),
    ("drillfric.estimation.chain", "seeded_pass", "seeded ensemble pass"),
    ("drillfric.estimation.chain", "_assemble", "diagnostics and statistics"),
    ("drillfric.estimation.bit_trace", "check_segment_trace", "kinematic check"),
    ("drillfric.estimation.chain", "_windows", "window-by-window check"),
    ("drillfric.estimation.chain", "fit_evidence", "fitted model over the segment"),
    ("drillfric.estimation.bit_torque", "torque_terms", "torque terms"),
    ("drillfric.runner.estimator", "output_frames", "output rows"),
    ("drillfric.runner.engine", "Engine.close", "close: revisions, checks, pooling"),
    ("drillfric.runner.engine", "finish", "result files"),
    ("drillfric.runner.time_log", "finish_engine", "state saved"),
    ("drillfric.runner.finish", "write_report", "report"),
]


class Timer:
    """Exclusive CPU and wall time per label (a stack of the open steps)."""

    def __init__(self):
        self.cpu: dict[str, float] = {}
        self.wall: dict[str, float] = {}
        self.calls: dict[str, int] = {}
        self.stack: list[list] = []

    @staticmethod
    def now() -> tuple[float, float]:
        usage = resource.getrusage(resource.RUSAGE_SELF)
        return usage.ru_utime + usage.ru_stime, time.perf_counter()

    def wrap(self, func, label: str):
        def timed(*args, **kwargs):
            cpu0, wall0 = self.now()
            self.stack.append([0.0, 0.0])
            try:
                return func(*args, **kwargs)
            finally:
                cpu1, wall1 = self.now()
                inner_cpu, inner_wall = self.stack.pop()
                cpu, wall = cpu1 - cpu0, wall1 - wall0
                self.cpu[label] = self.cpu.get(label, 0.0) + cpu - inner_cpu
                self.wall[label] = self.wall.get(label, 0.0) + wall - inner_wall
                self.calls[label] = self.calls.get(label, 0) + 1
                if self.stack:
                    self.stack[-1][0] += cpu
                    self.stack[-1][1] += wall
        return timed


def install(timer: Timer) -> None:
    """Wrap every step of :data:`STEPS` where its callers look it up."""
    for module_name, attr, label in STEPS:
        module = import_module(module_name)
        owner, name = module, attr
        if "." in attr:
            cls, name = attr.split(".")
            owner = getattr(module, cls)
        setattr(owner, name, timer.wrap(getattr(owner, name), label))


def main() -> None:
    timer = Timer()
    cpu0, wall0 = timer.now()
    install(timer)
    from drillfric.cli.main import main as cli

    try:
        cli(["-q", "run", *sys.argv[1:]])
    except SystemExit as exc:
        if exc.code not in (0, None):
            raise
    cpu1, wall1 = timer.now()
    total_cpu, total_wall = cpu1 - cpu0, wall1 - wall0
    rest_cpu = total_cpu - sum(timer.cpu.values())
    rest_wall = total_wall - sum(timer.wall.values())
    print(f"`drillfric run {' '.join(sys.argv[1:])}`: CPU {total_cpu:.1f} s, wall "
          f"{total_wall:.1f} s, load {os.getloadavg()[0]:.1f}")
    print()
    print("| step | calls | CPU [s] | share of CPU | wall [s] |")
    print("|---|---|---|---|---|")
    rows = sorted(timer.cpu, key=lambda k: -timer.cpu[k])
    for label in rows:
        print(f"| {label} | {timer.calls[label]} | {timer.cpu[label]:.2f} | "
              f"{timer.cpu[label] / total_cpu:.0%} | {timer.wall[label]:.2f} |")
    print(f"| start-up, reading the options, the rest | 1 | {rest_cpu:.2f} | "
          f"{rest_cpu / total_cpu:.0%} | {rest_wall:.2f} |")


if __name__ == "__main__":
    main()
