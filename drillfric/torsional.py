"""Distributed torsional drill-string model (the "plant"), docs/theory.md §3 and §3.1.

Implements the wave model of Aarsnes & Shor (JPSE 163, 2018) as used in Aarsnes et al.
(JPSE 179, 2019, Section 2 and Appendix A), with the errata of docs/theory.md §3 (viscous term
of eq. 11, free bit end of eq. 40). The string is cut into sections with their own polar
moment, shear modulus and density; the Riemann invariants α = ω + τ/ζ and β = ω − τ/ζ
(eq. 8) are carried on one cell array over the whole string. The time step Δt is common and
every section gets cells of length Δx_i = c_i·Δt, so the Courant number is exactly 1 in
every section: the upwind transport is an exact shift (docs/theory.md §3.1).

Layers: :func:`make_grid` (cells from a :class:`~drillfric.drillstring.DrillString`),
:class:`Plant` (grid + friction, damping, top-drive and bit parameters, as plain arrays),
:class:`Drive` (how the top drive is driven), :func:`run` (advance and record, calling the
numba kernel of :mod:`drillfric.kernels.plant` or its NumPy twin), and small physical helpers
(:func:`energy`, :func:`gravity_fc`). Everything is SI: rad/s, N·m, m, s.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from drillfric.config import default
from drillfric.drillstring import G_ACCEL, DrillString
from drillfric.errors import ModelError
from drillfric.units import RPM_TO_RAD_S

#: Top-drive modes of the kernel: PI speed control on a set-point series, a prescribed
#: motor-torque series, or a prescribed top-drive speed (the speed-driven model of §6.4).
DRIVE_MODES = {"pi": 0, "torque": 1, "speed": 2, "fed": 3}
#: Columns of the record array returned by the kernels.
RECORD_COLUMNS = ("surface_rad_s", "motor_torque_Nm", "string_torque_Nm", "bit_rad_s",
                  "bit_torque_Nm")
_CANDIDATE_SPREAD = 0.05  # the cell count may move ±5 % from the request to reduce rounding


@dataclass(frozen=True)
class Grid:
    """Cells of the Courant-1 discretisation (docs/theory.md §3.1).

    Attributes
    ----------
    dt_s : float
        Common time step Δt [s].
    section_start : ndarray of int
        First cell of each section, plus the total cell count at the end (length n_sec + 1).
    length_m : ndarray
        True section lengths [m].
    model_length_m : ndarray
        Modelled section lengths n_i·c_i·Δt [m].
    wave_speed_m_s : ndarray
        Wave speed c_i of each section [m/s].
    x_m : ndarray
        True measured depth of each cell centre [m] (cells spread evenly over the true
        section), where F_c(x) is evaluated.
    dx_true_m : ndarray
        True length represented by each cell, L_i/n_i [m].
    zeta_Nms : ndarray
        Line impedance ζ of each cell [N·m·s/rad].
    rho_j_kg_m : ndarray
        ρ·J of each cell [kg·m] (rotational inertia per metre).
    """

    dt_s: float
    section_start: np.ndarray
    length_m: np.ndarray
    model_length_m: np.ndarray
    wave_speed_m_s: np.ndarray
    x_m: np.ndarray
    dx_true_m: np.ndarray
    zeta_Nms: np.ndarray
    rho_j_kg_m: np.ndarray

    @property
    def n_cells(self) -> int:
        """Total number of cells."""
        return int(self.section_start[-1])

    @property
    def rounding_m(self) -> np.ndarray:
        """Modelled minus true length of each section [m] (whole cells of c_i·Δt)."""
        return self.model_length_m - self.length_m

    @property
    def travel_time_s(self) -> float:
        """Time for a wave to travel from the top drive to the bit, n·Δt [s]."""
        return self.n_cells * self.dt_s

    @property
    def junction_z(self) -> np.ndarray:
        """Impedance ratio Z = ζ_b/ζ_a at each junction, top-down (docs/theory.md §3)."""
        first = self.section_start[1:-1]
        return self.zeta_Nms[first] / self.zeta_Nms[first - 1]

    @property
    def dx_model_m(self) -> np.ndarray:
        """Modelled cell length c_i·Δt of each cell [m]."""
        counts = np.diff(self.section_start)
        return np.repeat(self.wave_speed_m_s * self.dt_s, counts)


def _section_cells(travel_s: np.ndarray, dt: float) -> np.ndarray:
    return np.maximum(1, np.rint(travel_s / dt)).astype(np.int64)


def make_grid(string: DrillString, cells: int = 500) -> Grid:
    """Cut a drill string into Courant-1 cells (docs/theory.md §3.1).

    Δt is chosen so that the string holds about ``cells`` cells; each section gets
    n_i = round(L_i/(c_i Δt)) ≥ 1 cells of length c_i·Δt. Among cell totals within ±5 %
    of ``cells`` the one with the smallest impedance-weighted rounding Σ ζ_i·|n_i c_i Δt − L_i|
    is taken (short BHA sections otherwise carry the largest relative error); the rounding
    that remains is reported in :attr:`Grid.rounding_m`.

    Parameters
    ----------
    string : DrillString
        Sections top-down, lengths summing to the bit depth.
    cells : int
        Requested number of cells (the paper: 500).

    Returns
    -------
    Grid

    Examples
    --------
    >>> from drillfric.drillstring import Section
    >>> s = DrillString((Section("dp", 0.15, 0.12, 1000.0, 0.075, 40.0, 79.3e9),))
    >>> g = make_grid(s, cells=100)
    >>> g.n_cells, bool(abs(g.rounding_m[0]) < 1e-9)
    (100, True)
    """
    if cells < 1:
        raise ModelError(f"the torsional model needs at least one cell, got {cells}")
    secs = string.sections
    length = np.array([s.length_m for s in secs], dtype=float)
    c = np.array([s.wave_speed_m_s for s in secs], dtype=float)
    zeta = np.array([s.impedance_Nms for s in secs], dtype=float)
    rho_j = np.array([s.steel_density_kg_m3 * s.polar_moment_m4 for s in secs], dtype=float)
    travel = length / c
    total = float(travel.sum())
    spread = max(1, int(cells * _CANDIDATE_SPREAD))
    best = None
    for n_try in range(max(len(secs), cells - spread), cells + spread + 1):
        dt = total / n_try
        n = _section_cells(travel, dt)
        cost = float(np.sum(zeta * np.abs(n * c * dt - length)) / np.sum(zeta * length))
        key = (round(cost, 9), abs(n_try - cells))
        if best is None or key < best[0]:
            best = (key, dt, n)
    _, dt, counts = best
    start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    sec_of_cell = np.repeat(np.arange(len(secs)), counts)
    local = np.arange(start[-1]) - start[sec_of_cell]
    top = np.concatenate([[0.0], np.cumsum(length)])[:-1]
    dx_true = (length / counts)[sec_of_cell]
    return Grid(dt_s=float(dt), section_start=start, length_m=length,
                model_length_m=counts * c * dt, wave_speed_m_s=c,
                x_m=top[sec_of_cell] + (local + 0.5) * dx_true, dx_true_m=dx_true,
                zeta_Nms=zeta[sec_of_cell], rho_j_kg_m=rho_j[sec_of_cell])


def gravity_fc(string: DrillString, inc_rad, x_m) -> np.ndarray:
    """Gravity-only Coulomb torque capacity F_c = r_c·g·ρ·A·sin I [N·m/m] (A&S 2018).

    The normal force of A&S 2018 (steel weight only, no buoyancy, no tension–curvature
    term; docs/theory.md §2, last paragraph), times the contact radius.

    Parameters
    ----------
    string : DrillString
    inc_rad : callable or array_like
        Inclination [rad] at ``x_m`` (a callable is evaluated at ``x_m``).
    x_m : array_like
        Measured depths [m].
    """
    x = np.asarray(x_m, dtype=float)
    inc = inc_rad(x) if callable(inc_rad) else np.asarray(inc_rad, dtype=float)
    area = string.along("steel_area_m2", x)
    rho = string.along("steel_density_kg_m3", x)
    rc = string.along("contact_radius_m", x)
    return rc * G_ACCEL * rho * area * np.sin(inc)


@dataclass(frozen=True)
class Plant:
    """Everything the kernel needs, as plain arrays and numbers (docs/theory.md §3).

    Attributes
    ----------
    grid : Grid
    fc_Nm_m : ndarray
        Coulomb torque capacity per unit length per unit friction F_c at the cell centres
        [N·m/m] (from torque and drag, docs/theory.md §2).
    mu_s, mu_k : float
        Static and kinetic friction factors [-].
    omega_c_rad_s : float
        Static/kinetic switching speed ω_c [rad/s].
    k_t_per_s : float
        Viscous damping rate k_t [1/s].
    top_drive_inertia_kg_m2 : float
        I_TD [kg·m²].
    bit_torque_cap_Nm : float
        Bit torque magnitude at high speed T_k = μ_bit·WOB·D_bit/3 [N·m]; 0 is a free bit
        (off bottom). See :func:`bit_torque_cap`.
    bit_weakening_ratio : float
        r ≥ 1, static (break-away) over high-speed bit torque of the rate-weakening bit
        T_bit(ω) = T_k·(1 + (r − 1)·exp(−|ω|/ω_b)) (docs/theory.md §3, bit) [-]; 1
        (default) is the Coulomb bit.
    bit_weakening_speed_rad_s : float
        ω_b, the bit speed over which the bit torque decays from r·T_k towards T_k [rad/s]
        (used when r > 1; default 10 RPM as ``simulate.bit_weakening_rpm``).
    fc_fixed_k_Nm_m, fc_fixed_s_Nm_m : ndarray, optional
        Fixed part of the friction profile (docs/theory.md §3.2): kinetic and static friction
        torque per metre of a zone whose friction factor is known (e.g. cased hole above the
        shoe), already times that factor [N·m/m], one value per cell, kinetic ≤ static.
        None (default) is zero: all friction is μ·F_c.
    stribeck_speed_rad_s : float, optional
        Stribeck decay speed v_s [rad/s] (docs/theory.md §3.2); 0 or None (default) is the
        step law at ω_c.
    stribeck_exponent : float
        Stribeck exponent δ, 1 ≤ δ ≤ 2 [-] (1 and 2 are the fast variants of the kernel).
    contact_radius_m : ndarray, optional
        Contact radius r_c of each cell [m] (tool-joint OD/2 for drill pipe, body OD/2 for
        collars; :func:`contact_radius`): needed only to run with axial pipe motion
        (:class:`Axial`, docs/theory.md §3.3), where the friction splits by ωr_c against v.
    """

    grid: Grid
    fc_Nm_m: np.ndarray
    mu_s: float
    mu_k: float
    omega_c_rad_s: float
    k_t_per_s: float = 0.0
    top_drive_inertia_kg_m2: float = default("rig.top_drive_inertia_kg_m2")
    bit_torque_cap_Nm: float = 0.0
    fc_fixed_k_Nm_m: np.ndarray | None = None
    fc_fixed_s_Nm_m: np.ndarray | None = None
    stribeck_speed_rad_s: float | None = None
    stribeck_exponent: float = 1.0
    bit_weakening_ratio: float = 1.0
    bit_weakening_speed_rad_s: float = 10.0 * RPM_TO_RAD_S  # the config's default, 10 RPM
    contact_radius_m: np.ndarray | None = None

    def __post_init__(self):
        if self.top_drive_inertia_kg_m2 <= 0:
            raise ModelError(f"top-drive inertia must be positive, got "
                             f"{self.top_drive_inertia_kg_m2} kg·m²",
                             fix="set rig.top_drive_inertia_kg_m2 > 0")
        if self.omega_c_rad_s <= 0:
            raise ModelError(f"ω_c must be positive, got {self.omega_c_rad_s} rad/s",
                             fix="set model.omega_c_rad_s (or omega_c_rpm) > 0")
        if self.mu_k < 0 or self.mu_s < 0 or self.mu_k > self.mu_s:
            raise ModelError(f"need 0 ≤ μ_k ≤ μ_s, got μ_s = {self.mu_s}, μ_k = {self.mu_k}",
                             fix="the kinetic friction factor cannot exceed the static one")
        if self.k_t_per_s < 0 or self.bit_torque_cap_Nm < 0:
            raise ModelError("viscous damping and bit torque must be ≥ 0")
        for name in ("fc_Nm_m", "fc_fixed_k_Nm_m", "fc_fixed_s_Nm_m"):
            value = getattr(self, name)
            if value is not None and (np.shape(value) != (self.grid.n_cells,) or np.any(
                    ~np.isfinite(value)) or np.any(np.asarray(value) < 0)):
                raise ModelError(f"{name} must be one finite, non-negative value per cell")
        if np.any(self.fixed_k_Nm_m > self.fixed_s_Nm_m):
            raise ModelError("the fixed kinetic friction exceeds the fixed static friction",
                             fix="give fc_fixed_k_Nm_m ≤ fc_fixed_s_Nm_m in every cell")
        if self.stribeck_speed_rad_s is not None and not self.stribeck_speed_rad_s >= 0:
            raise ModelError(f"the Stribeck speed must be ≥ 0 (0: step law), got "
                             f"{self.stribeck_speed_rad_s} rad/s",
                             fix="set simulate.stribeck_speed_rad_s > 0")
        if not (self.bit_weakening_ratio >= 1.0 and self.bit_weakening_speed_rad_s > 0
                and np.isfinite(self.bit_weakening_ratio * self.bit_weakening_speed_rad_s)):
            raise ModelError(f"the rate-weakening bit needs r ≥ 1 and ω_b > 0, got r = "
                             f"{self.bit_weakening_ratio}, ω_b = "
                             f"{self.bit_weakening_speed_rad_s} rad/s",
                             fix="set simulate.bit_weakening_ratio ≥ 1 and "
                             "simulate.bit_weakening_rpm > 0")
        rc = self.contact_radius_m
        if rc is not None and (np.shape(rc) != (self.grid.n_cells,)
                               or not np.all(np.asarray(rc) > 0) or not np.all(np.isfinite(rc))):
            raise ModelError("contact_radius_m must be one finite, positive radius per cell",
                             fix="give r_c [m] of each cell (torsional.contact_radius)")
        if not 1.0 <= self.stribeck_exponent <= 2.0:
            raise ModelError(f"the Stribeck exponent must be in [1, 2], got "
                             f"{self.stribeck_exponent}", fix="set simulate.stribeck_exponent")

    def _fixed(self, value) -> np.ndarray:
        return np.zeros(self.grid.n_cells) if value is None else np.asarray(value, float)

    @property
    def fixed_k_Nm_m(self) -> np.ndarray:
        """Fixed kinetic friction torque per metre of each cell, zeros if none [N·m/m]."""
        return self._fixed(self.fc_fixed_k_Nm_m)

    @property
    def fixed_s_Nm_m(self) -> np.ndarray:
        """Fixed static friction torque capacity per metre of each cell, zeros if none
        [N·m/m]."""
        return self._fixed(self.fc_fixed_s_Nm_m)

    def _rad_s(self, per_m: np.ndarray) -> np.ndarray:
        g = self.grid
        return per_m * (g.dx_true_m / g.dx_model_m) * g.dt_s / g.rho_j_kg_m

    @property
    def fcap_rad_s(self) -> np.ndarray:
        """Speed change friction can impose on a cell in one step, per unit μ [rad/s].

        F_c·(L_i/L_i^model)·Δt/(ρJ): the step-3 cap μ·F_c of docs/theory.md §3.1 in speed units.
        The factor L_i/L_i^model keeps the total capacity Σ = ∫F_c dx of the true string
        despite the length rounding.
        """
        return self._rad_s(self.fc_Nm_m)

    @property
    def fix_k_rad_s(self) -> np.ndarray:
        """Fixed kinetic part of the cap per cell and step, like :attr:`fcap_rad_s` but
        already times its friction factor [rad/s] (docs/theory.md §3.2)."""
        return self._rad_s(self.fixed_k_Nm_m)

    @property
    def fix_s_rad_s(self) -> np.ndarray:
        """Fixed static part of the cap per cell and step [rad/s] (docs/theory.md §3.2)."""
        return self._rad_s(self.fixed_s_Nm_m)

    @property
    def law_speed_rad_s(self) -> float:
        """Kernel argument ``law_speed``: v_s of the Stribeck law, 0 for the step law."""
        return float(self.stribeck_speed_rad_s or 0.0)

    @property
    def T_N_Nm(self) -> float:
        """T_N = ∫F_c dx over the true string (cell lengths L_i/n_i) [N·m] (A&S 2018 eq. 27
        per unit μ): the part the estimated μ multiplies."""
        return float(np.sum(self.fc_Nm_m * self.grid.dx_true_m))

    @property
    def T_fixed_k_Nm(self) -> float:
        """Kinetic Coulomb torque of the fixed part, ∫F_fixed,k dx [N·m]."""
        return float(np.sum(self.fixed_k_Nm_m * self.grid.dx_true_m))

    @property
    def T_fixed_s_Nm(self) -> float:
        """Static Coulomb torque capacity of the fixed part, ∫F_fixed,s dx [N·m]."""
        return float(np.sum(self.fixed_s_Nm_m * self.grid.dx_true_m))

    def friction_Nm_m(self, omega_rad_s: float, mu_s: float | None = None,
                      mu_k: float | None = None) -> np.ndarray:
        """Friction torque per metre of each cell turning at ω [N·m/m] (docs/theory.md §3.2).

        F_k + (F_s − F_k)·w(ω) with F_k = μ_k F_c + F_fixed,k, F_s = μ_s F_c + F_fixed,s and
        w = exp(−(|ω|/v_s)^δ) (Stribeck) or w = [|ω| ≤ ω_c] (step law: the static capacity
        inside the band). ``mu_s``, ``mu_k`` default to the plant's. Times the true cell
        lengths and summed, the Coulomb torque of the whole string turning at ω.
        """
        mu_s = self.mu_s if mu_s is None else mu_s
        mu_k = self.mu_k if mu_k is None else mu_k
        f_k = mu_k * self.fc_Nm_m + self.fixed_k_Nm_m
        f_s = mu_s * self.fc_Nm_m + self.fixed_s_Nm_m
        return f_k + (f_s - f_k) * self.static_weight(omega_rad_s)

    def static_weight(self, omega_rad_s: float) -> float:
        """Weight of the static cap at speed ω, (cap − cap_k)/(cap_s − cap_k) [-]
        (docs/theory.md §3.2): exp(−(|ω|/v_s)^δ) (Stribeck) or [|ω| ≤ ω_c] (step law)."""
        if self.law_speed_rad_s > 0:
            return float(np.exp(-(abs(omega_rad_s) / self.law_speed_rad_s)
                                ** self.stribeck_exponent))
        return float(abs(omega_rad_s) <= self.omega_c_rad_s)

    def bit_torque_Nm(self, omega_rad_s: float) -> float:
        """Sliding bit torque T_bit(ω) = T_k·(1 + (r − 1)·exp(−|ω|/ω_b)) of a bit turning
        at ω [N·m] (docs/theory.md §3, bit); at ω = 0 the break-away capacity r·T_k. The
        law in closed form: the tests' reference for the kernel's bit."""
        weak = (self.bit_weakening_ratio - 1.0) * np.exp(
            -abs(omega_rad_s) / self.bit_weakening_speed_rad_s)
        return float(self.bit_torque_cap_Nm * (1.0 + weak))

    def friction_torque_Nm(self, omega_rad_s: float, axial_speed_m_s: float = 0.0) -> float:
        """Coulomb torque of the whole string turning uniformly at ω, Σ friction·Δx [N·m]
        (docs/theory.md §3.2; the steady rotating surface torque without viscous part).

        With the pipe also moving axially at v (docs/theory.md eq. 3.3d) each cell carries
        the torsional share ω r_c/√((ωr_c)² + v²) of the friction at its contact speed
        √(ω² + (v/r_c)²) (``contact_radius_m`` needed).

        Examples
        --------
        >>> from drillfric.drillstring import Section, DrillString
        >>> g = make_grid(DrillString((Section("dp", 0.15, 0.12, 1000.0, 0.075, 40.0,
        ...                                    79.3e9),)), cells=10)
        >>> p = Plant(g, np.full(10, 10.0), 0.3, 0.2, 1.0, contact_radius_m=np.full(10, 0.1))
        >>> round(p.friction_torque_Nm(4.0), 6), round(p.friction_torque_Nm(4.0, 0.3), 6)
        (2000.0, 1600.0)
        """
        if axial_speed_m_s == 0.0:
            return float(np.sum(self.friction_Nm_m(omega_rad_s) * self.grid.dx_true_m))
        if self.contact_radius_m is None:
            raise ModelError("axial motion needs the contact radius of every cell",
                             fix="give Plant.contact_radius_m (torsional.contact_radius)")
        u = abs(axial_speed_m_s) / np.asarray(self.contact_radius_m, dtype=float)
        contact = np.hypot(omega_rad_s, u)
        f_k = self.mu_k * self.fc_Nm_m + self.fixed_k_Nm_m
        f_s = self.mu_s * self.fc_Nm_m + self.fixed_s_Nm_m
        weight = np.array([self.static_weight(c) for c in contact])
        per_m = (f_k + (f_s - f_k) * weight) * abs(omega_rad_s) / contact
        return float(np.sum(per_m * self.grid.dx_true_m))


def contact_radius(string: DrillString, grid: Grid) -> np.ndarray:
    """Contact radius r_c of each cell [m], of the section at the cell centre (the soft-string
    r_c of docs/theory.md §2: tool-joint OD/2 for drill pipe, body OD/2 for collars)."""
    return np.asarray(string.along("contact_radius_m", grid.x_m), dtype=float)


@dataclass(frozen=True)
class Axial:
    """Axial pipe speed v(t), uniform along the string (axially rigid; docs/theory.md §3.3),
    as a uniformly sampled series (linear in between, held beyond its ends).

    Attributes
    ----------
    values : ndarray
        v [m/s]; its sign (running in or pulling out) does not change the torsional share.
    dt_s : float
        Sample interval [s].
    t0_s : float
        Time of ``values[0]`` [s].
    """

    values: np.ndarray
    dt_s: float
    t0_s: float = 0.0

    def __post_init__(self):
        v = np.asarray(self.values, dtype=float)
        if not self.dt_s > 0 or v.ndim != 1 or v.size < 1 or not np.all(np.isfinite(v)):
            raise ModelError("an axial speed series needs finite values and dt_s > 0")

    def kernel_args(self, plant: Plant) -> tuple | None:
        """(v, t0, dt, 1/r_c per cell) for the kernels, None when v = 0 throughout."""
        if not np.any(np.asarray(self.values) != 0.0):
            return None
        if plant.contact_radius_m is None:
            raise ModelError("axial motion needs the contact radius of every cell",
                             fix="give Plant.contact_radius_m (torsional.contact_radius)")
        return (np.asarray(self.values, dtype=float), self.t0_s, self.dt_s,
                1.0 / np.asarray(plant.contact_radius_m, dtype=float))


def bit_torque_cap(bit_mu: float, wob_N: float, bit_diameter_m: float) -> float:
    """Bit torque magnitude T_bit = μ_bit·WOB·D_bit/3 [N·m] (uniform contact over the face).

    The bit is a Coulomb element at x = L: |τ_bit| ≤ T_bit while the bit is stuck,
    τ_bit = T_bit·sign(ω_bit) while it turns. With a rigid-face PDC assumption of uniform
    pressure the mean friction radius is D/3. A rate-weakening bit
    (:attr:`Plant.bit_weakening_ratio`) takes this as its high-speed torque T_k.

    Examples
    --------
    >>> bit_torque_cap(0.3, 60e3, 0.2159)
    1295.4
    """
    return float(bit_mu * wob_N * bit_diameter_m / 3.0)


@dataclass(frozen=True)
class Drive:
    """How the top drive is driven, as a uniformly sampled series (linear in between).

    Attributes
    ----------
    kind : str
        "pi" (PI speed control on a set-point series [rad/s]), "torque" (prescribed motor
        torque [N·m]), "speed" (prescribed top-drive speed [rad/s]) or "fed" (a logged
        drive replayed in closed loop: the logged motor torque plus PI control of the
        top-drive speed towards the logged speed, docs/theory.md §6.4).
    values : ndarray
        The series; held constant beyond its ends. "fed": shape (2, n), the motor torque
        [N·m] and the speed [rad/s].
    dt_s : float
        Sample interval of ``values`` [s].
    t0_s : float
        Time of ``values[0]`` [s].
    kp_Nms_rad, ki_Nm_rad : float
        PI gains (A&S 2018: 38e3 N·m·s/rad and 100e3 N·m/rad); of the correction in "fed".
    """

    kind: str
    values: np.ndarray
    dt_s: float
    t0_s: float = 0.0
    kp_Nms_rad: float = 38e3
    ki_Nm_rad: float = 100e3

    def __post_init__(self):
        if self.kind not in DRIVE_MODES:
            raise ModelError(f"unknown drive kind '{self.kind}'",
                             fix=f"use one of {', '.join(DRIVE_MODES)}")
        if self.dt_s <= 0 or np.size(self.values) < 1:
            raise ModelError("a drive series needs at least one value and dt_s > 0")
        if (self.kind == "fed") != (np.ndim(self.values) == 2 and len(self.values) == 2):
            raise ModelError(f"a '{self.kind}' drive takes "
                             + ("two series (motor torque, speed)" if self.kind == "fed"
                                else "one series"))


@dataclass
class State:
    """Mutable plant state between calls.

    Attributes
    ----------
    alpha, beta : ndarray
        Riemann invariants of every cell [rad/s] (eq. 8).
    top : ndarray
        [ω₀ (top-drive speed, rad/s), ∫(ω_ref − ω₀)dt (PI integral, rad)].
    t_s : float
        Time of the state [s].
    """

    alpha: np.ndarray
    beta: np.ndarray
    top: np.ndarray = field(default_factory=lambda: np.zeros(2))
    t_s: float = 0.0

    @classmethod
    def rest(cls, grid: Grid, t_s: float = 0.0) -> State:
        """String at rest with no twist."""
        return cls(np.zeros(grid.n_cells), np.zeros(grid.n_cells), np.zeros(2), t_s)

    @classmethod
    def wound(cls, grid: Grid, fc_Nm_m, torque_top_Nm: float, mu: float,
              omega_rad_s: float = 0.0, t_s: float = 0.0) -> State:
        """A string held twisted by friction, as it stands after it stuck while sliding.

        τ(x) = sign(τ₀)·max(|τ₀| − μ∫₀ˣF_c dx, 0) — the sliding torque gradient μ·F_c frozen
        from the surface torque τ₀ down to where the torque runs out (docs/theory.md §3,
        static friction holds each cell) — and every cell at ``omega_rad_s``.

        Parameters
        ----------
        grid : Grid
        fc_Nm_m : array_like
            F_c at the cells [N·m/m].
        torque_top_Nm : float
            Measured string torque at the surface τ₀ [N·m].
        mu : float
            Friction factor of the frozen gradient (the kinetic one) [-].

        Examples
        --------
        >>> from drillfric.drillstring import Section, DrillString
        >>> g = make_grid(DrillString((Section("dp", 0.15, 0.12, 1000.0, 0.075, 40.0, 79.3e9),
        ...                            )), cells=10)
        >>> tau = State.wound(g, np.full(10, 10.0), 3000.0, 0.5).torque_Nm(g)
        >>> np.round(tau[:3]).tolist(), float(tau[-1])
        ([2750.0, 2250.0, 1750.0], 0.0)
        """
        fc = np.broadcast_to(np.asarray(fc_Nm_m, dtype=float), grid.x_m.shape)
        capacity = np.cumsum(fc * grid.dx_true_m) - 0.5 * fc * grid.dx_true_m  # to centres
        torque = np.sign(torque_top_Nm) * np.maximum(abs(torque_top_Nm) - mu * capacity, 0.0)
        omega = np.full(grid.n_cells, float(omega_rad_s))
        return cls(omega + torque / grid.zeta_Nms, omega - torque / grid.zeta_Nms,
                   np.array([float(omega_rad_s), 0.0]), t_s)

    def on_grid(self, old: Grid, new: Grid) -> State:
        """This state (on grid ``old``) on the grid of a string that has moved along the
        hole, ``new`` (docs/theory.md §3.3, stand phases): ω and τ kept at each distance
        above the bit — the BHA and the lower string carry their motion and twist — and
        linearly interpolated between cell centres; pipe the new string has above the old
        one's top cell takes the top cell's ω and τ. Top drive and time are kept.

        Examples
        --------
        >>> from drillfric.drillstring import Section, DrillString
        >>> def grid(length):
        ...     return make_grid(DrillString((Section("dp", 0.15, 0.12, length, 0.075, 40.0,
        ...                                           79.3e9),)), cells=10)
        >>> a, b = grid(1000.0), grid(1100.0)
        >>> st = State.wound(a, np.full(10, 10.0), 3000.0, 0.2)
        >>> moved = st.on_grid(a, b)
        >>> float(moved.torque_Nm(b)[0]), round(float(moved.torque_Nm(b)[-1]), 6)
        (2900.0, 1110.0)
        """
        above_bit = float(np.sum(old.length_m)) - old.x_m
        d_new = float(np.sum(new.length_m)) - new.x_m
        omega = np.interp(-d_new, -above_bit, self.omega_rad_s)
        torque = np.interp(-d_new, -above_bit, self.torque_Nm(old))
        return State(omega + torque / new.zeta_Nms, omega - torque / new.zeta_Nms,
                     self.top.copy(), self.t_s)

    @property
    def omega_rad_s(self) -> np.ndarray:
        """Angular velocity ω = (α + β)/2 of every cell [rad/s]."""
        return 0.5 * (self.alpha + self.beta)

    def torque_Nm(self, grid: Grid) -> np.ndarray:
        """Torque τ = ζ(α − β)/2 of every cell [N·m]."""
        return 0.5 * grid.zeta_Nms * (self.alpha - self.beta)


@dataclass(frozen=True)
class Record:
    """Outputs at the requested rate, linearly interpolated between model steps.

    Attributes
    ----------
    time_s : ndarray
    surface_rad_s : ndarray
        Top-drive speed ω₀ [rad/s].
    motor_torque_Nm : ndarray
        Motor torque τ_m [N·m].
    string_torque_Nm : ndarray
        String torque at the top τ(0) = ζ(ω₀ − β(0)) [N·m] (= τ_m − I_TD dω₀/dt).
    bit_rad_s : ndarray
        Bit speed: ω of the last cell [rad/s].
    bit_torque_Nm : ndarray
        Torque the bit applies to the string τ_bit = ζ·clamp(α(L), ±T_bit/ζ) [N·m] (0 for a
        free bit), the value held over each model step.
    """

    time_s: np.ndarray
    surface_rad_s: np.ndarray
    motor_torque_Nm: np.ndarray
    string_torque_Nm: np.ndarray
    bit_rad_s: np.ndarray
    bit_torque_Nm: np.ndarray


def energy(grid: Grid, state: State, top_drive_inertia_kg_m2: float = 0.0) -> float:
    """Mechanical energy of the string (+ top drive) [J] (docs/theory.md §3).

    Per cell ρJω²/2 + τ²/(2JG) over Δx = c Δt equals ζ·Δt·(α² + β²)/4; the top drive adds
    I_TD·ω₀²/2.
    """
    string = 0.25 * grid.dt_s * float(np.sum(grid.zeta_Nms * (state.alpha**2 + state.beta**2)))
    return string + 0.5 * top_drive_inertia_kg_m2 * float(state.top[0]) ** 2


def record_times(t_start_s: float, duration_s: float, rate_hz: float) -> np.ndarray:
    """Sample times t_start + r/rate for r = 0 … floor(duration·rate) [s]."""
    n = int(np.floor(duration_s * rate_hz * (1 + 1e-12))) + 1
    return t_start_s + np.arange(n) / rate_hz


def kernel_args(plant: Plant, drive: Drive) -> tuple:
    """Plain-array arguments shared by the numba kernel and its NumPy twin (in order)."""
    g = plant.grid
    return (g.section_start, g.junction_z, g.zeta_Nms, plant.fcap_rad_s, plant.fix_k_rad_s,
            plant.fix_s_rad_s, g.dt_s, plant.k_t_per_s * g.dt_s, plant.mu_s, plant.mu_k,
            plant.omega_c_rad_s, plant.law_speed_rad_s, float(plant.stribeck_exponent),
            plant.bit_torque_cap_Nm / g.zeta_Nms[-1],
            (plant.bit_weakening_ratio - 1.0) * plant.bit_torque_cap_Nm / g.zeta_Nms[-1],
            1.0 / plant.bit_weakening_speed_rad_s, 1.0 / plant.top_drive_inertia_kg_m2,
            DRIVE_MODES[drive.kind], np.ascontiguousarray(drive.values, dtype=float).ravel(),
            drive.t0_s, drive.dt_s, drive.kp_Nms_rad, drive.ki_Nm_rad)


def model_steps(duration_s: float, dt_s: float) -> int:
    """Whole model steps that cover ``duration_s`` [-] (:func:`run` advances by as many)."""
    return int(np.ceil(duration_s / dt_s * (1 - 1e-12)))


def run(plant: Plant, drive: Drive, duration_s: float, rate_hz: float,
        state: State | None = None, *, backend: str = "numba",
        axial: Axial | None = None, times_s: np.ndarray | None = None) -> tuple[Record, State]:
    """Advance the plant for ``duration_s`` and record at ``rate_hz`` (docs/theory.md §3.1).

    Parameters
    ----------
    plant : Plant
    drive : Drive
    duration_s : float
        Simulated time [s] (> 0).
    rate_hz : float
        Recording rate [Hz] (> 0); records are interpolated linearly between model steps.
    state : State, optional
        Initial state (default: at rest, no twist, at t = 0). Not modified.
    backend : str
        "numba" (compiled kernel) or "numpy" (the twin, for tests and benchmarks).
    axial : Axial, optional
        Axial pipe speed v(t) (docs/theory.md §3.3; needs ``plant.contact_radius_m``). None
        (default) or v = 0 throughout is the plant without axial motion, bit for bit.
    times_s : ndarray, optional
        Record at these times [s] instead of every 1/``rate_hz`` from ``state.t_s``; they
        must lie within the steps run, [t_s, t_s + :func:`model_steps`·Δt].

    Returns
    -------
    (Record, State)
        The records from ``state.t_s`` to ``state.t_s + duration_s`` and the final state.
    """
    if not duration_s > 0 or not rate_hz > 0:
        raise ModelError(f"duration and rate must be positive, got {duration_s} s, "
                         f"{rate_hz} Hz")
    state = State.rest(plant.grid) if state is None else state
    alpha, beta, top = state.alpha.copy(), state.beta.copy(), state.top.copy()
    n_steps = model_steps(duration_s, plant.grid.dt_s)
    times = record_times(state.t_s, duration_s, rate_hz) if times_s is None \
        else np.asarray(times_s, dtype=float)
    out = np.empty((times.size, len(RECORD_COLUMNS)))
    if backend == "numba":
        from drillfric.kernels.plant import run_plant
    elif backend == "numpy":
        from drillfric.kernels.plant_numpy import run_plant
    else:
        raise ModelError(f"unknown backend '{backend}'", fix="use 'numba' or 'numpy'")
    run_plant(alpha, beta, top, state.t_s, n_steps, *kernel_args(plant, drive), times, out,
              axial=None if axial is None else axial.kernel_args(plant))
    rec = Record(times, *(out[:, k] for k in range(out.shape[1])))
    return rec, State(alpha, beta, top, state.t_s + n_steps * plant.grid.dt_s)
