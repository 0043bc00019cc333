"""How a rig recorder logs the plant's signals: averaging, lag, dropouts.

The simulator's surface channels are spot values at the model's rate. Real logs are not:
an electronic drilling recorder (EDR) stores each channel as the mean over 1 s or 5 s
(often with the interval's minimum and maximum), sensors lag, and links drop samples. These
functions turn a simulated record into what a recorder would have written, so that the
estimator is validated on data that depart from its own model the way rig data do (the
validation sweeps use them: benchmarks/validate_trust.py, docs/validation.md; `drillfric
simulate` itself records spot values).
"""

from __future__ import annotations

import numpy as np

#: Channels whose interval minimum and maximum an EDR records beside the mean
#: (``surface_torque_min_Nm``, ``surface_torque_max_Nm``, … — the names the readers map).
MINMAX = {"surface_torque_Nm": ("surface_torque_min_Nm", "surface_torque_max_Nm"),
          "surface_rpm": ("surface_rpm_min", "surface_rpm_max"),
          "hookload_N": ("hookload_min_N", "hookload_max_N")}


def block_means(columns: dict[str, np.ndarray], interval_s: float, *,
                minmax: bool = True) -> dict[str, np.ndarray]:
    """EDR-style records: each row the mean of one interval of ``interval_s``.

    Rows are stamped at the end of their interval (a recorder writes an average when the
    interval closes); with ``minmax`` the torque, speed and hook load also get the interval's
    minimum and maximum (:data:`MINMAX`). The truth channels (``bit_rpm``,
    ``string_torque_Nm``) are averaged too, so they stay comparable.

    Examples
    --------
    >>> out = block_means({"time_s": np.arange(10.0), "surface_rpm": np.arange(10.0)}, 5.0)
    >>> out["time_s"].tolist(), out["surface_rpm"].tolist(), out["surface_rpm_max"].tolist()
    ([5.0, 10.0], [2.0, 7.0], [4.0, 9.0])
    """
    t = np.asarray(columns["time_s"], dtype=float)
    dt = float(np.median(np.diff(t))) if t.size > 1 else interval_s
    bins = np.floor((t - t[0]) / interval_s + 1e-9).astype(np.int64)
    whole = bins < int(np.floor((t[-1] - t[0] + dt) / interval_s + 1e-9))
    bins = bins[whole]
    counts = np.bincount(bins)
    keep = counts > 0
    out = {"time_s": t[0] + interval_s * (np.flatnonzero(keep) + 1)}
    for name, values in columns.items():
        if name == "time_s":
            continue
        v = np.asarray(values, dtype=float)[whole]
        out[name] = (np.bincount(bins, weights=v) / np.maximum(counts, 1))[keep]
        if minmax and name in MINMAX:
            low, high = MINMAX[name]
            out[low] = _reduce(np.minimum, v, bins, keep, np.inf)
            out[high] = _reduce(np.maximum, v, bins, keep, -np.inf)
    return out


def _reduce(ufunc, values: np.ndarray, bins: np.ndarray, keep: np.ndarray,
            start: float) -> np.ndarray:
    acc = np.full(keep.size, start)
    ufunc.at(acc, bins, values)
    return acc[keep]


def lagged(time_s: np.ndarray, values: np.ndarray, lag_s: float) -> np.ndarray:
    """A sensor that reports ``lag_s`` late: value(t) = signal(t − lag), held at the start.

    Examples
    --------
    >>> lagged(np.arange(5.0), np.arange(5.0), 2.0).tolist()
    [0.0, 0.0, 0.0, 1.0, 2.0]
    """
    t = np.asarray(time_s, dtype=float)
    return np.interp(t - lag_s, t, np.asarray(values, dtype=float))


def dropouts(columns: dict[str, np.ndarray], per_hour: float, mean_s: float,
             rng: np.random.Generator, names=("surface_rpm", "surface_torque_Nm")
             ) -> dict[str, np.ndarray]:
    """Links that drop out: runs of missing values (NaN) in ``names``, ``per_hour`` of them
    on average (Poisson), each exponentially long with mean ``mean_s``."""
    t = np.asarray(columns["time_s"], dtype=float)
    hours = (t[-1] - t[0]) / 3600.0
    starts = rng.uniform(t[0], t[-1], rng.poisson(per_hour * hours))
    lengths = rng.exponential(mean_s, starts.size)
    gone = np.zeros(t.size, dtype=bool)
    for a, span in zip(starts, lengths, strict=True):
        gone |= (t >= a) & (t < a + span)
    out = dict(columns)
    for name in names:
        if name in out:
            out[name] = np.where(gone, np.nan, out[name])
    return out
