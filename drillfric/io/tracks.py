"""tracks.parquet: the whole surface log decimated for plotting (the report's time tracks).

A rig recorder logs 8.6 million rows a day at 100 Hz; a report draws a few thousand points
per channel. :class:`TrackAccumulator` reduces the log to time bins while the run streams
it, chunk by chunk, in bounded memory: per bin and channel the minimum, the maximum and the
mean (so a single-sample spike — a torque peak at break-over, a hook-load jerk — survives
as the bin's maximum), and the most frequent rig state.

Bins are ``width`` seconds wide, counted from the first sample. When the log's length is
known in advance the width is ``expected_duration_s / target_bins``; otherwise the width
starts at :data:`INITIAL_BIN_S`. Whenever a sample falls beyond ``max_bins`` bins, adjacent
bins are merged in pairs (the width doubles) until it fits, so a log of unknown length
ends with between ``max_bins / 2`` and ``max_bins`` bins (fewer only for a short log) and
the accumulator never holds more than ``max_bins`` bins. Merging is exact for min, max,
sums, counts and state counts, so the result does not depend on how the log was chunked
as long as the final width is the same (docs/reports.md "Time tracks").
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from drillfric.io.timebase import clock_at, origin_of
from drillfric.segmentation import RIG_STATES, UNKNOWN

#: Channels kept in tracks.parquet when the log has them (canonical names, SI units).
TRACK_CHANNELS = ("hookload_N", "surface_torque_Nm", "surface_rpm", "bit_depth_m",
                  "hole_depth_m", "block_position_m", "standpipe_pressure_Pa", "wob_N",
                  "flow_in_m3_s")
#: Documented target size of tracks.parquet [bins]: a 24 h log becomes ~4000 bins of ~22 s.
TARGET_BINS = 4000
#: Bin width when the log's duration is not known in advance [s].
INITIAL_BIN_S = 0.1
#: Narrowest bin a saved state may give [s] (a known duration sets duration / max_bins:
#: 1 ms is a 4-s log's).
MIN_BIN_S = 1e-3
_N_STATES = len(RIG_STATES)


class TrackAccumulator:
    """Reduce a streamed surface log to min/max/mean per time bin and channel.

    Parameters
    ----------
    expected_duration_s : float or None
        Length of the log if known [s] (sets the bin width to ``duration / max_bins``);
        None: unknown, start at :data:`INITIAL_BIN_S` and merge bins as the log grows.
    max_bins : int
        Upper bound on the number of bins held (and written).

    Examples
    --------
    A 1 h log at 10 Hz with one spike, fed in two chunks:

    >>> t = np.arange(0.0, 3600.0, 0.1)
    >>> torque = np.full(t.size, 10e3); torque[12345] = 40e3
    >>> frame = pd.DataFrame({"time_s": t, "surface_torque_Nm": torque})
    >>> acc = TrackAccumulator(max_bins=100)
    >>> acc.feed(frame.iloc[:20000]); acc.feed(frame.iloc[20000:])
    >>> out = acc.result()
    >>> len(out) <= 100, float(out["surface_torque_Nm_max"].max())
    (True, 40000.0)
    """

    def __init__(self, expected_duration_s: float | None = None, *,
                 max_bins: int = TARGET_BINS):
        if max_bins < 2:
            raise ValueError(f"max_bins must be ≥ 2, got {max_bins}")
        self.max_bins = int(max_bins)
        if expected_duration_s is not None and np.isfinite(expected_duration_s) \
                and expected_duration_s > 0:
            self.width_s = float(expected_duration_s) / self.max_bins
            self._expected_s = float(expected_duration_s)
        else:
            self.width_s = INITIAL_BIN_S
            self._expected_s = 0.0
        self.t0_s: float | None = None
        self.origin: pd.Timestamp | None = None
        self.channels: list[str] = []
        self._n = 0  # bins in use
        self._time_sum = np.zeros(0)
        self._time_count = np.zeros(0, dtype=np.int64)
        self._min: dict[str, np.ndarray] = {}
        self._max: dict[str, np.ndarray] = {}
        self._sum: dict[str, np.ndarray] = {}
        self._count: dict[str, np.ndarray] = {}
        self._states = np.zeros((0, _N_STATES), dtype=np.int64)

    @property
    def bins(self) -> int:
        """Number of bins currently held (≤ ``max_bins``)."""
        return self._n

    def feed(self, chunk: pd.DataFrame, states: np.ndarray | None = None) -> None:
        """Add the next rows of the log (in time order).

        Parameters
        ----------
        chunk : pandas.DataFrame
            Canonical columns: ``time_s`` [s] and any of :data:`TRACK_CHANNELS` (SI, NaN
            for nulls); ``timestamp`` (UTC) when the log has clock time.
        states : numpy.ndarray of int8, optional
            Rig state code of every row (:data:`drillfric.segmentation.RIG_STATES`).
        """
        t = chunk["time_s"].to_numpy(float)
        good = np.isfinite(t)
        if not good.any():
            return
        if self.t0_s is None:
            self.t0_s = float(t[good][0])
        self._note_origin(chunk, t)
        for name in TRACK_CHANNELS:
            if name in chunk and name not in self.channels:
                self._add_channel(name)
        since = t[good] - self.t0_s
        k = np.maximum(np.floor(since / self.width_s).astype(np.int64), 0)
        # the sample at exactly the expected duration closes the last bin
        k[(k == self.max_bins) & (since <= self._expected_s)] = self.max_bins - 1
        while k.max() >= self.max_bins:
            self._merge_pairs()
            k //= 2
        self._grow(int(k.max()) + 1)
        order = np.argsort(k, kind="stable")
        k = k[order]
        starts = np.flatnonzero(np.r_[True, k[1:] != k[:-1]])
        idx = k[starts]
        self._time_sum[idx] += np.add.reduceat(t[good][order], starts)
        self._time_count[idx] += np.diff(np.r_[starts, k.size])
        for name in self.channels:
            values = chunk[name].to_numpy(float)[good][order] if name in chunk else \
                np.full(k.size, np.nan)
            self._reduce(name, idx, starts, values)
        code = np.full(k.size, UNKNOWN, dtype=np.int64) if states is None else \
            np.asarray(states, dtype=np.int64)[good][order]
        code = np.where((code >= 0) & (code < _N_STATES), code, UNKNOWN)
        local = k - idx[0]
        counts = np.bincount(local * _N_STATES + code,
                             minlength=(idx[-1] - idx[0] + 1) * _N_STATES)
        self._states[idx[0]:idx[-1] + 1] += counts.reshape(-1, _N_STATES)

    def state(self) -> dict:
        """The bins held (arrays) and how they are laid out (plain values)."""
        return {"max_bins": self.max_bins, "width_s": self.width_s,
                "expected_s": self._expected_s, "t0_s": self.t0_s,
                "origin": None if self.origin is None else self.origin.isoformat(),
                "channels": list(self.channels), "n": self._n,
                "time_sum": self._time_sum, "time_count": self._time_count,
                "states": self._states,
                **{f"{stat}:{name}": getattr(self, f"_{stat}")[name]
                   for stat in ("min", "max", "sum", "count") for name in self.channels}}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state` (read from OUT, so checked: ValueError unless it has
        this accumulator's ``max_bins``, a finite bin width of at least :data:`MIN_BIN_S`
        and no more bins than ``max_bins`` — a tampered width or count asked for gigabytes).
        """
        if int(state["max_bins"]) != self.max_bins or not \
                MIN_BIN_S <= float(state["width_s"]) < np.inf or \
                not 0 <= int(state["n"]) <= self.max_bins:
            raise ValueError("tracks state outside its bounds")
        self.max_bins, self.width_s = int(state["max_bins"]), float(state["width_s"])
        self._expected_s, self.t0_s = float(state["expected_s"]), state["t0_s"]
        self.origin = None if state["origin"] is None else pd.Timestamp(state["origin"])
        self.channels, self._n = list(state["channels"]), int(state["n"])
        self._time_sum = np.asarray(state["time_sum"], float)
        self._time_count = np.asarray(state["time_count"], np.int64)
        self._states = np.asarray(state["states"], np.int64).reshape(-1, _N_STATES)
        for stat in ("min", "max", "sum", "count"):
            setattr(self, f"_{stat}", {name: np.asarray(state[f"{stat}:{name}"])
                                       for name in self.channels})

    def _note_origin(self, chunk: pd.DataFrame, t: np.ndarray) -> None:
        """Clock time of ``time_s = 0`` from the first row with a timestamp."""
        if self.origin is not None or "timestamp" not in chunk:
            return
        stamps = pd.to_datetime(chunk["timestamp"], utc=True)
        have = np.flatnonzero(stamps.notna().to_numpy() & np.isfinite(t))
        if have.size:
            i = have[0]
            self.origin = origin_of(stamps.iloc[i], t[i])

    def _add_channel(self, name: str) -> None:
        self.channels.append(name)
        size = self._time_sum.size
        self._min[name] = np.full(size, np.nan)
        self._max[name] = np.full(size, np.nan)
        self._sum[name] = np.zeros(size)
        self._count[name] = np.zeros(size, dtype=np.int64)

    def _reduce(self, name: str, idx: np.ndarray, starts: np.ndarray,
                values: np.ndarray) -> None:
        finite = np.isfinite(values)
        with np.errstate(invalid="ignore"):
            lo = np.fmin.reduceat(values, starts)
            hi = np.fmax.reduceat(values, starts)
        self._min[name][idx] = np.fmin(self._min[name][idx], lo)
        self._max[name][idx] = np.fmax(self._max[name][idx], hi)
        self._sum[name][idx] += np.add.reduceat(np.where(finite, values, 0.0), starts)
        self._count[name][idx] += np.add.reduceat(finite.astype(np.int64), starts)

    def _grow(self, needed: int) -> None:
        """Make room for ``needed`` bins (arrays grow geometrically, capped at max_bins)."""
        self._n = max(self._n, needed)
        size = self._time_sum.size
        if needed <= size:
            return
        new = min(self.max_bins, max(needed, 2 * size, 64))

        def pad(a: np.ndarray, fill) -> np.ndarray:
            extra = np.full((new - size, *a.shape[1:]), fill, dtype=a.dtype)
            return np.concatenate((a, extra))

        self._time_sum = pad(self._time_sum, 0.0)
        self._time_count = pad(self._time_count, 0)
        self._states = pad(self._states, 0)
        for name in self.channels:
            self._min[name] = pad(self._min[name], np.nan)
            self._max[name] = pad(self._max[name], np.nan)
            self._sum[name] = pad(self._sum[name], 0.0)
            self._count[name] = pad(self._count[name], 0)

    def _merge_pairs(self) -> None:
        """Merge bins 2i and 2i+1 (the bin width doubles); exact for every statistic."""
        self.width_s *= 2.0

        def pairs(a: np.ndarray, fill, ufunc) -> np.ndarray:
            if a.shape[0] % 2:
                a = np.concatenate((a, np.full((1, *a.shape[1:]), fill, dtype=a.dtype)))
            return ufunc(a[0::2], a[1::2])

        self._time_sum = pairs(self._time_sum, 0.0, np.add)
        self._time_count = pairs(self._time_count, 0, np.add)
        self._states = pairs(self._states, 0, np.add)
        for name in self.channels:
            self._min[name] = pairs(self._min[name], np.nan, np.fmin)
            self._max[name] = pairs(self._max[name], np.nan, np.fmax)
            self._sum[name] = pairs(self._sum[name], 0.0, np.add)
            self._count[name] = pairs(self._count[name], 0, np.add)
        self._n = (self._n + 1) // 2

    def result(self) -> pd.DataFrame:
        """The tracks table: one row per bin holding samples, in time order.

        Columns: ``time_s`` (mean time of the bin's samples) [s], ``timestamp`` (UTC, only
        when the log has clock time), ``{channel}_min/_max/_mean`` for every channel seen,
        ``rig_state`` (int8, the most frequent state code in the bin).
        """
        n = self._n
        used = self._time_count[:n] > 0
        out = {"time_s": self._time_sum[:n][used] / self._time_count[:n][used]}
        if self.origin is not None:
            out["timestamp"] = clock_at(self.origin, out["time_s"])
        for name in self.channels:
            count = self._count[name][:n][used]
            with np.errstate(invalid="ignore", divide="ignore"):
                mean = np.where(count > 0, self._sum[name][:n][used] / np.maximum(count, 1),
                                np.nan)
            out[f"{name}_min"] = self._min[name][:n][used]
            out[f"{name}_max"] = self._max[name][:n][used]
            out[f"{name}_mean"] = mean
        out["rig_state"] = np.argmax(self._states[:n][used], axis=1).astype(np.int8)
        return pd.DataFrame(out)


def write_tracks(path, frame: pd.DataFrame) -> None:
    """Write a :meth:`TrackAccumulator.result` table as tracks.parquet (float32 values:
    the figures need no more, and the file stays small)."""
    frame = frame.copy()
    for col in frame.columns:
        if col.endswith(("_min", "_max", "_mean")):
            frame[col] = frame[col].astype(np.float32)
    frame.to_parquet(path, index=False)
