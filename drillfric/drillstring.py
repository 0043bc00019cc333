"""Drill-string description: sections top-down and their per-position properties.

Quantities for docs/theory.md §2 (soft-string weights, contact radius) and §3 (polar moment
J = π(OD⁴ − ID⁴)/32, wave speed c = √(G/ρ), line impedance ζ = J·√(Gρ)). The top section
(drill pipe) fills from surface to whatever the lower sections leave, so a string is
rebuilt for every bit depth. Sections below the first form the "BHA" of the semi-lumped
model of §4 (I_BHA = ρ Σ J_i L_i).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric.errors import ModelError

G_ACCEL = 9.80665  # standard gravity [m/s²]
STEEL_DENSITY = 7850.0  # [kg/m³]


@dataclass(frozen=True)
class Section:
    """One string section.

    Attributes
    ----------
    name : str
    od_m, id_m : float
        Body outside and inside diameters [m].
    length_m : float
        Length [m].
    contact_radius_m : float
        Radius at which the string touches the wall r_c [m] (tool-joint OD/2 for pipe).
    linear_mass_kg_m : float
        Adjusted mass per metre in air, tool joints included [kg/m].
    shear_modulus_Pa : float
        Shear modulus G [Pa].
    steel_density_kg_m3 : float
        Steel density ρ [kg/m³].
    """

    name: str
    od_m: float
    id_m: float
    length_m: float
    contact_radius_m: float
    linear_mass_kg_m: float
    shear_modulus_Pa: float = 79.3e9
    steel_density_kg_m3: float = STEEL_DENSITY

    @property
    def outer_area_m2(self) -> float:
        """A_o = π·OD²/4 [m²]."""
        return np.pi * self.od_m**2 / 4.0

    @property
    def inner_area_m2(self) -> float:
        """A_i = π·ID²/4 [m²]."""
        return np.pi * self.id_m**2 / 4.0

    @property
    def steel_area_m2(self) -> float:
        """Cross-section of steel A_o − A_i [m²]."""
        return self.outer_area_m2 - self.inner_area_m2

    @property
    def polar_moment_m4(self) -> float:
        """Polar moment of area J = π(OD⁴ − ID⁴)/32 [m⁴] (docs/theory.md §3).

        Examples
        --------
        >>> s = Section("p", 0.2, 0.0, 1.0, 0.1, 100.0)
        >>> round(s.polar_moment_m4 * 1e6, 3)
        157.08
        """
        return np.pi * (self.od_m**4 - self.id_m**4) / 32.0

    @property
    def wave_speed_m_s(self) -> float:
        """Torsional wave speed c = √(G/ρ) [m/s] (docs/theory.md §3)."""
        return float(np.sqrt(self.shear_modulus_Pa / self.steel_density_kg_m3))

    @property
    def impedance_Nms(self) -> float:
        """Line impedance ζ = J·√(Gρ) [N·m·s/rad] (docs/theory.md §3)."""
        return self.polar_moment_m4 * float(np.sqrt(self.shear_modulus_Pa
                                                    * self.steel_density_kg_m3))

    @property
    def air_weight_N_m(self) -> float:
        """Weight per metre in air w_air = g·m_lin [N/m]."""
        return G_ACCEL * self.linear_mass_kg_m

    def buoyed_weight_N_m(self, mud_out_kg_m3: float, mud_in_kg_m3: float) -> float:
        """Buoyed weight per metre g·[m_lin − ρ_o·A_o + ρ_i·A_i] [N/m] (docs/theory.md §2 step 1).

        Examples
        --------
        >>> s = Section("p", 0.2, 0.1, 1.0, 0.1, 7850.0 * np.pi * (0.04 - 0.01) / 4)
        >>> bool(np.isclose(s.buoyed_weight_N_m(1200.0, 1200.0),
        ...                 s.air_weight_N_m * (1 - 1200.0 / 7850.0)))
        True
        """
        return G_ACCEL * (self.linear_mass_kg_m - mud_out_kg_m3 * self.outer_area_m2
                          + mud_in_kg_m3 * self.inner_area_m2)


def section_from_config(entry: dict, length_m: float) -> Section:
    """Build a :class:`Section` from a validated ``[[string.sections]]`` entry (SI keys)."""
    od, idm = entry["od_m"], entry["id_m"]
    rho = entry.get("steel_density_kg_m3") or STEEL_DENSITY
    mass = entry.get("linear_mass_kg_m") or rho * np.pi * (od**2 - idm**2) / 4.0
    tj = entry.get("tool_joint_od_m") or od
    return Section(name=entry.get("name") or "section", od_m=od, id_m=idm, length_m=length_m,
                   contact_radius_m=tj / 2.0, linear_mass_kg_m=mass,
                   shear_modulus_Pa=entry.get("shear_modulus_Pa") or 79.3e9,
                   steel_density_kg_m3=rho)


@dataclass(frozen=True)
class DrillString:
    """A string hung from the top drive (x = 0) to the bit (x = bit_depth_m).

    Attributes
    ----------
    sections : tuple of Section
        Top-down; the first (drill pipe) has the length that reaches the bit.
    """

    sections: tuple[Section, ...]

    @property
    def bit_depth_m(self) -> float:
        """Total length = bit measured depth [m]."""
        return float(sum(s.length_m for s in self.sections))

    @property
    def boundaries_m(self) -> np.ndarray:
        """Measured depth of the top of each section and of the bit, length n + 1 [m]."""
        return np.concatenate([[0.0], np.cumsum([s.length_m for s in self.sections])])

    @property
    def bha_top_m(self) -> float:
        """Top of the BHA L_p = length of the first (drill-pipe) section [m] (docs/theory.md §4)."""
        return float(self.sections[0].length_m)

    @property
    def bha_inertia_kg_m2(self) -> float:
        """Lumped BHA inertia I_BHA = ρ Σ J_i L_i over the sections below the pipe (§4)."""
        return float(sum(s.steel_density_kg_m3 * s.polar_moment_m4 * s.length_m
                         for s in self.sections[1:]))

    @property
    def polar_mass_moment_kg_m2(self) -> float:
        """J = ∫ρJ dx over the whole string [kg·m²]: its viscous torque is k_t·J·ω̄ in the
        mean (docs/theory.md §3 eq. 2–3, §6.4)."""
        return float(sum(s.steel_density_kg_m3 * s.polar_moment_m4 * s.length_m
                         for s in self.sections))

    def section_index(self, md_m) -> np.ndarray:
        """Index of the section containing each measured depth (bit depth → last section)."""
        md = np.atleast_1d(np.asarray(md_m, dtype=float))
        inner = self.boundaries_m[1:-1]
        return np.searchsorted(inner, md, side="right")

    def along(self, attribute: str, md_m) -> np.ndarray:
        """A per-section attribute or property evaluated at measured depths.

        Examples
        --------
        >>> a, b = Section("a", .2, .1, 10., .1, 50.), Section("b", .3, .1, 5., .15, 90.)
        >>> s = DrillString((a, b))
        >>> s.along("contact_radius_m", [0.0, 9.9, 10.0, 15.0]).tolist()
        [0.1, 0.1, 0.15, 0.15]
        """
        values = np.array([getattr(s, attribute) for s in self.sections], dtype=float)
        return values[self.section_index(md_m)]

    def buoyed_weight_N_m(self, md_m, mud_out_kg_m3: float, mud_in_kg_m3: float) -> np.ndarray:
        """Buoyed weight per metre [N/m] at measured depths (docs/theory.md §2 step 1).

        Examples
        --------
        >>> a = Section("a", .2, .1, 10., .1, 50.)
        >>> s = DrillString((a, Section("b", .3, .1, 5., .15, 90.)))
        >>> bool(s.buoyed_weight_N_m([1.0], 0.0, 0.0)[0] == a.air_weight_N_m)
        True
        """
        values = np.array([s.buoyed_weight_N_m(mud_out_kg_m3, mud_in_kg_m3)
                           for s in self.sections])
        return values[self.section_index(md_m)]


def build_string(entries, bit_depth_m: float) -> DrillString:
    """Resolve configured sections for a bit depth: the top section fills the rest.

    Parameters
    ----------
    entries : sequence of dict
        Validated ``[[string.sections]]`` entries, top-down (see :mod:`drillfric.config`).
    bit_depth_m : float
        Bit measured depth [m].

    Raises
    ------
    ModelError
        If the bit depth does not exceed the lower sections' total length, or a dimension
        is not physical.
    """
    if not np.isfinite(bit_depth_m) or bit_depth_m <= 0:
        raise ModelError(f"bit depth must be positive, got {bit_depth_m}")
    lower = [float(e["length_m"]) for e in entries[1:]]
    pipe = bit_depth_m - sum(lower)
    if pipe <= 0:
        from drillfric.config import DEFAULT_SECTIONS  # config does not import this module

        default = [e.get("name") for e in entries] == [d["name"] for d in DEFAULT_SECTIONS]
        # issue 35 (F-9): "shorten the BHA sections" did not say that no string was given
        parts = " + ".join((f"{float(e['length_m']):g} m " if e.get("length_m") else "")
                           + str(e.get("name")).removesuffix(" (assumed)") for e in entries)
        fix = ("no [[string.sections]] was given, so the built-in default string is used "
               f"({parts}); give the well's string "
               "as [[string.sections]] in the configuration (docs/configuration.md), or "
               "check the bit depth") if default else \
            "shorten the BHA sections ([[string.sections]] length_m) or check the bit depth"
        raise ModelError(f"the string below the top section is {sum(lower):.1f} m long but the "
                         f"bit is at {bit_depth_m:.1f} m", fix=fix)
    for e in entries:
        if e["od_m"] <= 0 or e["id_m"] < 0 or e["id_m"] >= e["od_m"]:
            raise ModelError(f"section '{e.get('name')}': need 0 ≤ id_m < od_m, got "
                             f"id {e['id_m']} m, od {e['od_m']} m")
    lengths = [pipe] + lower
    return DrillString(tuple(section_from_config(e, L) for e, L in zip(entries, lengths,
                                                                          strict=True)))
