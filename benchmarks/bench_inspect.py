"""``drillfric inspect`` on the real logs (issue 35 items 5 and 7: inspect makes run's checks).

The small file of bench_fixed_cost.py (a 60-s 10 Hz stand, the ≤ 1 s target of issue 17)
and each log of ../shared/data/real (absent ones are left out) are inspected in fresh
processes, the real logs as the tests invoke them: DSATS with examples/dsats_1hz.toml,
Volve F-4 alone (run refuses it over max_gap_s) and with its trajectory, tubular and
max_gap_s = 60 beside it (copied into a temporary folder), F-9 A alone, USROP F-5 with
examples/usrop_f5.toml and its survey. The wall time and the CPU time (user + system) of
each process are printed, median and minimum of ``--runs``. With ``--before TREE`` (a
checkout of other code, e.g. ``git archive`` of an earlier commit with ``drillfric/cli``
and ``drillfric/templates`` linked to its ``cli`` and ``templates``) the same commands run
with ``PYTHONPATH=TREE`` too, alternated with this code's, and both are printed.

    python benchmarks/bench_inspect.py [--runs 7] [--before TREE]

The machine is shared and noisy: the CPU times move less with the load than the wall
times; the load average is printed.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_fixed_cost import simulate_well

REPO = Path(__file__).resolve().parents[1]
REAL = REPO.parent / "shared" / "data" / "real"
#: The CLI's entry point in a fresh interpreter (PYTHONPATH decides which code it is).
MAIN = "import sys; from drillfric.cli.main import main; sys.argv[0] = 'drillfric'; main()"


def logs(folder: Path) -> dict[str, list[str]]:
    """The inspect arguments of each real log present (F-4's sidecars copied to ``folder``)."""
    witsml = REAL / "volve_witsml"
    cases = {
        "60-s 10 Hz file": [simulate_well(folder, "one_min", 60.0, 10.0)],
        "DSATS 1 Hz": [REAL / "dsats_1hz/SampleData1.csv", "--config",
                       REPO / "examples/dsats_1hz.toml"],
        "F-4 alone": [witsml / "F-4_time_log_1.xml"],
        "F-4 with sidecars": [folder / "F-4.xml"],
        "F-9 A": [witsml / "F-9_time_log_1.xml"],
        "USROP F-5 (depth)": [REAL / "volve_usrop_f5/USROP_F-5_depth.csv", "--config",
                              REPO / "examples/usrop_f5.toml", "--survey",
                              REAL / "volve_surveys/F-5_ACTUAL.txt"],
    }
    if witsml.is_dir():
        for source, name in (("F-4_time_log_1.xml", "F-4.xml"),
                             ("F-4_trajectory.xml", "F-4.survey.xml"),
                             ("F-4_tubular_run3.xml", "F-4.tubular.xml")):
            shutil.copyfile(witsml / source, folder / name)
        (folder / "F-4.toml").write_text("[segmentation]\nmax_gap_s = 60.0\n")
    return {name: [str(a) for a in args] for name, args in cases.items()
            if Path(args[0]).exists()}


def timed(args: list[str], env: dict) -> tuple[float, float]:
    """Wall and CPU seconds of one fresh ``drillfric inspect ARGS``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", MAIN, "inspect", *args], env=env,
                          capture_output=True, text=True, timeout=600)
    wall = time.perf_counter() - t0
    if done.returncode not in (0, 2) or "internal error" in done.stderr:  # 2: run refuses
        raise RuntimeError(f"inspect {' '.join(args)} failed: {done.stderr.strip()}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--before", type=Path, help="source tree of the code to compare")
    args = parser.parse_args()
    codes = {"this code": dict(os.environ)}
    if args.before:
        codes = {"before": dict(os.environ, PYTHONPATH=str(args.before)), **codes}
    print(f"cores: {os.cpu_count()}, load average at start: {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as tmp:
        cases = logs(Path(tmp))
        times = {(name, code): [] for name in cases for code in codes}
        for name, inspect_args in cases.items():
            timed(inspect_args, codes["this code"])  # caches and disk warm, unmeasured
            for _ in range(args.runs):
                for code, env in codes.items():
                    times[name, code].append(timed(inspect_args, env))
    for (name, code), runs in times.items():
        wall, cpu = ([run[i] for run in runs] for i in (0, 1))
        print(f"{name:<20} {code:<10} wall median {statistics.median(wall):5.2f} s "
              f"(min {min(wall):.2f}), CPU median {statistics.median(cpu):5.2f} s "
              f"(min {min(cpu):.2f})")
    print(f"load average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
