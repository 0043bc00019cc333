"""How far ``drillfric live``'s estimates lag the data on a loaded machine (issue 35, fourth
newcomer): the demo well (examples/demo, 20 Hz, four stick-slipping stands) replayed with
``drillfric replay`` at SPEED into a file that ``drillfric live`` follows, while the caller
runs a CPU hog (``python -c 'while 1: pass' &``); live.json polled every 0.1 s.

Printed: over the polls while the rig rotates, the share in which the estimates' state is
known (an open segment shown, or ``behind_s`` said; before issue 35 a null open segment read
"none"), ``behind_s`` p50/p95/max (log seconds between the newest sample and the rows the
published estimates rest on; before issue 35: the open segment's ``age_s``), when each open
segment first appears and when ``severe_stick_slip`` first appears against the wall time its
data were written (log time / SPEED after the replay's start).

Run: ``python benchmarks/bench_live_behind.py SPEED LOG_S TAG [SCRATCH]`` (LOG_S: replay the
first LOG_S seconds of the demo; default SCRATCH /tmp/drillfric-live-behind).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEMO = REPO / "examples" / "demo"


def main() -> None:
    speed, head_s, tag = float(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
    root = Path(sys.argv[4] if len(sys.argv) > 4 else "/tmp/drillfric-live-behind") / tag
    shutil.rmtree(root, ignore_errors=True)
    root.mkdir(parents=True)
    lines = (DEMO / "demo.csv").read_text().splitlines(keepends=True)
    keep = [lines[0]] + [ln for ln in lines[1:] if float(ln.split(",", 1)[0]) <= head_s]
    (root / "src.csv").write_text("".join(keep))
    shutil.copy(DEMO / "demo.survey.csv", root / "live.survey.csv")
    target, out = root / "live.csv", root / "out"
    cli = [sys.executable, "-m", "drillfric.cli.main"]
    live = subprocess.Popen([*cli, "-q", "live", str(target), "--out", str(out), "--config",
                             str(DEMO / "demo.toml"), "--until-idle", "8", "--no-report"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(3.0)  # live started, kernels loaded
    t0 = time.monotonic()
    replay = subprocess.Popen([*cli, "replay", str(root / "src.csv"), "--to", str(target),
                               "--speed", str(speed)], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    polls = []
    while live.poll() is None:
        try:
            polls.append((time.monotonic() - t0, json.loads((out / "live.json").read_text())))
        except (OSError, ValueError):
            pass
        time.sleep(0.1)
    replay.wait()
    report(polls, speed, head_s, tag)


def report(polls, speed: float, head_s: float, tag: str) -> None:
    behind, firsts, severe = [], {}, None
    for wall, doc in polls:
        if doc.get("last_sample_time_s") is None:
            continue
        opened = doc.get("open_segment")
        lag = doc.get("behind_s", (opened or {}).get("age_s"))
        if (doc.get("rig_state") or "").startswith("rotating") and doc.get("running"):
            behind.append(np.nan if lag is None else lag)
        if opened and opened.get("segment") not in firsts:
            firsts[opened["segment"]] = (wall, opened.get("t_start_s") or 0.0)
        for a in doc.get("alerts", []):
            if a["kind"] == "severe_stick_slip" and severe is None:
                severe = (wall, a.get("time_s") or 0.0, doc["last_sample_time_s"],
                          doc.get("running"))
    b = np.array(behind, float)
    known = np.isfinite(b)
    stats = (f"p50 {np.percentile(b[known], 50):.1f} p95 {np.percentile(b[known], 95):.1f} "
             f"max {b[known].max():.1f}") if known.any() else "never said"
    print(f"{tag}: {speed:g}x, log 0–{head_s:.0f} s, {len(polls)} polls; while rotating the "
          f"estimates' state known in {100 * known.mean():.0f} % of polls; behind (log s) {stats}")
    for seg, (wall, start) in firsts.items():
        print(f"  open segment {seg} first shown {wall - start / speed:.1f} s (wall) after its "
              f"first row was written ({wall * speed - start:.0f} s of log)")
    if severe is None:
        print("  severe_stick_slip never shown while the run went on")
    else:
        wall, time_s, newest, running = severe
        print(f"  severe_stick_slip first {wall - time_s / speed:.1f} s (wall) after the rows "
              f"it rests on (log {time_s:.1f} s) were written; newest sample then "
              f"{newest:.1f} s, running {running}")


if __name__ == "__main__":
    main()
