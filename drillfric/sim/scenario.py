"""A simulation's scenario: its stands and their set-point schedules, from the
configuration's ``[simulate]`` table or a scenario file (docs/simulator.md)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from drillfric.config import Config, read_toml
from drillfric.errors import ConfigError

_STARTS = ("ramp", "creep")


@dataclass(frozen=True)
class Stand:
    """One stand: the bit at a fixed depth, rotation started from rest and stopped.

    Attributes
    ----------
    bit_depth_m : float
        Bit measured depth during the stand [m].
    duration_s : float
        Rotating time from the start of the set-point to the start of the stop [s].
    rpm : float
        Set-point after the start-up [RPM].
    start : str
        "ramp" (0 → rpm in ``ramp_s``) or "creep" (0 → ``creep_rpm`` in ``creep_ramp_s``,
        hold ``creep_hold_s``, then ramp to rpm in ``ramp_s``), docs/theory.md §6.3.
    ramp_s, creep_rpm, creep_ramp_s, creep_hold_s : float
        Start-up shape [s], [RPM].
    idle_s : float
        Rest before the start [s].
    stop_s, stop_hold_s : float
        Ramp of the set-point down to 0 and the time held at 0 (torque trapped) [s].
    wob_N : float
        Weight on bit [N]; > 0 puts the bit on bottom.
    rop_m_h : float
        Rate of penetration of an on-bottom stand [m/h]: the recorded bit and hole depth
        advance at it while the set-point is held (the plant stays at ``bit_depth_m``, a few
        decimetres per stand; docs/simulator.md).
    bit_weakening_ratio, bit_weakening_rpm : float
        Rate-weakening bit of an on-bottom stand, T_bit(ω) = T_k·(1 + (r − 1)·exp(−|ω|/ω_b)):
        r [-] (1: the Coulomb bit) and ω_b [RPM] (docs/simulator.md, Bit).
    flow_m3_s : float
        Flow in through the string and its mud motor [m³/s], pumps on throughout the stand
        (idle, start-up and stop included; off in the connection after it).
    setpoint_rpm : tuple of (t_s, rpm), optional
        Explicit piecewise-linear set-point from the start of the stand (replaces the
        start-up/hold/stop shape; a repeated time makes a step).
    motor_torque_Nm : tuple of (t_s, N·m), optional
        Prescribed motor torque instead of the PI controller.
    stop : bool
        Stop rotation at the end (False for a single-stand run).
    axial_speed_m_s : float
        Speed of the pipe along the hole while it turns off bottom [m/s]: > 0 running in
        (reaming, the bit depth grows), < 0 pulling out (back-reaming); 0 (default) rotates
        in place. The string moves from ``axial_delay_s`` after the start-up to the start
        of the stop, reaching the speed in ``axial_ramp_s`` and slowing to rest in as long
        (docs/simulator.md, Reaming; docs/theory.md §3.3).
    axial_delay_s, axial_ramp_s : float
        Rotation in place between the end of the start-up and the start of the axial motion,
        and the block's acceleration time [s].
    mu_k_schedule : tuple of (t_s, factor), optional
        Friction that changes in time (a cuttings bed building up, a wiper trip clearing
        it): piecewise-linear factor [-] on the open hole's μ_k and μ_s (their ratio kept)
        from the start of the set-point, as ``setpoint_rpm`` (a repeated time makes a step;
        held after the last point). None: the friction is constant.
    top_drive_inertia_kg_m2 : float, optional
        The top drive's inertia during this stand [kg·m²] (a gear change between stands,
        issue 34 item 2); None: ``rig.top_drive_inertia_kg_m2``.
    """

    bit_depth_m: float
    duration_s: float = 120.0
    rpm: float = 60.0
    start: str = "ramp"
    ramp_s: float = 10.0
    creep_rpm: float = 5.0
    creep_ramp_s: float = 5.0
    creep_hold_s: float = 30.0
    idle_s: float = 5.0
    stop_s: float = 5.0
    stop_hold_s: float = 10.0
    wob_N: float = 0.0
    rop_m_h: float = 0.0
    bit_weakening_ratio: float = 1.0
    bit_weakening_rpm: float = 10.0
    flow_m3_s: float = 0.0
    setpoint_rpm: tuple | None = None
    motor_torque_Nm: tuple | None = None
    stop: bool = True
    axial_speed_m_s: float = 0.0
    axial_delay_s: float = 0.0
    axial_ramp_s: float = 2.0
    mu_k_schedule: tuple | None = None
    top_drive_inertia_kg_m2: float | None = None

    @property
    def start_up_s(self) -> float:
        """Time from the start of the set-point to the end of its start-up [s]."""
        creep = self.creep_ramp_s + self.creep_hold_s if self.start == "creep" else 0.0
        return creep + self.ramp_s

    @property
    def total_s(self) -> float:
        """Recorded length of the stand, rest to rest [s]."""
        if self.setpoint_rpm is not None or self.motor_torque_Nm is not None:
            series = self.setpoint_rpm or self.motor_torque_Nm
            return self.idle_s + float(series[-1][0])
        stop = self.stop_s + self.stop_hold_s if self.stop else 0.0
        return self.idle_s + self.duration_s + stop

    def friction_factor(self, t_s) -> np.ndarray:
        """The factor on μ_k and μ_s at ``t_s`` [s from the stand's start] [-] (1 without a
        schedule): ``mu_k_schedule`` piecewise linear, a repeated time a step (the later
        value from that time on), held before the first and after the last point."""
        t = np.asarray(t_s, dtype=float)
        if self.mu_k_schedule is None:
            return np.ones(t.shape)
        pts = np.asarray(self.mu_k_schedule, dtype=float)
        return step_interp(t, pts[:, 0] + self.idle_s, pts[:, 1])

    def knots(self) -> np.ndarray:
        """Set-point (t [s] from stand start, ω_ref [RPM]) knots of the piecewise-linear shape."""
        if self.setpoint_rpm is not None:
            pts = np.asarray(self.setpoint_rpm, dtype=float)
            return np.column_stack([pts[:, 0] + self.idle_s, pts[:, 1]])
        t = self.idle_s
        pts = [(0.0, 0.0), (t, 0.0)]
        if self.start == "creep":
            pts += [(t + self.creep_ramp_s, self.creep_rpm),
                    (t + self.creep_ramp_s + self.creep_hold_s, self.creep_rpm)]
        pts.append((t + self.start_up_s, self.rpm))
        pts.append((t + self.duration_s, self.rpm))
        if self.stop:
            pts += [(t + self.duration_s + self.stop_s, 0.0), (self.total_s, 0.0)]
        return np.asarray(pts, dtype=float)

    @property
    def end_depth_m(self) -> float:
        """Recorded bit depth at the end of the stand [m] (after drilling ``rop_m_h``, or
        reaming ``travel_m``)."""
        drilled = self.rop_m_h / 3600.0 * self.duration_s if self.on_bottom else 0.0
        return self.bit_depth_m + drilled + self.travel_m

    @property
    def moving(self) -> bool:
        """The pipe moves along the hole while it turns (reaming or back-reaming)."""
        return self.axial_speed_m_s != 0.0

    def axial_knots(self) -> np.ndarray:
        """Axial pipe speed (t [s] from stand start, v [m/s]) knots of the trapezoid: at rest
        until ``axial_delay_s`` after the start-up, ``axial_ramp_s`` up to the speed, held,
        ``axial_ramp_s`` down to rest at the start of the stop."""
        begin = self.idle_s + self.start_up_s + self.axial_delay_s
        end = self.idle_s + self.duration_s
        v, ramp = self.axial_speed_m_s, self.axial_ramp_s
        return np.array([(0.0, 0.0), (begin, 0.0), (begin + ramp, v), (end - ramp, v),
                         (end, 0.0), (max(self.total_s, end), 0.0)])

    @property
    def travel_m(self) -> float:
        """Signed distance the pipe moves along the hole in the stand [m] (+ running in):
        the integral of the trapezoid of :meth:`axial_knots`."""
        if not self.moving:
            return 0.0
        knots = self.axial_knots()
        return float(np.sum(np.diff(knots[:, 0]) * 0.5 * (knots[1:, 1] + knots[:-1, 1])))

    @property
    def plant_depth_m(self) -> float:
        """Bit depth of the string the plant models [m]: ``bit_depth_m``, or the middle of
        the travel of a reaming stand (the median depth of its reaming rows)."""
        return self.bit_depth_m + 0.5 * self.travel_m

    @property
    def reach_m(self) -> float:
        """Deepest bit depth the stand's plant or its travel needs the hole to reach [m]."""
        return max(self.bit_depth_m, self.bit_depth_m + self.travel_m)

    @property
    def on_bottom(self) -> bool:
        """Bit on bottom (WOB > 0)."""
        return self.wob_N > 0


@dataclass(frozen=True)
class Scenario:
    """Stands separated by connections.

    Attributes
    ----------
    stands : tuple of Stand
    connection_s : float
        Time between the end of one stand and the start of the next [s] (rotation 0,
        torque released, string in slips, bit moved to the next depth).
    """

    stands: tuple[Stand, ...]
    connection_s: float = 60.0

    @property
    def total_s(self) -> float:
        """Recorded length of the whole scenario [s]."""
        return sum(s.total_s for s in self.stands) + self.connection_s * (len(self.stands) - 1)


_STAND_FIELDS = {f for f in Stand.__dataclass_fields__ if f != "stop"}


def _stand_from_dict(raw: dict, defaults: dict, where: str, file) -> Stand:
    merged = defaults | raw
    unknown = set(merged) - _STAND_FIELDS
    if unknown:
        raise ConfigError(f"unknown key '{sorted(unknown)[0]}' in {where}", file=file,
                          fix=f"use one of: {', '.join(sorted(_STAND_FIELDS))}")
    if "bit_depth_m" not in merged:
        raise ConfigError(f"{where} needs bit_depth_m", file=file)
    values = {}
    for key, value in merged.items():
        if key in ("setpoint_rpm", "motor_torque_Nm", "mu_k_schedule"):
            values[key] = _series(value, f"{where}.{key}", file)
        elif key == "start":
            if value not in _STARTS:
                raise ConfigError(f"{where}.start must be 'ramp' or 'creep', got {value!r}",
                                  file=file)
            values[key] = value
        else:
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ConfigError(f"{where}.{key} must be a number, got {value!r}", file=file)
            values[key] = float(value)
    stand = Stand(**values)
    _check_stand(stand, where, file)
    return stand


def _series(value, where: str, file) -> tuple:
    try:
        pts = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        pts = np.empty((0, 0))
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2 or np.any(np.diff(pts[:, 0]) < 0) \
            or pts[0, 0] != 0.0 or not np.all(np.isfinite(pts)):
        raise ConfigError(f"{where} must be [[t_s, value], ...] from t = 0, times "
                          "non-decreasing, at least two points", file=file)
    return tuple(map(tuple, pts.tolist()))


def _check_stand(stand: Stand, where: str, file) -> None:
    positive = ("bit_depth_m", "duration_s", "ramp_s", "creep_ramp_s", "creep_hold_s",
                "bit_weakening_rpm")
    for key in positive:
        if not getattr(stand, key) > 0:
            raise ConfigError(f"{where}.{key} must be > 0, got {getattr(stand, key)}",
                              file=file)
    for key in ("rpm", "creep_rpm", "idle_s", "stop_s", "stop_hold_s", "wob_N", "rop_m_h",
                "flow_m3_s"):
        if getattr(stand, key) < 0:
            raise ConfigError(f"{where}.{key} must be ≥ 0, got {getattr(stand, key)}",
                              file=file)
    inertia = stand.top_drive_inertia_kg_m2
    if inertia is not None and not (np.isfinite(inertia) and inertia > 0):
        raise ConfigError(f"{where}.top_drive_inertia_kg_m2 must be > 0, got {inertia}",
                          file=file, fix="leave it out to use rig.top_drive_inertia_kg_m2")
    if not 1.0 <= stand.bit_weakening_ratio <= 10.0:
        raise ConfigError(f"{where}.bit_weakening_ratio must be in [1, 10], got "
                          f"{stand.bit_weakening_ratio}", file=file,
                          fix="1 is the Coulomb bit; r > 1 a bit that is stronger at rest")
    if stand.setpoint_rpm is None and stand.start_up_s > stand.duration_s:
        raise ConfigError(f"{where}: the start-up ({stand.start_up_s:g} s) is longer than "
                          f"duration_s ({stand.duration_s:g} s)", file=file,
                          fix="increase duration_s or shorten the ramp/creep")
    if stand.moving:
        _check_reaming(stand, where, file)
    if stand.mu_k_schedule is not None:
        factors = np.asarray(stand.mu_k_schedule)[:, 1]
        if not np.all((factors > 0) & (factors <= MAX_FRICTION_FACTOR)):
            raise ConfigError(f"{where}.mu_k_schedule factors must be in (0, "
                              f"{MAX_FRICTION_FACTOR:g}], got {factors.min():g}…"
                              f"{factors.max():g}", file=file,
                              fix="a factor multiplies the configured μ_k and μ_s: 1 keeps "
                                  "them, 1.3 is 30 % more friction")


#: Largest factor a ``mu_k_schedule`` may put on the configured friction [-] (μ up to 8× is
#: beyond any hole; the friction search stops at ``observer.mu_max``).
MAX_FRICTION_FACTOR = 8.0


def step_interp(t: np.ndarray, t_pts: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Piecewise-linear interpolation where a repeated knot time is a step (right value),
    held outside the knots.

    Examples
    --------
    >>> step_interp(np.array([0.0, 1.0, 1.5, 2.0, 9.0]), np.array([0.0, 1.0, 1.0, 3.0]),
    ...             np.array([1.0, 1.0, 2.0, 3.0])).tolist()
    [1.0, 2.0, 2.25, 2.5, 3.0]
    """
    idx = np.searchsorted(t_pts, t, side="right")
    idx = np.clip(idx, 1, len(t_pts) - 1)
    t0, t1 = t_pts[idx - 1], t_pts[idx]
    v0, v1 = values[idx - 1], values[idx]
    span = np.where(t1 > t0, t1 - t0, 1.0)
    frac = np.clip((t - t0) / span, 0.0, 1.0)
    return np.where(t >= t_pts[-1], values[-1], v0 + frac * (v1 - v0))


#: Fastest axial pipe speed a stand may ream at [m/s] (trips run at up to ~1.5 m/s).
MAX_AXIAL_SPEED_M_S = 1.5


def _check_reaming(stand: Stand, where: str, file) -> None:
    """A reaming stand turns off bottom on the PI set-point shape, within the trip speeds,
    with room in its hold for the block's two ramps."""
    if not abs(stand.axial_speed_m_s) <= MAX_AXIAL_SPEED_M_S:
        raise ConfigError(f"{where}.axial_speed_m_s must be within ±{MAX_AXIAL_SPEED_M_S:g} "
                          f"m/s, got {stand.axial_speed_m_s:g}", file=file)
    if stand.on_bottom or stand.rpm <= 0:
        raise ConfigError(f"{where}: reaming (axial_speed_m_s ≠ 0) turns off bottom: it needs "
                          "rpm > 0 and wob_N = 0", file=file,
                          fix="drill in a stand of its own; ream with rpm > 0")
    if stand.setpoint_rpm is not None or stand.motor_torque_Nm is not None:
        raise ConfigError(f"{where}: reaming takes the set-point shape (rpm), not "
                          "setpoint_rpm or motor_torque_Nm", file=file,
                          fix="give rpm, ramp_s and duration_s")
    if stand.axial_delay_s < 0 or stand.axial_ramp_s < 0:
        raise ConfigError(f"{where}.axial_delay_s and axial_ramp_s must be ≥ 0", file=file)
    room = stand.duration_s - stand.start_up_s - stand.axial_delay_s
    if room < 2.0 * stand.axial_ramp_s:
        raise ConfigError(f"{where}: the axial motion has {room:g} s between the start-up plus "
                          f"axial_delay_s and the stop, less than its two ramps "
                          f"(2 × {stand.axial_ramp_s:g} s)", file=file,
                          fix="increase duration_s or shorten axial_delay_s/axial_ramp_s")


def load_scenario(path: str | Path, base: Stand) -> Scenario:
    """Read a scenario TOML file (format: module docstring and docs/simulator.md).

    Parameters
    ----------
    path : str or Path
    base : Stand
        Defaults for every stand (from the ``[simulate]`` configuration); the file's
        ``[defaults]`` table and each ``[[stand]]`` override them.
    """
    raw = read_toml(path)
    allowed = {"connection_s", "defaults", "stand"}
    for key in raw:
        if key not in allowed:
            raise ConfigError(f"unknown key '{key}' in scenario", file=path,
                              fix="use connection_s, [defaults] and [[stand]]")
    stands_raw = raw.get("stand")
    if not isinstance(stands_raw, list) or not stands_raw:
        raise ConfigError("a scenario needs at least one [[stand]] with bit_depth_m",
                          file=path)
    defaults = raw.get("defaults", {})
    if not isinstance(defaults, dict):
        raise ConfigError("[defaults] must be a table", file=path)
    base_dict = {k: v for k, v in asdict(base).items()
                 if k in _STAND_FIELDS - {"bit_depth_m"} and v is not None}
    stands = tuple(_stand_from_dict(s, base_dict | defaults, f"stand[{i}]", path)
                   for i, s in enumerate(stands_raw, start=1))
    connection = raw.get("connection_s", 60.0)
    if isinstance(connection, bool) or not isinstance(connection, int | float) \
            or connection < 0:
        raise ConfigError(f"connection_s must be a number ≥ 0, got {connection!r}", file=path)
    return Scenario(stands, float(connection))


def base_stand(cfg: Config) -> Stand:
    """Stand defaults from the ``[simulate]`` table (bit depth filled in by the caller)."""
    return Stand(bit_depth_m=cfg.simulate.bit_depth_m or float("nan"),
                 duration_s=cfg.simulate.duration_s, rpm=cfg.simulate.rpm,
                 ramp_s=cfg.simulate.ramp_s, wob_N=cfg.simulate.wob_N,
                 bit_weakening_ratio=cfg.simulate.bit_weakening_ratio,
                 bit_weakening_rpm=cfg.simulate.bit_weakening_rpm,
                 flow_m3_s=cfg.simulate.flow_m3_s)


def single_stand(cfg: Config, bit_depth_m: float) -> Scenario:
    """A single stand (no stop): rest, ramp to ``simulate.rpm``, hold to ``duration_s``."""
    stand = replace(base_stand(cfg), bit_depth_m=bit_depth_m, idle_s=0.0, stop=False)
    if stand.ramp_s > stand.duration_s:
        stand = replace(stand, ramp_s=stand.duration_s)
    return Scenario((stand,), 0.0)
