"""What the configuration sets for the estimation chain of a segment, derived once per well.

:class:`ChainSettings` gathers the typed settings every step of
:mod:`drillfric.estimation.chain` takes — torque and drag, the observer's gains, the friction
zones and law, the speed-driven fit — built from a :class:`drillfric.config.Config` once
(:meth:`ChainSettings.from_config`) and passed to the steps, which never read the
configuration themselves.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from drillfric.config import torque_lag_s
from drillfric.estimation.batch.settings import BatchSettings
from drillfric.estimation.gains import GainSettings
from drillfric.friction import FrictionProfile
from drillfric.torque_drag import TDSettings

if TYPE_CHECKING:
    from drillfric.config import Config


@dataclass(frozen=True)
class ChainSettings:
    """The estimation chain's settings (docs/configuration.md), SI.

    Attributes
    ----------
    td : TDSettings
        Torque and drag: string, muds, elements, configured friction, assumed path.
    gains : GainSettings
        The observer's gain design and its tuning (docs/theory.md §5.1).
    friction : FrictionProfile
        The friction zones and law (docs/theory.md §3.2).
    batch : BatchSettings
        The speed-driven fit's settings (docs/theory.md §6.4); also ω_c, k_t and I_TD.
    observer : the ``[observer]`` table
        Its typed, frozen table (starts, ensemble, law, rates, clamp).
    cells : int
        Cells of the observer grid (``model.cells``).
    torque_kind : str
        What the logged torque is: ``"motor"`` or ``"string"`` (``rig.torque_kind``).
    sample_averaging_s : float or None
        The logger's declared averaging of each sample [s] (``rig.sample_averaging_s``).
    torque_lag_s : float or None
        The torque's configured lag behind the speed [s] (``[channels] lag_s``,
        :func:`drillfric.config.torque_lag_s`); None: identified from each segment.
    """

    td: TDSettings
    gains: GainSettings
    friction: FrictionProfile
    batch: BatchSettings
    observer: Any
    cells: int
    torque_kind: str
    sample_averaging_s: float | None
    torque_lag_s: float | None = None

    @classmethod
    def from_config(cls, cfg: Config) -> ChainSettings:
        """The chain's settings of a :class:`drillfric.config.Config`."""
        return cls(TDSettings.from_config(cfg), GainSettings.from_config(cfg),
                   FrictionProfile.from_config(cfg), BatchSettings.from_config(cfg),
                   cfg.observer, int(cfg.model.cells), cfg.rig.torque_kind,
                   cfg.rig.sample_averaging_s, torque_lag_s(cfg.channels))

    @property
    def omega_c_rad_s(self) -> float:
        """Static/kinetic switching speed ω_c [rad/s]."""
        return self.batch.omega_c_rad_s

    @property
    def top_drive_inertia_kg_m2(self) -> float:
        """I_TD [kg·m²]."""
        return self.batch.top_drive_inertia_kg_m2

    @property
    def speed_noise_rad_s(self) -> float:
        """Standard deviation of the logged speed's noise [rad/s]."""
        return self.gains.speed_noise_rad_s
