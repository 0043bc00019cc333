"""How the simulated plant is set up (:class:`PlantSettings`: cells, friction law, bit,
top drive) and the measurement errors added to what it records (:class:`Noise`),
from the configuration (docs/simulator.md)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric import torsional
from drillfric.config import Config
from drillfric.errors import ConfigError, ModelError
from drillfric.units import RPM_TO_RAD_S


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
    motor_rev_per_litre, motor_stall_torque_Nm : float, optional
        A mud motor in the BHA: k [rev/L] and its stall torque [N·m] (docs/simulator.md,
        Mud motor); None: no motor, no drop.
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
    motor_rev_per_litre: float | None = None
    motor_stall_torque_Nm: float | None = None

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
                  mu_s_cased=cfg.simulate.mu_s_cased, mu_k_cased=cfg.simulate.mu_k_cased,
                  motor_rev_per_litre=cfg.simulate.motor_rev_per_litre,
                  motor_stall_torque_Nm=cfg.simulate.motor_stall_torque_Nm)
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
              bit_weakening_ratio: float = 1.0, bit_weakening_rpm: float = 10.0,
              contact_radius_m: np.ndarray | None = None) -> torsional.Plant:
        """The true plant on ``grid`` with the capacity profile F_c at the cell centres and
        the bit T_k = ``bit_torque_cap_Nm`` [N·m], r, ω_b [RPM] (:class:`Stand`), and the
        cells' contact radius [m] (needed by a reaming stand, docs/theory.md §3.3).

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
                               bit_weakening_rpm * RPM_TO_RAD_S, contact_radius_m)
