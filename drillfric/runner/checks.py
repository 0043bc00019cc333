"""What a time log's run checks before it estimates anything: the first chunk (its rate,
a depth reckoned from the block, the work the configuration implies) and each segment (the
segmentation's verdict, then :func:`~drillfric.estimation.segment_data.check_segment`).

No model is built and the estimation chain is not imported, so ``drillfric inspect`` makes
the very same checks within its start-up budget (:mod:`drillfric.runner.preview`);
:mod:`drillfric.runner.estimator` makes them in a run.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from drillfric.errors import ConfigError, DrillfricError
from drillfric.estimation.segment_data import SegmentData, SkipSegment, check_segment
from drillfric.io.timebase import check_plausible_rate
from drillfric.io.well import Well
from drillfric.segmentation import Segment, above_rotary
from drillfric.vocabulary import Status

from .budget import check_work

#: Bit depth assumed when neither the log, the config nor a survey gives one [m].
DEFAULT_BIT_DEPTH_M = 2500.0


def check_first_chunk(well: Well, chunk: pd.DataFrame) -> None:
    """Checks of the first chunk: the rate, a depth reckoned from the block, and the work
    the configuration implies at the log's first bit depth (:mod:`drillfric.runner.budget`).

    Raises
    ------
    InputError, ConfigError
        An implausible rate; a depth reckoning that cannot tell the slips; a configuration
        beyond the work budget.
    """
    check_plausible_rate(chunk["time_s"].to_numpy(), file=well.files.data)
    check_depth_reckoning(well, chunk)
    depth = chunk["bit_depth_m"].to_numpy(float) if "bit_depth_m" in chunk else np.empty(0)
    depth = depth[np.isfinite(depth)]
    check_work(well.config, float(np.median(depth)) if depth.size else
               bit_depth_default(well, []), file=well.files.config or well.files.data)


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


@dataclass(frozen=True)
class Precheck:
    """What becomes of a segment before its estimation (:func:`precheck`).

    Attributes
    ----------
    status : Status
        OK: it goes to the estimation chain; SKIPPED or FAILED: it does not.
    message : str
        Why not (the segment's message in the results), else the segmentation's note.
    bit_depth_m : float
        The bit depth it is estimated at [m]: the log's, else the fallback
        (:func:`bit_depth_default`).
    data : SegmentData or None
        The estimator's samples (None unless OK).
    """

    status: Status
    message: str
    bit_depth_m: float
    data: SegmentData | None = None


def precheck(well: Well, seg: Segment, rows: pd.DataFrame,
             fallback_depth: Callable[[], float]) -> Precheck:
    """What becomes of segment ``seg`` (its ``rows``, as the segment stream hands them on)
    before its estimation: the segmentation's verdict, then
    :func:`~drillfric.estimation.segment_data.check_segment` on its samples at its bit
    depth — the log's, else ``fallback_depth()`` [m]."""
    depth = seg.bit_depth_m if np.isfinite(seg.bit_depth_m) else fallback_depth()
    if depth <= 0.0:
        return Precheck(Status.SKIPPED, above_rotary(depth), depth)
    if seg.status != Status.OK:
        return Precheck(Status.SKIPPED, seg.message, depth)
    data = segment_data(rows, seg, depth)
    try:
        check_segment(data, well.config, well.survey)
    except SkipSegment as exc:
        return Precheck(Status.SKIPPED, exc.problem, depth)
    except DrillfricError as exc:
        return Precheck(Status.FAILED, exc.message, depth)
    return Precheck(Status.OK, seg.message, depth, data)


def bit_depth_default(well: Well, assumed: list) -> float:
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


def segment_data(rows: pd.DataFrame, seg: Segment, depth: float) -> SegmentData:
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
                       torque_max_Nm=column("surface_torque_max_Nm"), **_axial(seg))


def _axial(seg: Segment) -> dict:
    """A reaming segment's axial speed and when the pipe moves (nothing in place)."""
    if seg.axial_speed_m_s is None:
        return {}
    return {"axial_speed_m_s": float(seg.axial_speed_m_s),
            "axial_span_s": (float(seg.axial_from_s), float(seg.axial_to_s))}
