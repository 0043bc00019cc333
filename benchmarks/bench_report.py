"""Report size and build time for a 24 h, 100 Hz well (issue 16): prints the numbers
recorded in docs/performance.md.

The result directory is constructed file by file (tests/synthetic_results.py): the 100 Hz
log (8.6 M rows, fed in 1-hour chunks) reduced to tracks.parquet by the streaming
accumulator, 10 Hz estimates for 24 segments of 30 min × (4 starts + the final pass),
summary.json and segments.parquet. Then report.html is built with the default number of
segment figures and with ``segments="all"``, and report.pdf, best of ``--repeat`` each
(wall time, interleaved: the machine is shared).

    python benchmarks/bench_report.py [--repeat 3] [--keep DIR]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from drillfric.report import write_well_report  # noqa: E402
from tests.synthetic_results import synthetic_result  # noqa: E402


def _timed(result: Path, **kw) -> tuple[float, int]:
    start = time.perf_counter()
    path = write_well_report(result, **kw)
    seconds = time.perf_counter() - start
    target = path.with_name("report.pdf") if kw.get("pdf") else path
    return seconds, target.stat().st_size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--keep", type=Path, help="build the result directory here")
    args = parser.parse_args()
    folder = args.keep or Path(tempfile.mkdtemp(prefix="bench-report-"))
    result = folder / "synthetic-24h"
    start = time.perf_counter()
    if not (result / "summary.json").is_file():
        synthetic_result(result)
    print(f"result directory built in {time.perf_counter() - start:.1f} s: {result}")
    sizes = {p.name: p.stat().st_size for p in result.iterdir() if p.suffix == ".parquet"}
    print("files: " + ", ".join(f"{k} {v / 1e6:.2f} MB" for k, v in sorted(sizes.items())))
    write_well_report(result)  # first call: imports, numba cache, font cache
    cases = {"html, default (10 segments)": {}, "html, all 24 segments": {"segments": "all"},
             "html + pdf, default": {"pdf": True}}
    best = {name: (float("inf"), 0) for name in cases}
    for _ in range(args.repeat):
        for name, kw in cases.items():
            seconds, size = _timed(result, **kw)
            best[name] = (min(best[name][0], seconds), size)
    print(f"load average {os.getloadavg()[0]:.1f} (2 cores)")
    print(f"{'case':32s} {'best wall [s]':>14s} {'size [MB]':>10s}")
    for name, (seconds, size) in best.items():
        print(f"{name:32s} {seconds:14.2f} {size / 1e6:10.2f}")


if __name__ == "__main__":
    main()
