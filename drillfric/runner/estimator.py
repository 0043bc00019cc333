"""Step 2 of a time log's run for every segment: the estimation chain with what passes from
one segment to the next (the warm start, the fallback bit depth), and the rate the run
resamples to (:mod:`drillfric.runner.engine` calls it as segments close).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from drillfric.errors import ConfigError, DrillfricError
from drillfric.estimation.chain import SegmentData, SkipSegment, check_segment, estimate_segment
from drillfric.estimation.settings import ChainSettings
from drillfric.io.timebase import check_plausible_rate, nominal_rate_hz
from drillfric.io.well import Well
from drillfric.result import SegmentRecord
from drillfric.segmentation import Segment
from drillfric.vocabulary import Kind, Status

from .budget import check_work
from .segment_output import output_frames, segment_record

#: Bit depth assumed when neither the log, the config nor a survey gives one [m].
DEFAULT_BIT_DEPTH_M = 2500.0
#: Relative margin by which a requested rate may exceed the data's nominal rate (timing
#: jitter) before it counts as upsampling.
RATE_MARGIN = 0.01


def first_chunk(well: Well, chunk: pd.DataFrame, rate_hz, warnings: list) -> float | None:
    """Checks of the first chunk (the rate; the work the configuration implies at the
    log's first bit depth, :mod:`drillfric.runner.budget`); the rate the estimation
    resamples to.

    Raises
    ------
    InputError, ConfigError
        An implausible rate; a configuration beyond the work budget.
    """
    check_plausible_rate(chunk["time_s"].to_numpy(), file=well.files.data)
    check_depth_reckoning(well, chunk)
    depth = chunk["bit_depth_m"].to_numpy(float) if "bit_depth_m" in chunk else np.empty(0)
    depth = depth[np.isfinite(depth)]
    check_work(well.config, float(np.median(depth)) if depth.size else
               _bit_depth_default(well, []), file=well.files.config or well.files.data)
    rate_used, note = effective_rate(rate_hz, chunk["time_s"].to_numpy())
    warnings += [note] * bool(note)
    return rate_used


def check_depth_reckoning(well: Well, chunk: pd.DataFrame) -> None:
    """Refuse bit depths reckoned from the block position (docs/segmentation.md) that
    cannot tell when the string moves with the block: without
    ``segmentation.slips_hookload_N`` every block movement in the slips (each connection)
    moved the bit too — the DSATS log run so put the bit at 896–926 m where it drilled
    934–1120 m, with nothing said.

    Raises
    ------
    ConfigError
        Depth from block position and a start depth, but no slips threshold.
    """
    seg = well.config.segmentation
    if "bit_depth_m" in chunk or "block_position_m" not in chunk or \
            seg.start_bit_depth_m is None or seg.slips_hookload_N is not None:
        return
    hook = "hookload_N" in chunk
    raise ConfigError(
        "the bit depth is reckoned from the block position (start_bit_depth_m), but nothing "
        "tells when the string is in the slips: every connection's block travel would move "
        "the bit", file=well.files.config or well.files.data,
        fix="set [segmentation] slips_hookload_N to a hook load between the block's weight "
            "and the string's (drillfric inspect shows the hook load)" if hook else
            "log a bit-depth channel, or the hook load with [segmentation] slips_hookload_N")


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
        depth = self._depth(seg)
        if seg.status != Status.OK:
            return segment_record(seg, depth, Status.SKIPPED, seg.message, rows), {}
        data = _segment_data(rows, seg, depth)
        try:
            check_segment(data, self.settings)
            est = estimate_segment(self.settings, self.well.survey, data, warm=self.warm,
                                   rate_hz=self.rate_hz,
                                   torque_channel=self.well.channels["surface_torque_Nm"])
        except SkipSegment as exc:
            return segment_record(seg, depth, Status.SKIPPED, exc.problem, rows), {}
        except DrillfricError as exc:
            return segment_record(seg, depth, Status.FAILED, exc.message, rows), {}
        if est.converged and seg.kind == Kind.OFF_BOTTOM:
            self.warm = (est.mu_s_seed, est.mu_k)
        return (segment_record(seg, depth, Status.OK, seg.message, rows, est),
                output_frames(seg, est, data, rows, self.settings.omega_c_rad_s))

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

    def _depth(self, seg: Segment) -> float:
        if np.isfinite(seg.bit_depth_m):
            return seg.bit_depth_m
        if self.fallback_depth is None:
            self.fallback_depth = _bit_depth_default(self.well, self.assumed)
        return self.fallback_depth


def _bit_depth_default(well: Well, assumed: list) -> float:
    """Bit depth [m] of segments the log gives none for: ``[well] bit_depth_m``, else a
    simulated well's ``[simulate] bit_depth_m``, else (announced in ``assumed``) the
    survey's last station or :data:`DEFAULT_BIT_DEPTH_M`."""
    cfg, survey = well.config, well.survey
    for given in (cfg.well.bit_depth_m, cfg.simulate.bit_depth_m):
        if given is not None:
            return given
    if survey is not None:
        assumed.append(f"bit depth {survey.md_max_m:.0f} m (the survey's last station): the "
                       "log has no bit depth")
        return survey.md_max_m
    assumed.append(f"bit depth {DEFAULT_BIT_DEPTH_M:.0f} m: neither the log nor a survey "
                   "gives one")
    return DEFAULT_BIT_DEPTH_M


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


def _segment_data(rows: pd.DataFrame, seg: Segment, depth: float) -> SegmentData:
    """The estimator's samples: rows with both speed and torque (the few nulls a segment
    may hold are bridged when the measurements are put on a uniform grid)."""
    rows = rows[np.isfinite(rows["surface_rpm"].to_numpy(float))
                & np.isfinite(rows["surface_torque_Nm"].to_numpy(float))]
    wob = float(np.nanmedian(rows["wob_N"])) if "wob_N" in rows and \
        rows["wob_N"].notna().any() else 0.0
    def column(name):
        return rows[name].to_numpy(float) if name in rows else None

    return SegmentData(rows["time_s"].to_numpy(float), rows["surface_rpm"].to_numpy(float),
                       rows["surface_torque_Nm"].to_numpy(float), float(depth), kind=seg.kind,
                       wob_N=max(wob, 0.0), bit_rpm=column("bit_rpm"),
                       torque_min_Nm=column("surface_torque_min_Nm"),
                       torque_max_Nm=column("surface_torque_max_Nm"),
                       **_axial(seg))


def _axial(seg: Segment) -> dict:
    """A reaming segment's axial speed and when the pipe moves (nothing in place)."""
    if seg.axial_speed_m_s is None:
        return {}
    return {"axial_speed_m_s": float(seg.axial_speed_m_s),
            "axial_span_s": (float(seg.axial_from_s), float(seg.axial_to_s))}


