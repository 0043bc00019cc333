"""Which friction the estimates are of: zones along the string and the friction law.

The estimator's models carry friction as docs/theory.md §3.2 states it: an estimated part
μ·F_c(x) and a fixed part for zones whose factor is known. :class:`FrictionProfile` builds
both from the configuration:

- without casing keys the whole string is one zone and the estimated μ is an **effective**
  factor — the torque-weighted blend of whatever the hole holds (cased and open);
- with ``model.casing_shoe_md_m`` and ``model.friction_cased`` (the cased factor, known from
  the previous section), cells above the shoe carry that known friction and μ is the
  **open-hole** factor;
- with ``model.casing_shoe_md_m`` and ``model.friction_ratio_cased`` (μ_cased/μ_open), the
  cased cells' F_c is scaled by the ratio and μ is again the open-hole factor.

A cased hole's *static* factor is rarely known. Unless ``model.friction_cased_static`` gives
it, the models take one of two hypotheses (:data:`CASED_STATIC`): the same static/kinetic
ratio as the open hole ("tied"), or no static excess ("kinetic"). A μ_s claimed for the open
hole must hold under both (drillfric.estimation.batch).

The friction law (``model.friction_law``: the step at ω_c or Stribeck's decay) is passed to
every model the estimator builds (:meth:`FrictionProfile.plant`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from drillfric import torsional

if TYPE_CHECKING:
    from drillfric.config import Config

#: Hypotheses for an unknown cased static factor: tied to the open hole's μ_s/μ_k, or none.
CASED_STATIC = ("tied", "kinetic")
#: Names of the zone the reported factors belong to (SegmentRecord.friction_zone).
OPEN_HOLE, EFFECTIVE = "open_hole", "effective"


@dataclass(frozen=True)
class FrictionProfile:
    """The friction zones and law of a well's models (docs/theory.md §3.2).

    Attributes
    ----------
    shoe_md_m : float or None
        Measured depth of the casing shoe [m]; None: one zone.
    cased_kinetic : float or None
        Known kinetic friction factor above the shoe [-].
    cased_static : float or None
        Known static friction factor above the shoe [-] (None: unknown, see
        :data:`CASED_STATIC`).
    ratio : float or None
        μ_cased/μ_open when the cased friction is given as a ratio [-].
    law_speed_rad_s : float or None
        Stribeck decay speed v_s [rad/s]; None: the step law at ω_c.
    law_exponent : float
        Stribeck exponent δ [-].
    """

    shoe_md_m: float | None = None
    cased_kinetic: float | None = None
    cased_static: float | None = None
    ratio: float | None = None
    law_speed_rad_s: float | None = None
    law_exponent: float = 1.0

    @classmethod
    def from_config(cls, cfg: Config) -> FrictionProfile:
        """The profile of ``[model]``: casing keys and friction law."""
        m = cfg.model
        stribeck = m.friction_law == "stribeck"
        if m.casing_shoe_md_m is None or (m.friction_cased is None
                                          and m.friction_ratio_cased is None):
            return cls(law_speed_rad_s=m.stribeck_speed_rad_s if stribeck else None,
                       law_exponent=m.stribeck_exponent)
        return cls(shoe_md_m=m.casing_shoe_md_m, cased_kinetic=m.friction_cased,
                   cased_static=m.friction_cased_static, ratio=m.friction_ratio_cased,
                   law_speed_rad_s=m.stribeck_speed_rad_s if stribeck else None,
                   law_exponent=m.stribeck_exponent)

    @property
    def zone(self) -> str:
        """Which factor the estimates are: ``open_hole`` or ``effective``."""
        return OPEN_HOLE if self.shoe_md_m is not None else EFFECTIVE

    @property
    def static_known(self) -> bool:
        """Whether no hypothesis is needed for the cased static factor."""
        return self.zone == EFFECTIVE or self.ratio is not None or self.cased_static is not None

    def cased_share(self, x_m: np.ndarray, dx_m: np.ndarray) -> np.ndarray:
        """Share of each cell's length above the shoe [-] (cells of length ``dx_m`` centred
        at ``x_m``)."""
        if self.shoe_md_m is None:
            return np.zeros(np.shape(x_m))
        top = np.asarray(x_m) - 0.5 * np.asarray(dx_m)
        return np.clip((self.shoe_md_m - top) / np.asarray(dx_m), 0.0, 1.0)

    def parts(self, x_m, dx_m, fc_Nm_m, mu_s: float, mu_k: float,
              cased_static: str = "tied") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(estimated F_c, fixed kinetic, fixed static) per cell [N·m/m].

        ``cased_static`` is the hypothesis for an unknown cased static factor
        (:data:`CASED_STATIC`); ``mu_s``, ``mu_k`` are the open-hole factors of the model
        (they tie the cased static factor under "tied").
        """
        fc = np.broadcast_to(np.asarray(fc_Nm_m, dtype=float), np.shape(x_m)).copy()
        zero = np.zeros_like(fc)
        if self.shoe_md_m is None:
            return fc, zero, zero
        cased = self.cased_share(x_m, dx_m)
        if self.ratio is not None:
            return fc * (1.0 - cased + self.ratio * cased), zero, zero
        static = self.cased_static
        if static is None:
            tie = mu_s / mu_k if cased_static == "tied" and mu_k > 0 else 1.0
            static = self.cased_kinetic * tie
        fixed = cased * fc
        return (1.0 - cased) * fc, self.cased_kinetic * fixed, max(static,
                                                                    self.cased_kinetic) * fixed

    def plant(self, grid: torsional.Grid, fc_Nm_m, mu_s: float, mu_k: float, *,
              omega_c_rad_s: float, k_t_per_s: float, top_drive_inertia_kg_m2: float,
              bit_torque_cap_Nm: float = 0.0, cased_static: str = "tied") -> torsional.Plant:
        """A model of the string on ``grid`` with this profile and law at (μ_s, μ_k)."""
        est, fix_k, fix_s = self.parts(grid.x_m, grid.dx_true_m, fc_Nm_m, mu_s, mu_k,
                                       cased_static)
        return torsional.Plant(grid, est, mu_s, mu_k, omega_c_rad_s, k_t_per_s,
                               top_drive_inertia_kg_m2, bit_torque_cap_Nm, fix_k, fix_s,
                               self.law_speed_rad_s, self.law_exponent)

    def describe(self) -> str:
        """One line for messages and the report."""
        law = ("step law at ω_c" if self.law_speed_rad_s is None else
               f"Stribeck law (v_s = {self.law_speed_rad_s:.3g} rad/s, δ = "
               f"{self.law_exponent:g})")
        if self.zone == EFFECTIVE:
            return f"effective friction factor over the whole string; {law}"
        cased = (f"cased = {self.ratio:g} × open" if self.ratio is not None else
                 f"cased μ_k = {self.cased_kinetic:g}" + (
                     f", μ_s = {self.cased_static:g}" if self.cased_static is not None
                     else ", cased μ_s unknown"))
        return f"open-hole friction factors below the shoe at {self.shoe_md_m:.0f} m " \
               f"({cased}); {law}"
