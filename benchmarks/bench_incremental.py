"""Nightly fleets process only what is new (issue 23): the cost of a fleet re-run after 10 %
of a well's rows arrived, against a full run.

Generates (once, cached in SCRATCH) a 100 Hz well with `drillfric simulate`: STANDS stands
of STAND_S seconds of off-bottom rotation with stick-slip and 100-s connections, bit depth
advancing 30 m per stand. For an appended CSV and for a Parquet file rewritten with more
rows, each in its own fleet folder:

1. the first 90 % of the rows: ``drillfric fleet --no-report`` (not timed);
2. the same again, unchanged (timed: ``unchanged`` — the fleet skips the well);
3. the last 10 % arrive (CSV: appended; Parquet: the file rewritten whole) and the fleet
   runs again (timed: ``grown`` — it continues from OUT/NAME/state);
4. ``--force`` on the grown well (timed: ``full``).

Target: (grown − unchanged) ≤ 15 % of (full − unchanged). Every fleet is a fresh
``python -m drillfric.cli.main`` process with one worker (the kernels come from the cache).
Each fleet's wall time and its CPU time (user + system of the process, which other jobs on
a shared machine disturb far less than the wall time) are reported; ``--repeat N`` takes the
median of N nights.

Run: ``python benchmarks/bench_incremental.py [SCRATCH] [--stands N] [--stand-s S]``
(default /tmp/drillfric-incremental, 24 stands of 300 s: 2.7 h, ~0.97 M rows).
"""

from __future__ import annotations

import argparse
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[1]
CONNECTION_S = 100.0
#: Share of the rows present before the night's new rows.
BEFORE = 0.9


def scenario_text(stands: int, stand_s: float) -> str:
    lines = [f"connection_s = {CONNECTION_S}", "", "[defaults]", f"duration_s = {stand_s}",
             "ramp_s = 10.0", ""]
    for i in range(stands):
        lines += ["[[stand]]", f"bit_depth_m = {1600.0 + 30.0 * i}",
                  f"rpm = {50 + 10 * (i % 3)}", ""]
    return "\n".join(lines)


def generate(scratch: Path, stands: int, stand_s: float) -> Path:
    """The simulated well (Parquet with its sidecars), made once."""
    data = scratch / "sim" / "well.parquet"
    if data.exists():
        return data
    data.parent.mkdir(parents=True, exist_ok=True)
    for name in ("demo.toml", "demo.survey.csv"):
        shutil.copy(REPO / "examples" / "demo" / name, data.parent / name)
    (data.parent / "demo.scenario.toml").write_text(scenario_text(stands, stand_s))
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "drillfric.cli.main", "-q", "simulate",
                    str(data.parent / "demo.toml"), "--out", str(data), "--rate", "100",
                    "--cells", "500"], check=True)
    print(f"generated {data} in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    return data


def fleet(folder: Path, out: Path, *extra: str) -> tuple[float, float]:
    """Wall and CPU (user + system) time of one `drillfric fleet --no-report` process [s]."""
    def cpu() -> float:
        use = resource.getrusage(resource.RUSAGE_CHILDREN)
        return use.ru_utime + use.ru_stime

    t0, c0 = time.perf_counter(), cpu()
    subprocess.run([sys.executable, "-m", "drillfric.cli.main", "-q", "fleet", str(folder),
                    "--out", str(out), "--workers", "1", "--no-report", *extra], check=True,
                   cwd=REPO)
    return time.perf_counter() - t0, cpu() - c0


def well_folder(sim: Path, folder: Path, suffix: str) -> Path:
    """A fleet folder holding the well's sidecars; its data file is written by the caller."""
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    shutil.copy(sim.with_suffix(".survey.csv"), folder / "well.survey.csv")
    toml = sim.with_suffix(".toml").read_text()
    (folder / "well.toml").write_text(toml.replace('data = "well.parquet"',
                                                   f'data = "well{suffix}"'))
    return folder / f"well{suffix}"


def night(frame: pd.DataFrame, scratch: Path, fmt: str) -> dict:
    """The four fleets of the module's list for one format; their (wall, CPU) times [s]."""
    data = well_folder(scratch / "sim" / "well.parquet", scratch / fmt / "wells",
                       ".csv" if fmt == "csv" else ".parquet")
    out = scratch / fmt / "out"
    shutil.rmtree(out, ignore_errors=True)
    cut = int(len(frame) * BEFORE)
    if fmt == "csv":
        frame.iloc[:cut].to_csv(data, index=False)
    else:
        frame.iloc[:cut].to_parquet(data, index=False)
    fleet(data.parent, out)
    times = {"unchanged": fleet(data.parent, out)}
    if fmt == "csv":
        frame.iloc[cut:].to_csv(data, mode="a", header=False, index=False)
    else:
        frame.to_parquet(data, index=False)
    times["grown"] = fleet(data.parent, out)
    resumed = pd.read_json(out / "well" / "summary.json", typ="series")["resumed"]
    times["full"] = fleet(data.parent, out, "--force")
    for k, name in enumerate(("ratio", "cpu_ratio")):
        grown, unchanged, full = (times[t][k] for t in ("grown", "unchanged", "full"))
        times[name] = (grown - unchanged) / (full - unchanged)
    times["resumed_from_row"] = resumed["from_row"]
    return times


def median_night(frame: pd.DataFrame, scratch: Path, fmt: str, repeat: int) -> dict:
    """:func:`night` ``repeat`` times; each time and ratio the median."""
    nights = [night(frame, scratch, fmt) for _ in range(repeat)]
    out = {}
    for key, value in nights[0].items():
        values = [n[key] for n in nights]
        out[key] = tuple(sorted(v[k] for v in values)[len(values) // 2] for k in (0, 1)) \
            if isinstance(value, tuple) else sorted(values)[len(values) // 2]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scratch", nargs="?", default="/tmp/drillfric-incremental")
    parser.add_argument("--stands", type=int, default=24)
    parser.add_argument("--stand-s", type=float, default=300.0)
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    scratch = Path(args.scratch)
    data = generate(scratch, args.stands, args.stand_s)
    frame = pd.read_parquet(data)
    span = float(frame["time_s"].iloc[-1] - frame["time_s"].iloc[0])
    print(f"{len(frame):,} rows, {span / 3600:.2f} h at 100 Hz, {args.stands} stands; "
          f"{BEFORE:.0%} before the night, {1 - BEFORE:.0%} new\n")
    print("| file | unchanged re-run | grown re-run | --force full run | "
          "(grown − unchanged) / (full − unchanged) | target |\n|---|---|---|---|---|---|")
    print("(wall / CPU; median of", args.repeat, "nights)")
    for fmt in ("csv", "parquet"):
        t = median_night(frame, scratch, fmt, args.repeat)
        show = {k: f"{t[k][0]:.1f} s / {t[k][1]:.1f} s" for k in ("unchanged", "grown", "full")}
        print(f"| {fmt} (continued from row {t['resumed_from_row']:,}) | "
              f"{show['unchanged']} | {show['grown']} | {show['full']} | "
              f"{t['ratio']:.1%} / {t['cpu_ratio']:.1%} | ≤ 15 % |", flush=True)


if __name__ == "__main__":
    main()
