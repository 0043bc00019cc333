"""Fleet throughput (issue 8): 20 synthetic wells on 1 vs 2 local workers, scheduling overhead
per well, and the extrapolation to 10 000 well-days per night. Prints the numbers recorded
in docs/performance.md.

    /work/venv/bin/python benchmarks/bench_fleet.py [--wells 20] [--duration 60]

The machine is shared and noisy: compare the ratios measured within one run.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.fleet.discovery import WellSpec
from drillfric.fleet.run import _client, run_many

REPO = Path(__file__).resolve().parents[1]
#: Off-bottom rotating segments per day of rig data: 49 segments in the 50 000 s of the
#: DSATS 1 Hz sample (docs/segmentation.md), i.e. ≈ 85 per day.
SEGMENTS_PER_DAY = 49 / 50_000 * 86_400


def make_wells(folder: Path, count: int, duration_s: float) -> list[WellSpec]:
    """``count`` single-stand wells from ``drillfric simulate`` (demo string, no scenario)."""
    folder.mkdir(parents=True)
    text = (REPO / "examples/demo/demo.toml").read_text(encoding="utf-8")
    keep = [ln for ln in text.splitlines()
            if not ln.startswith(("scenario", "data =", 'name = "demo"'))]
    config = folder / "sim.toml"
    config.write_text("\n".join(keep) + "\n", encoding="utf-8")
    (folder / "demo.survey.csv").write_bytes((REPO / "examples/demo/demo.survey.csv").read_bytes())
    wells = folder / "wells"
    runner = CliRunner()
    for i in range(count):
        mu_k = 0.2 + 0.005 * (i % 40)  # 0.200…0.395: always below μ_s = 0.5, any count
        out = wells / f"w{i:02d}.csv"
        result = runner.invoke(cli, ["-q", "simulate", str(config), "--out", str(out),
                                     "--duration", str(duration_s), "--rate", "10",
                                     "--mu-s", "0.5", "--mu-k", f"{mu_k:.3f}",
                                     "--bit-depth", "1500", "--seed", str(i)])
        assert result.exit_code == 0, result.output
    return [WellSpec(wells / f"w{i:02d}.csv") for i in range(count)]


def timed_fleet(wells, out: Path, workers: int) -> tuple[float, float]:
    """(wall [s], sum of task bodies [s]) of one forced fleet run."""
    t0 = time.perf_counter()
    result = run_many(wells, out, workers=workers, force=True)
    wall = time.perf_counter() - t0
    assert all(w.status == "ok" for w in result.wells), [w.message for w in result.wells]
    return wall, sum(w.task_s for w in result.wells)


def trivial_overhead(folder: Path, count: int, workers: int) -> tuple[float, float]:
    """(cluster start-up [s], overhead per well [s]) with wells that fail at once."""
    folder.mkdir()
    for i in range(count):
        (folder / f"t{i:03d}.csv").write_text("garbage\n")
    specs = [WellSpec(folder / f"t{i:03d}.csv") for i in range(count)]
    t0 = time.perf_counter()
    with _client(workers, None) as client:
        client.submit(os.getpid).result()
    startup = time.perf_counter() - t0
    t0 = time.perf_counter()
    result = run_many(specs, folder.parent / "trivial-out", workers=workers, force=True)
    wall = time.perf_counter() - t0
    body = sum(w.task_s for w in result.wells)
    return startup, (wall - startup - body / workers) / count


COLD_START = """
import os, sys, time
from drillfric.fleet.run import _client
t0 = time.perf_counter()
with _client(2, None) as client:
    client.gather([client.submit(os.getpid, pure=False) for _ in range(2)])
    ready = time.perf_counter() - t0
print(ready, time.perf_counter() - t0 - ready)
"""


def cold_start() -> tuple[float, float]:
    """(ready [s], shut-down [s]) of a 2-worker local cluster in a fresh process."""
    out = subprocess.run([sys.executable, "-c", COLD_START], capture_output=True, text=True,
                         check=True, timeout=300)
    ready, down = map(float, out.stdout.split())
    return ready, down


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wells", type=int, default=20)
    parser.add_argument("--duration", type=float, default=60.0, help="seconds per well")
    args = parser.parse_args()
    print(f"cores: {os.cpu_count()}, load average: {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        t0 = time.perf_counter()
        wells = make_wells(root / "src", args.wells, args.duration)
        print(f"simulated {args.wells} wells of {args.duration:.0f} s at 10 Hz "
              f"in {time.perf_counter() - t0:.1f} s")
        run_many(wells[:1], root / "warm", workers=1)  # JIT caches, imports
        wall1, body1 = timed_fleet(wells, root / "w1", 1)
        wall2, body2 = timed_fleet(wells, root / "w2", 2)
        print(f"1 worker : wall {wall1:6.1f} s, task bodies {body1:6.1f} s "
              f"({body1 / args.wells:.2f} s per well)")
        print(f"2 workers: wall {wall2:6.1f} s, task bodies {body2:6.1f} s "
              f"({body2 / args.wells:.2f} s per well)")
        print(f"speed-up 2 vs 1 workers: {wall1 / wall2:.2f}x")
        over = (2 * wall2 - body2) / args.wells
        print(f"2 workers: wall x workers - task bodies = {over:.2f} s per well "
              "(cluster start-up + scheduling + client work, amortised)")
        ready, down = cold_start()
        print(f"local cluster (2 workers), fresh process: ready in {ready:.1f} s, "
              f"shut down in {down:.1f} s")
        startup, per_well = trivial_overhead(root / "trivial", 100, 2)
        print(f"local cluster start-up (2 workers), forkserver warm: {startup:.1f} s; "
              f"scheduling overhead per well (100 trivial wells): {per_well * 1000:.1f} ms")
        per_segment = body1 / args.wells
        day = per_segment * SEGMENTS_PER_DAY
        print(f"per well-day: {SEGMENTS_PER_DAY:.0f} segments x {per_segment:.2f} s "
              f"= {day / 60:.1f} core-minutes")
        for workers in (32, 100, 300):
            hours = 10_000 * day / workers / 3600
            print(f"10 000 well-days on {workers:3d} single-threaded workers: {hours:5.1f} h")


if __name__ == "__main__":
    main()
