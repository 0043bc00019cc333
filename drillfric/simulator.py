"""Synthetic rig data with ground truth: the torsional plant driven stand by stand.

The pipeline behind ``drillfric simulate`` (docs/cli.md). For each stand of a
:class:`Scenario` the drill string is rebuilt at the stand's bit depth
(:func:`drillfric.drillstring.build_string`), its Coulomb capacity profile F_c(x) and hook
load come from soft-string torque and drag (:mod:`drillfric.torque_drag`, docs/theory.md §2), and
the plant of docs/theory.md §3 (:mod:`drillfric.torsional`) is run from rest under a PI
top-drive speed controller following the stand's set-point schedule (or a prescribed motor
torque). Between stands the rotation is stopped, the trapped torque released and the bit
moved to the next depth (a connection: speed and torque recorded as zero, the hook load
as the block weight ``hookload.block_weight_N``, 0 when not given — the string is in the
slips). The block weight is on the hook load throughout.
Measurement noise and quantisation are added last, seeded.

A scenario file (TOML, see docs/simulator.md)::

    connection_s = 60.0            # stop between stands
    [defaults]                     # any stand key, for every stand
    rpm = 40.0
    duration_s = 180.0
    [[stand]]
    bit_depth_m = 2000.0
    start = "creep"                # 0 → 5 RPM in 5 s, hold 30 s, then ramp to rpm
    [[stand]]
    bit_depth_m = 2030.0
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric import torsional
from drillfric.config import Config, read_toml
from drillfric.drillstring import DrillString, Section, build_string
from drillfric.errors import ConfigError, InputError, ModelError
from drillfric.units import RPM_TO_RAD_S
from drillfric.wellpath import WellPath, no_survey_path

_SERIES_DT_S = 0.01  # [s] sampling of the set-point series handed to the kernel
_STARTS = ("ramp", "creep")
#: CPU time of one plant cell-step [s] (0.52–0.55 ns measured, docs/performance.md;
#: rounded up so the work estimate errs high).
SIM_CELL_STEP_S = 1.0e-9
#: Budget of one simulation [CPU s] (a 24-h well at 500 cells takes ≈ 20 s).
MAX_SIM_CPU_S = 3600.0
#: Most rows one simulation records (each ~15 channels of 8 bytes, held in memory).
MAX_SIM_ROWS = 5e7


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
    setpoint_rpm : tuple of (t_s, rpm), optional
        Explicit piecewise-linear set-point from the start of the stand (replaces the
        start-up/hold/stop shape; a repeated time makes a step).
    motor_torque_Nm : tuple of (t_s, N·m), optional
        Prescribed motor torque instead of the PI controller.
    stop : bool
        Stop rotation at the end (False for a single-stand run).
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
    setpoint_rpm: tuple | None = None
    motor_torque_Nm: tuple | None = None
    stop: bool = True

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
        """Recorded bit depth at the end of the stand [m] (after drilling ``rop_m_h``)."""
        drilled = self.rop_m_h / 3600.0 * self.duration_s if self.on_bottom else 0.0
        return self.bit_depth_m + drilled

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
        if key in ("setpoint_rpm", "motor_torque_Nm"):
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
    for key in ("rpm", "creep_rpm", "idle_s", "stop_s", "stop_hold_s", "wob_N", "rop_m_h"):
        if getattr(stand, key) < 0:
            raise ConfigError(f"{where}.{key} must be ≥ 0, got {getattr(stand, key)}",
                              file=file)
    if not 1.0 <= stand.bit_weakening_ratio <= 10.0:
        raise ConfigError(f"{where}.bit_weakening_ratio must be in [1, 10], got "
                          f"{stand.bit_weakening_ratio}", file=file,
                          fix="1 is the Coulomb bit; r > 1 a bit that is stronger at rest")
    if stand.setpoint_rpm is None and stand.start_up_s > stand.duration_s:
        raise ConfigError(f"{where}: the start-up ({stand.start_up_s:g} s) is longer than "
                          f"duration_s ({stand.duration_s:g} s)", file=file,
                          fix="increase duration_s or shorten the ramp/creep")


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
                 bit_weakening_rpm=cfg.simulate.bit_weakening_rpm)


def single_stand(cfg: Config, bit_depth_m: float) -> Scenario:
    """A single stand (no stop): rest, ramp to ``simulate.rpm``, hold to ``duration_s``."""
    stand = replace(base_stand(cfg), bit_depth_m=bit_depth_m, idle_s=0.0, stop=False)
    if stand.ramp_s > stand.duration_s:
        stand = replace(stand, ramp_s=stand.duration_s)
    return Scenario((stand,), 0.0)


@dataclass(frozen=True)
class Noise:
    """Measurement errors added to the recorded surface channels.

    Attributes
    ----------
    rpm_sd, torque_sd_Nm, hookload_sd_N : float
        Standard deviations of Gaussian noise [RPM], [N·m], [N].
    rpm_step, torque_step_Nm : float
        Quantisation steps (0: none) [RPM], [N·m].
    seed : int
    """

    rpm_sd: float = 0.0
    torque_sd_Nm: float = 0.0
    hookload_sd_N: float = 0.0
    rpm_step: float = 0.0
    torque_step_Nm: float = 0.0
    seed: int = 0

    @classmethod
    def from_config(cls, cfg: Config) -> Noise:
        """Noise settings of the ``[simulate]`` table."""
        return cls(cfg.simulate.rpm_noise, cfg.simulate.torque_noise_Nm,
                   cfg.simulate.hookload_noise_N, cfg.simulate.rpm_resolution,
                   cfg.simulate.torque_resolution_Nm, cfg.simulate.seed)

    def apply(self, columns: dict[str, np.ndarray]) -> None:
        """Add noise then quantise ``surface_rpm``, ``surface_torque_Nm``, ``hookload_N``."""
        rng = np.random.default_rng(self.seed)
        for name, sd, step in (("surface_rpm", self.rpm_sd, self.rpm_step),
                               ("surface_torque_Nm", self.torque_sd_Nm, self.torque_step_Nm),
                               ("hookload_N", self.hookload_sd_N, 0.0)):
            x = columns[name]
            if sd > 0:
                x = x + rng.normal(0.0, sd, x.size)
            if step > 0:
                x = np.round(x / step) * step
            columns[name] = np.maximum(x, 0.0) if name == "hookload_N" else x


@dataclass(frozen=True)
class PlantSettings:
    """Physical settings shared by every stand (from the configuration).

    Attributes
    ----------
    mu_s, mu_k : float
        True friction factors [-] (of the open hole when the cased ones are given).
    omega_c_rad_s, k_t_per_s, top_drive_inertia_kg_m2 : float
        ω_c [rad/s], k_t [1/s], I_TD [kg·m²].
    kp_Nms_rad, ki_Nm_rad : float
        PI gains.
    cells : int
        Requested cells of the torsional model.
    bit_mu, bit_diameter_m : float
        Bit-torque model T_bit = μ_bit·WOB·D/3.
    torque_kind : str
        "motor" records τ_m as surface torque, "string" records τ(0).
    friction_law : str
        "step" or "stribeck" (docs/theory.md §3.2).
    stribeck_speed_rad_s, stribeck_exponent : float
        Stribeck decay speed v_s [rad/s] and exponent δ (used by "stribeck").
    casing_shoe_md_m : float, optional
        Casing shoe [m]; with ``mu_s_cased``, ``mu_k_cased`` the truth above it.
    mu_s_cased, mu_k_cased : float, optional
        True friction factors above the shoe (the fixed part of the profile) [-].
    """

    mu_s: float
    mu_k: float
    omega_c_rad_s: float
    k_t_per_s: float
    top_drive_inertia_kg_m2: float
    kp_Nms_rad: float
    ki_Nm_rad: float
    cells: int = 500
    bit_mu: float = 0.3
    bit_diameter_m: float = 0.2159
    torque_kind: str = "motor"
    friction_law: str = "step"
    stribeck_speed_rad_s: float = 1.0
    stribeck_exponent: float = 1.0
    casing_shoe_md_m: float | None = None
    mu_s_cased: float | None = None
    mu_k_cased: float | None = None

    @property
    def cased(self) -> bool:
        """The truth has its own friction factors above the casing shoe."""
        return self.mu_k_cased is not None

    def zones(self) -> list[dict]:
        """Truth of each friction zone: name, measured-depth span [m], μ_s, μ_k."""
        shoe = self.casing_shoe_md_m if self.cased else None
        zones = [{"zone": "open" if shoe is not None else "whole string",
                  "md_from_m": shoe or 0.0, "md_to_m": None, "mu_s": self.mu_s,
                  "mu_k": self.mu_k}]
        if shoe is not None:
            zones.insert(0, {"zone": "cased", "md_from_m": 0.0, "md_to_m": shoe,
                             "mu_s": self.mu_s_cased, "mu_k": self.mu_k_cased})
        return zones

    @classmethod
    def from_config(cls, cfg: Config) -> PlantSettings:
        """Settings of a configuration; raises ModelError for meaningless ones."""
        out = cls(mu_s=cfg.simulate.mu_s, mu_k=cfg.simulate.mu_k,
                  omega_c_rad_s=cfg.omega_c_rad_s, k_t_per_s=cfg.model.k_t_per_s,
                  top_drive_inertia_kg_m2=cfg.rig.top_drive_inertia_kg_m2,
                  kp_Nms_rad=cfg.simulate.kp_Nms_rad, ki_Nm_rad=cfg.simulate.ki_Nm_rad,
                  cells=cfg.simulate.cells, bit_mu=cfg.simulate.bit_mu,
                  bit_diameter_m=cfg.simulate.bit_diameter_m,
                  torque_kind=cfg.rig.torque_kind,
                  friction_law=cfg.simulate.friction_law,
                  stribeck_speed_rad_s=cfg.simulate.stribeck_speed_rad_s,
                  stribeck_exponent=cfg.simulate.stribeck_exponent,
                  casing_shoe_md_m=cfg.model.casing_shoe_md_m,
                  mu_s_cased=cfg.simulate.mu_s_cased, mu_k_cased=cfg.simulate.mu_k_cased)
        for zone, mu_s, mu_k in (("", out.mu_s, out.mu_k),
                                 ("_cased", out.mu_s_cased, out.mu_k_cased)):
            if mu_k is not None and mu_s is not None and mu_k > mu_s:
                raise ModelError(f"μ_k = {mu_k} is larger than μ_s = {mu_s}",
                                 file=cfg.source, fix="the kinetic friction factor cannot "
                                 f"exceed the static one (simulate.mu_k{zone} ≤ "
                                 f"simulate.mu_s{zone})")
        if (out.mu_s_cased is None) != (out.mu_k_cased is None):
            raise ConfigError("simulate.mu_s_cased and simulate.mu_k_cased go together",
                              file=cfg.source, fix="give both (or neither)")
        if out.cased and out.casing_shoe_md_m is None:
            raise ConfigError("simulate.mu_s_cased/mu_k_cased need a casing shoe",
                              file=cfg.source, fix="set model.casing_shoe_md_m")
        return out

    def cased_share(self, grid: torsional.Grid) -> np.ndarray:
        """Share of each cell's true length above the casing shoe [-] (zeros without a cased
        truth)."""
        if not self.cased:
            return np.zeros(grid.n_cells)
        top = grid.x_m - 0.5 * grid.dx_true_m
        return np.clip((self.casing_shoe_md_m - top) / grid.dx_true_m, 0.0, 1.0)

    def plant(self, grid: torsional.Grid, fc_Nm_m: np.ndarray, bit_torque_cap_Nm: float,
              bit_weakening_ratio: float = 1.0,
              bit_weakening_rpm: float = 10.0) -> torsional.Plant:
        """The true plant on ``grid`` with the capacity profile F_c at the cell centres and
        the bit T_k = ``bit_torque_cap_Nm`` [N·m], r, ω_b [RPM] (:class:`Stand`).

        With a cased truth, each cell's F_c is split by the share of its true length above
        the shoe: that share times μ_k_cased, μ_s_cased is the fixed part of the profile,
        the rest is the open hole that μ_s, μ_k multiply (docs/theory.md §3.2).
        """
        fixed_k = fixed_s = None
        if self.cased:
            cased = self.cased_share(grid)
            fixed_k = self.mu_k_cased * cased * fc_Nm_m
            fixed_s = self.mu_s_cased * cased * fc_Nm_m
            fc_Nm_m = (1.0 - cased) * fc_Nm_m
        stribeck = self.friction_law == "stribeck"
        return torsional.Plant(grid, fc_Nm_m, self.mu_s, self.mu_k, self.omega_c_rad_s,
                               self.k_t_per_s, self.top_drive_inertia_kg_m2, bit_torque_cap_Nm,
                               fixed_k, fixed_s,
                               self.stribeck_speed_rad_s if stribeck else None,
                               self.stribeck_exponent, bit_weakening_ratio,
                               bit_weakening_rpm * RPM_TO_RAD_S)


@dataclass(frozen=True)
class StandResult:
    """Truth of one simulated stand (times on the global clock).

    ``T_N_Nm`` is ∫F_c dx over the part of the string whose truth is ``mu_s``, ``mu_k``
    (the open hole with a cased truth, else the whole string), ``T_N_cased_Nm`` over the
    cased part (0 without a cased truth) [N·m per unit friction factor].
    ``bit_torque_time_mean_Nm`` is the time-mean of the torque the bit applied from the end of the
    start-up to the start of the stop [N·m] (0 off bottom): with a rate-weakening bit in
    stick-slip it differs from ``bit_torque_k_Nm`` = T_k = μ_bit·WOB·D_bit/3.
    ``bit_power_torque_Nm`` is the bit's mean power over its mean speed over the same span,
    ⟨τ_bit·ω_bit⟩/⟨ω_bit⟩ [N·m] (docs/theory.md §2.3): the torque Teale's MSE and μ_bit
    describe — a stuck bit's holding torque does no work and is not in it.
    """

    index: int
    bit_depth_m: float
    t_start_s: float
    t_rotation_start_s: float
    t_end_s: float
    start: str
    rpm: float
    wob_N: float
    T_N_Nm: float
    hookload_N: float
    cells: int
    dt_s: float
    max_rounding_m: float
    bit_stuck_fraction: float
    creep_end_s: float | None = None
    T_N_cased_Nm: float = 0.0
    bit_torque_time_mean_Nm: float = 0.0
    bit_torque_k_Nm: float = 0.0
    bit_weakening_ratio: float = 1.0
    bit_weakening_rpm: float = 10.0
    bit_power_torque_Nm: float = 0.0


@dataclass(frozen=True)
class Simulation:
    """Result of :func:`simulate`.

    Attributes
    ----------
    columns : dict of ndarray
        Canonical surface channels (docs/ingestion.md) plus the noise-free truth ``bit_rpm``
        and ``string_torque_Nm`` (τ(0) = τ_m − I_TD dω₀/dt).
    stands : tuple of StandResult
    settings : PlantSettings
    noise : Noise
    rate_hz : float
    """

    columns: dict
    stands: tuple
    settings: PlantSettings
    noise: Noise
    rate_hz: float
    notes: tuple = field(default_factory=tuple)

    def __repr__(self) -> str:
        n = len(next(iter(self.columns.values()), ()))
        return (f"<Simulation μ_s {self.settings.mu_s:g}, μ_k {self.settings.mu_k:g}: "
                f"{len(self.stands)} stand{'s' * (len(self.stands) != 1)}, {n} rows at "
                f"{self.rate_hz:g} Hz; columns {', '.join(self.columns)}>")

    def truth(self) -> dict:
        """Ground truth as plain data (NAME.truth.json, file metadata)."""
        from drillfric._version import __version__

        law = {"friction_law": self.settings.friction_law}
        if self.settings.friction_law == "stribeck":
            law |= {"stribeck_speed_rad_s": self.settings.stribeck_speed_rad_s,
                    "stribeck_exponent": self.settings.stribeck_exponent}
        return {"drillfric_version": __version__, "mu_s": self.settings.mu_s,
                "mu_k": self.settings.mu_k, **law, "zones": self.settings.zones(),
                "settings": asdict(self.settings),
                "noise": asdict(self.noise), "rate_hz": self.rate_hz,
                "stands": [asdict(s) for s in self.stands], "notes": list(self.notes)}


def fc_profile(cfg: Config, path: WellPath | None, bit_depth_m: float, wob_N: float = 0.0):
    """Soft-string F_c profile and hook load at a bit depth (docs/theory.md §2, rotating).

    Returns the :class:`~drillfric.torque_drag.TDResult` of the rotating off-bottom case, or
    on bottom with ``wob_N`` when it is positive.
    """
    from drillfric.torque_drag import solve_config

    if wob_N > 0:
        return solve_config(cfg, path, bit_depth_m, load_case="rotating_on_bottom",
                            wob_N=wob_N)
    return solve_config(cfg, path, bit_depth_m, load_case="rotating_off_bottom")


def check_depths(scenario: Scenario, path: WellPath | None, file=None) -> None:
    """Every stand must lie within the survey (raises InputError)."""
    if path is None:
        return
    for i, stand in enumerate(scenario.stands, start=1):
        if stand.bit_depth_m > path.md_max_m + 1e-6:
            raise InputError(f"stand {i} at {stand.bit_depth_m:g} m is deeper than the survey "
                             f"({path.md_max_m:g} m)", file=file,
                             fix="extend the survey or move the stand up")


def _drive(stand: Stand, settings: PlantSettings) -> torsional.Drive:
    if stand.motor_torque_Nm is not None:
        pts = np.asarray(stand.motor_torque_Nm, dtype=float)
        kind, t_pts, values = "torque", pts[:, 0] + stand.idle_s, pts[:, 1]
        t_pts, values = np.concatenate([[0.0], t_pts]), np.concatenate([[0.0], values])
    else:
        knots = stand.knots()
        kind, t_pts, values = "pi", knots[:, 0], knots[:, 1] * RPM_TO_RAD_S
    t = np.arange(0.0, stand.total_s + _SERIES_DT_S, _SERIES_DT_S)
    return torsional.Drive(kind, _interp_steps(t, t_pts, values), _SERIES_DT_S, 0.0,
                           settings.kp_Nms_rad, settings.ki_Nm_rad)


def _interp_steps(t: np.ndarray, t_pts: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Piecewise-linear interpolation where a repeated knot time is a step (right value)."""
    idx = np.searchsorted(t_pts, t, side="right")
    idx = np.clip(idx, 1, len(t_pts) - 1)
    t0, t1 = t_pts[idx - 1], t_pts[idx]
    v0, v1 = values[idx - 1], values[idx]
    span = np.where(t1 > t0, t1 - t0, 1.0)
    frac = np.clip((t - t0) / span, 0.0, 1.0)
    return np.where(t >= t_pts[-1], values[-1], v0 + frac * (v1 - v0))


def plant_for(cfg: Config, settings: PlantSettings, path: WellPath | None,
              stand: Stand) -> tuple[torsional.Plant, object]:
    """Plant of one stand: string at the stand's depth, F_c from torque and drag."""
    string = build_string(cfg.sections, stand.bit_depth_m)
    grid = torsional.make_grid(string, settings.cells)
    td = fc_profile(cfg, path, stand.bit_depth_m, stand.wob_N)
    cap = torsional.bit_torque_cap(settings.bit_mu, stand.wob_N, settings.bit_diameter_m)
    plant = settings.plant(grid, td.fc_at(grid.x_m), cap, stand.bit_weakening_ratio,
                           stand.bit_weakening_rpm)
    return plant, td


def simulate(cfg: Config, path: WellPath | None, scenario: Scenario, *,
             rate_hz: float | None = None, noise: Noise | None = None,
             progress: Callable[[float], None] | None = None) -> Simulation:
    """Simulate a scenario stand by stand (docs/theory.md §3) and build the surface channels.

    Parameters
    ----------
    cfg : Config
        Well configuration (string, mud, rig, model, simulate tables).
    path : WellPath or None
        Well path; when None, the path ``run`` assumes without a survey (vertical with the
        nominal tortuosity ``survey.tortuosity_deg_30m``) to the deepest stand.
    scenario : Scenario
    rate_hz : float, optional
        Recording rate [Hz] (default ``simulate.rate_hz``).
    noise : Noise, optional
        Measurement errors (default from the configuration).
    progress : callable, optional
        Called with the simulated seconds after each stand.

    Returns
    -------
    Simulation
    """
    rate = cfg.simulate.rate_hz if rate_hz is None else rate_hz
    if not rate > 0:
        raise ModelError(f"recording rate must be positive, got {rate} Hz")
    settings = PlantSettings.from_config(cfg)
    noise = Noise.from_config(cfg) if noise is None else noise
    check_depths(scenario, path, cfg.source)
    check_work(cfg, settings, scenario, rate)
    if path is None:
        path = no_survey_path(max(s.bit_depth_m for s in scenario.stands),
                              cfg.tortuosity_rad_m)
    parts, stands, t0 = [], [], 0.0
    for i, stand in enumerate(scenario.stands):
        if i > 0 and scenario.connection_s > 0:
            parts.append(_connection(t0, scenario.connection_s, rate,
                                     scenario.stands[i - 1], stand, cfg))
            t0 += scenario.connection_s
        cols, result = _run_stand(cfg, settings, path, stand, i + 1, t0, rate)
        parts.append(cols)
        stands.append(result)
        t0 += stand.total_s
        if progress is not None:
            progress(stand.total_s + (scenario.connection_s if i > 0 else 0.0))
    columns = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    keep = np.concatenate([[True], np.diff(columns["time_s"]) > 0.5 / rate])
    columns = {k: v[keep] for k, v in columns.items()}
    if not any(s.on_bottom for s in scenario.stands):
        columns.pop("wob_N")
    block = cfg.hookload.block_weight_N
    columns["hookload_N"] = columns["hookload_N"] + (block or 0.0)
    noise.apply(columns)
    notes = _notes(stands)
    return Simulation(columns, tuple(stands), settings, noise, rate, notes)


def check_work(cfg: Config, settings: PlantSettings, scenario: Scenario,
               rate_hz: float) -> float:
    """The plant's CPU time for ``scenario`` [s], estimated as cells²/t_w cell-steps per
    simulated second (t_w: the wave's travel time along the stand's string; the Courant-1
    grid, docs/theory.md §3.1) at :data:`SIM_CELL_STEP_S` each; and its recorded rows.

    Raises
    ------
    ConfigError
        Beyond :data:`MAX_SIM_CPU_S` (``[simulate] cells`` enters squared), or more than
        :data:`MAX_SIM_ROWS` rows at ``rate_hz``.
    """
    seconds = sum(st.total_s for st in scenario.stands) + \
        scenario.connection_s * max(0, len(scenario.stands) - 1)
    if seconds * rate_hz > MAX_SIM_ROWS:
        raise ConfigError(f"{seconds:.4g} s recorded at {rate_hz:g} Hz is {seconds * rate_hz:.3g} "
                          f"rows; the budget is {MAX_SIM_ROWS:.0e} (≈ 6 days at 100 Hz)",
                          file=cfg.source, fix="a lower [simulate] rate_hz (--rate) or "
                                               "shorter stands")
    cell_steps = 0.0
    for stand in scenario.stands:
        string = build_string(cfg.sections, stand.bit_depth_m)
        travel = sum(sec.length_m / sec.wave_speed_m_s for sec in string.sections)
        cell_steps += stand.total_s * settings.cells ** 2 / travel
    cpu_s = cell_steps * SIM_CELL_STEP_S
    if cpu_s > MAX_SIM_CPU_S:
        raise ConfigError(f"[simulate] cells = {settings.cells} over the scenario's "
                          f"{sum(st.total_s for st in scenario.stands):.0f} s would take ≈ "
                          f"{cpu_s / 3600:.3g} CPU-hours (cost ∝ cells²); the budget is "
                          f"{MAX_SIM_CPU_S / 3600:g}", file=cfg.source,
                          fix="fewer cells (default 2500) or shorter stands")
    return cpu_s


def _run_stand(cfg, settings, path, stand: Stand, index: int, t0: float, rate: float):
    plant, td = plant_for(cfg, settings, path, stand)
    rec, _ = torsional.run(plant, _drive(stand, settings), stand.total_s, rate)
    surface_torque = rec.motor_torque_Nm if settings.torque_kind == "motor" \
        else rec.string_torque_Nm
    n = rec.time_s.size
    off = 0.0 if stand.on_bottom else cfg.simulate.off_bottom_m
    depth = stand.bit_depth_m + _drilled_m(stand, rec.time_s)
    rotating = rec.time_s >= stand.idle_s + stand.start_up_s
    stuck = float(np.mean(np.abs(rec.bit_rad_s[rotating]) < 0.1 * settings.omega_c_rad_s)) \
        if rotating.any() else 0.0
    cols = {"time_s": rec.time_s + t0, "surface_rpm": rec.surface_rad_s / RPM_TO_RAD_S,
            "surface_torque_Nm": surface_torque, "hookload_N": np.full(n, td.hookload_N),
            "bit_depth_m": depth, "hole_depth_m": depth + off,
            "wob_N": np.full(n, stand.wob_N), "bit_rpm": rec.bit_rad_s / RPM_TO_RAD_S,
            "string_torque_Nm": rec.string_torque_Nm}
    grid = plant.grid
    cased_T_N = float(np.sum(settings.cased_share(grid) * td.fc_at(grid.x_m) * grid.dx_true_m))
    creep_end = (t0 + stand.idle_s + stand.creep_ramp_s + stand.creep_hold_s
                 if stand.start == "creep" and stand.setpoint_rpm is None else None)
    result = StandResult(index=index, bit_depth_m=stand.bit_depth_m, t_start_s=t0,
                         t_rotation_start_s=t0 + stand.idle_s, t_end_s=t0 + stand.total_s,
                         start=stand.start, rpm=stand.rpm, wob_N=stand.wob_N,
                         T_N_Nm=plant.T_N_Nm, T_N_cased_Nm=cased_T_N,
                         hookload_N=float(td.hookload_N),
                         cells=plant.grid.n_cells, dt_s=plant.grid.dt_s,
                         max_rounding_m=float(np.max(np.abs(plant.grid.rounding_m))),
                         bit_stuck_fraction=stuck, creep_end_s=creep_end,
                         bit_torque_time_mean_Nm=_mean_bit_torque_Nm(stand, rec),
                         bit_power_torque_Nm=_power_bit_torque_Nm(stand, rec),
                         bit_torque_k_Nm=plant.bit_torque_cap_Nm,
                         bit_weakening_ratio=stand.bit_weakening_ratio,
                         bit_weakening_rpm=stand.bit_weakening_rpm)
    return cols, result


def _mean_bit_torque_Nm(stand: Stand, rec: torsional.Record) -> float:
    """Time-mean of the bit torque the plant applied over the stand's rotation after its
    start-up, up to the stop [N·m] (0 off bottom or without such a span)."""
    held = _drilling_rows(stand, rec)
    return float(np.mean(rec.bit_torque_Nm[held])) if held.any() else 0.0


def _power_bit_torque_Nm(stand: Stand, rec: torsional.Record) -> float:
    """⟨τ_bit·ω_bit⟩/⟨ω_bit⟩ over the rows of :func:`_drilling_rows` [N·m] (0 off bottom,
    without such rows or with the bit at rest throughout)."""
    held = _drilling_rows(stand, rec)
    speed = float(np.mean(rec.bit_rad_s[held])) if held.any() else 0.0
    if speed <= 0:
        return 0.0
    return float(np.mean(rec.bit_torque_Nm[held] * rec.bit_rad_s[held]) / speed)


def _drilling_rows(stand: Stand, rec: torsional.Record) -> np.ndarray:
    """The rows of an on-bottom stand from the end of its start-up to its stop (none off
    bottom)."""
    if not stand.on_bottom:
        return np.zeros(rec.time_s.size, dtype=bool)
    return (rec.time_s >= stand.idle_s + stand.start_up_s) & (
        rec.time_s <= stand.idle_s + stand.duration_s)


def _drilled_m(stand: Stand, time_s: np.ndarray) -> np.ndarray:
    """Depth drilled since the start of an on-bottom stand [m]: ``rop_m_h`` from the start
    of the set-point to the start of the stop (0 off bottom)."""
    if not stand.on_bottom:
        return np.zeros(time_s.size)
    return stand.rop_m_h / 3600.0 * np.clip(time_s - stand.idle_s, 0.0, stand.duration_s)


def _connection(t0: float, span: float, rate: float, before: Stand, after: Stand, cfg):
    """Rows of a connection: no rotation, torque released, in slips, bit moving down."""
    t = t0 + np.arange(1, int(np.floor(span * rate + 1e-9)) + 1) / rate
    t = t[t < t0 + span - 0.5 / rate]
    frac = (t - t0) / span
    depth = before.end_depth_m + frac * (after.bit_depth_m - before.end_depth_m)
    off = cfg.simulate.off_bottom_m
    zero = np.zeros(t.size)
    return {"time_s": t, "surface_rpm": zero, "surface_torque_Nm": zero.copy(),
            "hookload_N": zero.copy(), "bit_depth_m": depth, "hole_depth_m": depth + off,
            "wob_N": zero.copy(), "bit_rpm": zero.copy(), "string_torque_Nm": zero.copy()}


def _notes(stands) -> tuple:
    notes = []
    worst = max(stands, key=lambda s: s.max_rounding_m)
    if worst.max_rounding_m > 0.5:
        notes.append(f"section lengths rounded to whole cells by up to "
                     f"{worst.max_rounding_m:.2f} m (stand {worst.index}); raise model.cells "
                     "to reduce it")
    return tuple(notes)


# ------------------------------------------------------------------ published reference case

#: A&S 2018 Well B BHA sections (docs/reference_cases.md): length, OD, ID [m]; order top-down is
#: drillfric's
#: choice (OD increasing towards the bit).
WELL_B_BHA = ((48.700, 0.150473, 0.096207), (114.800, 0.187322, 0.098912),
              (56.700, 0.209550, 0.071438), (38.880, 0.247280, 0.123391))


def well_b_string(bit_depth_m: float = 2500.0) -> DrillString:
    """A&S 2018 Well B string: 5 7/8in pipe (G = 61 GPa) over the four BHA sections (67 GPa).

    Plain steel (mass from the steel area, ρ = 7850 kg/m³) and contact radius OD/2, as in
    A&S's gravity-only friction model.
    """
    def sec(name, od, id_, length, g):
        return Section(name, od, id_, length, od / 2.0,
                       7850.0 * np.pi * (od**2 - id_**2) / 4.0, g)

    bha = tuple(sec(f"BHA {i}", od, id_, length, 67e9)
                for i, (length, od, id_) in enumerate(WELL_B_BHA, start=1))
    pipe = bit_depth_m - sum(b.length_m for b in bha)
    return DrillString((sec("drill pipe", 0.146529, 0.123024, pipe, 61e9),) + bha)


def well_b_inclination(md_m) -> np.ndarray:
    """Well B inclination [rad]: 0° to 500 m, linear to 60° at 1600 m, 60° below
    (docs/reference_cases.md)."""
    return np.radians(np.interp(md_m, [0.0, 500.0, 1600.0], [0.0, 0.0, 60.0]))


def well_b_plant(cells: int = 500, k_t_per_s: float = 0.1, mu_s: float = 0.885,
                 mu_k: float = 0.425, omega_c_rad_s: float = 0.9) -> torsional.Plant:
    """The A&S 2018 Well B plant at 2500 m MD with its published friction fit
    (docs/reference_cases.md).

    F_c is A&S's gravity-only r_c·g·ρ·A·sin I (docs/theory.md §2, last paragraph); I_TD = 2900
    kg·m².
    """
    string = well_b_string()
    grid = torsional.make_grid(string, cells)
    fc = torsional.gravity_fc(string, well_b_inclination, grid.x_m)
    return torsional.Plant(grid, fc, mu_s, mu_k, omega_c_rad_s, k_t_per_s, 2900.0)


def plan(cfg: Config, config_path: Path | None, well_path: WellPath | None,
         scenario: Path | None = None, single: bool = False) -> tuple[Path | None, Scenario]:
    """The stands to simulate: ``scenario`` (else the configuration's ``[simulate]
    scenario``), or one stand at ``simulate.bit_depth_m`` (else the survey's last station).

    ``single`` ignores the configuration's scenario (a bit depth given on its own).

    Raises
    ------
    ConfigError
        No bit depth from anywhere.
    """
    name = None if single else cfg.simulate.scenario
    base = config_path.parent if config_path is not None else Path(".")
    path = scenario if scenario is not None else (None if name is None else base / name)
    if path is not None:
        return path, load_scenario(path, base_stand(cfg))
    depth = cfg.simulate.bit_depth_m
    if depth is None:
        if well_path is None:
            raise ConfigError("no bit depth: give --bit-depth, simulate.bit_depth_m, a survey "
                              "or a scenario", file=config_path)
        depth = well_path.md_max_m
    return None, single_stand(cfg, depth)


def simulate_config(config, *, out=None, overrides: dict | None = None, survey=None,
                    scenario=None, progress=None) -> Simulation:
    """Simulate the well a configuration describes, and write it when ``out`` is given.

    The survey is ``survey``, else the configuration's ``[survey] file``, else
    ``NAME.survey.csv`` beside the configuration; without one the path ``run`` assumes
    (vertical with the nominal tortuosity). ``out`` gets the data file and its sidecars
    (:func:`drillfric.io.writers.write_well`), the well named after ``out``.
    """
    from drillfric.io.well import open_config
    from drillfric.io.writers import data_format, write_well

    if out is not None:
        data_format(out)
    cfg, survey_path, well_path = open_config(config, survey=survey, overrides=overrides)
    _, stands = plan(cfg, Path(config), well_path, scenario,
                     single=bool(overrides and "simulate.bit_depth_m" in overrides)
                     and scenario is None)
    check_depths(stands, well_path, survey_path)
    result = simulate(cfg, well_path, stands, progress=progress)
    if out is not None:
        if well_path is None:
            well_path = no_survey_path(max(s.bit_depth_m for s in stands.stands),
                                       cfg.tortuosity_rad_m)
        keep = tuple(p for p in (Path(config), survey_path) if p is not None)
        write_well(out, pd.DataFrame(result.columns), config=written_config(cfg),
                   survey=well_path, truth=result.truth(), keep=keep)
    return result


def written_config(cfg: Config) -> dict:
    """The simulated well's configuration as written beside it (``Config.to_dict()``), stating
    the block weight its hook load carries — the configured one, else 0 (the simulated hook
    load is then the string alone) — so that ``run`` can weigh the string without a
    connection in the record (docs/theory.md §2.1)."""
    config = cfg.to_dict()
    hook = dict(config.get("hookload") or {})
    hook["block_weight_N"] = hook.get("block_weight_N") or 0.0
    return config | {"hookload": hook}
