"""A well's fixed cost (issue 17): fresh-process commands and a warm fleet worker.

Times, in one run on this machine (median of ``--runs``, min–max beside it):

- ``drillfric --help`` and ``drillfric inspect`` of a small file, fresh processes;
- ``drillfric -q run`` of a 10-minute 100 Hz well in a fresh process, default settings,
  report included (numba caches already on disk, as after the first run of an install);
- a 60-s 10 Hz well run in-process after a warm-up well (what a fleet worker does),
  with and without the well's report;
- where a fresh process spends the 10-minute well's time: importing the run path, the
  run, importing the report stack, the first report and a second one (layouts cached);
- the bundled example under CPU load with OpenBLAS allowed 1 or 2 threads, alternated
  (A B A B): the library pins BLAS to one thread around its linear algebra, so the ratio
  should be ≈ 1.

    python benchmarks/bench_fixed_cost.py [--runs 5] [--skip-blas]

The machine is shared and noisy: read the ratios within one run; the load average is printed.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: The installed console script beside this interpreter (what a user runs).
DRILLFRIC = [str(Path(sys.executable).with_name("drillfric"))]


def simulate_well(folder: Path, name: str, duration_s: float, rate_hz: float) -> Path:
    """One off-bottom stand from the demo string and survey (scenario removed)."""
    text = (REPO / "examples/demo/demo.toml").read_text(encoding="utf-8")
    keep = [ln for ln in text.splitlines()
            if not ln.startswith(("scenario", "data =", 'name = "demo"'))]
    config = folder / f"{name}.toml"
    config.write_text("\n".join(keep) + "\n", encoding="utf-8")
    (folder / "demo.survey.csv").write_bytes(  # the config's [survey] file
        (REPO / "examples/demo/demo.survey.csv").read_bytes())
    out = folder / f"{name}.parquet"
    subprocess.run([*DRILLFRIC, "-q", "simulate", str(config), "--out", str(out),
                    "--duration", str(duration_s), "--rate", str(rate_hz),
                    "--mu-s", "0.5", "--mu-k", "0.25", "--bit-depth", "1500", "--seed", "1"],
                   check=True, capture_output=True, timeout=900)
    return out


def wall_times(command: list[str], runs: int, env: dict | None = None) -> list[float]:
    """Wall seconds of ``runs`` fresh processes (after one unmeasured warm-up)."""
    times = []
    for i in range(runs + 1):
        t0 = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True, timeout=900, env=env)
        if i:
            times.append(time.perf_counter() - t0)
    return times


def warm_worker(data: Path, out: Path, runs: int, report: bool) -> list[float]:
    """Wall seconds of in-process runs of one well after a warm-up (a fleet worker)."""
    import drillfric

    well = drillfric.open_well(data)
    drillfric.run(well, out / "warm-up", report=report)
    times = []
    for i in range(runs):
        t0 = time.perf_counter()
        drillfric.run(drillfric.open_well(data), out / f"r{i}", report=report)
        times.append(time.perf_counter() - t0)
    return times


_PHASES = """
import sys, time
from pathlib import Path
t0 = time.perf_counter()
from drillfric.io.well import open_well
from drillfric.runner import run_well
t1 = time.perf_counter()
result = run_well(open_well(sys.argv[1]), Path(sys.argv[2]))
t2 = time.perf_counter()
from drillfric.report import write_well_report
t3 = time.perf_counter()
write_well_report(result.out_dir)
t4 = time.perf_counter()
write_well_report(result.out_dir)
t5 = time.perf_counter()
print(t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4)
"""
_PHASE_NAMES = ("import run path", "run (no report)", "import drillfric.report",
                "first report", "second report, same process")


def phases(data: Path, out: Path, runs: int) -> list[list[float]]:
    """Seconds of each of :data:`_PHASE_NAMES` in ``runs`` fresh processes."""
    rows = []
    for i in range(runs):
        done = subprocess.run([sys.executable, "-c", _PHASES, str(data), str(out / f"p{i}")],
                              check=True, capture_output=True, text=True, timeout=900)
        rows.append([float(v) for v in done.stdout.split()])
    return [list(col) for col in zip(*rows, strict=True)]


def blas_pairs(out: Path, runs: int) -> list[tuple[float, float]]:
    """(1 thread, 2 threads) wall seconds of the bundled example, alternated, under load."""
    load = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(2)]
    try:
        pairs = []
        for i in range(runs):
            pair = []
            for threads in ("1", "2"):
                env = dict(os.environ, OPENBLAS_NUM_THREADS=threads, OMP_NUM_THREADS=threads)
                command = [*DRILLFRIC, "-q", "run", str(REPO / "examples/demo/demo.csv"),
                           "--out", str(out / f"b{threads}-{i}"), "--no-report"]
                t0 = time.perf_counter()
                subprocess.run(command, check=True, capture_output=True, timeout=900, env=env)
                pair.append(time.perf_counter() - t0)
            pairs.append(tuple(pair))
        return pairs
    finally:
        for process in load:
            process.kill()


def show(label: str, times: list[float], target: str) -> None:
    print(f"{label:<52} median {statistics.median(times):6.2f} s "
          f"({min(times):.2f}–{max(times):.2f})" + (f"   target {target}" if target else ""))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--skip-blas", action="store_true")
    args = parser.parse_args()
    print(f"cores: {os.cpu_count()}, load average at start: {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        long_well = simulate_well(root, "ten_min", 600.0, 100.0)
        short_well = simulate_well(root, "one_min", 60.0, 10.0)
        show("drillfric --help (fresh process)",
             wall_times([*DRILLFRIC, "--help"], args.runs), "≤ 0.3 s")
        show("drillfric inspect, 60-s 10 Hz file (fresh process)",
             wall_times([*DRILLFRIC, "inspect", str(short_well)], args.runs), "≤ 1 s")
        run = wall_times([*DRILLFRIC, "-q", "run", str(long_well), "--out",
                          str(root / "fresh")], args.runs)
        show("run 10 min at 100 Hz, report (fresh process)", run, "≤ 2 s (≥ 300×)")
        print(f"{'':<52} real-time factor {600 / statistics.median(run):.0f}×")
        show("60-s well, warm worker, --no-report",
             warm_worker(short_well, root / "nr", args.runs, report=False), "≤ 0.5 s")
        show("60-s well, warm worker, report",
             warm_worker(short_well, root / "wr", args.runs, report=True), "≤ 1 s")
        print("where the 10-minute well's fresh process spends its time:")
        for name, times in zip(_PHASE_NAMES, phases(long_well, root / "phases", args.runs),
                               strict=True):
            show(f"  {name}", times, "")
        if not args.skip_blas:
            pairs = blas_pairs(root / "blas", max(2, args.runs // 2))
            ratios = [two / one for one, two in pairs]
            print(f"bundled example under 2 busy loops: 1 BLAS thread "
                  f"{statistics.median([p[0] for p in pairs]):.1f} s, 2 threads "
                  f"{statistics.median([p[1] for p in pairs]):.1f} s, ratio 2/1 "
                  f"{statistics.median(ratios):.2f} ({min(ratios):.2f}–{max(ratios):.2f})")
    print(f"load average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
