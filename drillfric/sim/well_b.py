"""The published reference case Well B of A&S 2018 (docs/reference_cases.md): its string,
inclination and plant with the published friction fit."""

from __future__ import annotations

import numpy as np

from drillfric import torsional
from drillfric.drillstring import DrillString, Section

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
