"""The samples of one segment and the checks they pass before the estimation chain.

:func:`check_segment` is what :mod:`drillfric.estimation.chain` needs of a segment before
it builds a model: enough samples, rotation above ω_c, a survey and a string that reach the
bit. No model is solved here and nothing heavy is imported, so ``drillfric inspect`` makes
the same checks as ``run`` within its start-up budget (:mod:`drillfric.runner.preview`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from drillfric.drillstring import build_string
from drillfric.errors import DrillfricError
from drillfric.units import RPM_TO_RAD_S
from drillfric.vocabulary import Kind
from drillfric.wellpath import WellPath

if TYPE_CHECKING:
    from drillfric.config import Config

#: Fewest samples (with speed and torque) a segment is estimated from.
MIN_SAMPLES = 20


class SkipSegment(DrillfricError):
    """The segment holds nothing to estimate (not a failure): kept as "skipped"."""


@dataclass(frozen=True)
class SegmentData:
    """The samples of one segment, in SI (rpm only in the name).

    Attributes
    ----------
    time_s, surface_rpm, surface_torque_Nm : ndarray
    bit_depth_m : float
        Bit depth of the segment [m].
    kind : Kind
        Segment kind (off or on bottom).
    wob_N : float
        Median weight on bit [N] (0 off bottom).
    bit_rpm : ndarray or None
        Downhole truth when the input has it (validation).
    torque_min_Nm, torque_max_Nm : ndarray or None
        The torque's minimum and maximum within each logged interval, when the log has them.
    axial_speed_m_s : float
        Of a reaming (> 0) or back-reaming (< 0) segment, the pipe's steady axial speed
        [m/s] (0: it turns in place; :func:`drillfric.segmentation.axial_motion`).
    axial_span_s : (float, float) or None
        When the pipe moves at that speed [s] (at rest before and after).
    """

    time_s: np.ndarray
    surface_rpm: np.ndarray
    surface_torque_Nm: np.ndarray
    bit_depth_m: float
    kind: Kind = Kind.OFF_BOTTOM
    wob_N: float = 0.0
    bit_rpm: np.ndarray | None = None
    torque_min_Nm: np.ndarray | None = None
    torque_max_Nm: np.ndarray | None = None
    axial_speed_m_s: float = 0.0
    axial_span_s: tuple | None = None


def check_reach(path: WellPath | None, bit_depth_m: float) -> None:
    """Raise DrillfricError when the survey ``path`` ends above the bit at ``bit_depth_m``
    [m] (no survey: the assumed path is drawn to the bit)."""
    if path is not None and bit_depth_m > path.md_max_m + 1e-6:
        raise DrillfricError(f"the survey ends at {path.md_max_m:.1f} m, above the bit at "
                             f"{bit_depth_m:.1f} m", fix="extend the survey to the bit depth")


def check_segment(data: SegmentData, cfg: Config, path: WellPath | None) -> None:
    """The checks of a segment before the chain, in the order the chain would meet them:
    enough samples, a top drive turning faster than ω_c, a survey ``path`` that reaches the
    bit and a configured string that fits above it.

    Raises
    ------
    SkipSegment
        Fewer than :data:`MIN_SAMPLES` samples, or never faster than ω_c: nothing to
        estimate from.
    DrillfricError
        The survey ends above the bit, or the string's sections below the top one are
        longer than the bit depth (:func:`drillfric.drillstring.build_string`).

    Examples
    --------
    >>> from drillfric.config import load_config
    >>> t = np.arange(30.0)
    >>> data = SegmentData(t, np.full(30, 60.0), np.full(30, 5e3), bit_depth_m=100.0)
    >>> check_segment(data, load_config(), None)
    Traceback (most recent call last):
    ...
    drillfric.errors.ModelError: the string below the top section is 230.0 m long but the \
bit is at 100.0 m — fix: no [[string.sections]] was given, so the built-in default string is \
used (5 7/8in DP + 110 m 5in HWDP + 120 m 8in collars); give the well's string as \
[[string.sections]] in the configuration (docs/configuration.md), or check the bit depth
    """
    if data.time_s.size < MIN_SAMPLES:
        raise SkipSegment(f"only {data.time_s.size} samples")
    top = np.nanmax(np.abs(data.surface_rpm))
    if top * RPM_TO_RAD_S <= cfg.omega_c_rad_s:
        raise SkipSegment(f"the top drive never turns faster than ω_c "
                          f"({cfg.omega_c_rad_s / RPM_TO_RAD_S:.3g} RPM): at most {top:.3g} RPM")
    check_reach(path, data.bit_depth_m)
    build_string(cfg.sections, data.bit_depth_m)
