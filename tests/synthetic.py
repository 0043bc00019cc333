"""Synthetic wells with known truth for estimator tests (built from the project's own plant).

A&S 2018 drill pipe (docs/reference_cases.md) on a build-and-hold path; the BHA is two collar
sections so
the plant has junctions. Plants used as "truth" run on a finer grid than the estimators.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric import torque_drag, torsional
from drillfric.config import config_from_dict
from drillfric.drillstring import DrillString, build_string
from drillfric.units import RPM_TO_RAD_S as RPM
from drillfric.wellpath import WellPath, minimum_curvature

#: A&S 2018 drill pipe and the Well A collar sections (docs/reference_cases.md), G = 61 / 67 GPa.
AS_SECTIONS = [
    {"name": "DP", "od_m": 0.146529, "id_m": 0.123024, "shear_modulus_Pa": 61e9},
    {"name": "c1", "od_m": 0.150167, "id_m": 0.096799, "length_m": 76.32,
     "shear_modulus_Pa": 67e9},
    {"name": "c2", "od_m": 0.206375, "id_m": 0.0762, "length_m": 10.24,
     "shear_modulus_Pa": 67e9},
    {"name": "c3", "od_m": 0.150167, "id_m": 0.096799, "length_m": 95.4,
     "shear_modulus_Pa": 67e9},
    {"name": "c4", "od_m": 0.222392, "id_m": 0.095964, "length_m": 48.5,
     "shear_modulus_Pa": 67e9},
]


def build_and_hold(kop_m: float, hold_deg: float, td_m: float,
                   build_deg_30m: float = 3.0) -> WellPath:
    """Vertical to ``kop_m``, build at ``build_deg_30m`` to ``hold_deg``, hold to ``td_m``."""
    end_build = kop_m + hold_deg / build_deg_30m * 30.0
    md = np.array([0.0, kop_m, end_build, td_m])
    inc = np.radians([0.0, 0.0, hold_deg, hold_deg])
    return minimum_curvature(md, inc, np.zeros(4))


def config(gains: str = "kalman", observer: dict | None = None, **model):
    """Well configuration with the A&S drill pipe and a two-section BHA (``observer``: more
    ``[observer]`` keys, ``model``: ``[model]`` keys)."""
    sections = [
        {"name": "DP", "od_m": 0.146529, "id_m": 0.123024, "tool_joint_od_m": 0.1778,
         "shear_modulus_Pa": 61e9},
        {"name": "HW", "od_m": 0.150167, "id_m": 0.096799, "length_m": 80.0,
         "shear_modulus_Pa": 67e9},
        {"name": "DC", "od_m": 0.206375, "id_m": 0.0762, "length_m": 120.0,
         "shear_modulus_Pa": 67e9}]
    return config_from_dict({"string": {"sections": sections},
                             "model": {"k_t_per_s": 0.1, **model},
                             "observer": {"gains": gains, **(observer or {})}})


@dataclass(frozen=True)
class Case:
    """A synthetic record with its truth."""

    string: DrillString
    path: WellPath
    td: torque_drag.TDResult
    record: torsional.Record
    mu_s: float
    mu_k: float


def simulate(path: WellPath, bit_depth_m: float, mu_s: float, mu_k: float, rpm: float,
             duration_s: float, *, cells: int = 800, rate_hz: float = 100.0,
             ramp_s: float = 10.0, cfg=None) -> Case:
    """PI-driven plant from rest, set-point ramped to ``rpm`` over ``ramp_s``."""
    cfg = cfg or config()
    string = build_string(cfg.sections, bit_depth_m)
    td = torque_drag.solve(path, string, load_case="rotating_off_bottom",
                           mud_out_kg_m3=cfg.fluid.mud_density_kg_m3)
    grid = torsional.make_grid(string, cells)
    plant = torsional.Plant(grid, td.fc_at(grid.x_m), mu_s, mu_k, cfg.omega_c_rad_s,
                            cfg.model.k_t_per_s, cfg.rig.top_drive_inertia_kg_m2)
    t = np.arange(0.0, duration_s + 1.0, 0.1)
    drive = torsional.Drive("pi", np.minimum(t / ramp_s, 1.0) * rpm * RPM, 0.1)
    record, _ = torsional.run(plant, drive, duration_s, rate_hz)
    return Case(string, path, td, record, mu_s, mu_k)


def noisy(record: torsional.Record, rpm_sd: float = 0.5, torque_sd_Nm: float = 200.0,
          seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Measured speed [rad/s] and motor torque [N·m] with Gaussian noise (seeded)."""
    rng = np.random.default_rng(seed)
    n = record.time_s.size
    return (record.surface_rad_s + rng.normal(0.0, rpm_sd * RPM, n),
            record.motor_torque_Nm + rng.normal(0.0, torque_sd_Nm, n))
