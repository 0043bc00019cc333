"""Latency and CPU of ``drillfric live`` (issue 24): a 100 Hz well written to a CSV at 1× and
20× real time while ``drillfric live`` follows it.

Lag of a sample = the first wall time at which OUT/live.json's ``last_sample_time_s`` reached
the sample's log time − the wall time at which the writer wrote it. The writer (a thread of
this process) appends the rows of a simulated well as a rig logger would, every TICK_S, the
rows whose log time has come (lines cut at a random byte across writes, as ``drillfric
replay`` does), and records (wall time, last log time written). The poller (this process's
main thread) reads live.json every POLL_S and records (wall time, last_sample_time_s).
``drillfric live`` is a real subprocess (``python -m drillfric.cli.main live``, kernels from
the cache); its CPU is read from /proc/PID/stat (utime + stime) when the writer starts and
when live.json reflects the last row, and given as a share of one core over that wall time
(the process's start-up and the final results excluded).

The well (made once with ``drillfric simulate``, cached in SCRATCH), 100 Hz with CONNECTION_S
s connections: an off-bottom stand, a LONG_S stand drilled on bottom (an open segment that
grows for 15 minutes: what an estimate of the open segment costs grows with it), then STANDS
stands of STAND_S s, every third drilled on bottom, the others rotating off bottom. 1×
replays its first ONE_X_S seconds (into the long stand), 20× all of it.

Target: 1× p95 lag ≤ 1 s with ≤ 30 % of one core; 20× p95 lag ≤ 2 s.

Run: ``python benchmarks/bench_live_lag.py [SCRATCH] [--speeds 1 20] [--one-x-s 480]``
(default /tmp/drillfric-live-lag). The machine is shared: the load average is printed with
each case.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
STANDS, STAND_S, LONG_S, CONNECTION_S = 12, 100.0, 900.0, 40.0
TICK_S, POLL_S = 0.1, 0.05
#: Seconds of log replayed at 1× (the rest of the well is replayed at higher speeds only).
ONE_X_S = 480.0


def scenario_text() -> str:
    """An off-bottom stand, a long stand drilled on bottom (LONG_S), then STANDS stands of
    STAND_S, every third one drilled on bottom, the others rotating off bottom."""
    lines = [f"connection_s = {CONNECTION_S}", "", "[defaults]", f"duration_s = {STAND_S}",
             "ramp_s = 10.0", "", "[[stand]]", "bit_depth_m = 1600.0", "rpm = 50.0", "",
             "[[stand]]", "bit_depth_m = 1630.0", "rpm = 60.0", f"duration_s = {LONG_S}",
             "wob_N = 60e3", "rop_m_h = 20.0", ""]
    for i in range(STANDS):
        lines += ["[[stand]]", f"bit_depth_m = {1660.0 + 30.0 * i}", f"rpm = {40 + 10 * (i % 3)}"]
        if i % 3 == 2:
            lines += ["wob_N = 60e3", "rop_m_h = 20.0"]
        lines.append("")
    return "\n".join(lines)


def generate(scratch: Path) -> Path:
    """The simulated well (CSV with its sidecars), made once."""
    data = scratch / "sim" / "well.csv"
    if data.exists():
        return data
    data.parent.mkdir(parents=True, exist_ok=True)
    for name in ("demo.toml", "demo.survey.csv"):
        shutil.copy(REPO / "examples" / "demo" / name, data.parent / name)
    (data.parent / "well.scenario.toml").write_text(scenario_text())
    subprocess.run([sys.executable, "-m", "drillfric.cli.main", "-q", "simulate",
                    str(data.parent / "demo.toml"), "--scenario",
                    str(data.parent / "well.scenario.toml"), "--out", str(data), "--rate", "100",
                    "--cells", "100", "--seed", "3"], check=True, cwd=REPO,
                   env=os.environ | {"PYTHONPATH": str(REPO)})
    return data


def rows_of(data: Path, span_s: float | None) -> tuple[bytes, list[bytes], np.ndarray]:
    """The header, the data lines and their log times [s] (the first ``span_s`` seconds)."""
    header, *lines = data.read_bytes().splitlines(keepends=True)
    times = np.array([float(line.split(b",", 1)[0]) for line in lines])
    if span_s is not None:
        keep = int(np.searchsorted(times, times[0] + span_s, side="right"))
        lines, times = lines[:keep], times[:keep]
    return header, lines, times


def writer(target: Path, header: bytes, lines: list[bytes], times: np.ndarray, speed: float,
           record: list, seed: int = 0) -> None:
    """Append the lines as their log time comes (× ``speed``), one write every TICK_S cut at
    a random byte of its last line (the rest follows in the next write); ``record`` gets
    (wall time, log time of the last complete line written)."""
    rng = np.random.default_rng(seed)
    text = b"".join(lines)
    ends = np.cumsum([len(line) for line in lines])  # where each line ends [bytes]
    with open(target, "ab") as fh:
        fh.write(header)
        fh.flush()
        t0, pos = time.monotonic(), 0
        while pos < len(text):
            due = int(np.searchsorted(times, times[0] + (time.monotonic() - t0) * speed,
                                      side="right"))
            upto = int(ends[due - 1]) if due else 0
            if due < len(lines) and upto > pos:  # cut inside the last due line
                upto -= int(rng.integers(0, len(lines[due - 1])))
            if upto > pos:
                fh.write(text[pos:upto])
                fh.flush()
                pos = upto
                complete = int(np.searchsorted(ends, pos, side="right"))
                if complete:
                    record.append((time.monotonic(), float(times[complete - 1])))
            time.sleep(TICK_S)


def cpu_s(pid: int) -> float:
    """CPU seconds (user + system) of process ``pid`` so far."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def last_sample(path: Path) -> float | None:
    try:
        return json.loads(path.read_text()).get("last_sample_time_s")
    except (OSError, ValueError):
        return None


def case(data: Path, scratch: Path, speed: float, span_s: float | None) -> dict:
    """One live run against the writer at ``speed``; lags and CPU."""
    header, lines, times = rows_of(data, span_s)
    feed, out = scratch / f"x{speed:g}" / "feed", scratch / f"x{speed:g}" / "out"
    shutil.rmtree(feed.parent, ignore_errors=True)
    feed.mkdir(parents=True)
    shutil.copy(data.with_suffix(".survey.csv"), feed / "well.survey.csv")
    shutil.copy(data.with_suffix(".toml"), feed / "well.toml")
    target = feed / "well.csv"
    live = subprocess.Popen([sys.executable, "-m", "drillfric.cli.main", "live", str(target),
                             "--out", str(out), "--until-idle", "5", "--no-report"],
                            cwd=REPO, env=os.environ | {"PYTHONPATH": str(REPO)},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    status = out / "live.json"
    while not status.is_file():  # started: imports done, kernels loaded
        time.sleep(0.05)
    time.sleep(1.0)
    load0 = os.getloadavg()
    written: list = []
    thread = threading.Thread(target=writer, args=(target, header, lines, times, speed,
                                                   written))
    cpu0, wall0 = cpu_s(live.pid), time.monotonic()
    thread.start()
    seen: list = []
    final = times[-1]
    deadline = wall0 + (times[-1] - times[0]) / speed + 120
    while time.monotonic() < deadline:
        value, now = last_sample(status), time.monotonic()
        if value is not None:
            seen.append((now, value))
            if value >= final:
                break
        time.sleep(POLL_S)
    cpu1, wall1 = cpu_s(live.pid), time.monotonic()
    load1 = os.getloadavg()
    thread.join()
    _, err = live.communicate(timeout=600)
    if live.returncode != 0:
        raise SystemExit(f"live failed ({live.returncode}): {err}")
    gap = json.loads(status.read_text())["max_update_gap_s"]
    return {"speed": speed, "span_s": float(times[-1] - times[0]), "rows": len(lines),
            "lag": lags(written, seen), "cpu_share": (cpu1 - cpu0) / (wall1 - wall0),
            "cpu_s": cpu1 - cpu0, "wall_s": wall1 - wall0, "load": (load0[0], load1[0]),
            "max_update_gap_s": gap}


def lags(written: list, seen: list) -> np.ndarray:
    """Per write: the first poll at which live.json's last sample reached the write's last
    complete line, minus the write's wall time [s] (writes never reflected count as inf)."""
    seen_t = np.array([s[0] for s in seen])
    seen_v = np.maximum.accumulate(np.array([s[1] for s in seen]))
    out = []
    for wall, value in written:
        if value is None:
            continue
        i = int(np.searchsorted(seen_v, value, side="left"))
        out.append(seen_t[i] - wall if i < len(seen_t) else np.inf)
    return np.array(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scratch", nargs="?", default="/tmp/drillfric-live-lag")
    parser.add_argument("--speeds", type=float, nargs="+", default=[1.0, 20.0])
    parser.add_argument("--one-x-s", type=float, default=ONE_X_S)
    args = parser.parse_args()
    scratch = Path(args.scratch)
    data = generate(scratch)
    print("| speed | log replayed | lag p50 | p95 | max | CPU (share of one core) | "
          "longest live.json gap | load average (start → end) |\n|---|---|---|---|---|---|---|---|")
    for speed in args.speeds:
        r = case(data, scratch, speed, args.one_x_s if speed < 2 else None)
        lag = r["lag"]
        print(f"| {speed:g}× | {r['span_s']:.0f} s, {r['rows']:,} rows | "
              f"{np.percentile(lag, 50):.2f} s | {np.percentile(lag, 95):.2f} s | "
              f"{lag.max():.2f} s | {r['cpu_share']:.0%} ({r['cpu_s']:.1f} CPU s in "
              f"{r['wall_s']:.0f} s) | {r['max_update_gap_s']:.2f} s | "
              f"{r['load'][0]:.1f} → {r['load'][1]:.1f} |", flush=True)


if __name__ == "__main__":
    main()
