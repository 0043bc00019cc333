"""`drillfric simulate` (docs/cli.md): synthetic surface data with ground truth.

Thin layer: options become configuration overrides (command line > file > defaults), the
survey is resolved, :func:`drillfric.sim.run.plan` picks the stands (the scenario, else one
stand), :func:`drillfric.sim.run.simulate` runs the plant stand
by stand, :func:`drillfric.io.writers.write_well` writes the data file and its sidecars.
"""

from __future__ import annotations

from pathlib import Path

import click

from drillfric.io.text import plural

from .common import Quantity, echo, progress, warn


def _overrides(**options) -> dict:
    keys = {"duration": "simulate.duration_s", "rate": "simulate.rate_hz",
            "mu_s": "simulate.mu_s", "mu_k": "simulate.mu_k",
            "bit_depth": "simulate.bit_depth_m", "rpm": "simulate.rpm", "seed": "simulate.seed",
            "rpm_noise": "simulate.rpm_noise", "torque_noise": "simulate.torque_noise_Nm",
            "wob": "simulate.wob_N", "cells": "simulate.cells", "flow": "simulate.flow_m3_s",
            "motor": "simulate.motor_rev_per_litre",
            "motor_stall_torque": "simulate.motor_stall_torque_Nm"}
    return {keys[k]: v for k, v in options.items() if v is not None}


def _load(config: Path, survey: Path | None, overrides: dict, omega_c_rpm: float | None):
    """The configuration and its survey (``--survey`` > ``[survey] file`` >
    ``NAME.survey.{csv,parquet}`` beside ``NAME.toml``, as ``run`` finds a well's:
    :func:`drillfric.io.well.open_config`), with ``--omega-c-rpm`` in the configuration's
    own ω_c key."""
    from drillfric.io.well import open_config

    cfg, survey_path, well_path = open_config(config, survey=survey, overrides=overrides)
    if omega_c_rpm is not None:
        key = "model.omega_c_rpm" if cfg.model.omega_c_rpm is not None or \
            cfg.model.omega_c_rad_s is None else "model.omega_c_rad_s"
        from drillfric.units import RPM_TO_RAD_S

        value = omega_c_rpm if key.endswith("rpm") else omega_c_rpm * RPM_TO_RAD_S
        cfg = open_config(config, survey=survey, overrides=overrides | {key: value})[0]
    return cfg, survey_path, well_path


def _say_scenario_duration(duration: float, used: Path, plan) -> None:
    """Warn what --duration does with a scenario: it is a stand's rotating time only where
    the scenario (its stand or its [defaults]) states none, and the record is as long as the
    scenario's stands and connections."""
    took = sum(s.duration_s == duration for s in plan.stands)
    warn(f"--duration {duration:g} s with the scenario {used.name}: the rotating time of the "
         f"stands that state none ({took} of {len(plan.stands)}); the record lasts "
         f"{plan.total_s:.0f} s. For one stand of {duration:g} s give --bit-depth (the "
         "scenario is then not used)")


@click.command("simulate")
@click.argument("config", type=click.Path(path_type=Path))
@click.option("--out", "out", required=True, type=click.Path(path_type=Path),
              help="Output data file: .parquet, .csv, .h5 or .hdf5 (sidecars written beside).")
@click.option("--duration", type=Quantity("s"), help="Simulated seconds of a single stand "
              "(with --scenario: default rotating time of each stand); e.g. 120 or \"2 min\".")
@click.option("--rate", type=Quantity("Hz"), help="Recording rate [Hz] (default 100).")
@click.option("--mu-s", type=float, help="True static friction factor.")
@click.option("--mu-k", type=float, help="True kinetic friction factor.")
@click.option("--omega-c-rpm", type=Quantity("RPM"),
              help="Static/kinetic switching speed ω_c [RPM].")
@click.option("--bit-depth", type=Quantity("m"), help="Bit depth of a single stand [m], e.g. "
              "2500 or \"8200 ft\" (default: simulate.bit_depth_m, else the end of the "
              "survey); without --scenario it overrides the configuration's scenario.")
@click.option("--rpm", type=Quantity("RPM"),
              help="Surface speed set-point after the ramp [RPM].")
@click.option("--wob", type=Quantity("N"), help="Weight on bit of a single stand [N] (> 0: on "
              "bottom), e.g. \"30 klbf\".")
@click.option("--flow", type=Quantity("m³/s"), help="Flow in of every stand that gives none "
              "[m³/s] (pumps on), e.g. \"1800 L/min\".")
@click.option("--motor", type=Quantity("rev/L"), help="A mud motor in the simulated BHA: its "
              "speed per unit of flow [rev/L], e.g. \"0.15 rev/gal\" (docs/simulator.md).")
@click.option("--motor-stall-torque", type=Quantity("N·m"), help="The motor's stall torque "
              "[N·m]: its speed falls linearly with the bit torque (default: no drop).")
@click.option("--seed", type=int, help="Seed of the measurement noise.")
@click.option("--rpm-noise", type=Quantity("RPM"), help="Gaussian surface-speed noise [RPM].")
@click.option("--torque-noise", type=Quantity("N·m"), help="Gaussian torque noise [N·m].")
@click.option("--cells", type=int, help="Cells of the simulated (true) string model "
              "(default simulate.cells = 2500).")
@click.option("--scenario", type=click.Path(path_type=Path),
              help="Scenario TOML of several stands (docs/simulator.md).")
@click.option("--survey", type=click.Path(path_type=Path),
              help="Survey file (overrides the configuration's [survey] file and a "
                   "CONFIG-stem.survey.csv beside it).")
def command(config: Path, out: Path, duration, rate, mu_s, mu_k, omega_c_rpm, bit_depth, rpm,
            wob, flow, motor, motor_stall_torque, seed, rpm_noise, torque_noise, cells,
            scenario, survey) -> None:
    """Simulate surface data with ground truth from the torsional plant (docs/theory.md §3).

    Writes OUT with time_s, surface_rpm, surface_torque_Nm, hookload_N, bit_depth_m,
    hole_depth_m, bit_rpm and string_torque_Nm (noise-free truth; with --flow flow_in_m3_s,
    with --motor bha_rpm, the string's bottom, and bit_rpm adds the motor), plus OUT's sidecars
    NAME.toml, NAME.survey.csv and NAME.truth.json, so that `drillfric run OUT` reads it
    directly (NAME: OUT's stem, also the well's name in NAME.toml). The survey is --survey,
    else CONFIG's [survey] file, else CONFIG-stem.survey.csv beside CONFIG (as `run` finds
    a well's).
    """
    import pandas as pd

    from drillfric.io.writers import data_format, write_well
    from drillfric.sim import run as sim
    from drillfric.wellpath import no_survey_path

    data_format(out)
    overrides = _overrides(duration=duration, rate=rate, mu_s=mu_s, mu_k=mu_k,
                           bit_depth=bit_depth, rpm=rpm, seed=seed, rpm_noise=rpm_noise,
                           torque_noise=torque_noise, wob=wob, cells=cells, flow=flow,
                           motor=motor, motor_stall_torque=motor_stall_torque)
    cfg, survey_path, well_path = _load(config, survey, overrides, omega_c_rpm)
    used, plan = sim.plan(cfg, config, well_path, scenario,
                          single=bit_depth is not None and scenario is None)
    sim.check_depths(plan, well_path, survey_path)
    if duration is not None and used is not None:
        _say_scenario_duration(duration, used, plan)
    with progress("simulating", plan.total_s) as advance:
        result = sim.simulate(cfg, well_path, plan, progress=advance)
    for note in result.notes:
        warn(note)
    if well_path is None:  # the path simulate() assumed; written as NAME.survey.csv
        well_path = no_survey_path(max(s.reach_m for s in plan.stands),
                                   cfg.tortuosity_rad_m)
        warn(f"no survey: simulated on a vertical hole with a nominal tortuosity of "
             f"{cfg.survey.tortuosity_deg_30m:g}°/30 m (survey.tortuosity_deg_30m), "
             "written as the output's survey")
    keep = tuple(p for p in (config, survey_path) if p is not None)
    written = write_well(out, pd.DataFrame(result.columns), config=sim.written_config(cfg),
                         survey=well_path, truth=result.truth(), keep=keep)
    rows = len(result.columns["time_s"])
    echo(f"wrote {out}: {plural(rows, 'row')}, {plan.total_s:.0f} s at {result.rate_hz:g} Hz, "
         f"{plural(len(plan.stands), 'stand')}, μ_s = {result.settings.mu_s:g}, "
         f"μ_k = {result.settings.mu_k:g}")
    for s in result.stands:
        echo(f"  stand {s.index}: bit {s.bit_depth_m:g} m, {s.start} to {s.rpm:g} RPM, "
             f"{_reaming(s)}T_N = {s.T_N_Nm / 1e3:.1f} kN·m, bit stuck "
             f"{100 * s.bit_stuck_fraction:.0f} % of the rotating time")
    echo("sidecars: " + ", ".join(str(p) for k, p in written.items() if k != "data"))


def _reaming(stand) -> str:
    """'reaming to 2266.4 m at 0.3 m/s, ' for a stand whose pipe moves, else ''."""
    if not stand.axial_speed_m_s:
        return ""
    way = "reaming" if stand.axial_speed_m_s > 0 else "back-reaming"
    return (f"{way} to {stand.bit_depth_m + stand.travel_m:.1f} m at "
            f"{abs(stand.axial_speed_m_s):g} m/s, ")
