"""Step 2 of a time log's run for every segment: the estimation chain with what passes from
one segment to the next (the warm start, the fallback bit depth), and the rate the run
resamples to (:mod:`drillfric.runner.engine` calls it as segments close).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from drillfric.errors import DrillfricError
from drillfric.estimation.chain import SkipSegment, estimate_segment
from drillfric.estimation.settings import ChainSettings
from drillfric.io.timebase import nominal_rate_hz
from drillfric.io.well import Well
from drillfric.result import SegmentRecord
from drillfric.segmentation import Segment
from drillfric.vocabulary import Kind, Status

from .checks import bit_depth_default, check_first_chunk, precheck
from .segment_output import motor_fields, output_frames, segment_record

#: Relative margin by which a requested rate may exceed the data's nominal rate (timing
#: jitter) before it counts as upsampling.
RATE_MARGIN = 0.01


def first_chunk(well: Well, chunk: pd.DataFrame, rate_hz, warnings: list) -> float | None:
    """Checks of the first chunk (:func:`~drillfric.runner.checks.check_first_chunk`); the
    rate the estimation resamples to.

    Raises
    ------
    InputError, ConfigError
        An implausible rate; a depth reckoning that cannot tell the slips; a configuration
        beyond the work budget.
    """
    check_first_chunk(well, chunk)
    rate_used, note = effective_rate(rate_hz, chunk["time_s"].to_numpy())
    warnings += [note] * bool(note)
    return rate_used


class SegmentEstimator:
    """Step 2 for every segment of a well, carrying what passes from one to the next (the
    warm start, the fallback bit depth and what was assumed for it)."""

    def __init__(self, well: Well):
        self._well: Well | None = None
        self.well = well
        self.rate_hz: float | None = None
        self.has_truth = False
        self.warm: tuple | None = None
        self.fallback_depth: float | None = None
        self.assumed: list[str] = []

    @property
    def well(self) -> Well:
        """The well estimated (a string-weight calibration replaces it with its string
        rescaled, :class:`drillfric.hookload.StringWeightCalibration`)."""
        return self._well

    @well.setter
    def well(self, well: Well) -> None:
        """Set the well; the chain's settings are derived once per configuration."""
        if self._well is None or well.config is not self._well.config:
            self.settings = ChainSettings.from_config(well.config)
        self._well = well

    def segment(self, seg: Segment, rows: pd.DataFrame) -> tuple[SegmentRecord, dict]:
        """The record and output rows (estimates, profile; none when not estimated) of one
        segment."""
        pre = precheck(self.well, seg, rows, self._fallback_depth)
        depth, data = pre.bit_depth_m, pre.data
        if data is None:
            return segment_record(seg, depth, pre.status, pre.message, rows), {}
        try:
            est = estimate_segment(self.settings, self.well.survey, data, warm=self.warm,
                                   rate_hz=self.rate_hz,
                                   torque_channel=self.well.channels["surface_torque_Nm"])
        except SkipSegment as exc:
            return segment_record(seg, depth, Status.SKIPPED, exc.problem, rows), {}
        except DrillfricError as exc:
            return segment_record(seg, depth, Status.FAILED, exc.message, rows), {}
        if est.converged and seg.kind == Kind.OFF_BOTTOM:
            self.warm = (est.mu_s_seed, est.mu_k)
        record = segment_record(seg, depth, Status.OK, seg.message, rows, est)
        cfg = self.well.config
        frames = output_frames(seg, est, data, rows, self.settings.omega_c_rad_s, cfg)
        return replace(record, **motor_fields(rows, cfg, seg.kind == Kind.ON_BOTTOM,
                                              frames["estimates"], record)), frames

    def state(self) -> dict:
        """What passes to the next segment (plain values)."""
        return {"rate_hz": self.rate_hz, "has_truth": self.has_truth,
                "warm": None if self.warm is None else [float(v) for v in self.warm],
                "fallback_depth": self.fallback_depth, "assumed": list(self.assumed)}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self.rate_hz, self.has_truth = state["rate_hz"], bool(state["has_truth"])
        self.warm = None if state["warm"] is None else tuple(state["warm"])
        self.fallback_depth, self.assumed = state["fallback_depth"], list(state["assumed"])

    def _fallback_depth(self) -> float:
        """The bit depth of segments the log gives none for [m], found (and what was
        assumed for it noted) once."""
        if self.fallback_depth is None:
            self.fallback_depth = bit_depth_default(self.well, self.assumed)
        return self.fallback_depth


def effective_rate(rate_hz: float | None, time_s: np.ndarray) -> tuple[float | None, str | None]:
    """The rate to resample to [Hz] and, when it differs from ``rate_hz``, why.

    A requested rate above the data's nominal rate would only interpolate between logged
    samples (upsampling invents nothing the observer could use, and costs time): the data
    are then estimated at their own rate (None) and a warning says so.

    Parameters
    ----------
    rate_hz : float or None
        Requested rate (``run --rate``) [Hz].
    time_s : ndarray
        Sample times of (the start of) the log [s].

    Examples
    --------
    >>> effective_rate(5.0, np.arange(10.0))[0] is None
    True
    >>> effective_rate(0.5, np.arange(10.0))
    (0.5, None)
    """
    data_rate = nominal_rate_hz(time_s)
    if rate_hz is None or data_rate <= 0 or rate_hz <= data_rate * (1.0 + RATE_MARGIN):
        return rate_hz, None
    return None, (f"requested rate {rate_hz:g} Hz is above the data's logging rate "
                  f"({data_rate:.3g} Hz): estimated at the data's rate, not upsampled")
