"""What the batch fit reproduces of a segment, and what it does not, in one sentence.

The fit is scored on its mean torque (that is μ_k) and, as ``fit_quality``, on its misfit
relative to the measured torque swing over the whole segment. A segment whose string
stick-slips for ten minutes and then turns steadily can keep a fit model that stick-slips
to the end (a bistable regime, docs/batch_refinement.md): the whole-segment quality looks
normal, yet for half the segment the model shows a 10–30 kN·m swing the data do not.

So the report compares the fitted model's surface torque with the measured one over the
segment's **second half** (estimates.parquet, final pass, every sample): each is called
stick-slipping when the standard deviation of its 1-s smoothed torque exceeds
:data:`~drillfric.estimation.batch.settings.STICK_SLIP_FLUCTUATION` of its mean (the fit's own rule
for the data), and the misfit there is stated as a quality of its own — RMS of the 1-s
smoothed measured − model torque over the measured 5–95 % swing of that half (floored at
:data:`SWING_FLOOR` of the mean torque, so a steady half does not divide by ~0). Where the
regimes differ the report states the worse of the two qualities.

"Reproduces" follows a stated criterion (issue 35: a report said the fit reproduced a
steady rotation its model overshot by 38 %): the same regime, the second half's mean
torque within :data:`MEAN_TOLERANCE` of the measured one and, in stick-slip, the swings
within a factor :data:`SWING_RATIO`. Where one fails the sentence says "does not
reproduce" and names what, with the tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from drillfric.estimation.batch.settings import STICK_SLIP_FLUCTUATION, TORQUE_SMOOTH_S
from drillfric.estimation.creep import smooth

from .display import SI, Units

#: The smallest swing a misfit is measured against, as a share of the mean torque [-]: a
#: steady torque's 5–95 % range is its noise, and a quality over noise says nothing.
SWING_FLOOR = 0.05
#: Fewest samples with both torques in the second half for a verdict.
MIN_SAMPLES = 20
#: Swings (stick-slip in both) further apart than this factor are said to differ.
SWING_RATIO = 2.0
#: Largest |model − measured| mean torque over the second half, as a share of the
#: measured mean, for the fit to be said to reproduce the torque [-].
MEAN_TOLERANCE = 0.10


@dataclass(frozen=True)
class Reproduction:
    """The fitted model against the measured torque over a segment's second half.

    Attributes
    ----------
    t_half_s : float
        Start of the second half [s of log time].
    measured_swing_Nm, model_swing_Nm : float
        5–95 % range of the 1-s smoothed measured and modelled torque there [N·m].
    measured_stick_slip, model_stick_slip : bool
        Whether each stick-slips there (fluctuation above ``STICK_SLIP_FLUCTUATION``).
    mean_error : float
        |model − measured| mean torque over |measured mean| there [-].
    quality : float
        RMS of the 1-s smoothed measured − model torque over the measured swing there
        (floored at :data:`SWING_FLOOR` × the mean) [-].
    """

    t_half_s: float
    measured_swing_Nm: float
    model_swing_Nm: float
    measured_stick_slip: bool
    model_stick_slip: bool
    mean_error: float
    quality: float
    mean_bias: float = 0.0

    @property
    def regime_reproduced(self) -> bool:
        """Whether model and data are in the same regime (both stick-slip or both steady)."""
        return self.measured_stick_slip == self.model_stick_slip

    @property
    def mean_reproduced(self) -> bool:
        """Whether the modelled mean torque is within :data:`MEAN_TOLERANCE` of the data's."""
        return bool(self.mean_error <= MEAN_TOLERANCE)

    @property
    def size_reproduced(self) -> bool:
        """Whether stick-slip swings (both stick-slipping) are within :data:`SWING_RATIO`."""
        if not (self.measured_stick_slip and self.model_stick_slip):
            return True
        ratio = max(self.model_swing_Nm, 1e-9) / max(self.measured_swing_Nm, 1e-9)
        return 1 / SWING_RATIO <= ratio <= SWING_RATIO

    @property
    def reproduced(self) -> bool:
        """Whether the fit reproduces the second half by the stated criterion: same regime,
        mean torque within :data:`MEAN_TOLERANCE`, swings within :data:`SWING_RATIO`."""
        return self.regime_reproduced and self.mean_reproduced and self.size_reproduced

    def _mean_text(self) -> str:
        tol = f"tolerance {100 * MEAN_TOLERANCE:g} %"
        if self.mean_reproduced:
            return f"mean torque within {100 * self.mean_error:.1f} % of the measured, {tol}"
        side = "above" if self.mean_bias > 0 else "below"
        return f"mean torque {100 * self.mean_error:.0f} % {side} the measured, {tol}"

    def sentence(self, when: str, units: Units = SI) -> str:
        """What the fit reproduces over the second half and what not; ``when``: the time
        the second half starts, as shown."""
        swing = units.label("torque")
        model = f"{units.text(self.model_swing_Nm, 'torque', '.1f')} {swing}"
        data = f"{units.text(self.measured_swing_Nm, 'torque', '.1f')} {swing}"
        half = f"over the second half (from {when})"
        mean = self._mean_text()
        if not self.regime_reproduced:
            head = (f"The fit reproduces the mean torque (μ_k: {mean}) but not the regime"
                    if self.mean_reproduced else
                    f"The fit reproduces neither the regime nor the mean torque ({mean})")
            if self.model_stick_slip:
                return (f"{head}: {half} its model keeps stick-slip (torque swing {model}) "
                        f"where the measured torque is steady (swing {data}) — a bistable "
                        f"regime; fit quality there {self.quality:.2f}.")
            return (f"{head}: {half} the measured torque stick-slips (swing {data}) where "
                    f"its model turns steadily (swing {model}); fit quality there "
                    f"{self.quality:.2f}.")
        if not self.measured_stick_slip:
            if self.mean_reproduced:
                return f"The fit reproduces the steady rotation {half}: {mean}."
            return f"The fit does not reproduce the steady rotation {half}: {mean}."
        swings = f"torque swing {model} modelled, {data} measured"
        if self.reproduced:
            return f"The fit reproduces the stick-slip {half}: {swings} ({mean})."
        missed = " nor ".join(w for w, ok in (("its size", self.size_reproduced),
                                               ("its mean torque", self.mean_reproduced))
                              if not ok)
        return (f"The fit stick-slips like the data {half} but does not reproduce {missed}: "
                f"{swings} ({mean}; swings within a factor {SWING_RATIO:g}).")


def reproduction(rows: pd.DataFrame) -> Reproduction | None:
    """Compare ``surface_torque_fit_Nm`` with ``surface_torque_Nm`` over the second half of
    a segment's final-pass ``rows`` (every sample, uniform in time); None when the file has
    no fit torque or too few samples."""
    if "surface_torque_fit_Nm" not in rows or "surface_torque_Nm" not in rows:
        return None
    rows = rows.sort_values("time_s", kind="stable")
    both = rows["surface_torque_Nm"].notna() & rows["surface_torque_fit_Nm"].notna()
    rows = rows[both]
    if len(rows) < 2 * MIN_SAMPLES:
        return None
    t = rows["time_s"].to_numpy(float)
    dt = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    measured = smooth(rows["surface_torque_Nm"].to_numpy(float), dt, TORQUE_SMOOTH_S)
    model = smooth(rows["surface_torque_fit_Nm"].to_numpy(float), dt, TORQUE_SMOOTH_S)
    half = t >= t[0] + 0.5 * (t[-1] - t[0])
    if half.sum() < MIN_SAMPLES:
        return None
    m, f = measured[half], model[half]
    mean = abs(float(np.mean(m)))
    swing_m, swing_f = (float(np.subtract(*np.percentile(x, [95.0, 5.0]))) for x in (m, f))
    misfit = float(np.sqrt(np.mean((m - f) ** 2)))
    floor = max(swing_m, SWING_FLOOR * mean)
    return Reproduction(
        t_half_s=float(t[half][0]), measured_swing_Nm=swing_m, model_swing_Nm=swing_f,
        measured_stick_slip=_fluctuation(m) > STICK_SLIP_FLUCTUATION,
        model_stick_slip=_fluctuation(f) > STICK_SLIP_FLUCTUATION,
        mean_error=abs(float(np.mean(f)) - float(np.mean(m))) / mean if mean > 0 else np.inf,
        quality=misfit / floor if floor > 0 else np.inf,
        mean_bias=(float(np.mean(f)) - float(np.mean(m))) / mean if mean > 0 else 0.0)


def _fluctuation(torque: np.ndarray) -> float:
    """std/|mean| of a smoothed torque (the fit's stick-slip measure) [-]."""
    mean = abs(float(np.mean(torque)))
    return float(np.std(torque)) / mean if mean > 0 else 0.0


def stated_quality(fit_quality, found: Reproduction | None) -> tuple[float | None, bool]:
    """The fit quality a report states, and whether it is the second half's: where the fit
    does not reproduce the regime of the second half, the worse (larger) of the segment's
    and the second half's; else the segment's."""
    whole = None if fit_quality is None or pd.isna(fit_quality) else float(fit_quality)
    if found is None or found.regime_reproduced or not np.isfinite(found.quality):
        return whole, False
    if whole is None or found.quality > whole:
        return found.quality, True
    return whole, False
