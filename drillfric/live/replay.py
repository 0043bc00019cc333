"""A recorded well streamed into a file as a rig logger would write it (``drillfric replay``,
docs/live.md): the text in writes cut at random bytes, paced to the log's own rate."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.io.well import open_well


def recorded_frame(path: Path):
    """The well at ``path``, its rows as canonical channels (``time_s``, … SI units) and the
    clock time of ``time_s = 0`` (None when the log has none)."""
    well = open_well(path)
    if well.depth_indexed:
        raise InputError("a depth-indexed log is no time series to replay", file=path,
                         fix="replay a time log")
    tracker = well.time_tracker()
    frames = [well.canonical(raw, tracker) for raw in well.source.chunks()]
    frames.append(tracker.flush())
    frames = [f for f in frames if f is not None and len(f)]
    canonical = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    if len(canonical) < 2:
        raise InputError("fewer than two timed rows", file=path, fix="replay a longer log")
    span_s = float(canonical["time_s"].iloc[-1] - canonical["time_s"].iloc[0])
    if not span_s > 0:
        raise InputError("the log spans no time", file=path, fix="replay a time log")
    return well, canonical, tracker.origin


def recorded_text(path: Path) -> tuple[bytes, float]:
    """The bytes to replay and the time span of the log they hold [s]: a CSV's own bytes,
    any other well file as CSV of its canonical channels (``time_s``, … SI units)."""
    well, canonical, _ = recorded_frame(path)
    span_s = float(canonical["time_s"].iloc[-1] - canonical["time_s"].iloc[0])
    if well.source.format == "csv":
        return Path(well.files.data).read_bytes(), span_s
    return canonical.to_csv(index=False).encode(), span_s


def replay(text: bytes, target: Path, *, rate_bps: float, tick_s: float = 0.1,
           seed: int = 0) -> float:
    """Append ``text`` to ``target`` at ``rate_bps`` bytes per wall second, one write every
    ``tick_s`` cut at a random byte (0.2–1.8 × the tick's share); returns the wall time [s]."""
    rng = np.random.default_rng(seed)
    t0, done = time.monotonic(), 0
    with open(target, "ab") as fh:
        while done < len(text):
            due = (time.monotonic() - t0 + tick_s) * rate_bps
            size = max(1, int(max(due - done, 0) * rng.uniform(0.2, 1.8)))
            fh.write(text[done:done + size])
            fh.flush()
            done += size
            time.sleep(tick_s)
    return time.monotonic() - t0
