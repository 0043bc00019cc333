"""Two (or three) commits of drillfric side by side on one well (issue 32): CPU and wall.

Each REF (a commit, tag or branch; ``WORKTREE`` for this environment's install) is checked
out into a temporary git worktree and installed, without dependencies, into a temporary
venv that borrows this environment's libraries. The runs are interleaved —
A B [C] A B [C] … — after one warm-up each (it compiles the numba kernels into the
worktree's cache), and each run's CPU (user + system of the finished child and its
threads) and wall time are read. Ratios against the first REF are taken pair by pair and
their median printed: pairing keeps a ratio meaningful when the machine's speed drifts.
Quote the load printed with the table.

Usage::

    python benchmarks/bench_compare.py REF [REF2 ...] [--pairs N] [--well FILE]
        [-- RUN OPTIONS]

Default well: the 24 h benchmark well of :mod:`benchmarks.bench_run_24h` cut to its first
3 stands (3 h, 1.07 million rows at 100 Hz), generated once into /tmp/drillfric-24h with the
demo's configuration without its ``[hookload]`` table (keys an older commit may not know).
Default run options: ``--config`` that file, the demo's survey, ``--no-report``.
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

REPO = Path(__file__).resolve().parents[1]
SCRATCH = Path("/tmp/drillfric-24h")
STAND_S = 3600.0


def three_hour_well() -> list[str]:
    """The default well and its run options (generated once)."""
    sys.path.insert(0, str(REPO / "benchmarks"))
    import pandas as pd
    from bench_run_24h import generate

    data = SCRATCH / "well3.parquet"
    if not data.exists():
        full = pd.read_parquet(generate(SCRATCH))
        full[full["time_s"] < 3 * STAND_S - 100.0].to_parquet(data)
    config = SCRATCH / "compare.toml"
    text = (REPO / "examples" / "demo" / "demo.toml").read_text()
    head, _, rest = text.partition("[hookload]")
    config.write_text(head + ("[" + rest.split("\n[", 1)[1] if "\n[" in rest else ""))
    return [str(data), "--config", str(config), "--survey",
            str(REPO / "examples" / "demo" / "demo.survey.csv"), "--no-report"]


def install(ref: str, root: Path) -> Path:
    """A Python with ``ref`` installed (this environment's Python for WORKTREE): a worktree
    of ``ref`` installed without dependencies into a venv under ``root`` that borrows this
    environment's libraries (a ``.pth`` line: a path, no code)."""
    if ref == "WORKTREE":
        return Path(sys.executable)
    folder = root / ref.replace("/", "_")
    subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(folder / "src"),
                    ref], check=True, capture_output=True)
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(folder / "venv")],
                   check=True)
    python = folder / "venv" / "bin" / "python"
    site = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_path("
                           "'purelib'))"], check=True, capture_output=True, text=True)
    ours = next(p for p in sys.path if p.endswith("site-packages"))
    (Path(site.stdout.strip()) / "borrowed.pth").write_text(ours + "\n")
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "-q",
                    "--no-deps", str(folder / "src")], check=True)
    return python


def timed_run(python: Path, args: list[str], out: Path) -> tuple[float, float]:
    """(CPU, wall) [s] of one ``drillfric -q run`` by ``python`` into ``out``."""
    shutil.rmtree(out, ignore_errors=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall = time.perf_counter()
    subprocess.run([str(python), "-m", "drillfric.cli.main", "-q", "run", *args,
                    "--out", str(out)], check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - wall
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall


def main() -> None:
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else None
    argv = argv[:argv.index("--")] if "--" in argv else argv
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("refs", nargs="+")
    parser.add_argument("--pairs", type=int, default=3)
    parser.add_argument("--well", help="data file (default: the 3-h well)")
    opts = parser.parse_args(argv)
    args = ([opts.well] + (extra or [])) if opts.well else (three_hour_well() + (extra or []))
    with tempfile.TemporaryDirectory(prefix="drillfric-compare-") as tmp:
        root = Path(tmp)
        try:
            pythons = [install(ref, root) for ref in opts.refs]
            for i, python in enumerate(pythons):  # warm-up: compile into each cache
                timed_run(python, args, root / f"out{i}")
            runs: list[list[tuple[float, float]]] = [[] for _ in pythons]
            for _ in range(opts.pairs):
                for i, python in enumerate(pythons):
                    runs[i].append(timed_run(python, args, root / f"out{i}"))
        finally:
            for ref in opts.refs:
                if ref != "WORKTREE":
                    subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force",
                                    str(root / ref.replace("/", "_") / "src")],
                                   capture_output=True)
    print(f"{' '.join(args)}: {opts.pairs} interleaved runs each, load "
          f"{os.getloadavg()[0]:.1f}, {os.cpu_count()} cores")
    print()
    print("| ref | CPU [s] median (min–max) | wall [s] median (min–max) | CPU ratio | "
          "wall ratio |")
    print("|---|---|---|---|---|")
    for ref, mine in zip(opts.refs, runs, strict=True):
        cpu = [c for c, _ in mine]
        wall = [w for _, w in mine]
        ratio_cpu = statistics.median(c / b[0] for (c, _), b in zip(mine, runs[0], strict=True))
        ratio_wall = statistics.median(w / b[1] for (_, w), b in zip(mine, runs[0],
                                                                     strict=True))
        print(f"| {ref} | {statistics.median(cpu):.1f} ({min(cpu):.1f}–{max(cpu):.1f}) | "
              f"{statistics.median(wall):.1f} ({min(wall):.1f}–{max(wall):.1f}) | "
              f"×{ratio_cpu:.3f} | ×{ratio_wall:.3f} |")


if __name__ == "__main__":
    main()
