"""Friction that moves within a segment: μ_k(t) from windowed re-fits of the mean torque,
and the drift test (docs/theory.md §6.6).

The batch fit (§6.4) gives one μ_k from the first ``batch.window_s`` of a segment; its model,
driven by the measured top-drive speed over the whole segment at that μ_k (the fit's evidence,
:func:`drillfric.estimation.chain.fit_evidence`), carries the torque and drag, the viscous
and cased torque, the stick-slip and every set-point change of the segment. Over a window of
``batch.trend_window_s`` (50 % overlap) the measured whole-cycle mean string torque M_w and
the model's m_w then differ only by the friction that moved and by what the evidence's model
(driven by the logged speed) does not share with the fit's (the replayed drive), which the
span B the fit matched μ_k on measures (eq. 6.6a):

    μ_k,w = μ_k + (M_w − m_w − (M_B − m_B)) / T_N,

T_N = ∫F_c dx of the estimated part (the mean friction torque's slope in μ_k, §6.4: with all
else fixed the mean torque of the model is linear in μ_k to within its jitter). Each window
states its 95 % half-width (eq. 6.6b): the validated tolerance of the batch μ_k
(:func:`~drillfric.estimation.batch.settings.mu_k_tolerance`) and 2σ of the window, σ = √2 ×
the standard error of the data's whole-cycle mean over T_N (the model's mean scatters as
much), in quadrature.

The drift test (eq. 6.6c) uses the windows that do not overlap: a weighted linear trend
of μ_k,w against time, flagged ``mu_k_drift`` when its slope is significant at 95 % (the
residual scatter counted where it exceeds the windows' own σ) and the change over the
windows exceeds the validated tolerance — or when two windows differ by more than the
tolerance plus 2σ of their difference (a step up and back down). Model-form errors common to
all windows (the batch μ_k's own bias) cancel in the test.

Rows of a segment whose friction did not move take the level the independent windows agree
on (their weighted linear trend, eq. 6.6d). Of a drifting segment, rows between window
centres take μ_k(t) linearly interpolated (exact on a ramp: a window's mean of a linear
change is its centre's value); a change faster than the windows resolve (a step) makes the
window values bend: where a window's second difference exceeds
:data:`MAX_BEND` the rows within a hop of it are withheld, as are the rows beyond the first
and last centres of a drifting segment and the rows of windows whose own uncertainty is
above :data:`MU_K_CLAIM` (nothing is claimed there).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from drillfric.estimation.batch.harness import cycle_mean, cycle_mean_error
from drillfric.estimation.batch.settings import MU_K_CLAIM
from drillfric.estimation.creep import true_runs
from drillfric.result import Flag

#: Share of a window that must be usable rotation (after the start-up) for its μ_k [-].
MIN_USED = 0.5
#: Largest second difference of neighbouring window μ_k relative to μ_k [-] over which rows
#: are interpolated: a step of Δ bends the window values by Δ/2, which is the largest error
#: of the interpolated rows near it (module docstring).
MAX_BEND = 0.05
#: Independent (non-overlapping) windows the drift test needs.
MIN_WINDOWS = 3
#: Two-sided 95 % normal quantile of the drift test.
Z95 = 1.96
#: Second differences of the windows that estimate their scatter beyond statistics.
MIN_BENDS = 3


@dataclass(frozen=True)
class FrictionTrend:
    """μ_k(t) of one segment and its drift test (docs/theory.md §6.6).

    Attributes
    ----------
    centre_s : ndarray
        Window centres [s].
    mu_k : ndarray
        Window μ_k [-] (NaN: the window holds too little rotation or too few cycles).
    half_width : ndarray
        95 % half-width of each window's μ_k [-] (eq. 6.6b).
    sigma : ndarray
        1-σ uncertainty of each window's μ_k [-]: statistical, raised to the windows'
        scatter beyond it (:func:`form_scatter`) and with the anchor's error.
    drift : bool
        Whether the friction moved beyond its uncertainty (eq. 6.6c).
    rate_per_h : float or None
        Linear trend of the independent windows' μ_k [1/h] (None with fewer than
        :data:`MIN_WINDOWS`).
    tolerance : float
        Relative validated tolerance the test used [-].
    window_s : float
        Window length [s].
    """

    centre_s: np.ndarray
    mu_k: np.ndarray
    half_width: np.ndarray
    sigma: np.ndarray
    drift: bool = False
    rate_per_h: float | None = None
    tolerance: float = 0.0
    window_s: float = 0.0

    @property
    def mean(self) -> float | None:
        """Mean of the window μ_k over the segment [-] (None without windows)."""
        ok = np.isfinite(self.mu_k)
        return float(np.mean(self.mu_k[ok])) if ok.any() else None

    def at(self, time_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """μ_k(t) [-] and its 95 % half-width [-] at ``time_s`` [s], NaN where withheld
        (module docstring): of a drifting segment the windows interpolated (withheld near a
        bend, beyond the end centres, across a gap); else the level the windows agree on
        (:meth:`level`)."""
        t = np.asarray(time_s, dtype=float)
        if not self.drift:
            return self.level(t)
        ok = np.isfinite(self.mu_k) & (self.sigma * 2.0 <= MU_K_CLAIM * self.mu_k)
        out = np.full(t.size, np.nan), np.full(t.size, np.nan)
        if not ok.any():
            return out
        c, mu, hw = self.centre_s[ok], self.mu_k[ok], self.half_width[ok]
        value, width = np.interp(t, c, mu), np.interp(t, c, hw)
        hop = 0.5 * self.window_s
        gone = (t < c[0]) | (t > c[-1])
        for i in _bent(mu):
            gone |= np.abs(t - c[i]) < hop * (1.0 + 1e-9)
        for a, b in zip(c[:-1], c[1:], strict=True):
            if b - a > 2.0 * hop * (1.0 + 1e-9):  # a gap: nothing known between
                gone |= (t > a) & (t < b)
        return np.where(gone, np.nan, value), np.where(gone, np.nan, width)

    def level(self, time_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """μ_k(t) of a segment whose friction did not move beyond its uncertainty [-], and
        its 95 % half-width [-]: the weighted linear trend of the independent windows (their
        weighted mean with fewer than :data:`MIN_WINDOWS`), held beyond the first and last
        centres; NaN where its 2σ exceeds :data:`MU_K_CLAIM` of it (eq. 6.6d), and
        everywhere when too few windows for the drift test differ by more than the
        tolerance."""
        t = np.asarray(time_s, dtype=float)
        valid = np.flatnonzero(np.isfinite(self.mu_k))
        index = _spaced(self.centre_s, valid, self.window_s)
        if index.size == 0 or (index.size < MIN_WINDOWS and np.ptp(self.mu_k[valid])
                               > self.tolerance * float(np.mean(self.mu_k[valid]))):
            # no windows, or too few to test a drift and apart by more than the tolerance:
            # a change the test cannot see, so no level is claimed
            return np.full(t.size, np.nan), np.full(t.size, np.nan)
        c = self.centre_s[index]
        line = _line(c / 3600.0, self.mu_k[index], self.sigma[index],
                     slope=index.size >= MIN_WINDOWS)
        value, se = line.at(np.clip(t, c[0], c[-1]) / 3600.0)
        gone = 2.0 * se > MU_K_CLAIM * value
        width = np.hypot(self.tolerance * value, 2.0 * se)
        return np.where(gone, np.nan, value), np.where(gone, np.nan, width)


@dataclass(frozen=True)
class _Line:
    """A weighted straight line μ = level + slope·(t − t_mean) [t in h] and what its
    standard error needs (weights 1/σ², the scale max(χ²/dof, 1))."""

    level: float
    slope: float
    t_mean: float
    sum_w: float
    sxx: float
    scale: float

    def at(self, t_h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The line and its standard error at ``t_h`` [h]."""
        dt = np.asarray(t_h, dtype=float) - self.t_mean
        var = self.scale * (1.0 / self.sum_w + (dt**2 / self.sxx if self.sxx > 0 else 0.0))
        return self.level + self.slope * dt, np.sqrt(var)

    @property
    def slope_se(self) -> float:
        """Standard error of the slope [1/h] (inf without a slope)."""
        return float(np.sqrt(self.scale / self.sxx)) if self.sxx > 0 else float("inf")


def _line(t_h: np.ndarray, mu: np.ndarray, sigma: np.ndarray, *, slope: bool) -> _Line:
    """Weighted least squares of ``mu`` on ``t_h`` [h] with 1-σ ``sigma`` (a constant when
    not ``slope``); the scale of its errors is the residuals' χ² per degree of freedom where
    it exceeds 1 (the windows scatter more than their σ say)."""
    w = 1.0 / np.maximum(sigma, 1e-12) ** 2
    tm = float(np.sum(w * t_h) / np.sum(w))
    level = float(np.sum(w * mu) / np.sum(w))
    sxx = float(np.sum(w * (t_h - tm) ** 2)) if slope else 0.0
    b = float(np.sum(w * (t_h - tm) * (mu - level)) / sxx) if sxx > 0 else 0.0
    dof = mu.size - (2 if slope else 1)
    chi2 = float(np.sum(w * (mu - level - b * (t_h - tm)) ** 2))
    return _Line(level, b, tm, float(np.sum(w)), sxx, max(chi2 / dof, 1.0) if dof > 0 else 1.0)


def _bent(mu: np.ndarray) -> np.ndarray:
    """Indices of windows whose second difference exceeds :data:`MAX_BEND` of their μ_k."""
    if mu.size < 3:
        return np.array([], dtype=int)
    bend = np.abs(mu[:-2] - 2.0 * mu[1:-1] + mu[2:])
    return np.flatnonzero(bend > MAX_BEND * mu[1:-1]) + 1


def windows(time_s: np.ndarray, usable: np.ndarray, window_s: float
            ) -> list[tuple[float, float]]:
    """Windows [a, a + ``window_s``) of hop ``window_s``/2 over the usable samples [s], the
    last one ending at the last usable sample (so the end of the segment is covered); one
    window over all of them when they span less than a window."""
    t = np.asarray(time_s, dtype=float)[usable]
    if t.size < 2:
        return []
    first, last = float(t[0]), float(t[-1])
    if last - first <= window_s:
        return [(first, last)]
    hop = 0.5 * window_s
    starts = list(first + hop * np.arange(int(np.floor((last - first - window_s) / hop)) + 1))
    if last - window_s > starts[-1] + 1e-9:
        starts.append(last - window_s)
    return [(a, a + window_s) for a in starts]


def friction_trend(time_s, measured_Nm, model_Nm, usable, *, mu_k: float, T_N_Nm: float,
                   tolerance: float, window_s: float,
                   anchor_end_s: float | None = None) -> FrictionTrend:
    """μ_k of each window and the drift test of one segment (docs/theory.md §6.6).

    Parameters
    ----------
    time_s : array_like
        Uniform sample times [s].
    measured_Nm, model_Nm : array_like
        Measured string torque and the fitted model's at ``mu_k`` [N·m].
    usable : array_like of bool
        Samples compared: turning, after the start-up.
    mu_k : float
        The segment's batch μ_k the model ran at [-].
    T_N_Nm : float
        ∫F_c dx of the estimated part [N·m]: the mean torque's slope in μ_k.
    tolerance : float
        Validated relative tolerance of μ_k at this logging [-] (the half-width's floor and
        the smallest change the drift test calls a drift).
    window_s : float
        Window length [s] (``batch.trend_window_s``); windows overlap by half.
    anchor_end_s : float, optional
        End of the span the batch fit matched ``mu_k`` over [s]: the model's mean torque
        misses the data's there by what the model of the evidence does not share with the
        fit's (eq. 6.6a), taken off every window. None: no offset.
    """
    t = np.asarray(time_s, dtype=float)
    meas, model = np.asarray(measured_Nm, dtype=float), np.asarray(model_Nm, dtype=float)
    use = np.asarray(usable, dtype=bool)
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    spans = windows(t, use, window_s)
    centre, mu, sigma = (np.full(len(spans), np.nan) for _ in range(3))
    offset, offset_sigma = _offset(meas, model, use & (t <= (
        np.inf if anchor_end_s is None else anchor_end_s)), dt, anchor_end_s is not None)
    for i, (a, b) in enumerate(spans):
        inside = use & (t >= a) & (t <= b)
        centre[i] = 0.5 * (a + b)
        if inside.sum() * dt < MIN_USED * min(window_s, b - a) or T_N_Nm <= 0:
            continue
        parts = _runs(inside)
        error = cycle_mean_error([[meas[r] for r in parts]], dt)
        if error is None:
            continue
        mu[i] = mu_k + (cycle_mean([meas[r] for r in parts], dt)
                        - cycle_mean([model[r] for r in parts], dt) - offset) / T_N_Nm
        sigma[i] = np.hypot(np.sqrt(2.0) * error[0], offset_sigma) / T_N_Nm
    sigma = np.maximum(sigma, form_scatter(mu))
    half = np.hypot(tolerance * mu, 2.0 * sigma)
    trend = FrictionTrend(centre, mu, half, sigma, tolerance=tolerance, window_s=window_s)
    return drift_test(trend)


def _offset(measured: np.ndarray, model: np.ndarray, span: np.ndarray, dt: float,
            anchored: bool) -> tuple[float, float]:
    """Whole-cycle mean of measured − model torque over ``span`` [N·m] and its standard error
    (√2 × the data's, as a window's) [N·m]; (0, 0) when not ``anchored`` or the span holds
    too few cycles."""
    if not anchored or span.sum() < 3:
        return 0.0, 0.0
    parts = _runs(span)
    error = cycle_mean_error([[measured[r] for r in parts]], dt)
    if error is None:
        return 0.0, 0.0
    return (cycle_mean([measured[r] for r in parts], dt)
            - cycle_mean([model[r] for r in parts], dt), float(np.sqrt(2.0) * error[0]))


def _runs(mask: np.ndarray) -> list[slice]:
    """The runs of consecutive True samples of ``mask``, as slices: the parts of a window
    whose samples between (held readings, docs/theory.md §6.6) are left out, so that no
    torque cycle is pieced together across them."""
    return [slice(a, b + 1) for a, b in true_runs(mask)]


def drift_test(trend: FrictionTrend) -> FrictionTrend:
    """The trend with its drift test (eq. 6.6c) on the windows that do not overlap (every
    other one, from the first valid): a weighted linear trend significant at 95 % whose change
    over them exceeds ``trend.tolerance`` of the mean μ_k, or two of them apart by more than
    that plus 2σ of their difference."""
    ok = np.flatnonzero(np.isfinite(trend.mu_k))
    independent = _spaced(trend.centre_s, ok, trend.window_s)
    if independent.size < MIN_WINDOWS:
        return trend
    t_h = trend.centre_s[independent] / 3600.0
    mu, sig = trend.mu_k[independent], trend.sigma[independent]
    line = _line(t_h, mu, sig, slope=True)
    level = float(np.mean(mu))
    change = line.slope * float(t_h[-1] - t_h[0])
    trending = abs(line.slope) > Z95 * line.slope_se and abs(change) > trend.tolerance * level
    hi, lo = int(np.argmax(mu)), int(np.argmin(mu))
    stepped = mu[hi] - mu[lo] > trend.tolerance * level + 2.0 * Z95 * float(
        np.hypot(sig[hi], sig[lo]))
    return replace(trend, drift=bool(trending or stepped), rate_per_h=line.slope)


def form_scatter(mu: np.ndarray) -> float:
    """1-σ scatter of the window μ_k [-] that their statistics do not explain (a model that
    misses the record by a share that wanders from window to window), eq. 6.6b: from the
    median |second difference| of consecutive windows, which a ramp leaves at 0 and a step
    moves at two windows only; with windows overlapping by half var(Δ²μ) = 2σ², so
    σ = median|Δ²μ| / (0.6745·√2) (0.6745σ: the median of |N(0, σ²)|). 0 with fewer than
    :data:`MIN_BENDS` second differences.

    Examples
    --------
    >>> form_scatter(np.linspace(0.25, 0.35, 9)) < 1e-12  # a ramp: no scatter
    True
    >>> round(form_scatter(np.array([0.25, 0.27] * 4)), 3)  # windows alternating by 0.02
    0.042
    """
    ok = np.asarray(mu, dtype=float)
    ok = ok[np.isfinite(ok)]
    if ok.size < MIN_BENDS + 2:
        return 0.0
    bend = np.abs(ok[:-2] - 2.0 * ok[1:-1] + ok[2:])
    return float(np.median(bend) / (0.6745 * np.sqrt(2.0)))


def _spaced(centre_s: np.ndarray, index: np.ndarray, window_s: float) -> np.ndarray:
    """Of ``index`` (in time order), those at least a window after the previous kept one."""
    kept: list[int] = []
    for i in index:
        if not kept or centre_s[i] - centre_s[kept[-1]] >= window_s * (1.0 - 1e-9):
            kept.append(int(i))
    return np.asarray(kept, dtype=int)


def drift_verdict(trend: FrictionTrend | None) -> tuple[tuple, tuple]:
    """The flag and the sentence of a segment whose friction moved (none when it did not):
    ``mu_k_drift``; the segment's μ_k is then the mean of the windows, a mean over the
    drift."""
    if trend is None or not trend.drift:
        return (), ()
    return (Flag.MU_K_DRIFT,), (drift_note(trend),)


def drift_note(trend: FrictionTrend) -> str:
    """The segment's sentence on a drift: the range of μ_k(t), its rate, and that the
    segment's μ_k is a mean over it (no number of the segment's μ_k: it may be withheld)."""
    ok = np.isfinite(trend.mu_k)
    lo, hi = float(np.min(trend.mu_k[ok])), float(np.max(trend.mu_k[ok]))
    rate = trend.rate_per_h or 0.0
    return (f"friction moved within the segment (mu_k_drift): the {trend.window_s:g}-s "
            f"windows' μ_k(t) ran from {lo:.3f} to {hi:.3f}, a trend of {rate:+.3f}/h "
            f"({100 * rate / trend.mean:+.0f} %/h); the segment's μ_k, where shown, is the "
            "mean over the drift, estimates.parquet's μ_k column holds μ_k(t) "
            "(docs/theory.md §6.6)")
