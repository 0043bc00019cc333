"""The work a configuration implies, checked before any is done (docs/security.md, "Work
budget").

Each configuration key has a range, but a product of keys inside their ranges can ask for
hours of CPU or all the memory: ``[model] cells`` enters the observer's cost squared (the
Courant-1 grid's time step shrinks as its cells, docs/theory.md §3.1), ``element_length_m``
sets the torque-and-drag mesh, ``observer.starts`` multiplies the start-up window. This
module estimates that work from the configuration and the first rows of the data and
refuses, in one line naming the key and the budget, a run that would exceed it.

The estimate is physical, not a measurement: one observer pass costs cells²/t_w cell-steps
per second of data (t_w, the torsional wave's travel time along the configured string:
:func:`travel_s`), at :data:`CELL_STEP_S` each — on the 24 h benchmark (docs/performance.md) the
estimate of the whole run is within 20 % of the measured CPU time.
"""

from __future__ import annotations

from dataclasses import dataclass

from drillfric.config import Config
from drillfric.drillstring import build_string
from drillfric.errors import ConfigError, DrillfricError
from drillfric.torque_drag import MAX_ELEMENTS as MAX_TD_ELEMENTS

#: Torsional wave speed of steel, √(G/ρ) = √(79.3 GPa / 7850 kg/m³) [m/s].
WAVE_SPEED_M_S = 3180.0
#: CPU time of one cell-step of the observer [s] (0.8 ns measured, docs/performance.md;
#: rounded up so the estimate errs on the high side).
CELL_STEP_S = 1.0e-9
#: Bit depths the estimate is made for [m]: the cost grows as the string shortens, and a
#: log's absurd depth (a segment of its own fails on it) is no reason to refuse the config.
MIN_DEPTH_M, MAX_DEPTH_M = 100.0, 15_000.0
#: Budget of the observer passes: CPU seconds per hour of data (1 h: a run no slower than
#: real time, which live and a nightly fleet need; the defaults take ≈ 10 s).
MAX_CPU_S_PER_DATA_HOUR = 3600.0
#: Budget of the start-up window of one segment (every ``observer.starts`` over
#: ``starts_window_s``) [CPU s] (the defaults take < 1 s).
MAX_START_CPU_S = 600.0


@dataclass(frozen=True)
class Work:
    """The work a configuration implies at one bit depth.

    Attributes
    ----------
    cpu_s_per_data_hour : float
        Observer passes (the ensemble's members and the first pass) [CPU s per hour of data].
    start_cpu_s : float
        The start-up window of one segment [CPU s].
    td_elements : int
        Torque-and-drag elements along the string.
    """

    cpu_s_per_data_hour: float
    start_cpu_s: float
    td_elements: int


def work(cfg: Config, bit_depth_m: float) -> Work:
    """The work of ``cfg`` with the bit at ``bit_depth_m`` [m] (see the module's text).

    Examples
    --------
    >>> from drillfric.config import load_config
    >>> w = work(load_config(None), 2000.0)
    >>> round(w.cpu_s_per_data_hour), w.td_elements
    (9, 1001)
    """
    depth = _clamped(bit_depth_m)
    cells = float(cfg.model.cells)
    per_pass_s = cells * cells / travel_s(cfg, depth) * CELL_STEP_S  # per data second
    passes = cfg.observer.ensemble_members + 1
    starts = len(cfg.observer.starts) * cfg.observer.starts_window_s * per_pass_s
    return Work(3600.0 * passes * per_pass_s, starts,
                int(depth / cfg.model.element_length_m) + 1)


def travel_s(cfg: Config, depth_m: float) -> float:
    """The torsional wave's travel time down the configured string to ``depth_m`` [s]:
    Σ L_i / √(G_i/ρ_i) over its sections (docs/theory.md §3.1) — the materials are the
    configuration's, so a light, stiff one cannot slip past the budget; steel's
    :data:`WAVE_SPEED_M_S` where the string cannot be built to that depth."""
    try:
        string = build_string(cfg.sections, depth_m)
    except DrillfricError:
        return depth_m / WAVE_SPEED_M_S
    return sum(sec.length_m / sec.wave_speed_m_s for sec in string.sections)


def _clamped(bit_depth_m: float) -> float:
    """``bit_depth_m`` within [:data:`MIN_DEPTH_M`, :data:`MAX_DEPTH_M`] (NaN: the deepest)."""
    depth = float(bit_depth_m)
    return MAX_DEPTH_M if not depth == depth else min(max(depth, MIN_DEPTH_M), MAX_DEPTH_M)


def check_work(cfg: Config, bit_depth_m: float, *, file=None) -> Work:
    """:func:`work`, refused beyond the budgets of this module.

    Raises
    ------
    ConfigError
        One line naming the key, the work it implies and the budget.
    """
    w, bit_depth_m = work(cfg, bit_depth_m), _clamped(bit_depth_m)
    if w.td_elements > MAX_TD_ELEMENTS:
        shortest = bit_depth_m / MAX_TD_ELEMENTS
        raise ConfigError(f"[model] element_length_m = {cfg.model.element_length_m:g} m gives "
                          f"{w.td_elements:.3g} torque-and-drag elements at {bit_depth_m:.0f} m; "
                          f"the budget is {MAX_TD_ELEMENTS:.0e}", file=file,
                          fix=f"element_length_m ≥ {shortest:.2g} m (default 2 m)")
    if w.cpu_s_per_data_hour > MAX_CPU_S_PER_DATA_HOUR:
        raise ConfigError(f"[model] cells = {cfg.model.cells} with {cfg.observer.ensemble_members}"
                          f" ensemble members would take ≈ {w.cpu_s_per_data_hour / 3600:.3g} "
                          f"CPU-hours per hour of data at {bit_depth_m:.0f} m (cost ∝ cells²); "
                          "the budget is 1 (no slower than real time)", file=file,
                          fix="fewer cells (the paper's 500) or ensemble members")
    if w.start_cpu_s > MAX_START_CPU_S:
        raise ConfigError(f"{len(cfg.observer.starts)} observer.starts over "
                          f"starts_window_s = {cfg.observer.starts_window_s:g} s would take ≈ "
                          f"{w.start_cpu_s:.3g} CPU-s per segment at {bit_depth_m:.0f} m; the "
                          f"budget is {MAX_START_CPU_S:g} s", file=file,
                          fix="fewer starts (the default 3) or a shorter starts_window_s")
    return w
