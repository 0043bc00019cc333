"""Is the logged torque in the unit it claims? A plausibility check per rotating segment.

Off bottom the soft-string model gives a mean rotating surface torque μ·T_N (docs/theory.md §2,
§5.1, T_N = ∫F_c dx); no physical friction factor puts it 1000 times higher or lower. A
segment whose mean torque lies far outside what friction factors in :data:`PLAUSIBLE_MU`
can give fails with advice on the unit (kN·m read as N·m, ft·lbf, …), rather than being
reported with μ_k = 0.001 (docs/segmentation.md, "Failed segments").
"""

from __future__ import annotations

import numpy as np

from drillfric.errors import DrillfricError
from drillfric.io.channels import factor
from drillfric.units import RPM_TO_RAD_S
from drillfric.vocabulary import Kind

#: Friction factors bounding any physical rotating torque (generous): off bottom the soft
#: string gives a surface torque μ·T_N (docs/theory.md §2, §5.1), so μ ∈ this range bounds it.
PLAUSIBLE_MU = (0.02, 1.5)
#: How far outside the plausible torque range (either way) a segment's mean rotating torque
#: may lie before the segment fails: beyond it the torque channel is almost surely in
#: another unit (kN·m read as N·m is a factor 1000), not a model error.
TORQUE_SCALE_LIMIT = 30.0
#: Bit torque allowed on bottom per newton of WOB [m]: μ_bit·D_bit/3 (Coulomb bit model,
#: :func:`drillfric.torsional.bit_torque_cap`) with μ_bit up to 1.5 and D_bit up to 0.5 m.
BIT_TORQUE_PER_WOB_M = 0.25
#: Bit torque allowed on bottom when no WOB is logged [N·m] (large PDC bits reach ~40 kN·m).
BIT_TORQUE_UNKNOWN_WOB_NM = 50e3
#: Torque unit spellings offered when a channel's scale is implausible.
_TORQUE_UNITS = ("N.m", "kN.m", "ft.lbf", "kft.lbf")


def plausible_torque_range(T_N_Nm: float, kind: str, wob_N: float = 0.0) -> tuple[float, float]:
    """Mean rotating surface torque [N·m] that friction factors in :data:`PLAUSIBLE_MU`
    can give: μ·T_N off bottom (docs/theory.md §5.1), plus an allowance for the bit torque on
    bottom.

    Parameters
    ----------
    T_N_Nm : float
        T_N = ∫F_c dx at the segment's bit depth [N·m].
    kind : str
        Segment kind; "on_bottom_rotating" adds the bit torque allowance.
    wob_N : float
        Median weight on bit [N] (0: not logged, a fixed allowance is used).

    Examples
    --------
    >>> plausible_torque_range(10e3, "off_bottom_rotating")
    (200.0, 15000.0)
    >>> plausible_torque_range(10e3, "on_bottom_rotating", wob_N=100e3)
    (200.0, 40000.0)
    """
    lo, hi = PLAUSIBLE_MU[0] * T_N_Nm, PLAUSIBLE_MU[1] * T_N_Nm
    if kind == Kind.ON_BOTTOM:
        hi += BIT_TORQUE_PER_WOB_M * wob_N if wob_N > 0 else BIT_TORQUE_UNKNOWN_WOB_NM
    return lo, hi


def check_torque_scale(data, T_N_Nm: float, omega_c_rad_s: float, *,
                       torque_channel=None) -> None:
    """Fail a segment whose rotating torque no plausible friction can explain.

    The median surface torque [N·m] while the top drive turns faster than 2ω_c [rad/s] (a
    unit scales every sample, a spike of 1e30 N·m one: the eleventh attack of issue 30 had
    failed a stand on one such sample, blaming the unit) is compared with
    :func:`plausible_torque_range`; more than :data:`TORQUE_SCALE_LIMIT`
    times above its top or below its bottom means the torque channel is in another unit
    (a factor 1000: N·m and kN·m), a wrong column, or a wrong sign.

    Parameters
    ----------
    data : drillfric.estimation.segment_data.SegmentData
    T_N_Nm : float
        T_N = ∫F_c dx at the segment's bit depth [N·m].
    omega_c_rad_s : float
        Static/kinetic switching speed ω_c [rad/s].
    torque_channel : drillfric.io.channels.Mapping, optional
        How the torque was read, to say which unit would fit and where to set it.

    Raises
    ------
    DrillfricError
        Naming the factor, the range and the unit that would fit.
    """
    rotating = np.abs(data.surface_rpm) * RPM_TO_RAD_S > 2.0 * omega_c_rad_s
    if rotating.sum() < 10:
        return
    mean = float(np.median(data.surface_torque_Nm[rotating]))
    lo, hi = plausible_torque_range(T_N_Nm, data.kind, data.wob_N)
    bit = " plus bit torque" if data.kind == Kind.ON_BOTTOM else ""
    where = (f"the torque-and-drag range at {data.bit_depth_m:.0f} m (median {_kNm(mean)} kN·m "
             f"while rotating; range {_kNm(lo)}–{_kNm(hi)} kN·m for μ {PLAUSIBLE_MU[0]}–"
             f"{PLAUSIBLE_MU[1]}{bit})")
    if mean <= 0.0:
        raise DrillfricError(f"surface torque not positive, outside {where}",
                             fix="check the torque column and its sign ([channels] "
                                 "surface_torque)")
    if mean > TORQUE_SCALE_LIMIT * hi:
        problem = f"surface torque {mean / hi:.0f}x the top of {where}"
    elif mean < lo / TORQUE_SCALE_LIMIT:
        problem = f"surface torque 1/{lo / mean:.0f} of the bottom of {where}"
    else:
        return
    raise DrillfricError(f"{problem}: is the torque channel in another unit?",
                         fix=torque_unit_fix(torque_channel, mean > hi))


def _kNm(torque_Nm: float) -> str:
    """A torque [N·m] in kN·m for messages: three significant digits, no exponent.

    Examples
    --------
    >>> _kNm(16234.0), _kNm(1.62e7), _kNm(12.0)
    ('16.2', '16200', '0.012')
    """
    value = torque_Nm / 1e3
    return f"{value:.0f}" if abs(value) >= 1e3 else f"{value:.3g}"


def torque_unit_fix(channel, too_high: bool) -> str:
    """Advice for a torque channel 1000 times off: the common unit that would fit, and
    where to state it (``[channels]``, or the file when the file states the unit).

    Parameters
    ----------
    channel : drillfric.io.channels.Mapping or None
        How the torque was read.
    too_high : bool
        The torque reads too high (the log's unit is 1000 times smaller than assumed).
    """
    generic = ('state the unit of the log: [channels] surface_torque = { unit = "..." } '
               "(N.m, kN.m, ft.lbf, kft.lbf)")
    if channel is None:
        return generic
    target = channel.factor * (1e-3 if too_high else 1e3)
    other = next((u for u in _TORQUE_UNITS
                  if abs(np.log(factor(u, channel.channel) / target)) < 0.01), None)
    read = f"column {channel.column} is read as {channel.unit} ({channel.source})"
    if other is None:
        return f"{read}; {generic}"
    if channel.source in ("default", "config"):
        return (f'{read}; if the log is in {other}, set [channels] surface_torque = '
                f'{{ unit = "{other}" }}')
    return (f"{read}; if the log is in {other}, correct the unit in the file "
            f'(e.g. header "TORQUE [{other}]"): a [channels] unit cannot contradict it')
