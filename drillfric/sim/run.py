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
from drillfric.config import Config
from drillfric.drillstring import build_string
from drillfric.errors import ConfigError, InputError, ModelError
from drillfric.io.text import plural
from drillfric.sim.recorder import lagged
from drillfric.sim.scenario import (
    Scenario,
    Stand,
    base_stand,
    load_scenario,
    single_stand,
    step_interp,
)
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
    ``mu_k_schedule`` is the open hole's true μ_k in time of a stand whose friction follows
    a schedule, [[t_s on the global clock, μ_k], ...] (None: constant ``mu_k``).
    ``bit_torque_time_mean_Nm`` is the time-mean of the torque the bit applied from the end of the
    start-up to the start of the stop [N·m] (0 off bottom): with a rate-weakening bit in
    stick-slip it differs from ``bit_torque_k_Nm`` = T_k = μ_bit·WOB·D_bit/3.
    ``bit_power_torque_Nm`` is the bit's mean power over its mean speed over the same span,
    ⟨τ_bit·ω_bit⟩/⟨ω_bit⟩ [N·m] (docs/theory.md §2.3): the torque Teale's MSE and μ_bit
    describe — a stuck bit's holding torque does no work and is not in it.
    A reaming stand (docs/simulator.md, Reaming) adds its axial speed ``axial_speed_m_s``
    [m/s] (+ running in), the times its pipe is at that speed (``axial_start_s`` to
    ``axial_end_s``), its signed ``travel_m`` [m], the bit depth its plant models
    while it moves (``plant_bit_depth_m``, the middle of the travel), and the soft-string
    rotating slack-off / pick-up case at the truth's μ_k, |v| and ``rpm`` there:
    ``T_N_moving_Nm`` (the axial friction changes the tension, hence F_N),
    ``hookload_moving_N`` (string only, no block) and ``torque_moving_Nm`` (the steady
    surface torque without the viscous part, docs/theory.md eq. 3.3d). ``T_N_Nm`` and
    ``hookload_N`` stay those of the rotation in place at ``bit_depth_m``.
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
    flow_m3_s: float = 0.0
    bit_power_torque_Nm: float = 0.0
    axial_speed_m_s: float = 0.0
    axial_start_s: float | None = None
    axial_end_s: float | None = None
    travel_m: float = 0.0
    plant_bit_depth_m: float | None = None
    hookload_moving_N: float | None = None
    torque_moving_Nm: float | None = None
    T_N_moving_Nm: float | None = None
    mu_k_schedule: list | None = None


@dataclass(frozen=True)
class Simulation:
    """Result of :func:`simulate`.

    Attributes
    ----------
    columns : dict of ndarray
        Canonical surface channels (docs/ingestion.md; ``flow_in_m3_s`` where a stand
        pumps) plus the noise-free truth ``bit_rpm``, ``string_torque_Nm`` (τ(0) = τ_m −
        I_TD dω₀/dt) and, with a mud motor, ``bha_rpm`` (the string's bottom; ``bit_rpm``
        adds the motor's speed).
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


def moving_profile(cfg: Config, settings: PlantSettings, path: WellPath | None,
                   bit_depth_m: float, axial_speed_m_s: float, rpm: float):
    """Soft-string profile of a string turning at ``rpm`` while it moves at
    ``axial_speed_m_s`` (> 0 running in: ``rotating_slack_off``; < 0 pulling out:
    ``rotating_pick_up``), at the truth's kinetic friction factors (docs/theory.md §2 steps
    3–4, §3.3): the axial share of the friction changes the tension, hence F_N, F_c and the
    hook load, so the factor matters here as it does not for pure rotation."""
    from drillfric.torque_drag import SectionFriction, solve_config

    friction = settings.mu_k
    if settings.cased:
        friction = SectionFriction(settings.casing_shoe_md_m, settings.mu_k_cased,
                                   settings.mu_k)
    case = "rotating_slack_off" if axial_speed_m_s > 0 else "rotating_pick_up"
    return solve_config(cfg, path, bit_depth_m, load_case=case, friction=friction,
                        axial_speed_m_s=abs(axial_speed_m_s), rpm=rpm)


def check_depths(scenario: Scenario, path: WellPath | None, file=None) -> None:
    """Every stand must lie within the survey (raises InputError)."""
    if path is None:
        return
    for i, stand in enumerate(scenario.stands, start=1):
        if stand.bit_depth_m > path.md_max_m + 1e-6:
            raise InputError(f"stand {i} at {stand.bit_depth_m:g} m is deeper than the survey "
                             f"({path.md_max_m:g} m)", file=file,
                             fix="extend the survey or move the stand up")
        if stand.reach_m > path.md_max_m + 1e-6:
            raise InputError(f"stand {i} reams from {stand.bit_depth_m:g} m to "
                             f"{stand.end_depth_m:g} m, deeper than the survey "
                             f"({path.md_max_m:g} m)", file=file,
                             fix="extend the survey, ream up, or shorten the stand")


def check_travel(scenario: Scenario, file=None) -> None:
    """A back-reaming stand must end below the surface (raises InputError)."""
    for i, stand in enumerate(scenario.stands, start=1):
        if stand.bit_depth_m + min(stand.travel_m, 0.0) <= 0.0:
            raise InputError(f"stand {i} back-reams {-stand.travel_m:.4g} m from "
                             f"{stand.bit_depth_m:g} m: the bit would leave the hole",
                             file=file, fix="a slower or shorter back-ream")


def _drive(stand: Stand, settings: PlantSettings) -> torsional.Drive:
    if stand.motor_torque_Nm is not None:
        pts = np.asarray(stand.motor_torque_Nm, dtype=float)
        kind, t_pts, values = "torque", pts[:, 0] + stand.idle_s, pts[:, 1]
        t_pts, values = np.concatenate([[0.0], t_pts]), np.concatenate([[0.0], values])
    else:
        knots = stand.knots()
        kind, t_pts, values = "pi", knots[:, 0], knots[:, 1] * RPM_TO_RAD_S
    t = np.arange(0.0, stand.total_s + _SERIES_DT_S, _SERIES_DT_S)
    return torsional.Drive(kind, step_interp(t, t_pts, values), _SERIES_DT_S, 0.0,
                           settings.kp_Nms_rad, settings.ki_Nm_rad)


def plant_for(cfg: Config, settings: PlantSettings, path: WellPath | None, stand: Stand,
              depth_m: float | None = None,
              moving: bool = False) -> tuple[torsional.Plant, object]:
    """Plant of one stand: string at the stand's depth (or ``depth_m``), F_c from torque and
    drag — of the string moving at the stand's axial speed when ``moving``
    (:func:`moving_profile`), else of the rotating one."""
    depth = stand.bit_depth_m if depth_m is None else depth_m
    string = build_string(cfg.sections, depth)
    grid = torsional.make_grid(string, settings.cells)
    if moving:
        td = moving_profile(cfg, settings, path, depth, stand.axial_speed_m_s, stand.rpm)
    else:
        td = fc_profile(cfg, path, depth, stand.wob_N)
    cap = torsional.bit_torque_cap(settings.bit_mu, stand.wob_N, settings.bit_diameter_m)
    plant = settings.plant(grid, td.fc_at(grid.x_m), cap, stand.bit_weakening_ratio,
                           stand.bit_weakening_rpm, torsional.contact_radius(string, grid))
    if stand.top_drive_inertia_kg_m2 is not None:  # a gear change between stands
        plant = replace(plant, top_drive_inertia_kg_m2=stand.top_drive_inertia_kg_m2)
    return plant, td


def _axial(stand: Stand) -> torsional.Axial | None:
    """The stand's axial pipe speed as the kernel's series (None when it turns in place)."""
    if not stand.moving:
        return None
    knots = stand.axial_knots()
    t = np.arange(0.0, stand.total_s + _SERIES_DT_S, _SERIES_DT_S)
    return torsional.Axial(step_interp(t, knots[:, 0], knots[:, 1]), _SERIES_DT_S, 0.0)


def _moved_m(axial: torsional.Axial | None, time_s: np.ndarray) -> np.ndarray:
    """Distance moved along the hole since the stand began [m] (+ running in): the exact
    integral of the series the plant was driven with (piecewise linear between samples),
    interpolated at ``time_s`` (within (Δt²/8)·|dv/dt|, ~1e-5 m)."""
    if axial is None:
        return np.zeros(time_s.size)
    v = np.asarray(axial.values)
    moved = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * axial.dt_s)])
    return np.interp(time_s, axial.t0_s + axial.dt_s * np.arange(v.size), moved)


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
    check_travel(scenario, cfg.source)
    check_work(cfg, settings, scenario, rate)
    if path is None:
        path = no_survey_path(max(s.reach_m for s in scenario.stands), cfg.tortuosity_rad_m)
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
    if not any(s.flow_m3_s > 0 for s in scenario.stands):
        columns.pop("flow_in_m3_s")
    if settings.motor_rev_per_litre is None:
        columns.pop("bha_rpm")
    if all(s.mu_k_schedule is None for s in scenario.stands):
        columns.pop("mu_k_true")
    block = cfg.hookload.block_weight_N
    columns["hookload_N"] = columns["hookload_N"] + (block or 0.0)
    columns["surface_torque_Nm"] = lagged(columns["time_s"], columns["surface_torque_Nm"],
                                          cfg.simulate.torque_lag_s)
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
        string = build_string(cfg.sections, stand.plant_depth_m)
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


def _phases(stand: Stand) -> list[tuple[float, float, bool]]:
    """(end [s from stand start], bit depth of the plant [m], moving) of each phase of a
    stand: one for a stand turning in place; for a reaming stand the rotation in place at
    ``bit_depth_m`` until the block starts, the motion (ramps included) on the string at the
    middle of the travel, and the stop at the end depth (docs/simulator.md, Reaming).
    Phases of no duration (a stand without a stop) are left out."""
    if not stand.moving:
        return [(stand.total_s, stand.bit_depth_m, False)]
    knots = stand.axial_knots()
    phases = [(knots[1, 0], stand.bit_depth_m, False), (knots[4, 0], stand.plant_depth_m, True),
              (stand.total_s, stand.end_depth_m, False)]
    return [p for i, p in enumerate(phases) if i == 0 or p[0] > phases[i - 1][0]]


def _run_phases(cfg: Config, settings, path, stand: Stand, rate: float):
    """Run the plant through the stand's phases (:func:`_phases`), each on its own string,
    the state carried from one to the next aligned at the bit
    (:meth:`~drillfric.torsional.State.on_grid`), records at the stand's common times.

    Returns (record, plants, torque-and-drag results), one plant and result per phase."""
    drive, axial = _drive(stand, settings), _axial(stand)
    times = torsional.record_times(0.0, stand.total_s, rate)
    recs, plants, tds, state = [], [], [], None
    phases = _phases(stand)
    for k, (end, depth, moving) in enumerate(phases):
        plant, td = plant_for(cfg, settings, path, stand, depth, moving)
        state = torsional.State.rest(plant.grid) if state is None \
            else state.on_grid(plants[-1].grid, plant.grid)
        pieces = friction_pieces(stand, state.t_s, end)
        for j, (piece_end, factor) in enumerate(pieces):
            start = state.t_s
            stop = start + torsional.model_steps(piece_end - start, plant.grid.dt_s) \
                * plant.grid.dt_s
            eps = 1e-9 * plant.grid.dt_s
            last = k == len(phases) - 1 and j == len(pieces) - 1
            mine = times[(times >= start - eps) & ((times < stop - eps) | last)]
            rec, state = torsional.run(_scaled(plant, factor), drive, piece_end - start, rate,
                                       state, times_s=mine, axial=axial if moving else None)
            recs.append(rec)
        plants.append(plant)
        tds.append(td)
    columns = {f: np.concatenate([getattr(r, f) for r in recs])
               for f in torsional.Record.__dataclass_fields__}
    return torsional.Record(**columns), plants, tds


#: Longest piece of a ``mu_k_schedule`` the plant holds at one friction factor [s]: a ramp
#: becomes steps of at most this (a 40 % ramp over 5 min: steps of 0.27 %).
SCHEDULE_PIECE_S = 2.0


def friction_pieces(stand: Stand, start_s: float, end_s: float) -> list[tuple[float, float]]:
    """(end [s from the stand's start], factor [-]) of the pieces of [``start_s``, ``end_s``]
    over which the plant holds the stand's friction factor (:meth:`Stand.friction_factor`):
    one piece at 1 without a schedule; with one, the knots cut the span and each linear part
    is cut into pieces of at most :data:`SCHEDULE_PIECE_S`, each at the factor of its middle.

    Examples
    --------
    >>> friction_pieces(Stand(100.0, idle_s=0.0, mu_k_schedule=((0.0, 1.0), (3.0, 1.0),
    ...                                                          (3.0, 2.0))), 0.0, 5.0)
    [(3.0, 1.0), (5.0, 2.0)]
    """
    if stand.mu_k_schedule is None:
        return [(end_s, 1.0)]
    knots = np.asarray(stand.mu_k_schedule, dtype=float)[:, 0] + stand.idle_s
    cuts = np.unique(np.r_[start_s, knots[(knots > start_s) & (knots < end_s)], end_s])
    ends = []
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        ends += list(a + (b - a) * np.arange(1, int(np.ceil((b - a) / SCHEDULE_PIECE_S
                                                             - 1e-9)) + 1)
                     / max(int(np.ceil((b - a) / SCHEDULE_PIECE_S - 1e-9)), 1))
    ends = np.asarray(ends)
    middles = 0.5 * (np.r_[start_s, ends[:-1]] + ends)
    factors = stand.friction_factor(middles)
    keep = np.r_[factors[1:] != factors[:-1], True]  # merge pieces at one factor
    return [(float(e), float(f)) for e, f in zip(ends[keep], factors[keep], strict=True)]


def _scaled(plant: torsional.Plant, factor: float) -> torsional.Plant:
    """The plant with its open hole's μ_s and μ_k times ``factor`` (the cased part's fixed
    friction unchanged)."""
    if factor == 1.0:
        return plant
    return replace(plant, mu_s=plant.mu_s * factor, mu_k=plant.mu_k * factor)


def _run_stand(cfg: Config, settings, path, stand: Stand, index: int, t0: float, rate: float):
    rec, plants, tds = _run_phases(cfg, settings, path, stand, rate)
    plant, td, axial = plants[0], tds[0], _axial(stand)
    surface_torque = rec.motor_torque_Nm if settings.torque_kind == "motor" \
        else rec.string_torque_Nm
    n = rec.time_s.size
    off = 0.0 if stand.on_bottom else cfg.simulate.off_bottom_m
    depth = stand.bit_depth_m + _drilled_m(stand, rec.time_s) + _moved_m(axial, rec.time_s)
    hole = np.full(n, stand.reach_m + off) if stand.moving else depth + off
    rotating = rec.time_s >= stand.idle_s + stand.start_up_s
    stuck = float(np.mean(np.abs(rec.bit_rad_s[rotating]) < 0.1 * settings.omega_c_rad_s)) \
        if rotating.any() else 0.0
    hookload = _hookload(cfg, path, stand, td, tds, axial, depth, rec.time_s)
    motor = pdm_speed_rad_s(stand.flow_m3_s, settings.motor_rev_per_litre,
                            rec.bit_torque_Nm, settings.motor_stall_torque_Nm)
    cols = {"time_s": rec.time_s + t0, "surface_rpm": rec.surface_rad_s / RPM_TO_RAD_S,
            "surface_torque_Nm": surface_torque, "hookload_N": hookload,
            "bit_depth_m": depth, "hole_depth_m": hole,
            "wob_N": np.full(n, stand.wob_N),
            "bit_rpm": (rec.bit_rad_s + motor) / RPM_TO_RAD_S,
            "string_torque_Nm": rec.string_torque_Nm,
            "flow_in_m3_s": np.full(n, stand.flow_m3_s), "bha_rpm": rec.bit_rad_s / RPM_TO_RAD_S,
            "mu_k_true": settings.mu_k * _held_factor(stand, rec.time_s)}
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
                         max_rounding_m=max(float(np.max(np.abs(p.grid.rounding_m)))
                                            for p in plants),
                         bit_stuck_fraction=stuck, creep_end_s=creep_end,
                         bit_torque_time_mean_Nm=_mean_bit_torque_Nm(stand, rec),
                         bit_power_torque_Nm=_power_bit_torque_Nm(stand, rec),
                         bit_torque_k_Nm=plant.bit_torque_cap_Nm,
                         bit_weakening_ratio=stand.bit_weakening_ratio,
                         bit_weakening_rpm=stand.bit_weakening_rpm, flow_m3_s=stand.flow_m3_s,
                         mu_k_schedule=_schedule_truth(stand, settings.mu_k, t0),
                         **_reaming_truth(stand, plants, tds, t0))
    return cols, result


def pdm_speed_rad_s(flow_m3_s: float, rev_per_litre: float | None, bit_torque_Nm: np.ndarray,
                    stall_torque_Nm: float | None) -> np.ndarray:
    """Speed of the simulated mud motor's rotor relative to its housing [rad/s]: the
    positive displacement motor's linear characteristic ω_m = 2π·k·Q·(1 − τ_bit/τ_stall),
    clipped to [0, 2π·k·Q] (docs/theory.md eqs. 2.4a–b; k [rev/L] × 1000 L/m³); 0 without a
    motor, no drop without a stall torque.

    Examples
    --------
    >>> rpm = pdm_speed_rad_s(0.03, 0.1, np.array([0.0, 500.0, 4000.0]), 2000.0) * 30 / np.pi
    >>> rpm.round(6).tolist()
    [180.0, 135.0, 0.0]
    """
    torque = np.asarray(bit_torque_Nm, dtype=float)
    if rev_per_litre is None:
        return np.zeros(torque.size)
    no_load = 2.0 * np.pi * rev_per_litre * 1000.0 * flow_m3_s
    if stall_torque_Nm is None:
        return np.full(torque.size, no_load)
    return no_load * np.clip(1.0 - np.maximum(torque, 0.0) / stall_torque_Nm, 0.0, 1.0)


def _schedule_truth(stand: Stand, mu_k: float, t0: float) -> list | None:
    """The stand's ``mu_k_schedule`` as the open hole's μ_k on the global clock,
    [[t_s, μ_k], ...] (None without one)."""
    if stand.mu_k_schedule is None:
        return None
    return [[t0 + stand.idle_s + t, mu_k * f] for t, f in stand.mu_k_schedule]


def _held_factor(stand: Stand, time_s: np.ndarray) -> np.ndarray:
    """The friction factor the plant held at each recorded time [-]
    (:func:`friction_pieces`: each piece's factor up to its end)."""
    pieces = friction_pieces(stand, 0.0, stand.total_s)
    ends = np.array([e for e, _ in pieces])
    idx = np.minimum(np.searchsorted(ends, time_s - 1e-9, side="left"), ends.size - 1)
    return np.array([f for _, f in pieces])[idx]


def _reaming_truth(stand: Stand, plants, tds, t0: float) -> dict:
    """The reaming fields of :class:`StandResult` (none for a stand turning in place): those
    of the moving phase (:func:`_phases`)."""
    if not stand.moving:
        return {}
    knots = stand.axial_knots()
    return {"axial_speed_m_s": stand.axial_speed_m_s, "axial_start_s": t0 + knots[2, 0],
            "axial_end_s": t0 + knots[3, 0], "travel_m": stand.travel_m,
            "plant_bit_depth_m": stand.plant_depth_m, "T_N_moving_Nm": plants[1].T_N_Nm,
            "hookload_moving_N": float(tds[1].hookload_N),
            "torque_moving_Nm": float(tds[1].surface_torque_Nm)}


def _hookload(cfg, path, stand: Stand, td, tds, axial, depth_m: np.ndarray,
              time_s: np.ndarray) -> np.ndarray:
    """Hook load of the stand's rows without the block [N]: the rotating case's (``td``) for
    a stand turning in place. A reaming stand: the rotating hook load H_rot(d) at the
    recorded bit depth d (linear between the start, middle and end of the travel) plus the
    drag of the moving case at the middle, H_v − H_rot (``tds[1]``,
    :func:`moving_profile`), times v(t)/v — all of it at full speed, none at rest, linear
    over the block's ramps (docs/simulator.md, Reaming)."""
    if axial is None:
        return np.full(time_s.size, td.hookload_N)
    ends = (stand.bit_depth_m, stand.plant_depth_m, stand.end_depth_m)
    rest = [fc_profile(cfg, path, d).hookload_N for d in ends]
    order = np.argsort(ends)
    at_rest = np.interp(depth_m, np.asarray(ends)[order], np.asarray(rest)[order])
    v = np.interp(time_s, axial.t0_s + axial.dt_s * np.arange(np.size(axial.values)),
                  axial.values)
    return at_rest + (tds[1].hookload_N - rest[1]) * v / stand.axial_speed_m_s


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
            "wob_N": zero.copy(), "bit_rpm": zero.copy(), "string_torque_Nm": zero.copy(),
            "flow_in_m3_s": zero.copy(), "bha_rpm": zero.copy(),
            "mu_k_true": np.full(t.size, np.nan)}


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
            well_path = no_survey_path(max(s.reach_m for s in stands.stands),
                                       cfg.tortuosity_rad_m)
        keep = tuple(p for p in (Path(config), survey_path) if p is not None)
        write_well(out, pd.DataFrame(result.columns), config=written_config(cfg),
                   survey=well_path, truth=result.truth(), keep=keep)
    return result


def written_config(cfg: Config) -> dict:
    """The simulated well's configuration as written beside it (``Config.to_dict()``), stating
    the block weight its hook load carries — the configured one, else 0 (the simulated hook
    load is then the string alone) — so that ``run`` can weigh the string without a
    connection in the record (docs/theory.md §2.1), and the torque's lag behind the speed
    it was recorded with (``[channels] surface_torque lag_s``: the simulator knows its
    channels' timing, which a log of stick-slip alone cannot tell; docs/bit_speed.md)."""
    config = cfg.to_dict()
    hook = dict(config.get("hookload") or {})
    hook["block_weight_N"] = hook.get("block_weight_N") or 0.0
    channels = {k: dict(v) for k, v in (config.get("channels") or {}).items()}
    channels.setdefault("surface_torque", {})["lag_s"] = float(cfg.simulate.torque_lag_s)
    channels.get("surface_rpm", {}).pop("lag_s", None)  # the speed is the reference
    return config | {"hookload": hook, "channels": channels}
