"""Static friction log of a depth-indexed drilling log: torque and drag back-calculated per
depth window.

A depth-indexed log (per-depth averages of surface torque, RPM, WOB, hook load — the most
common post-well data) has no time series, so the observer of docs/theory.md §5 cannot
run and μ_s cannot be identified. What the data do hold is the mean torque at each depth,
and for a rotating string the soft-string model (docs/theory.md §2, docs/torque_drag.md)
gives that torque as the bit torque plus μ·T_N, T_N = ∫F_c dx. So, per window of
``[friction_log] window_m`` of measured depth (one stand, 30 m, by default):

1. the **rotating rows** (surface RPM above ``segmentation.rotating_rpm``, torque logged) are
   split by **load case** (:func:`on_bottom`). A row of a drilling log is a depth of hole
   drilled, so it is on bottom unless the data say otherwise: a rate of penetration above
   zero says hole was made there, whatever the WOB channel reads; without it, WOB above
   ``segmentation.wob_on_bottom_N``; without WOB, the bit (``bit_depth_m``, else the row's
   measured depth) within ``segmentation.on_bottom_m`` of ``hole_depth_m``; with none of
   these the load case is unknown (counted on bottom, so apparent, and said so);
2. the **medians** of the window's rows of one load case (depth, torque, RPM, WOB, hook
   load) stand for it (medians: a few spikes of a reamed connection do not move them);
3. the **friction factor** is the μ for which the modelled surface torque at the window's
   bit depth equals the median torque (:func:`drillfric.torque_drag.back_calculate_friction`),
   with the well's string, survey and mud. Off bottom it is the kinetic friction factor of
   the string (``off_bottom_rotating``). On bottom the WOB is put at the bit and a bit
   torque T_bit = μ_bit·WOB·D_bit/3 is assumed (``[friction_log] bit_mu``, ``bit_diameter_m``;
   μ_bit = 0 by default: none) — surface data cannot separate the bit torque from the
   string's friction, so the on-bottom factor is **apparent** friction, flagged
   ``bit_torque_in_friction``.

One friction factor holds along the whole string at each depth (cased and open hole are
not separated). The run writes the results as a time log's are
(:func:`drillfric.runner.depth_log.run_depth_log`), with ``method = "td_backcalc"``, μ_s
null and no estimates over time.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from drillfric.drillstring import build_string
from drillfric.errors import InputError, ModelError
from drillfric.estimation.verdict import TYPICAL_MU
from drillfric.io.well import CHUNK_ROWS, Well
from drillfric.result import Flag, SegmentRecord
from drillfric.torque_drag import TDResult, TDSettings, back_calculate_friction, solve
from drillfric.vocabulary import Kind, Method, Status

if TYPE_CHECKING:
    from drillfric.config import Config

#: What a depth log cannot give, said in every summary and segment message.
NO_OBSERVER = ("depth-indexed log: no time series, so no observer — μ_s is not identifiable "
               "and there is no bit speed")


@dataclass(frozen=True)
class Window:
    """The rows of one depth window and one load case, as the medians μ is fitted to.

    Attributes
    ----------
    id : int
        Segment id, 1-based in depth order.
    kind : Kind
        Load case of the rows.
    md_top_m, md_bottom_m : float
        The window's measured-depth interval [m].
    rows : int
        Rotating rows of this load case in the window.
    rows_unknown : int
        Of these, rows whose load case the data do not give (no ROP, WOB or hole depth).
    bit_depth_m : float
        Median bit depth [m] (the measured depth where the log has no bit depth).
    surface_torque_Nm, surface_rpm, wob_N, hookload_N : float
        Median surface torque [N·m], surface speed [RPM], weight on bit [N] and hook load
        [N] of the rows (NaN when not logged).
    """

    id: int
    kind: Kind
    md_top_m: float
    md_bottom_m: float
    rows: int
    rows_unknown: int
    bit_depth_m: float
    surface_torque_Nm: float
    surface_rpm: float
    wob_N: float
    hookload_N: float


@dataclass(frozen=True)
class WindowResult:
    """One window's record, its torque-and-drag solution (None when not estimated) and the
    bit torque assumed [N·m]."""

    window: Window
    record: SegmentRecord
    td: TDResult | None = field(default=None, repr=False)
    bit_torque_Nm: float = 0.0


# --------------------------------------------------------------------------- reading
def read_depth_log(well: Well, chunk_rows: int = CHUNK_ROWS) -> pd.DataFrame:
    """The canonical SI columns of a depth-indexed log, rows with a measured depth only.

    Raises
    ------
    InputError
        The well is not a depth-indexed log, or no row has a measured depth.
    """
    if not well.depth_indexed:
        raise InputError("not a depth-indexed log", file=well.files.data,
                         fix="run a time log with drillfric.run")
    chunks = [c for c in well.chunks(chunk_rows) if len(c)]
    log = pd.concat(chunks, ignore_index=True) if chunks else pd.DataFrame()
    if not log.empty:
        log = log[np.isfinite(log["measured_depth_m"].to_numpy(float))]
    if log.empty:
        raise InputError("no data rows with a measured depth", file=well.files.data,
                         fix="give a file with data rows below its header")
    return log.reset_index(drop=True)


def _column(log: pd.DataFrame, name: str) -> np.ndarray:
    """A channel as floats (all NaN when the log does not have it)."""
    return log[name].to_numpy(float) if name in log else np.full(len(log), np.nan)


def bit_depth(log: pd.DataFrame) -> np.ndarray:
    """Bit depth of each row [m]: the logged bit depth, else the row's measured depth."""
    bit = _column(log, "bit_depth_m")
    return np.where(np.isfinite(bit), bit, log["measured_depth_m"].to_numpy(float))


def on_bottom(log: pd.DataFrame, cfg: Config) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Whether each row is on bottom, which rows the data leave unknown, and notes.

    A row of a depth-indexed drilling log is a depth of hole drilled: on bottom unless the
    data say otherwise. In order of evidence:

    1. a rate of penetration above 0: hole was made at that depth, so the bit was on it,
       whatever the WOB channel reads (a WOB at most ``segmentation.wob_on_bottom_N`` there
       is read as a zero offset, not the bit off bottom: noted, the WOB kept as logged);
    2. else the WOB where logged: on bottom above ``segmentation.wob_on_bottom_N``;
    3. else the bit within ``segmentation.on_bottom_m`` of ``hole_depth_m`` where logged;
    4. else unknown: counted on bottom, so its friction is apparent (any bit torque is in
       it), never the string's off-bottom factor.
    """
    wob, rop = _column(log, "wob_N"), _column(log, "rop_m_s")
    gap = _column(log, "hole_depth_m") - bit_depth(log)
    threshold = cfg.segmentation.wob_on_bottom_N
    by_wob = np.where(np.isfinite(gap), gap <= cfg.segmentation.on_bottom_m, True)
    by_wob = np.where(np.isfinite(wob), wob > threshold, by_wob)
    drilled = rop > 0
    unknown = ~np.isfinite(rop) & ~np.isfinite(wob) & ~np.isfinite(gap)
    notes = []
    light = drilled & (wob <= threshold)
    if light.any():
        notes.append(f"on bottom in {int(light.sum())} of {light.size} rows that log WOB ≤ "
                     f"{threshold / 1e3:g} kN (segmentation.wob_on_bottom_N) while the hole "
                     "advanced (ROP > 0): read as a WOB zero offset, not the bit off bottom")
    if unknown.any():
        notes.append(f"load case unknown in {int(unknown.sum())} of {unknown.size} rows that "
                     "log neither ROP, WOB nor hole depth: counted on bottom, so their friction "
                     "is apparent (bit torque in it), not the string's off-bottom factor")
    return drilled | by_wob, unknown, notes


# --------------------------------------------------------------------------- windows
def windows(log: pd.DataFrame, cfg: Config) -> tuple[list[Window], list[str]]:
    """The depth windows of a log, one :class:`Window` per window and load case with rows.

    Windows are ``[friction_log] window_m`` long and aligned on its multiples (2820–2850 m),
    in depth order; a window whose rows do not rotate gives one window of zero rows (listed
    as skipped). Returns the windows and what was assumed.
    """
    width = cfg.friction_log.window_m
    md = log["measured_depth_m"].to_numpy(float)
    rpm, torque = _column(log, "surface_rpm"), _column(log, "surface_torque_Nm")
    rotating = (rpm > cfg.segmentation.rotating_rpm) & np.isfinite(torque)
    bottom, unknown, notes = on_bottom(log, cfg)
    slot = np.floor(md / width).astype(np.int64)
    out: list[Window] = []
    for k in np.unique(slot):
        here = slot == k
        kinds = [(Kind.OFF_BOTTOM, here & rotating & ~bottom),
                 (Kind.ON_BOTTOM, here & rotating & bottom)]
        kinds = [(kind, rows) for kind, rows in kinds if rows.any()] or [
            (Kind.ON_BOTTOM if bottom[here].mean() >= 0.5 else Kind.OFF_BOTTOM, here)]
        for kind, rows in kinds:
            out.append(_window(len(out) + 1, kind, k * width, width, log, rows & rotating,
                               rows, unknown))
    return out, notes


def _window(wid: int, kind: Kind, top: float, width: float, log: pd.DataFrame,
            rows: np.ndarray, where: np.ndarray, unknown: np.ndarray) -> Window:
    """The medians of ``rows`` (the depth of ``where`` when none rotate); ``unknown`` marks
    the rows of unknown load case."""
    def median(values: np.ndarray) -> float:
        finite = values[rows & np.isfinite(values)]
        return float(np.median(finite)) if finite.size else float("nan")

    depth = median(bit_depth(log)) if rows.any() else float(np.median(bit_depth(log)[where]))
    return Window(id=wid, kind=kind, md_top_m=float(top), md_bottom_m=float(top + width),
                  rows=int(rows.sum()), rows_unknown=int((rows & unknown).sum()),
                  bit_depth_m=depth,
                  surface_torque_Nm=median(_column(log, "surface_torque_Nm")),
                  surface_rpm=median(_column(log, "surface_rpm")),
                  wob_N=median(_column(log, "wob_N")),
                  hookload_N=median(_column(log, "hookload_N")))


# --------------------------------------------------------------------------- back-calculation
def bit_torque_Nm(wob_N: float, cfg: Config) -> float:
    """Bit torque assumed on bottom [N·m]: T_bit = μ_bit·WOB·D_bit/3 (a Coulomb bit face,
    as the simulator's, docs/simulator.md), 0 without WOB or with μ_bit = 0.

    Examples
    --------
    >>> from drillfric.config import config_from_dict
    >>> cfg = config_from_dict({"friction_log": {"bit_mu": 0.3, "bit_diameter_m": 0.2}})
    >>> round(bit_torque_Nm(100e3, cfg), 6)
    2000.0
    """
    if not np.isfinite(wob_N) or wob_N <= 0:
        return 0.0
    return cfg.friction_log.bit_mu * wob_N * cfg.friction_log.bit_diameter_m / 3.0


def back_calculate(window: Window, well: Well, td: TDSettings) -> WindowResult:
    """The friction factor of one window (docs/ingestion.md *Depth-indexed logs*), with the
    well's torque-and-drag settings ``td``.

    A window :func:`check_window` does not pass is skipped or failed with its message; one
    whose torque no friction factor in [0, 2] reproduces has failed (with the model's
    message).
    """
    base = _base_record(window)
    status, message = check_window(window, well)
    if status is not Status.OK:
        return WindowResult(window, SegmentRecord(**base, status=status, message=message))
    on = window.kind is Kind.ON_BOTTOM
    wob = window.wob_N if on and np.isfinite(window.wob_N) else 0.0
    torque_bit = bit_torque_Nm(wob, well.config) if on else 0.0
    kw = {"load_case": "rotating_on_bottom" if on else "rotating_off_bottom", "wob_N": wob,
          "bit_torque_Nm": torque_bit, "mud_out_kg_m3": td.mud_out_kg_m3,
          "mud_in_kg_m3": td.mud_in_kg_m3, "element_length_m": td.element_length_m}
    path = td.path_to(well.survey, window.bit_depth_m)
    string = td.string(window.bit_depth_m)
    try:
        mu = back_calculate_friction(path, string, surface_torque_Nm=window.surface_torque_Nm,
                                     **kw)
    except ModelError as exc:
        return WindowResult(window, SegmentRecord(**base, status=Status.FAILED,
                                                  message=exc.message), None, torque_bit)
    td = solve(path, string, friction=mu, **kw)
    return WindowResult(window, _record(base, window, mu, td, torque_bit), td, torque_bit)


def check_window(window: Window, well: Well) -> tuple[Status, str]:
    """What becomes of a window before its back-calculation, with the message its record
    gets (``drillfric inspect`` calls this too): SKIPPED without enough rotating rows or
    with the bit beyond the survey; FAILED when the configured string's sections below the
    top one are longer than the bit depth (:func:`drillfric.drillstring.build_string`);
    else OK and no message."""
    problem = _skip_reason(window, well)
    if problem:
        return Status.SKIPPED, f"{problem}; {NO_OBSERVER}"
    try:
        build_string(well.config.sections, window.bit_depth_m)
    except ModelError as exc:
        return Status.FAILED, exc.message
    return Status.OK, ""


def _base_record(window: Window) -> dict:
    return dict(id=window.id, kind=window.kind, t_start_s=float("nan"),
                t_end_s=float("nan"), duration_s=float("nan"), bit_depth_m=window.bit_depth_m)


def _skip_reason(window: Window, well: Well) -> str:
    where = f"{window.md_top_m:.0f}–{window.md_bottom_m:.0f} m"
    least = well.config.friction_log.min_rows
    if window.rows == 0:
        return f"no rotation in {where}"
    if window.rows < least:
        return (f"{window.rows} rotating rows in {where}, fewer than friction_log.min_rows "
                f"= {least}")
    if well.survey is not None and window.bit_depth_m > well.survey.md_max_m:
        return (f"bit depth {window.bit_depth_m:.1f} m is beyond the survey (last station "
                f"{well.survey.md_max_m:.1f} m)")
    return ""


def _record(base: dict, window: Window, mu: float, td: TDResult,
            torque_bit: float) -> SegmentRecord:
    """The record of a back-calculated window."""
    notes = [f"{window.md_top_m:.0f}–{window.md_bottom_m:.0f} m window, {window.rows} "
             "rotating rows, friction factor by torque-and-drag back-calculation"]
    flags = []
    if window.rows_unknown:
        notes.append(f"load case unknown in {window.rows_unknown} of {window.rows} rows (no "
                     "ROP, WOB or hole depth): counted on bottom")
    if window.kind is Kind.ON_BOTTOM:
        flags.append(Flag.BIT_TORQUE_IN_FRICTION)
        notes.append(f"apparent friction: bit torque assumed {torque_bit / 1e3:.2f} kN·m "
                     "(friction_log.bit_mu), not separated by the data")
    if not TYPICAL_MU[0] <= mu <= TYPICAL_MU[1]:
        flags.append(Flag.OUTSIDE_TYPICAL_RANGE)
        notes.append(f"μ = {mu:.3f} is outside the range usually seen ({TYPICAL_MU[0]}–"
                     f"{TYPICAL_MU[1]}): check string, survey, torque units")
    notes.append(NO_OBSERVER)
    return SegmentRecord(**base, mu_k=mu, mu_td=mu, T_N_Nm=td.T_N_Nm, converged=True,
                         method=Method.TD_BACKCALC, status=Status.OK, message="; ".join(notes),
                         quality_flags=tuple(flags))


def estimate(well: Well, log: pd.DataFrame | None = None,
             progress: Callable[[int], None] | None = None) -> tuple[list[WindowResult], list]:
    """Every window of a depth-indexed well back-calculated, and what was assumed.

    ``progress`` is called with the number of windows done.
    """
    log = read_depth_log(well) if log is None else log
    found, assumed = windows(log, well.config)
    results, td = [], TDSettings.from_config(well.config)
    for window in found:
        results.append(back_calculate(window, well, td))
        if progress:
            progress(len(results))
    return results, assumed


def friction_log(well: Well) -> list[SegmentRecord]:
    """The static friction log of a depth-indexed well: one record per window and load
    case (the module's description), in depth order."""
    return [r.record for r in estimate(well)[0]]
