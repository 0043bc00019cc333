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
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric import torsional
from drillfric.config import Config
from drillfric.drillstring import build_string
from drillfric.errors import ConfigError, InputError, ModelError
from drillfric.io.text import plural
from drillfric.sim.scenario import Scenario, Stand, base_stand, load_scenario, single_stand
from drillfric.sim.settings import Noise, PlantSettings
from drillfric.units import RPM_TO_RAD_S
from drillfric.wellpath import WellPath, no_survey_path

_SERIES_DT_S = 0.01  # [s] sampling of the set-point series handed to the kernel
#: CPU time of one plant cell-step [s] (0.52–0.55 ns measured, docs/performance.md;
#: rounded up so the work estimate errs high).
SIM_CELL_STEP_S = 1.0e-9
#: Budget of one simulation [CPU s] (a 24-h well at 500 cells takes ≈ 20 s).
MAX_SIM_CPU_S = 3600.0
#: Fewest rows a simulated stand records (fewer is no record to estimate from).
MIN_STAND_ROWS = 10
#: Most rows one simulation records (each ~15 channels of 8 bytes, held in memory).
MAX_SIM_ROWS = 5e7


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
        """One line: the truth, the stands' bit depths [m], rows, rate and span [s], columns."""
        time = np.asarray(self.columns.get("time_s", ()), dtype=float)
        span = f", {time[-1] - time[0]:.0f} s" if time.size else ""
        depths = [s.bit_depth_m for s in self.stands]
        bits = f" at bit {min(depths):.0f}–{max(depths):.0f} m" if depths else ""
        return (f"<Simulation μ_s {self.settings.mu_s:g}, μ_k {self.settings.mu_k:g}: "
                f"{plural(len(self.stands), 'stand')}{bits}, {plural(time.size, 'row')} at "
                f"{self.rate_hz:g} Hz{span}; columns {', '.join(self.columns)}>")

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
    _check_bounded(columns, cfg)
    if not any(s.on_bottom for s in scenario.stands):
        columns.pop("wob_N")
    block = cfg.hookload.block_weight_N
    columns["hookload_N"] = columns["hookload_N"] + (block or 0.0)
    noise.apply(columns)
    notes = _notes(stands)
    return Simulation(columns, tuple(stands), settings, noise, rate, notes)


#: Largest |speed| [RPM] and |torque| [N·m] a simulated top drive may show: beyond, the
#: plant has diverged (a controller too stiff for the time step), not drilled.
_DIVERGED_RPM, _DIVERGED_NM = 1e5, 1e10


def _check_bounded(columns: dict, cfg: Config) -> None:
    """ModelError when the recorded surface channels are not finite or beyond any drive's
    (a top-drive controller gain that makes the explicit scheme diverge: written out, the
    file held inf and 1e305 with exit 0)."""
    rpm, torque = columns["surface_rpm"], columns["surface_torque_Nm"]
    if not (np.all(np.isfinite(rpm)) and np.all(np.isfinite(torque)) and
            np.max(np.abs(rpm), initial=0.0) < _DIVERGED_RPM and
            np.max(np.abs(torque), initial=0.0) < _DIVERGED_NM):
        raise ModelError("the simulated plant diverged (the top drive's speed or torque ran "
                         "to infinity): its controller is too stiff for the time step",
                         file=cfg.source, fix="lower [simulate] kp_Nms_rad and ki_Nm_rad "
                                              "(or raise cells)")


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
    short = min(st.total_s for st in scenario.stands) * rate_hz
    if short < MIN_STAND_ROWS:
        raise ConfigError(f"a stand of {min(st.total_s for st in scenario.stands):.4g} s at "
                          f"{rate_hz:g} Hz records {short:.3g} rows; a record needs at least "
                          f"{MIN_STAND_ROWS} per stand", file=cfg.source,
                          fix="a higher [simulate] rate_hz (--rate) or longer stands")
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


def _run_stand(cfg: Config, settings, path, stand: Stand, index: int, t0: float, rate: float):
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


def _connection(t0: float, span: float, rate: float, before: Stand, after: Stand, cfg: Config):
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
