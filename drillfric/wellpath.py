"""Well path by the minimum-curvature method (docs/theory.md §1).

Reference: S.J. Sawaryn, J.L. Thorogood, "A compendium of directional calculations based on
the minimum curvature method", SPE Drilling & Completion 20(1), 2005, SPE-84246-PA.

Public functions take and return SI units and radians; degrees exist only in the survey
readers (:mod:`drillfric.io.survey`). Points between stations lie on the circular arc
(slerp of the unit tangents), which is the only interpolation consistent with minimum
curvature — linear interpolation of inclination and azimuth is not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric.errors import InputError

_SMALL_DOGLEG = 1e-4  # [rad] below this, series expansions replace 1/sin and tan ratios


def unit_tangent(inc_rad, azi_rad) -> np.ndarray:
    """Unit tangent in North-East-Down axes, t = (sin I cos A, sin I sin A, cos I) (§1).

    Parameters
    ----------
    inc_rad, azi_rad : array_like
        Inclination and azimuth [rad].

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> unit_tangent(0.0, 1.0).tolist()
    [0.0, 0.0, 1.0]
    """
    inc = np.asarray(inc_rad, dtype=float)
    azi = np.asarray(azi_rad, dtype=float)
    return np.stack([np.sin(inc) * np.cos(azi), np.sin(inc) * np.sin(azi), np.cos(inc)], axis=-1)


def dogleg(t1: np.ndarray, t2: np.ndarray) -> np.ndarray:
    """Dogleg angle β = 2·atan2(|t₂ − t₁|, |t₂ + t₁|) [rad] between unit tangents (§1).

    The atan2 form keeps full precision at small angles, unlike arccos(t₁·t₂).

    Examples
    --------
    >>> float(np.degrees(dogleg(np.array([0, 0, 1.0]), np.array([1.0, 0, 0]))))
    90.0
    """
    return 2.0 * np.arctan2(np.linalg.norm(t2 - t1, axis=-1), np.linalg.norm(t2 + t1, axis=-1))


def ratio_factor(beta: np.ndarray) -> np.ndarray:
    """Minimum-curvature ratio factor RF = (2/β)·tan(β/2), with its series near β = 0 (§1).

    Examples
    --------
    >>> float(ratio_factor(np.array(0.0)))
    1.0
    """
    beta = np.asarray(beta, dtype=float)
    small = np.abs(beta) < _SMALL_DOGLEG
    safe = np.where(small, 1.0, beta)
    return np.where(small, 1.0 + beta**2 / 12.0 + beta**4 / 120.0,
                    2.0 / safe * np.tan(safe / 2.0))


def _slerp_weights(frac: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Weights (w₁, w₂) with t(f) = w₁ t₁ + w₂ t₂ on the arc: sin((1−f)β)/sin β, sin(fβ)/sin β."""
    small = np.abs(beta) < _SMALL_DOGLEG
    safe = np.where(small, 1.0, beta)
    w1 = np.where(small, 1.0 - frac, np.sin((1.0 - frac) * safe) / np.sin(safe))
    w2 = np.where(small, frac, np.sin(frac * safe) / np.sin(safe))
    return w1, w2


@dataclass(frozen=True)
class WellPath:
    """A well path: survey stations and their minimum-curvature positions.

    Attributes
    ----------
    md_m : ndarray
        Measured depth of the stations [m], strictly increasing.
    inc_rad, azi_rad : ndarray
        Inclination and azimuth at the stations [rad].
    tvd_m, north_m, east_m : ndarray
        Position of the stations [m] (TVD positive down).
    dogleg_rad : ndarray
        Dogleg β of each interval [rad], length ``n − 1``.
    """

    md_m: np.ndarray
    inc_rad: np.ndarray
    azi_rad: np.ndarray
    tvd_m: np.ndarray
    north_m: np.ndarray
    east_m: np.ndarray
    dogleg_rad: np.ndarray

    @property
    def dls_rad_m(self) -> np.ndarray:
        """Dogleg severity β/Δs of each interval [rad/m]."""
        return self.dogleg_rad / np.diff(self.md_m)

    @property
    def md_max_m(self) -> float:
        """Deepest station [m]."""
        return float(self.md_m[-1])

    def _locate(self, md_m) -> tuple[np.ndarray, np.ndarray]:
        md = np.atleast_1d(np.asarray(md_m, dtype=float))
        lo, hi = self.md_m[0], self.md_m[-1]
        tol = 1e-9 * max(1.0, hi)
        if md.size and (md.min() < lo - tol or md.max() > hi + tol):
            raise InputError(f"measured depth {md.min():.1f}–{md.max():.1f} m is outside the "
                             f"survey ({lo:.1f}–{hi:.1f} m)",
                             fix="extend the survey to the bit depth")
        if len(self.md_m) == 1:  # a lone station: only its own depth is on the path
            return np.zeros(md.size, dtype=int), np.zeros(md.size)
        k = np.clip(np.searchsorted(self.md_m, md, side="right") - 1, 0, len(self.md_m) - 2)
        frac = np.clip((md - self.md_m[k]) / (self.md_m[k + 1] - self.md_m[k]), 0.0, 1.0)
        return k, frac

    def tangent(self, md_m) -> np.ndarray:
        """Unit tangent (N, E, Down) at measured depths, on the circular arcs, shape (n, 3)."""
        if len(self.md_m) == 1:
            return np.broadcast_to(unit_tangent(self.inc_rad[0], self.azi_rad[0]),
                                   (np.size(md_m), 3)).copy()
        k, frac = self._locate(md_m)
        t = unit_tangent(self.inc_rad, self.azi_rad)
        w1, w2 = _slerp_weights(frac, self.dogleg_rad[k])
        out = w1[:, None] * t[k] + w2[:, None] * t[k + 1]
        return out / np.linalg.norm(out, axis=1, keepdims=True)

    def position(self, md_m) -> np.ndarray:
        """(north, east, tvd) [m] at measured depths, on the circular arcs, shape (n, 3)."""
        k, frac = self._locate(md_m)
        start = np.stack([self.north_m, self.east_m, self.tvd_m], axis=1)[k]
        if len(self.md_m) == 1:
            return start
        t = unit_tangent(self.inc_rad, self.azi_rad)
        beta_part = frac * self.dogleg_rad[k]
        ds = frac * np.diff(self.md_m)[k]
        tf = self.tangent(md_m)
        return start + (ds * ratio_factor(beta_part) / 2.0)[:, None] * (t[k] + tf)

    def at(self, md_m) -> dict[str, np.ndarray]:
        """Inclination, azimuth [rad], TVD, north, east [m] at measured depths (arc-consistent).

        Examples
        --------
        A 90° build over 300 m is a quarter circle of radius 2·300/π ≈ 190.99 m; half-way
        the hole is at 45° and sin 45° of the radius deeper:

        >>> p = minimum_curvature([0.0, 300.0], [0.0, np.pi / 2], [0.0, 0.0])
        >>> mid = p.at(150.0)
        >>> round(float(np.degrees(mid["inc_rad"][0])), 9), round(float(mid["tvd_m"][0]), 3)
        (45.0, 135.047)
        """
        t = self.tangent(md_m)
        pos = self.position(md_m)
        inc = np.arctan2(np.hypot(t[:, 0], t[:, 1]), t[:, 2])
        azi = np.mod(np.arctan2(t[:, 1], t[:, 0]), 2 * np.pi)
        return {"md_m": np.atleast_1d(np.asarray(md_m, float)), "inc_rad": inc, "azi_rad": azi,
                "tvd_m": pos[:, 2], "north_m": pos[:, 0], "east_m": pos[:, 1]}


def minimum_curvature(md_m, inc_rad, azi_rad, *, tie_in=None) -> WellPath:
    """Compute station positions by minimum curvature (docs/theory.md §1).

    Parameters
    ----------
    md_m : array_like
        Station measured depths [m], strictly increasing.
    inc_rad, azi_rad : array_like
        Station inclination [0, π] and azimuth [rad].
    tie_in : tuple of float, optional
        (tvd, north, east) [m] of the first station. Default: a survey starting below the
        surface gets a vertical station at MD 0 prepended (the hole above the first station
        is the minimum-curvature arc from vertical at the surface).

    Returns
    -------
    WellPath

    Raises
    ------
    InputError
        Depths not strictly increasing, angles out of range, or a 180° dogleg (no unique
        arc).

    Examples
    --------
    >>> p = minimum_curvature([0.0, 100.0], [0.0, 0.0], [0.0, 0.0])
    >>> float(p.tvd_m[-1])
    100.0
    """
    md = np.asarray(md_m, dtype=float)
    inc = np.asarray(inc_rad, dtype=float)
    azi = np.asarray(azi_rad, dtype=float)
    if md.ndim != 1 or md.size < 1 or inc.shape != md.shape or azi.shape != md.shape:
        raise InputError("survey needs equal-length MD, inclination and azimuth columns")
    if np.any(~np.isfinite(md)) or np.any(~np.isfinite(inc)) or np.any(~np.isfinite(azi)):
        raise InputError("survey has missing values", fix="remove or fill the empty stations")
    if np.any(np.diff(md) <= 0):
        bad = int(np.argmax(np.diff(md) <= 0)) + 1
        raise InputError(f"survey depths not increasing at station {bad + 1} "
                         f"(MD {md[bad - 1]:g} then {md[bad]:g})",
                         fix="sort the survey by MD and remove duplicate stations")
    if np.any((inc < 0) | (inc > np.pi)):
        raise InputError("inclination outside 0–180°", fix="check the inclination column")
    if tie_in is None and md[0] > 0.0:
        # the hole above the first station: a minimum-curvature arc from vertical at the
        # surface, so positions and tangents (torque and drag) describe the same path
        md, inc, azi = np.r_[0.0, md], np.r_[0.0, inc], np.r_[azi[0], azi]
    t = unit_tangent(inc, azi)
    beta = dogleg(t[:-1], t[1:])
    if np.any(np.pi - beta < 1e-6):
        bad = int(np.argmax(np.pi - beta < 1e-6))
        raise InputError(f"the survey reverses direction between MD {md[bad]:g} and "
                         f"{md[bad + 1]:g} m (dogleg 180°): no unique minimum-curvature arc",
                         fix="check the inclination and azimuth of those stations")
    disp = (np.diff(md) / 2.0 * ratio_factor(beta))[:, None] * (t[:-1] + t[1:])
    tvd0, n0, e0 = (md[0], 0.0, 0.0) if tie_in is None else tie_in
    pos = np.vstack([[n0, e0, tvd0], np.array([n0, e0, tvd0]) + np.cumsum(disp, axis=0)])
    return WellPath(md_m=md, inc_rad=inc, azi_rad=np.mod(azi, 2 * np.pi), tvd_m=pos[:, 2],
                    north_m=pos[:, 0], east_m=pos[:, 1], dogleg_rad=beta)


def vertical(depth_m: float) -> WellPath:
    """An exactly vertical well path from surface to ``depth_m`` [m] (no side force)."""
    return minimum_curvature([0.0, float(depth_m)], [0.0, 0.0], [0.0, 0.0])


#: Helix period of the assumed tortuous path [m]: long against the 30 m of a survey
#: interval, so a survey of the path at 30 m reads 98 % of its curvature (sinc(π·30/300)).
TORTUOUS_PERIOD_M = 300.0
#: Station spacing of the assumed tortuous path [m] (12° of azimuth per station).
TORTUOUS_STATION_M = 10.0


def tortuous_vertical(depth_m: float, dls_rad_m: float, *, period_m: float = TORTUOUS_PERIOD_M,
                      station_m: float = TORTUOUS_STATION_M) -> WellPath:
    """A nominally vertical hole with constant tortuosity: a helix about the vertical.

    Real "vertical" holes are tortuous; in an exactly vertical one the soft-string side
    force is zero (docs/theory.md §2) and friction cannot act on the torque. This is the path
    assumed when a well has no survey: constant inclination I, azimuth turning uniformly,
    A(s) = 2π s/P, so that the curvature is the same everywhere.

    Curvature of the helix: with t(s) = (sin I cos A, sin I sin A, cos I) (docs/theory.md §1),
    dt/ds = sin I·(2π/P)·(−sin A, cos A, 0), so κ = |dt/ds| = (2π/P)·sin I. The path is
    built from stations every h = ``station_m`` (ΔA = 2π h/P); between two stations the
    minimum-curvature dogleg (§1) is β = 2·atan2(|t₂ − t₁|, |t₂ + t₁|) with
    |t₂ − t₁| = 2 sin I sin(ΔA/2), i.e. sin(β/2) = sin I·sin(ΔA/2). Choosing

        sin I = sin(κh/2) / sin(ΔA/2)

    makes the dogleg severity β/h of every interval exactly κ = ``dls_rad_m``: the path is
    a chain of circular arcs of curvature κ, each in its own plane (as h → 0 it tends to the
    helix, sin I → κP/2π). The soft-string side force per unit length is then
    F_N ≈ √((F·κ)² + (w·sin I)²) with F the tension and w the buoyed weight per metre
    (§2 step 2; the two terms are orthogonal at mid-arc, within ΔA/2 of it at the
    stations): F·κ wherever the tension is large.

    Parameters
    ----------
    depth_m : float
        Deepest measured depth the path must reach [m]; it ends at the first station at or
        below it.
    dls_rad_m : float
        Tortuosity: dogleg severity κ of every interval [rad/m], > 0.
    period_m : float
        Helix period P [m] (one full turn of azimuth).
    station_m : float
        Station spacing h [m].

    Returns
    -------
    WellPath

    Raises
    ------
    ValueError
        A non-positive input, or a curvature too large for the period (sin I > 1).

    Examples
    --------
    1°/30 m with the default period: a helix of inclination ≈ 1.6° and radius ≈ 1.3 m:

    >>> p = tortuous_vertical(1000.0, np.radians(1.0) / 30.0)
    >>> dls_deg_30m = np.degrees(p.dls_rad_m) * 30.0
    >>> round(float(dls_deg_30m.min()), 9), round(float(dls_deg_30m.max()), 9)
    (1.0, 1.0)
    >>> round(float(np.degrees(p.inc_rad[0])), 2)
    1.59
    """
    depth, kappa = float(depth_m), float(dls_rad_m)
    if not (depth > 0 and kappa > 0 and period_m > 0 and station_m > 0):
        raise ValueError("depth, tortuosity, period and station spacing must be positive")
    d_azi = 2.0 * np.pi * station_m / period_m
    sin_inc = np.sin(kappa * station_m / 2.0) / np.sin(d_azi / 2.0)
    if not sin_inc <= 1.0:
        raise ValueError(f"tortuosity {kappa:.3g} rad/m is too large for a {period_m:g} m "
                         "helix period")
    n = int(np.ceil(depth / station_m - 1e-9))
    k = np.arange(n + 1)
    inc = np.full(k.size, np.arcsin(sin_inc))
    return minimum_curvature(k * station_m, inc, k * d_azi)


def no_survey_path(depth_m: float, tortuosity_rad_m: float) -> WellPath:
    """The path assumed when a well has no survey, to ``depth_m`` [m].

    :func:`tortuous_vertical` with dogleg severity ``tortuosity_rad_m`` [rad/m]; exactly
    :func:`vertical` when it is 0 (then the soft-string side force is zero, docs/theory.md §2).

    Examples
    --------
    >>> no_survey_path(500.0, 0.0).inc_rad.tolist()
    [0.0, 0.0]
    """
    if tortuosity_rad_m == 0:
        return vertical(depth_m)
    return tortuous_vertical(depth_m, tortuosity_rad_m)
