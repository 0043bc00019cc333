"""The first run after an install (issue 25, point 8): its cost against a warm run, and the
longest silence a user sees on a terminal.

For a checkout (this one, and optionally a baseline checkout given with ``--baseline DIR``,
e.g. a worktree of an older commit), alternately (A B A B …):

- a **first run**: ``drillfric run`` of the bundled demo (report included) with an empty
  kernel cache (a fresh ``NUMBA_CACHE_DIR``), in a pseudo-terminal;
- a **warm run**: the same command again on that cache.

It prints each pair's wall times, the first/warm ratio and the longest stretch without any
output on the terminal (from the start, between outputs, and to the exit). Targets
(issue 25): first run ≤ 2 × a warm run; never silent for more than 2 s.

    python benchmarks/bench_first_run.py [--pairs 3] [--baseline /path/to/old/checkout]

The machine is shared: compare ratios measured side by side in one run; the load is printed.
"""

from __future__ import annotations

import argparse
import os
import pty
import select
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def on_terminal(command: list[str], cwd: Path, env: dict) -> tuple[float, float]:
    """Run ``command`` with stdout and stderr on a pseudo-terminal; (wall s, longest
    silence s)."""
    master, slave = pty.openpty()
    t0 = time.monotonic()
    proc = subprocess.Popen(command, cwd=cwd, env=env, stdin=subprocess.DEVNULL,
                            stdout=slave, stderr=slave)
    os.close(slave)
    last, longest = t0, 0.0
    while True:
        ready, _, _ = select.select([master], [], [], 0.05)
        now = time.monotonic()
        if ready:
            try:
                data = os.read(master, 65536)
            except OSError:
                data = b""
            if not data:
                break
            longest, last = max(longest, now - last), now
        elif proc.poll() is not None:
            break
    proc.wait()
    end = time.monotonic()
    os.close(master)
    if proc.returncode != 0:
        raise SystemExit(f"{command} failed ({proc.returncode})")
    return end - t0, max(longest, end - last)


def first_and_warm(root: Path, out: Path) -> tuple[tuple[float, float], tuple[float, float]]:
    """(wall, silence) of a first run on an empty kernel cache and of the warm run after it."""
    cache = Path(tempfile.mkdtemp(prefix="nbcache-"))
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env |= {"NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(root), "COLUMNS": "100"}
    command = [sys.executable, "-m", "drillfric.cli.main", "run", "examples/demo/demo.csv",
               "--out", str(out)]
    return on_terminal(command, root, env), on_terminal(command, root, env)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=3)
    parser.add_argument("--baseline", type=Path, help="another checkout to measure beside")
    args = parser.parse_args()
    roots = {"this checkout": REPO}
    if args.baseline:
        roots["baseline"] = args.baseline.resolve()
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    rows: dict[str, list] = {name: [] for name in roots}
    with tempfile.TemporaryDirectory() as out:
        for _ in range(args.pairs):
            for name, root in roots.items():
                rows[name].append(first_and_warm(root, Path(out) / name))
    print("| checkout | first run s | warm run s | first / warm | longest silence, first run s |")
    print("|---|---|---|---|---|")
    for name, pairs in rows.items():
        ratios = [f[0] / w[0] for f, w in pairs]
        print(f"| {name} | {statistics.median(f[0] for f, _ in pairs):.1f} | "
              f"{statistics.median(w[0] for _, w in pairs):.1f} | "
              f"{statistics.median(ratios):.2f} ({min(ratios):.2f}–{max(ratios):.2f}) | "
              f"{max(f[1] for f, _ in pairs):.1f} |")


if __name__ == "__main__":
    main()
