"""Soft-string torque and drag: normal force, effective tension and torque along the string.

Implements docs/theory.md §2, the soft-string model of [1] in the vector form of the normal
force, marched from the bit to the surface over elements that follow the minimum-curvature
arc (docs/theory.md §1). Its main product for the friction observer is the Coulomb torque
capacity per unit length per unit friction factor F_c(x) = r_c(x)·F_N(x) [N·m/m] and its
integral T_N = ∫F_c dx (docs/theory.md §5.1).

[1] C.A. Johancsik, D.B. Friesen, R. Dawson, "Torque and drag in directional wells —
    prediction and measurement", JPT 36(6), 1984, SPE-11380-PA.

Layers: :func:`element_normal_force` (one element, pure maths), the compiled bit-to-surface
march ``_march_many`` (numba), :func:`solve` (one bit depth, one load case),
:func:`solve_config` (from a well configuration), :func:`back_calculate_friction` and
:func:`broomstick` (many depths × friction factors × load cases, vectorised over the last
two inside one compiled call per depth).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from drillfric.drillstring import DrillString, build_string
from drillfric.errors import ModelError
from drillfric.kernels.lazy import lazy_jit
from drillfric.units import RPM_TO_RAD_S
from drillfric.vocabulary import LoadCase
from drillfric.wellpath import WellPath, no_survey_path

if TYPE_CHECKING:
    from drillfric.config import Config

#: Load cases (docs/theory.md §2 step 3): σ is the axial share of the friction (+1 pulling out,
#: −1 running in, 0 rotating), the torque share is the tangential one.
LOAD_CASES = tuple(LoadCase)
#: Load cases with the bit on bottom (bit boundary F = −WOB). ``sliding`` is slack-off with
#: weight on bit and no rotation (motor drilling); its bit torque is not modelled (M = 0).
ON_BOTTOM_CASES = (LoadCase.ROTATING_ON_BOTTOM, LoadCase.SLIDING)
_MIN_ELEMENT_M = 1e-6  # [m] nodes closer than this are merged
#: Most elements of one string's mesh (each a few hundred bytes and a step of every sweep;
#: the default 2-m elements give 3000 at 6 km): a budget on the work ``element_length_m``
#: implies (docs/security.md, "Work budget").
MAX_ELEMENTS = 200_000
_FRICTION_BRACKET = (0.0, 2.0)

Friction = float | Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class TDResult:
    """Soft-string profile at one bit depth for one load case (docs/theory.md §2).

    Attributes
    ----------
    md_m : ndarray
        Node measured depths from surface (0) to the bit, length n + 1 [m].
    inc_rad, azi_rad : ndarray
        Inclination and azimuth at the nodes [rad].
    tension_N : ndarray
        Effective axial force at the nodes, tension positive [N].
    torque_Nm : ndarray
        Torque at the nodes [N·m].
    normal_force_N_m : ndarray
        Side force per unit length F_N of each element, length n [N/m].
    fc_Nm_m : ndarray
        F_c = r_c·F_N of each element: Coulomb torque capacity per unit length per unit
        friction factor [N·m/m] (docs/theory.md §2).
    hookload_N : float
        Effective tension at surface [N] (no block weight, no sheave friction).
    surface_torque_Nm : float
        Torque at surface [N·m].
    T_N_Nm : float
        T_N = ∫F_c dx over the string [N·m] (docs/theory.md §5.1).
    load_case : str
        One of :data:`LOAD_CASES`.
    friction : float or None
        The friction factor when one value was used (None when it varies along the hole).
    """

    md_m: np.ndarray
    inc_rad: np.ndarray
    azi_rad: np.ndarray
    tension_N: np.ndarray
    torque_Nm: np.ndarray
    normal_force_N_m: np.ndarray
    fc_Nm_m: np.ndarray
    hookload_N: float
    surface_torque_Nm: float
    T_N_Nm: float
    load_case: str
    friction: float | None

    @property
    def bit_depth_m(self) -> float:
        """Bit measured depth [m]."""
        return float(self.md_m[-1])

    def __repr__(self) -> str:
        """One line, in kN and kN·m: ``<TDResult pick_up at 2300.0 m, friction 0.25: hook
        load 997.8 kN, surface torque 0.00 kN·m, T_N 68.76 kN·m, 1151 nodes>``."""
        friction = "varies" if self.friction is None else f"{self.friction:g}"
        return (f"<TDResult {self.load_case} at {self.bit_depth_m:.1f} m, friction {friction}: "
                f"hook load {self.hookload_N / 1e3:.1f} kN, surface torque "
                f"{self.surface_torque_Nm / 1e3:.2f} kN·m, T_N {self.T_N_Nm / 1e3:.2f} kN·m, "
                f"{self.md_m.size} nodes>")

    def fc_at(self, md_m) -> np.ndarray:
        """F_c [N·m/m] of the element containing each measured depth (bit → last element)."""
        md = np.atleast_1d(np.asarray(md_m, dtype=float))
        k = np.searchsorted(self.md_m, md, side="right") - 1
        return self.fc_Nm_m[np.clip(k, 0, self.fc_Nm_m.size - 1)]

    def to_frame(self):
        """Profile as a table: node rows, element values on the element below each node.

        Columns md_m, inc_deg, azi_deg, tension_N, torque_Nm, normal_force_N_m, fc_Nm_m
        (the bit row repeats the last element's values).
        """
        import pandas as pd

        below = np.append(np.arange(self.fc_Nm_m.size), self.fc_Nm_m.size - 1)
        return pd.DataFrame({"md_m": self.md_m, "inc_deg": np.degrees(self.inc_rad),
                             "azi_deg": np.degrees(self.azi_rad), "tension_N": self.tension_N,
                             "torque_Nm": self.torque_Nm,
                             "normal_force_N_m": self.normal_force_N_m[below],
                             "fc_Nm_m": self.fc_Nm_m[below]})


def element_normal_force(force_lower_N: float, t_upper, t_lower, weight_N: float) -> float:
    """Side force N [N] on one element, vector form (docs/theory.md §2 step 2, after [1]).

    q = F_d·(t_d − t_u) + W·(ĝ − (ĝ·t̄)·t̄), N = |q|, with t̄ = normalise(t_u + t_d) and
    ĝ = (0, 0, 1) pointing down.

    Parameters
    ----------
    force_lower_N : float
        Effective axial force at the lower node F_d, tension positive [N].
    t_upper, t_lower : array_like, shape (3,)
        Unit tangents (north, east, down) at the upper and lower node.
    weight_N : float
        Buoyed weight of the element W [N].

    Examples
    --------
    A straight element at 90° carries its whole weight on the wall:

    >>> element_normal_force(1e5, [1.0, 0, 0], [1.0, 0, 0], 300.0)
    300.0
    """
    tu = np.asarray(t_upper, dtype=float)
    td = np.asarray(t_lower, dtype=float)
    tbar = (tu + td) / np.linalg.norm(tu + td)
    q = force_lower_N * (td - tu) + weight_N * (np.array([0.0, 0.0, 1.0]) - tbar[2] * tbar)
    return float(np.linalg.norm(q))


def _march_many(t, weight, rc, mu, sigma, share, force_bit, torque_bit,
                force, torque, normal):  # pragma: no cover - compiled; oracle-tested
    """Bit-to-surface march (docs/theory.md §2 steps 2–5) for k load variants on one mesh.

    t (n+1, 3) node tangents; weight, rc (n,) element buoyed weight [N] and contact radius
    [m]; mu, sigma, share (n, k) friction factor, axial and tangential friction shares;
    force_bit, torque_bit (k,) bit boundary values. Writes force, torque (n+1, k) and
    normal (n, k) [N] in place. The element geometry is computed once for all k variants.
    """
    n = weight.size
    k = force_bit.size
    for j in range(k):
        force[n, j] = force_bit[j]
        torque[n, j] = torque_bit[j]
    for e in range(n - 1, -1, -1):
        ux, uy, uz = t[e, 0], t[e, 1], t[e, 2]
        dx, dy, dz = t[e + 1, 0] - ux, t[e + 1, 1] - uy, t[e + 1, 2] - uz
        bx, by, bz = ux + t[e + 1, 0], uy + t[e + 1, 1], uz + t[e + 1, 2]
        norm = np.sqrt(bx * bx + by * by + bz * bz)
        if norm < 1e-12:  # a 180° turn inside one element: take the upper tangent
            bx, by, bz = ux, uy, uz
        else:
            bx, by, bz = bx / norm, by / norm, bz / norm
        w = weight[e]
        # W·(ĝ − (ĝ·t̄)·t̄) with ĝ = (0, 0, 1)
        gx, gy, gz = -w * bz * bx, -w * bz * by, w * (1.0 - bz * bz)
        w_axial = w * bz
        for j in range(k):
            fd = force[e + 1, j]
            qx, qy, qz = fd * dx + gx, fd * dy + gy, fd * dz + gz
            nn = np.sqrt(qx * qx + qy * qy + qz * qz)
            normal[e, j] = nn
            drag = mu[e, j] * nn
            force[e, j] = fd + w_axial + sigma[e, j] * drag
            torque[e, j] = torque[e + 1, j] + share[e, j] * drag * rc[e]


@dataclass(frozen=True)
class _Mesh:
    """Elements of one string at one bit depth: nodes, tangents, per-element properties."""

    md_m: np.ndarray        # (n+1,) node depths [m]
    tangent: np.ndarray     # (n+1, 3)
    weight_N: np.ndarray    # (n,) buoyed weight of each element [N]
    rc_m: np.ndarray        # (n,) contact radius [m]
    mid_m: np.ndarray       # (n,) element mid depths [m]

    @property
    def ds_m(self) -> np.ndarray:
        return np.diff(self.md_m)


#: :func:`_march_many` compiled on first use: importing this module (``inspect``'s run
#: checks reach :data:`MAX_ELEMENTS`) does not load numba.
_compiled_march = lazy_jit(_march_many)


def _check_inputs(path: WellPath, string: DrillString, mud_out: float, mud_in: float,
                  element_length_m: float) -> None:
    if not np.isfinite(element_length_m) or element_length_m <= 0:
        raise ModelError(f"element length must be positive, got {element_length_m} m")
    for name, rho in (("annulus", mud_out), ("bore", mud_in)):
        if not np.isfinite(rho) or rho < 0:
            raise ModelError(f"{name} mud density must be ≥ 0, got {rho} kg/m³")
    for s in string.sections:
        if not (s.od_m > 0 and 0 <= s.id_m < s.od_m and s.length_m > 0
                and s.contact_radius_m > 0 and s.linear_mass_kg_m > 0):
            raise ModelError(f"section '{s.name}': dimensions must be positive with "
                             f"0 ≤ ID < OD (OD {s.od_m} m, ID {s.id_m} m, length "
                             f"{s.length_m} m, mass {s.linear_mass_kg_m} kg/m)",
                             fix="check the [[string.sections]] entries")
        if mud_out >= s.steel_density_kg_m3:
            raise ModelError(f"mud density {mud_out:g} kg/m³ is not lighter than the steel "
                             f"of '{s.name}' ({s.steel_density_kg_m3:g} kg/m³)",
                             fix="give the mud density in kg/m³ (e.g. 1200)")
    bit = string.bit_depth_m
    if bit > path.md_max_m + 1e-6 * max(1.0, bit):
        raise ModelError(f"bit depth {bit:.1f} m is beyond the survey (last station "
                         f"{path.md_max_m:.1f} m)", fix="extend the survey or a shallower bit")


def _mesh(path: WellPath, string: DrillString, element_length_m: float, mud_out: float,
          mud_in: float, extra_nodes_m=()) -> _Mesh:
    """Nodes every ``element_length_m`` plus section boundaries, survey stations and extras."""
    bit = string.bit_depth_m
    n_reg = max(1, int(np.ceil(bit / element_length_m - 1e-9)))
    if n_reg > MAX_ELEMENTS:
        raise ModelError(f"element length {element_length_m:g} m gives {n_reg:.3g} "
                         f"torque-and-drag elements to {bit:.0f} m; at most {MAX_ELEMENTS:.0e}",
                         fix=f"[model] element_length_m ≥ {bit / MAX_ELEMENTS:.2g} m "
                             "(default 2 m)")
    stations = path.md_m[(path.md_m > 0) & (path.md_m < bit)]
    extra = np.asarray(extra_nodes_m, dtype=float)
    nodes = np.concatenate([np.linspace(0.0, bit, n_reg + 1), string.boundaries_m, stations,
                            extra[(extra > 0) & (extra < bit)]])
    nodes = np.unique(nodes)
    nodes = nodes[np.concatenate([[True], np.diff(nodes) > _MIN_ELEMENT_M])]
    nodes[0], nodes[-1] = 0.0, bit  # the bit is the largest node; a near-duplicate was dropped
    top = path.md_m[0]
    # above the first station (only with a tie-in: minimum_curvature otherwise adds a
    # surface station) the hole is taken as having the first station's direction
    tangent = path.tangent(np.clip(nodes, top, None))
    mid = 0.5 * (nodes[1:] + nodes[:-1])
    weight = string.buoyed_weight_N_m(mid, mud_out, mud_in) * np.diff(nodes)
    return _Mesh(md_m=nodes, tangent=tangent, weight_N=weight,
                 rc_m=string.along("contact_radius_m", mid), mid_m=mid)


def _friction_array(friction: Friction, mid_m: np.ndarray) -> np.ndarray:
    mu = friction(mid_m) if callable(friction) else np.full(mid_m.shape, float(friction))
    mu = np.broadcast_to(np.asarray(mu, dtype=float), mid_m.shape)
    if not np.all(np.isfinite(mu)) or np.any(mu < 0):
        raise ModelError("friction factor must be finite and ≥ 0")
    return mu


def _shares(load_case: str, rc_m: np.ndarray, axial_speed_m_s: float,
            rpm: float) -> tuple[np.ndarray, np.ndarray]:
    """Axial σ and tangential share of the friction per element (docs/theory.md §2 steps 3–4)."""
    if load_case not in LOAD_CASES:
        raise ModelError(f"unknown load case '{load_case}'",
                         fix=f"use one of: {', '.join(LOAD_CASES)}")
    one, zero = np.ones_like(rc_m), np.zeros_like(rc_m)
    if load_case in (LoadCase.ROTATING_OFF_BOTTOM, LoadCase.ROTATING_ON_BOTTOM):
        return zero, one
    if load_case == LoadCase.PICK_UP:
        return one, zero
    if load_case in (LoadCase.SLACK_OFF, LoadCase.SLIDING):
        return -one, zero
    v, omega = abs(axial_speed_m_s), abs(rpm) * RPM_TO_RAD_S
    if v <= 0 or omega <= 0:
        raise ModelError(f"load case '{load_case}' needs a positive axial speed and RPM, got "
                         f"{axial_speed_m_s} m/s and {rpm} RPM",
                         fix="give axial_speed_m_s and rpm (e.g. 0.3 m/s and 60 RPM)")
    speed = np.hypot(v, omega * rc_m)
    sign = 1.0 if load_case == LoadCase.ROTATING_PICK_UP else -1.0
    return sign * v / speed, omega * rc_m / speed


def _bit_boundary(load_case: str, wob_N: float, bit_torque_Nm: float) -> tuple[float, float]:
    """Bit boundary (docs/theory.md §2 step 5): F = −WOB, M = torque on bit on bottom; else 0."""
    if load_case not in ON_BOTTOM_CASES:
        return 0.0, 0.0
    if not np.isfinite(wob_N) or wob_N < 0:
        raise ModelError(f"WOB must be ≥ 0, got {wob_N} N")
    torque = float(bit_torque_Nm) if load_case == LoadCase.ROTATING_ON_BOTTOM else 0.0
    return -float(wob_N), torque


def _run(mesh: _Mesh, mu: np.ndarray, sigma: np.ndarray, share: np.ndarray,
         force_bit: np.ndarray, torque_bit: np.ndarray):
    """Run the compiled march for k variants given as (n, k) arrays; returns (k, ·) arrays."""
    n, k = mu.shape
    force = np.empty((n + 1, k))
    torque = np.empty((n + 1, k))
    normal = np.empty((n, k))

    def arr(x):  # one compiled signature: C-contiguous, writable float64
        return np.require(x, dtype=np.float64, requirements=["C", "W"])

    _compiled_march()(arr(mesh.tangent), arr(mesh.weight_N), arr(mesh.rc_m), arr(mu),
                      arr(sigma), arr(share), arr(force_bit), arr(torque_bit), force, torque,
                      normal)
    return force.T, torque.T, normal.T


def solve(path: WellPath, string: DrillString, *, friction: Friction = 0.25,
          load_case: str = "rotating_off_bottom", wob_N: float = 0.0,
          bit_torque_Nm: float = 0.0, mud_out_kg_m3: float = 1200.0,
          mud_in_kg_m3: float | None = None, element_length_m: float = 2.0,
          axial_speed_m_s: float = 0.0, rpm: float = 0.0,
          extra_nodes_m=()) -> TDResult:
    """Soft-string torque and drag at one bit depth (docs/theory.md §2, after [1]).

    Parameters
    ----------
    path : WellPath
        Hole geometry; must reach the bit depth.
    string : DrillString
        The string hung from surface to the bit (``string.bit_depth_m``).
    friction : float or callable
        Friction factor μ [-], or a function of element mid depth [m] → μ array
        (e.g. cased above the shoe, open hole below).
    load_case : str
        One of :data:`LOAD_CASES`.
    wob_N, bit_torque_Nm : float
        Weight and torque on bit [N], [N·m]; used by on-bottom cases only.
    mud_out_kg_m3, mud_in_kg_m3 : float
        Annulus and bore mud densities [kg/m³] (bore defaults to annulus).
    element_length_m : float
        Target element length [m]; section boundaries, survey stations and
        ``extra_nodes_m`` are nodes too.
    axial_speed_m_s, rpm : float
        Trip speed [m/s] and rotary speed [RPM] of the combined-motion cases:
        σ = v/√(v² + (ω r_c)²), torque share ω r_c/√(v² + (ω r_c)²).

    Returns
    -------
    TDResult

    Raises
    ------
    ModelError
        Bit beyond the survey, non-physical dimensions or densities, unknown load case.
    """
    mud_in = mud_out_kg_m3 if mud_in_kg_m3 is None else mud_in_kg_m3
    _check_inputs(path, string, mud_out_kg_m3, mud_in, element_length_m)
    mesh = _mesh(path, string, element_length_m, mud_out_kg_m3, mud_in, extra_nodes_m)
    mu = _friction_array(friction, mesh.mid_m)
    sigma, share = _shares(load_case, mesh.rc_m, axial_speed_m_s, rpm)
    f_bit, m_bit = _bit_boundary(load_case, wob_N, bit_torque_Nm)
    force, torque, normal = _run(mesh, mu[:, None], sigma[:, None], share[:, None],
                                 np.array([f_bit]), np.array([m_bit]))
    return _result(mesh, force[0].copy(), torque[0].copy(), normal[0].copy(), load_case,
                   None if callable(friction) else float(friction))


def _result(mesh: _Mesh, force, torque, normal, load_case, friction) -> TDResult:
    fn = normal / mesh.ds_m
    fc = mesh.rc_m * fn
    t = mesh.tangent
    inc = np.arctan2(np.hypot(t[:, 0], t[:, 1]), t[:, 2])
    azi = np.mod(np.arctan2(t[:, 1], t[:, 0]), 2 * np.pi)
    return TDResult(md_m=mesh.md_m, inc_rad=inc, azi_rad=azi, tension_N=force,
                    torque_Nm=torque, normal_force_N_m=fn, fc_Nm_m=fc,
                    hookload_N=float(force[0]), surface_torque_Nm=float(torque[0]),
                    T_N_Nm=float(np.sum(mesh.rc_m * normal)), load_case=load_case,
                    friction=friction)


def config_friction(cfg: Config, friction: Friction | None = None) -> Friction:
    """Friction factor from a configuration: ``friction`` if given (a number, or a function of
    measured depth like :class:`SectionFriction`), else per hole section.

    Above ``model.casing_shoe_md_m`` the cased value applies, below it the open-hole value;
    a missing one falls back to ``model.friction``.
    """
    if friction is not None:
        return friction if callable(friction) else float(friction)
    base = cfg.model.friction
    shoe = cfg.model.casing_shoe_md_m
    cased, open_ = cfg.model.friction_cased, cfg.model.friction_open
    if shoe is None or (cased is None and open_ is None):
        return float(base)
    mu_c = base if cased is None else cased
    mu_o = base if open_ is None else open_
    return SectionFriction(float(shoe), float(mu_c), float(mu_o))


@dataclass(frozen=True)
class SectionFriction:
    """μ(md) = cased above the shoe, open hole below (picklable, unlike a lambda)."""

    shoe_md_m: float
    cased: float
    open_hole: float

    def __call__(self, md_m: np.ndarray) -> np.ndarray:
        return np.where(np.asarray(md_m) < self.shoe_md_m, self.cased, self.open_hole)


@dataclass(frozen=True)
class TDSettings:
    """What a well's configuration sets for its torque and drag, derived once per well.

    Attributes
    ----------
    sections : tuple of dict
        ``[[string.sections]]``, top-down (:func:`drillfric.drillstring.build_string`).
    friction : Friction
        The configured friction factor, per hole section (:func:`config_friction`) [-].
    mud_out_kg_m3, mud_in_kg_m3 : float
        Mud density in the annulus and inside the string [kg/m³].
    element_length_m : float
        Soft-string element length [m] (``model.element_length_m``).
    casing_shoe_md_m : float or None
        The casing shoe, a node of every mesh [m] (``model.casing_shoe_md_m``).
    tortuosity_rad_m : float
        Tortuosity of the path assumed without a survey [rad/m].
    """

    sections: tuple
    friction: Friction
    mud_out_kg_m3: float
    mud_in_kg_m3: float
    element_length_m: float
    casing_shoe_md_m: float | None
    tortuosity_rad_m: float

    @classmethod
    def from_config(cls, cfg: Config) -> TDSettings:
        """The torque-and-drag settings of a :class:`drillfric.config.Config`."""
        return cls(cfg.sections, config_friction(cfg), cfg.fluid.mud_density_kg_m3,
                   cfg.inner_mud_density_kg_m3, cfg.model.element_length_m,
                   cfg.model.casing_shoe_md_m, cfg.tortuosity_rad_m)

    def path_to(self, path: WellPath | None, bit_depth_m: float) -> WellPath:
        """``path``, or without a survey the assumed one to the bit: vertical with the
        nominal tortuosity (:func:`drillfric.wellpath.no_survey_path`)."""
        return no_survey_path(bit_depth_m, self.tortuosity_rad_m) if path is None else path

    def string(self, bit_depth_m: float) -> DrillString:
        """The configured string with its bit at ``bit_depth_m`` [m]."""
        return build_string(self.sections, bit_depth_m)

    def solve(self, path: WellPath | None, bit_depth_m: float, **kw) -> TDResult:
        """:func:`solve` with these settings' string, muds, element length and friction.

        Parameters
        ----------
        path : WellPath or None
            Hole geometry; None: the assumed path to the bit (:meth:`path_to`).
        bit_depth_m : float
            Bit measured depth [m].
        **kw
            Passed to :func:`solve` (``friction`` overrides the configured friction).
        """
        kw = dict(kw)
        given = kw.get("friction")
        kw["friction"] = self.friction if given is None else (
            given if callable(given) else float(given))
        kw.setdefault("mud_out_kg_m3", self.mud_out_kg_m3)
        kw.setdefault("mud_in_kg_m3", self.mud_in_kg_m3)
        kw.setdefault("element_length_m", self.element_length_m)
        if self.casing_shoe_md_m is not None:
            kw.setdefault("extra_nodes_m", (self.casing_shoe_md_m,))
        return solve(self.path_to(path, bit_depth_m), self.string(bit_depth_m), **kw)


def solve_config(cfg: Config, path: WellPath | None, bit_depth_m: float, **kw) -> TDResult:
    """:func:`solve` from a configuration (an entry point: the API's ``td``, the simulator):
    :meth:`TDSettings.solve` of :meth:`TDSettings.from_config`."""
    return TDSettings.from_config(cfg).solve(path, bit_depth_m, **kw)


def back_calculate_friction(path: WellPath, string: DrillString, *,
                            surface_torque_Nm: float | None = None,
                            hookload_N: float | None = None,
                            load_case: str = "rotating_off_bottom", friction_of=None,
                            **kw) -> float:
    """Friction factor that makes the model match a measured surface torque or hook load.

    A scalar root find (scipy ``brentq``) of model − measurement over μ ∈ [0, 2].

    Parameters
    ----------
    surface_torque_Nm : float, optional
        Measured surface torque [N·m] (rotating load cases).
    hookload_N : float, optional
        Measured effective hook load [N] (pick-up / slack-off), block weight removed.
    load_case : str
        Load case of the measurement.
    friction_of : callable, optional
        μ → the friction to solve with (e.g. a known cased factor above the shoe and μ
        below: μ is then the open hole's); default μ everywhere.
    **kw
        Passed to :func:`solve` (WOB, bit torque, muds, element length, ...).

    Raises
    ------
    ModelError
        Neither or both measurements given, or no friction factor in [0, 2] matches.
    """
    from scipy.optimize import brentq

    if (surface_torque_Nm is None) == (hookload_N is None):
        raise ModelError("give exactly one of surface_torque_Nm and hookload_N")
    target = float(surface_torque_Nm if hookload_N is None else hookload_N)
    attr = "surface_torque_Nm" if hookload_N is None else "hookload_N"

    def residual(mu: float) -> float:
        friction = mu if friction_of is None else friction_of(mu)
        return getattr(solve(path, string, friction=friction, load_case=load_case, **kw),
                       attr) - target

    lo, hi = _FRICTION_BRACKET
    r_lo, r_hi = residual(lo), residual(hi)
    if r_lo == 0.0:
        return lo
    if np.sign(r_lo) == np.sign(r_hi):
        what = "surface torque" if hookload_N is None else "hook load"
        raise ModelError(f"no friction factor in [{lo:g}, {hi:g}] reproduces the measured "
                         f"{what} {target:.6g} (model gives {r_lo + target:.6g} at μ = {lo:g} "
                         f"and {r_hi + target:.6g} at μ = {hi:g})",
                         fix="check the measurement's units, the load case and the string")
    return float(brentq(residual, lo, hi, xtol=1e-8, rtol=1e-10))


def broomstick(path: WellPath, string_or_sections, bit_depths_m, frictions,
               load_cases=("rotating_off_bottom", "pick_up", "slack_off",
                           "rotating_on_bottom"), **kw):
    """Hook load and surface torque over bit depths × friction factors × load cases.

    Parameters
    ----------
    path : WellPath
    string_or_sections : DrillString or sequence of dict
        Configured sections (top one fills to the bit, see
        :func:`drillfric.drillstring.build_string`), or a fixed DrillString whose top
        section is resized for each depth.
    bit_depths_m : array_like
        Bit depths [m].
    frictions : sequence of float
        Friction factors [-].
    load_cases : sequence of str
    **kw
        As :func:`solve` (wob_N, bit_torque_Nm, muds, element_length_m, speeds).

    Returns
    -------
    pandas.DataFrame
        One row per depth × friction × case: bit_depth_m, friction_factor, load_case,
        hookload_N, surface_torque_Nm, T_N_Nm.
    """
    import pandas as pd

    sections = _as_sections(string_or_sections)
    frictions = [float(f) for f in frictions]
    load_cases = list(load_cases)
    mud_out = kw.pop("mud_out_kg_m3", 1200.0)
    mud_in = kw.pop("mud_in_kg_m3", None)
    mud_in = mud_out if mud_in is None else mud_in
    h = kw.pop("element_length_m", 2.0)
    wob, bit_torque = kw.pop("wob_N", 0.0), kw.pop("bit_torque_Nm", 0.0)
    v, rpm = kw.pop("axial_speed_m_s", 0.0), kw.pop("rpm", 0.0)
    extra = kw.pop("extra_nodes_m", ())
    if kw:
        raise TypeError(f"unexpected arguments: {', '.join(kw)}")
    rows = []
    for depth in np.atleast_1d(np.asarray(bit_depths_m, dtype=float)):
        string = build_string(sections, float(depth))
        _check_inputs(path, string, mud_out, mud_in, h)
        mesh = _mesh(path, string, h, mud_out, mud_in, extra)
        n_f = len(frictions)
        shares = [_shares(case, mesh.rc_m, v, rpm) for case in load_cases]
        bits = np.repeat([_bit_boundary(case, wob, bit_torque) for case in load_cases], n_f,
                         axis=0)
        # variant j = case index · n_f + friction index, laid out (n, k) for the kernel
        force, torque, normal = _run(
            mesh, np.broadcast_to(np.tile(frictions, len(load_cases)), (mesh.mid_m.size,
                                                                        bits.shape[0])),
            np.repeat(np.stack([sh[0] for sh in shares], axis=1), n_f, axis=1),
            np.repeat(np.stack([sh[1] for sh in shares], axis=1), n_f, axis=1),
            bits[:, 0], bits[:, 1])
        labels = [(case, f) for case in load_cases for f in frictions]
        t_n = normal @ mesh.rc_m
        for j, (case, f) in enumerate(labels):
            rows.append((float(depth), f, case, force[j, 0], torque[j, 0], t_n[j]))
    return pd.DataFrame(rows, columns=["bit_depth_m", "friction_factor", "load_case",
                                       "hookload_N", "surface_torque_Nm", "T_N_Nm"])


def _as_sections(string_or_sections) -> list[dict]:
    """Section entries for :func:`build_string` from a DrillString or config entries."""
    if not isinstance(string_or_sections, DrillString):
        return [dict(e) for e in string_or_sections]
    out = []
    for s in string_or_sections.sections:
        out.append({"name": s.name, "od_m": s.od_m, "id_m": s.id_m, "length_m": s.length_m,
                    "tool_joint_od_m": 2 * s.contact_radius_m,
                    "linear_mass_kg_m": s.linear_mass_kg_m,
                    "shear_modulus_Pa": s.shear_modulus_Pa,
                    "steel_density_kg_m3": s.steel_density_kg_m3})
    return out


def broomstick_figure(table, measured=None, *, size=(10.0, 7.0), note: str | None = None,
                      units: str = "si"):
    """Broomstick plot of a :func:`broomstick` table: hook load and torque versus depth.

    Left: hook load of every load case and friction factor; right: surface torque of the
    rotating cases. Depth increases downwards. Returns a matplotlib Figure.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`broomstick` output.
    measured : pandas.DataFrame, optional
        Measured points drawn on top, one per segment: ``bit_depth_m``, ``hookload_N``
        [N], ``surface_torque_Nm`` [N·m] and ``kind`` (``off_bottom_rotating`` filled
        black circles, ``on_bottom_rotating`` hollow triangles: their torque includes the
        bit's). The measured hook load includes the travelling block; the model's does not.
    size : (float, float)
        Figure size [in].
    note : str, optional
        A line printed under the title (e.g. the string-weight check).
    units : str
        Display units of the axes, ``"si"`` (m, kN, kN·m) or ``"field"`` (ft, klbf,
        kft·lbf): :data:`drillfric.units.DISPLAY_UNITS`.
    """
    import matplotlib
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    from drillfric.units import display_unit, to_display

    def show(values, quantity):
        return to_display(values, quantity, units)

    fig = Figure(figsize=size, layout="constrained")
    ax_h, ax_t = fig.subplots(1, 2, sharey=True)
    styles = {"pick_up": "-", "slack_off": "--", "rotating_off_bottom": ":",
              "rotating_on_bottom": "-.", "rotating_pick_up": (0, (5, 1)),
              "rotating_slack_off": (0, (1, 1))}
    frictions = sorted(table["friction_factor"].unique())
    cmap = matplotlib.colormaps["viridis"]
    colours = {f: cmap(i / max(1, len(frictions) - 1)) for i, f in enumerate(frictions)}
    for (case, mu), grp in table.groupby(["load_case", "friction_factor"], sort=False):
        grp = grp.sort_values("bit_depth_m")
        kw = {"color": colours[mu], "linestyle": styles.get(case, "-"), "lw": 1.2}
        ax_h.plot(show(grp["hookload_N"], "force"), show(grp["bit_depth_m"], "length"), **kw)
        if case.startswith("rotating"):
            ax_t.plot(show(grp["surface_torque_Nm"], "torque"),
                      show(grp["bit_depth_m"], "length"), **kw)
    handles = [Line2D([], [], color="k", linestyle=styles.get(c, "-"), label=c.replace("_", " "))
               for c in table["load_case"].unique()]
    handles += [Line2D([], [], color=colours[f], label=f"μ = {f:g}") for f in frictions]
    handles += _measured_points(ax_h, ax_t, measured, show)
    ax_h.invert_yaxis()
    ax_h.set(xlabel=f"hook load [{display_unit('force', units)}] (model: effective, no block)",
             ylabel=f"bit depth MD [{display_unit('length', units)}]")
    ax_t.set(xlabel=f"surface torque [{display_unit('torque', units)}]")
    ax_h.legend(handles=handles, fontsize="small")
    for ax in (ax_h, ax_t):
        ax.grid(alpha=0.3)
        ax.margins(x=0.06, y=0.04)
    title = "Broomstick: soft-string torque and drag (docs/theory.md §2)"
    fig.suptitle(title if note is None else f"{title}\n{note}", fontsize=11 if note else 12)
    return fig


def _measured_points(ax_h, ax_t, measured, show) -> list:
    """Draw measured points (see :func:`broomstick_figure`; ``show(values, quantity)``: SI
    to display units); returns legend handles."""
    from matplotlib.lines import Line2D

    if measured is None or not len(measured):
        return []
    styles = {"off_bottom_rotating": ("o", "black", "measured, rotating off bottom"),
              "on_bottom_rotating": ("^", "none", "measured, rotating on bottom")}
    handles = []
    for kind, (marker, face, label) in styles.items():
        rows = measured[measured["kind"] == kind]
        if not len(rows):
            continue
        kw = {"marker": marker, "linestyle": "none", "color": "black",
              "markerfacecolor": face, "markersize": 6, "clip_on": False, "zorder": 5}
        depth = show(rows["bit_depth_m"], "length")
        ax_h.plot(show(rows["hookload_N"], "force"), depth, **kw)
        ax_t.plot(show(rows["surface_torque_Nm"], "torque"), depth, **kw)
        handles.append(Line2D([], [], label=label, **{k: v for k, v in kw.items()
                                                        if k not in ("clip_on", "zorder")}))
    return handles
