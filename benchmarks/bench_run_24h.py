"""`drillfric run` on a synthetic 24 h, 100 Hz well (issue 6): speed and peak memory.

Generates (once, cached in a scratch directory) a 24-stand well with `drillfric simulate`:
stands of 3400 s of off-bottom rotation at 50–70 RPM with stick-slip, 200-s connections,
bit depth advancing 30 m per stand (8.64 million rows of Parquet), then times
`drillfric -q run` in a child process and reads its peak resident memory (ru_maxrss).
Targets: peak memory < 1.5 GB, run ≥ 300× faster than real time with 500 cells, 3 starts.

Run: ``python benchmarks/bench_run_24h.py [SCRATCH_DIR]`` (default /tmp/drillfric-24h).
Generation takes a few minutes (the truth plant runs at 500 cells here to keep it short).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
STANDS = 24
STAND_S = 3400.0
CONNECTION_S = 200.0


def scenario_text() -> str:
    lines = [f"connection_s = {CONNECTION_S}", "", "[defaults]", f"duration_s = {STAND_S}",
             "ramp_s = 10.0", ""]
    for i in range(STANDS):
        lines += ["[[stand]]", f"bit_depth_m = {1600.0 + 30.0 * i}",
              f"rpm = {50 + 10 * (i % 3)}",
                  ""]
    return "\n".join(lines)


def generate(scratch: Path) -> Path:
    data = scratch / "well24.parquet"
    if data.exists():
        return data
    scratch.mkdir(parents=True, exist_ok=True)
    for name in ("demo.toml", "demo.survey.csv"):
        shutil.copy(REPO / "examples" / "demo" / name, scratch / name)
    (scratch / "demo.scenario.toml").write_text(scenario_text())
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "drillfric.cli.main", "-q", "simulate",
                    str(scratch / "demo.toml"), "--out", str(data), "--rate", "100",
                    "--cells", "500"], check=True)
    print(f"generated {data} in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    return data


#: Child process: run the CLI, then report its own CPU time and peak RSS (ru_maxrss of
#: RUSAGE_CHILDREN would include the simulate child that generated the data).
_MEASURED_RUN = """
import resource, sys
from drillfric.cli.main import main
try:
    main(sys.argv[1:])
except SystemExit as exc:
    if exc.code not in (0, None):
        raise
finally:
    u = resource.getrusage(resource.RUSAGE_SELF)
    print(u.ru_utime + u.ru_stime, u.ru_maxrss, file=sys.stderr)
"""


def main() -> None:
    scratch = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("/tmp/drillfric-24h")
    data = generate(scratch)
    out = scratch / "out"
    t0 = time.perf_counter()
    child = subprocess.run([sys.executable, "-c", _MEASURED_RUN, "-q", "run", str(data),
                            "--out", str(out)], check=True, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    cpu, maxrss_kb = (float(v) for v in child.stderr.split()[-2:])
    import pandas as pd

    rows = pd.read_parquet(data, columns=["time_s"])
    span = float(rows["time_s"].iloc[-1] - rows["time_s"].iloc[0])
    print("| quantity | value | target |\n|---|---|---|")
    print(f"| rows | {len(rows):,} | 8.6 M |")
    print(f"| data span | {span / 3600:.2f} h | 24 h |")
    print(f"| wall time of `run` | {wall:.0f} s | |")
    print(f"| CPU time of `run` | {cpu:.0f} s | |")
    print(f"| real-time factor (data span / CPU) | {span / cpu:.0f}× | ≥ 300× |")
    print(f"| peak resident memory of `run` | {maxrss_kb / 1024:.0f} MB | < 1500 MB |")


if __name__ == "__main__":
    main()
