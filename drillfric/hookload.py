"""Hook-load calibration: the block weight from the slips, the string weight from the
rotating hook load, and the check of the configured string against both.

docs/theory.md §2.1. The hook carries the travelling block and top drive (weight B) and,
off the slips, the string. Rotating off bottom the soft-string model has no axial friction
(σ = 0, docs/theory.md §2 step 3), so the measured hook load is

    H_rot = B + W_b,            W_b = Σ w_buoyed·Δs·cos Ī  (the model's ``hookload_N``),

and in the slips H_slips = B. The log therefore weighs the string itself:
W_meas = H_rot − H_slips. The friction factors scale as 1/W (T_N is proportional to the
string's weight when it rotates off bottom), so a configured string the hook load
contradicts gives wrong friction factors: they are withheld, or — where the configuration
allows it (``[hookload] calibrate_string_weight``) — the string's buoyed weight is scaled
to the measured one before each segment is estimated (:class:`StringWeightCalibration`).

Layers: pure functions (:func:`modelled_string_weight_N`, :func:`scaled_sections`,
:func:`block_weight`, :func:`point_problem`), the streaming :class:`PlateauFinder` (the
in-slips evidence, chunk by chunk), and :func:`judge`, which applies the check to a well's
segment records.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from drillfric import torque_drag
from drillfric.drillstring import section_from_config
from drillfric.io.text import plural, share, split_notes
from drillfric.kernels.lazy import lazy_jit
from drillfric.result import Flag, SegmentRecord
from drillfric.vocabulary import Kind, LoadCase, Status

if TYPE_CHECKING:
    from drillfric.config import Config

#: Heaviest plausible travelling equipment (block, hook, top drive, elevators) [N]: about
#: 70 t, above the heaviest offshore top-drive systems. Without an in-slips plateau a hook
#: load above the modelled string weight by more than this cannot be the configured string.
MAX_BLOCK_WEIGHT_N = 700e3
#: Lightest plausible string, buoyed weight per metre [N/m] (2⅜-in tubing, ~6 kg/m in mud).
#: A quiet plateau is only taken for the slips when it lies below the rotating hook loads by
#: at least this string's weight at their bit depths (else it is the string hanging).
MIN_STRING_WEIGHT_N_M = 50.0
#: Shortest quiet stretch that counts as a plateau [s].
PLATEAU_MIN_S = 10.0
#: A plateau's hook load stays within this share of its level (or :data:`PLATEAU_BAND_N`,
#: the larger) of its running mean; leaving it for :data:`PLATEAU_BREAK_S` ends it.
PLATEAU_BAND = 0.03
PLATEAU_BAND_N = 3e3
PLATEAU_BREAK_S = 2.0
#: Depth (bit, else block) speed below which the string or block counts as still [m/s].
STILL_M_S = 0.05
#: Range of the string-weight scale a calibration may apply; beyond it the configured
#: string is too far off to be rescued by one factor (fix the string instead).
CALIBRATION_RANGE = (0.5, 2.0)
#: Plateaus listed in summary.json as the block weight's evidence (the longest).
EVIDENCE_LISTED = 20


@dataclass(frozen=True)
class Plateau:
    """A stretch of steady hook load while the string does not turn or move.

    Attributes
    ----------
    t_start_s, t_end_s : float
        First and last row of the stretch [s].
    rows : int
        Rows inside the hook-load band.
    level_N : float
        Mean hook load of those rows [N].
    """

    t_start_s: float
    t_end_s: float
    rows: int
    level_N: float

    @property
    def duration_s(self) -> float:
        return self.t_end_s - self.t_start_s


@dataclass(frozen=True)
class BlockWeight:
    """The block weight the hook load gives, with its evidence.

    Attributes
    ----------
    weight_N : float or None
        Hook load in the slips [N]; None when the log gives none (``reason`` says why).
    source : str
        ``"slips_hookload_N"`` (rows below the configured threshold), ``"log"`` (the
        lowest quiet plateau), ``"config"`` (``hookload.block_weight_N``, the log giving
        none) or ``"none"``.
    plateaus : tuple of Plateau
        The plateaus the weight rests on.
    reason : str
        Why there is no block weight ("" when there is one).
    """

    weight_N: float | None
    source: str
    plateaus: tuple = ()
    reason: str = ""

    def text(self, slips_N: float | None = None) -> str:
        """The block weight as messages state it: the number summary.json
        ``hookload.block_weight_N`` holds (kN, 3 significant figures) and where it comes
        from, told apart from the slips threshold it is found under (issue 35: "block weight
        147 kN from slips_hookload_N" read as the configured 177.9 kN)."""
        value = f"block weight {_kN(self.weight_N)} kN"
        if self.source == "slips_hookload_N":
            below = "" if slips_N is None else f" = {_kN(slips_N)} kN"
            return (f"{value}: median hook load of the in-slips plateaus, those below "
                    f"segmentation.slips_hookload_N{below}")
        if self.source == "log":
            return f"{value}: median hook load of the lowest quiet plateaus (the slips)"
        if self.source == "config":
            return f"{value}: hookload.block_weight_N"
        return value

    def evidence(self) -> dict:
        """summary.json ``hookload.block_weight_evidence``: rows, seconds, time span and
        the longest plateaus as [t_start_s, t_end_s, level_N]."""
        if not self.plateaus:
            return {"rows": 0, "seconds": 0.0, "plateaus": []}
        longest = sorted(self.plateaus, key=lambda p: -p.duration_s)[:EVIDENCE_LISTED]
        return {"rows": int(sum(p.rows for p in self.plateaus)),
                "seconds": float(sum(p.duration_s for p in self.plateaus)),
                "first_s": float(min(p.t_start_s for p in self.plateaus)),
                "last_s": float(max(p.t_end_s for p in self.plateaus)),
                "plateaus": [[p.t_start_s, p.t_end_s, p.level_N]
                             for p in sorted(longest, key=lambda p: p.t_start_s)]}


def _kN(force_N: float) -> str:
    """A force in kN to 3 significant figures (147 kN, 178 kN, 1.52e+03 → 1520 kN)."""
    value = force_N / 1e3
    return f"{value:.0f}" if abs(value) >= 100 else f"{value:.3g}"


# --------------------------------------------------------------------------- physics
def modelled_string_weight_N(td: torque_drag.TDSettings, path, bit_depth_m: float) -> float:
    """Modelled rotating off-bottom hook load of the configured string [N]: the string's
    buoyed weight along the path, no block (docs/theory.md §2, σ = 0).

    For a vertical string of one section it is ρ_steel·A·L·g·(1 − ρ_mud/ρ_steel).
    """
    return float(td.solve(path, bit_depth_m, load_case=LoadCase.ROTATING_OFF_BOTTOM).hookload_N)


def scaled_sections(sections, scale: float, mud_out_kg_m3: float,
                    mud_in_kg_m3: float) -> tuple[dict, ...]:
    """Configured sections whose buoyed weight per metre is ``scale`` times theirs.

    Only the adjusted linear mass changes (diameters, stiffness, inertia stay):
    m' = c·m + (1 − c)·(ρ_o·A_o − ρ_i·A_i), so that g·(m' − ρ_o·A_o + ρ_i·A_i) = c·w
    (docs/theory.md §2 step 1). m' > 0 for every c > 0 and m above the mud it displaces.
    """
    out = []
    for entry in sections:
        sec = section_from_config(entry, 1.0)
        displaced = mud_out_kg_m3 * sec.outer_area_m2 - mud_in_kg_m3 * sec.inner_area_m2
        mass = scale * sec.linear_mass_kg_m + (1.0 - scale) * displaced
        out.append(dict(entry) | {"linear_mass_kg_m": float(mass)})
    return tuple(out)


def band_N(level_N: float) -> float:
    """Half-width of a plateau's hook-load band at ``level_N`` [N]."""
    return max(PLATEAU_BAND * abs(level_N), PLATEAU_BAND_N)


def point_problem(hookload_N: float, model_N: float, block_N: float | None,
                  tolerance: float) -> str:
    """What the hook load of one off-bottom rotating segment says against the model ("" when
    nothing): with a block weight, the measured string weight H − B off the modelled one by
    more than ``tolerance``; without one, only what no block weight can explain (H below
    the modelled string by more than the tolerance, or above it plus
    :data:`MAX_BLOCK_WEIGHT_N`)."""
    if block_N is not None:
        ratio = (hookload_N - block_N) / model_N
        if abs(ratio - 1.0) <= tolerance:
            return ""
        return (f"string weight from the hook load {(hookload_N - block_N) / 1e3:.0f} kN "
                f"(hook load {hookload_N / 1e3:.0f} − block {block_N / 1e3:.0f} kN) is "
                f"{ratio:.2f}× the configured string's {model_N / 1e3:.0f} kN")
    if hookload_N < (1.0 - tolerance) * model_N:
        return (f"hook load {hookload_N / 1e3:.0f} kN is below the configured string's "
                f"buoyed weight {model_N / 1e3:.0f} kN: the string cannot be that heavy")
    if hookload_N > (1.0 + tolerance) * model_N + MAX_BLOCK_WEIGHT_N:
        return (f"hook load {hookload_N / 1e3:.0f} kN exceeds the configured string's "
                f"{model_N / 1e3:.0f} kN by more than any block weight "
                f"({MAX_BLOCK_WEIGHT_N / 1e3:.0f} kN)")
    return ""


# --------------------------------------------------------------------------- plateaus
def _plateau_kernel(t, hook, quiet, min_s, band_rel, band_abs, break_s, max_gap_s, carry,
                    out_t0, out_t1, out_n, out_level):
    """Steady stretches of ``hook`` over ``quiet`` rows; appends finished ones to the
    ``out_*`` arrays and returns how many (see :class:`PlateauFinder`).

    ``carry`` = [t0, t_last, n, sum, t_out, n_out, sum_out, t_prev]: the open plateau, the
    rows outside its band since ``t_out`` and the previous row's time.
    """
    k = 0
    t0, t_last, n, total = carry[0], carry[1], carry[2], carry[3]
    t_out, n_out, sum_out, t_prev = carry[4], carry[5], carry[6], carry[7]
    for i in range(t.size):
        gap = not np.isnan(t_prev) and t[i] - t_prev > max_gap_s
        if not quiet[i] or np.isnan(hook[i]) or gap:
            if n > 0 and t_last - t0 >= min_s:
                out_t0[k], out_t1[k], out_n[k], out_level[k] = t0, t_last, n, total / n
                k += 1
            n, total, n_out, sum_out = 0.0, 0.0, 0.0, 0.0
            if gap and quiet[i] and not np.isnan(hook[i]):
                t0, t_last, n, total = t[i], t[i], 1.0, hook[i]
        elif n == 0:
            t0, t_last, n, total, n_out, sum_out = t[i], t[i], 1.0, hook[i], 0.0, 0.0
        else:
            level = total / n
            if abs(hook[i] - level) <= max(band_rel * abs(level), band_abs):
                t_last, n, total, n_out, sum_out = t[i], n + 1.0, total + hook[i], 0.0, 0.0
            else:
                if n_out == 0:
                    t_out = t[i]
                n_out, sum_out = n_out + 1.0, sum_out + hook[i]
                if t[i] - t_out >= break_s:
                    if t_last - t0 >= min_s:
                        out_t0[k], out_t1[k], out_n[k], out_level[k] = t0, t_last, n, \
                            total / n
                        k += 1
                    t0, t_last, n, total = t_out, t[i], n_out, sum_out
                    n_out, sum_out = 0.0, 0.0
        if not np.isnan(t[i]):
            t_prev = t[i]
    carry[0], carry[1], carry[2], carry[3] = t0, t_last, n, total
    carry[4], carry[5], carry[6], carry[7] = t_out, n_out, sum_out, t_prev
    return k


_compiled_plateaus = lazy_jit(_plateau_kernel)
_PLAIN_ROWS = 20_000


def _column(frame: pd.DataFrame, name: str) -> np.ndarray:
    return frame[name].to_numpy(float) if name in frame else np.full(len(frame), np.nan)


class PlateauFinder:
    """In-slips evidence of a log, fed chunk by chunk (bounded memory: only the plateaus).

    A row is *quiet* when the top drive does not turn (surface speed at most
    ``segmentation.rotating_stop_rpm``) and either its hook load is below
    ``segmentation.slips_hookload_N`` (when configured: the string is in the slips, the
    block may move) or, without that threshold, the string does not move (bit depth, else
    block position, changes slower than :data:`STILL_M_S`) and the bit is off bottom
    (:meth:`on_bottom`). Quiet rows whose hook load stays
    within the band (:func:`band_N`) of their running mean for at least
    :data:`PLATEAU_MIN_S` make a :class:`Plateau`.

    Parameters
    ----------
    cfg : Config
    """

    def __init__(self, cfg: Config):
        self._seg = cfg.segmentation
        self._carry = np.array([np.nan, np.nan, 0.0, 0.0, np.nan, 0.0, 0.0, np.nan])
        self._last = (np.nan, np.nan)  # time and depth of the previous row
        self.plateaus: list[Plateau] = []

    @property
    def configured(self) -> bool:
        """Whether in-slips rows come from ``slips_hookload_N`` (not from the log alone)."""
        return self._seg.slips_hookload_N is not None

    def quiet(self, chunk: pd.DataFrame) -> np.ndarray:
        """The quiet rows of a chunk (class description)."""
        rpm, hook = _column(chunk, "surface_rpm"), _column(chunk, "hookload_N")
        still_turning = ~(rpm <= self._seg.rotating_stop_rpm)
        if self.configured:
            return ~still_turning & (hook < self._seg.slips_hookload_N)
        depth = _column(chunk, "bit_depth_m" if "bit_depth_m" in chunk else
                        "block_position_m")
        t = _column(chunk, "time_s")
        prev_t, prev_d = self._last
        dt = np.diff(np.r_[prev_t, t])
        with np.errstate(invalid="ignore", divide="ignore"):
            speed = np.abs(np.diff(np.r_[prev_d, depth])) / np.where(dt > 0, dt, np.nan)
        if len(chunk):
            self._last = (t[-1], depth[-1])
        moving = speed > STILL_M_S if ("bit_depth_m" in chunk or "block_position_m" in chunk) \
            else np.zeros(len(chunk), bool)
        return ~still_turning & ~moving & ~self.on_bottom(chunk)

    def on_bottom(self, chunk: pd.DataFrame) -> np.ndarray:
        """Rows with the bit on bottom, by the segmentation's rule (hole − bit depth ≤
        ``segmentation.on_bottom_m``, else WOB > ``segmentation.wob_on_bottom_N``): a string
        standing on bottom hangs lighter by the weight set on the bit, so a stop there is
        neither the slips nor the string hanging free (a 12-t WOB held through a stop after
        drilling was taken for the slips: docs/validation.md)."""
        by_wob = _column(chunk, "wob_N") > self._seg.wob_on_bottom_N
        if "bit_depth_m" in chunk and "hole_depth_m" in chunk:
            gap = _column(chunk, "hole_depth_m") - _column(chunk, "bit_depth_m")
            # the hole depth above the bit cannot be: there the WOB decides (segmentation)
            return np.where(gap < -self._seg.on_bottom_m, by_wob, gap <= self._seg.on_bottom_m)
        return by_wob

    def feed(self, chunk: pd.DataFrame, states=None) -> None:
        """Consume the next rows (canonical SI columns; ``states``, the rig states, are
        not needed: quiet rows are judged here)."""
        if "hookload_N" not in chunk or not len(chunk):
            return
        self._run(_column(chunk, "time_s"), _column(chunk, "hookload_N"), self.quiet(chunk))

    def close(self) -> list[Plateau]:
        """The plateaus of the whole log, the last one closed."""
        self._run(np.array([np.nan]), np.array([np.nan]), np.array([False]))
        return self.plateaus

    def state(self) -> dict:
        """The open plateau's carry, the previous row and the plateaus found (arrays; one
        row [t_start_s, t_end_s, rows, level_N] per plateau)."""
        found = [[p.t_start_s, p.t_end_s, p.rows, p.level_N] for p in self.plateaus]
        return {"carry": self._carry.copy(), "last": np.array(self._last, float),
                "plateaus": np.array(found, float).reshape(-1, 4)}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self._carry = np.array(state["carry"], float)
        self._last = tuple(float(v) for v in state["last"])
        self.plateaus = [Plateau(float(a), float(b), int(n), float(level))
                         for a, b, n, level in np.asarray(state["plateaus"]).reshape(-1, 4)]

    def _run(self, t, hook, quiet) -> None:
        kernel = _plateau_kernel if t.size <= _PLAIN_ROWS else _compiled_plateaus()
        out = [np.empty(t.size + 1) for _ in range(4)]
        k = kernel(t, hook, quiet, PLATEAU_MIN_S, PLATEAU_BAND, PLATEAU_BAND_N,
                   PLATEAU_BREAK_S, float(self._seg.max_gap_s), self._carry, *out)
        self.plateaus += [Plateau(float(a), float(b), int(n), float(level))
                          for a, b, n, level in zip(*(o[:k] for o in out), strict=True)]


def find_plateaus(frame: pd.DataFrame, cfg: Config) -> list[Plateau]:
    """The plateaus of a whole log in memory (:class:`PlateauFinder`)."""
    finder = PlateauFinder(cfg)
    finder.feed(frame)
    return finder.close()


# --------------------------------------------------------------------------- block weight
def _weighted_median(levels: np.ndarray, weights: np.ndarray) -> float:
    order = np.argsort(levels)
    cum = np.cumsum(weights[order])
    return float(levels[order][np.searchsorted(cum, 0.5 * cum[-1])])


def block_weight(plateaus: list[Plateau], points: pd.DataFrame,
                 configured: bool) -> BlockWeight:
    """The block weight (hook load in the slips) from the plateaus of a log.

    With ``configured`` (rows below ``slips_hookload_N``) every plateau is in the slips:
    the duration-weighted median of their levels. Otherwise the slips are the lowest
    plateau — but only plateaus that lie below the off-bottom rotating hook loads
    (``points``: ``hookload_N``, ``bit_depth_m``) by at least the lightest plausible
    string's weight (:data:`MIN_STRING_WEIGHT_N_M`) count (a plateau above that is the
    string hanging, not the slips); the weight is the duration-weighted median of the
    plateaus within :func:`band_N` of the lowest.
    """
    if not plateaus:
        return BlockWeight(None, "none", (), "no quiet hook-load plateau of "
                           f"{PLATEAU_MIN_S:g} s without rotation" + (
                               " below segmentation.slips_hookload_N" if configured else
                               " and without string movement"))
    if not configured:
        if not len(points):
            return BlockWeight(None, "none", (), "no off-bottom rotating hook load to tell "
                               "the slips from the string hanging")
        floor = float(np.median(points["hookload_N"]
                                - MIN_STRING_WEIGHT_N_M * points["bit_depth_m"]))
        plateaus = [p for p in plateaus if p.level_N <= floor]
        if not plateaus:
            return BlockWeight(None, "none", (), "no quiet plateau lies below the rotating "
                               f"hook load by the weight of the lightest string "
                               f"({MIN_STRING_WEIGHT_N_M:g} N/m): no slips in the log")
        lowest = min(p.level_N for p in plateaus)
        plateaus = [p for p in plateaus if p.level_N <= lowest + band_N(lowest)]
    levels = np.array([p.level_N for p in plateaus])
    weights = np.array([max(p.duration_s, 1e-9) for p in plateaus])
    return BlockWeight(_weighted_median(levels, weights),
                       "slips_hookload_N" if configured else "log", tuple(plateaus))


def block_weight_of(plateaus: list[Plateau], points: pd.DataFrame, cfg: Config) -> BlockWeight:
    """The block weight of a well: from the log (:func:`block_weight`), else the configured
    ``hookload.block_weight_N`` (source ``"config"``), else none."""
    block = block_weight(plateaus, points, cfg.segmentation.slips_hookload_N is not None)
    configured = cfg.hookload.block_weight_N
    if block.weight_N is not None or configured is None:
        return block
    return BlockWeight(float(configured), "config", (), "")


# --------------------------------------------------------------------------- the check
def off_bottom_points(records) -> pd.DataFrame:
    """The off-bottom rotating segments with a measured and a modelled hook load."""
    rows = [(r.id, r.bit_depth_m, r.hookload_N, r.hookload_model_N) for r in records
            if r.status is Status.OK and r.kind is Kind.OFF_BOTTOM
            and r.hookload_N is not None and r.hookload_model_N is not None
            and np.isfinite(r.hookload_N) and np.isfinite(r.hookload_model_N)
            and r.hookload_model_N > 0]
    return pd.DataFrame(rows, columns=["id", "bit_depth_m", "hookload_N", "hookload_model_N"])


@dataclass(frozen=True)
class Calibration:
    """A string-weight calibration (:class:`StringWeightCalibration`).

    Attributes
    ----------
    scale : float or None
        Factor applied to the string's buoyed weight; None when not calibrated.
    block : BlockWeight
    segments : int
        Off-bottom rotating segments the factor rests on.
    reason : str
        Why not calibrated ("" when calibrated).
    """

    scale: float | None
    block: BlockWeight
    segments: int = 0
    reason: str = ""


@dataclass
class Outcome:
    """What the hook-load check did to a well (:func:`judge`)."""

    records: list
    summary: dict
    warnings: list = field(default_factory=list)

    def mu_k_reason(self, mu_k: float | None) -> str | None:
        """summary.json ``mu_k_reason``: why the well-level μ_k is null when the hook-load
        check withheld segments (None otherwise)."""
        if mu_k is not None or not self.summary.get("withheld_segments"):
            return None
        why = self.summary.get("reason") or "their hook load contradicts the configured string"
        return f"withheld by the hook-load check (docs/theory.md §2.1): {why}"


#: The friction numbers a contradicted segment withholds.
_WITHHELD = ("mu_s", "mu_k", "mu_s_lower_bound", "mu_s_spread", "mu_k_spread",
             "mu_k_damping_uncertainty", "mu_k_observer", "mu_s_observer", "mu_td",
             "mu_k_drift_per_h", "mu_k_first", "mu_k_last")


#: A note that states a friction factor: μ_k or μ_s, a relation and a number.
_STATES_FRICTION = re.compile(r"μ_[ks][^;]{0,12}?(=|≥|≤|≈|<|>)\s*[-+]?\d")


def withhold_friction(record: SegmentRecord, why: str, flag: Flag | None) -> SegmentRecord:
    """``record`` with its friction numbers null, ``why`` in its message and ``flag`` (None:
    no new flag, the record's own say why).

    The notes of its message that state a friction factor are left out (a reader would take
    "μ_k = 0.038 ± 0.003" in a withheld segment for a result: issue 35 item 6), and how many
    is said.

    Examples
    --------
    >>> r = SegmentRecord(mu_k=0.2, message="fit note; μ_k = 0.200 ± 0.010 (95 %: …)")
    >>> withheld = withhold_friction(r, "the hook load says so", Flag.TORQUE_ZERO_OFFSET)
    >>> for note in withheld.message.split("; "):
    ...     print(note)
    fit note
    1 note stating the withheld friction factors left out
    friction factors withheld: the hook load says so
    """
    nulls = {name: None for name in _WITHHELD}
    notes = split_notes(record.message or "")  # a "; " in brackets is inside its note
    kept = [n for n in notes if not _STATES_FRICTION.search(n)]
    cut = len(notes) - len(kept)
    left_out = (f"{cut} note{'s' * (cut != 1)} stating the withheld friction factors left "
                "out") if cut else ""
    message = "; ".join(filter(None, kept + [left_out, f"friction factors withheld: {why}"]))
    flags = record.quality_flags + ((flag,) if flag is not None else ())
    return replace(record, **nulls, converged=False, message=message,
                   quality_flags=tuple(dict.fromkeys(flags)))


def light_string(hookload_N, model_N, tolerance: float) -> str:
    """Why a depth-indexed log's hook load contradicts the configured string ("" when it
    does not), one-sided: without the in-slips rows of a time log the block weight is not
    known, but it only adds, so the logged hook load cannot be below the model's (the buoyed
    string less the WOB, no block; rotating, so no axial drag) by more than ``tolerance``.
    Depths and a survey in ft read as m had put it at 0.35× and printed μ 54 % low.

    Parameters
    ----------
    hookload_N, model_N : array_like
        Each window's median logged hook load and the model's [N].
    tolerance : float
        ``hookload.tolerance`` [-].
    """
    hook, model = np.asarray(hookload_N, float), np.asarray(model_N, float)
    ok = np.isfinite(hook) & np.isfinite(model) & (model > 0)
    if ok.sum() < 3:
        return ""
    ratio = float(np.median(hook[ok] / model[ok]))
    if ratio >= 1.0 - tolerance:
        return ""
    return (f"the logged hook load is {ratio:.2f}× the configured string's weight less the "
            f"WOB (median of {int(ok.sum())} windows), below it by more than hookload."
            f"tolerance = {tolerance:g}, though the block only adds to it: depths or survey "
            "in ft read as m, or a lighter string than configured?")


@dataclass(frozen=True)
class WeightVerdict:
    """What the string-weight check does to one segment.

    Attributes
    ----------
    withhold : str
        Why its friction factors are withheld ("" when they are not).
    flag : Flag or None
        The flag it gets (None: none).
    """

    withhold: str = ""
    flag: Flag | None = None


def weight_verdict(status: Status, contradiction: str, unverified: str,
                   calibrated: bool) -> WeightVerdict:
    """The string-weight check's rule for one segment (docs/theory.md §2.1), in order:

    1. not estimated (skipped, failed): nothing;
    2. the hook load contradicts the string (well-wide, or this segment's ``contradiction``):
       withheld, ``hookload_contradicts_string``;
    3. no block weight to weigh the string (``unverified``, the reason): withheld,
       ``string_weight_unverified``;
    4. the string's weight was ``calibrated`` to the hook load: shown,
       ``string_weight_calibrated``;
    5. else shown, no flag.
    """
    if status is not Status.OK:
        return WeightVerdict()
    if contradiction:
        return WeightVerdict(contradiction, Flag.HOOKLOAD_CONTRADICTS_STRING)
    if unverified:
        return WeightVerdict(unverified, Flag.STRING_WEIGHT_UNVERIFIED)
    return WeightVerdict(flag=Flag.STRING_WEIGHT_CALIBRATED if calibrated else None)


def _unverified(block: BlockWeight) -> str:
    """Why friction factors resting on a string weight the log cannot measure are withheld."""
    return (f"the string weight is unverified: no block weight ({block.reason}), so the hook "
            "load (block + string) cannot weigh the string, and μ scales as 1/(string "
            "weight) — a string 40 % off the configured one would pass")


def in_slips_reason(hookload_N, bit_depth_m, plateaus: list[Plateau]) -> str:
    """Why an off-bottom rotating segment is a rotation in the slips ("" when it is not):
    its hook load lies above the log's lowest quiet plateau (the block alone) by less than
    the lightest plausible string at its bit depth (:data:`MIN_STRING_WEIGHT_N_M`) while the
    plateaus of the string hanging (their 90th percentile) are heavier than it by at least
    that much. Volve F-4 (issue 35):
    eight top-drive make-up/break-out bursts at 0.63–0.67 MN against 1.3–1.7 MN hanging,
    labelled off-bottom rotation for want of ``segmentation.slips_hookload_N``."""
    if not plateaus or hookload_N is None or bit_depth_m is None \
            or not np.isfinite(hookload_N) or not np.isfinite(bit_depth_m):
        return ""
    levels = [p.level_N for p in plateaus]
    lowest, hanging = min(levels), float(np.percentile(levels, 90.0))
    lightest = MIN_STRING_WEIGHT_N_M * max(bit_depth_m, 0.0)
    if hookload_N - lowest >= lightest or hanging - hookload_N < lightest:
        return ""
    return (f"rotation in the slips: its hook load {hookload_N / 1e3:.0f} kN is at the "
            f"block's level (the lowest quiet plateau, {lowest / 1e3:.0f} kN), "
            f"{(hanging - hookload_N) / 1e3:.0f} kN below the string hanging "
            f"({hanging / 1e3:.0f} kN): the top drive turned a "
            "connection being made up or broken out, not the string in the hole — not an "
            "off-bottom rotation, skipped (set segmentation.slips_hookload_N between the two "
            "to label such rows in_slips)")


def _in_slips(records: list, plateaus: list[Plateau]) -> list:
    """``records`` with the off-bottom rotations that are in the slips skipped, saying so
    (:func:`in_slips_reason`)."""
    out = []
    for r in records:
        why = in_slips_reason(r.hookload_N, r.bit_depth_m, plateaus) \
            if r.kind is Kind.OFF_BOTTOM and r.status is not Status.FAILED else ""
        if why:
            r = replace(r, **{name: None for name in _WITHHELD}, status=Status.SKIPPED,
                        message="; ".join(filter(None, [why, r.message])))
        out.append(r)
    return out


def judge(records: list, plateaus: list[Plateau], cfg: Config,
          calibration: Calibration | None = None) -> Outcome:
    """Check the configured string against the hook load; withhold what it contradicts.

    Per off-bottom rotating segment: :func:`point_problem`. Well-wide: the median measured
    string weight over the modelled one (needs the block weight); outside
    ``1 ± hookload.tolerance`` every segment's friction factors are withheld (all segments
    share the string). A segment whose own hook load contradicts the model is withheld
    too. Without a block weight (no in-slips plateau, no ``hookload.block_weight_N``) the
    log cannot weigh the string: every estimated segment's friction factors are withheld
    (flag ``string_weight_unverified``). With a ``calibration`` every estimated segment is
    flagged ``string_weight_calibrated``.
    """
    tol = cfg.hookload.tolerance
    if cfg.segmentation.slips_hookload_N is None:  # else the slips are a rig state already
        records = _in_slips(records, plateaus)
    points = off_bottom_points(records)
    block = calibration.block if calibration is not None and calibration.scale is not None \
        else block_weight_of(plateaus, points, cfg)
    summary = _summary_base(cfg, block, calibration, len(points))
    if not len(points) and (block.weight_N is not None or not _hooked(records)):
        summary.update(verdict="not_checked", reason="no estimated off-bottom rotating "
                       "segment with a hook load")
        return Outcome(list(records), summary, _unchecked(records))
    problems = {int(p.id): point_problem(p.hookload_N, p.hookload_model_N, block.weight_N, tol)
                for p in points.itertuples()}
    well_problem = ""
    if block.weight_N is not None:
        ratio = float(np.median((points["hookload_N"] - block.weight_N)
                                / points["hookload_model_N"]))
        summary["string_weight_ratio"] = ratio
        if abs(ratio - 1.0) > tol:
            well_problem = (f"the hook load contradicts the configured string: the string "
                            f"weight it measures is {ratio:.2f}× the modelled one (median of "
                            f"{plural(len(points), 'off-bottom segment')}; "
                            f"{block.text(cfg.segmentation.slips_hookload_N)}), beyond "
                            f"±{tol:.0%}")
    else:
        bad = [i for i, why in problems.items() if why]
        if len(bad) > len(points) / 2:
            well_problem = (f"the hook load contradicts the configured string in "
                            f"{share(len(bad), len(points), 'off-bottom segment')} "
                            f"({problems[bad[0]]})")
    unverified = _unverified(block) if block.weight_N is None and not well_problem else ""
    calibrated = calibration is not None and calibration.scale is not None
    out, withheld = [], []
    for r in records:
        rule = weight_verdict(r.status, well_problem or problems.get(r.id, ""), unverified,
                              calibrated)
        if rule.withhold:
            out.append(withhold_friction(r, rule.withhold, rule.flag))
            withheld.append(r.id)
        else:
            out.append(r if rule.flag is None else
                       replace(r, quality_flags=r.quality_flags + (rule.flag,)))
    summary.update(verdict=_verdict(well_problem, block, calibration),
                   withheld_segments=withheld, reason=well_problem or unverified or None)
    contradicted = [i for i in withheld if well_problem or problems.get(i)]
    warnings = _warnings(well_problem, contradicted, problems, block, calibration, cfg,
                         summary.get("string_weight_ratio"))
    return Outcome(out, summary, warnings)


def _hooked(records) -> bool:
    """Whether any estimated segment has a measured hook load."""
    return any(r.status is Status.OK and r.hookload_N is not None
               and np.isfinite(r.hookload_N) for r in records)


def _unchecked(records) -> list[str]:
    """The warning of estimated segments whose string weight nothing checked (no off-bottom
    rotating segment with a hook load to weigh it against): their friction factors rest on
    the configured string's weight."""
    ids = [str(r.id) for r in records if r.status is Status.OK]
    if not ids:
        return []
    return [f"string weight not checked: no off-bottom rotating segment with a hook load to "
            f"weigh it against, so the friction factors of {_segments(ids)} rest "
            "on the configured string's weight (μ scales as 1/W; docs/theory.md §2.1): log "
            "the hook load, and rotate off bottom"]


def _segments(ids) -> str:
    """``"segment 3"`` or ``"segments 1, 3, 4"``."""
    ids = [str(i) for i in ids]
    return f"segment{'s' * (len(ids) != 1)} {', '.join(ids)}"


def _verdict(well_problem: str, block: BlockWeight, calibration: Calibration | None) -> str:
    """summary.json ``hookload.verdict`` of a checked well: ``contradicted``, ``calibrated``,
    ``consistent`` (the string weight measured and within the tolerance) or ``unverified``
    (no block weight: the log cannot weigh the string, and the friction factors, which
    scale as 1/(string weight), are withheld)."""
    if well_problem:
        return "contradicted"
    if calibration is not None and calibration.scale is not None:
        return "calibrated"
    return "consistent" if block.weight_N is not None else "unverified"


def _summary_base(cfg: Config, block: BlockWeight, calibration: Calibration | None,
                  checked: int) -> dict:
    """summary.json ``hookload`` before the verdict."""
    return {"verdict": None, "reason": None, "tolerance": cfg.hookload.tolerance,
            "block_weight_N": block.weight_N, "block_weight_source": block.source,
            "block_weight_reason": block.reason or None,
            "block_weight_evidence": block.evidence(), "segments_checked": checked,
            "string_weight_ratio": None, "withheld_segments": [],
            "calibration_allowed": bool(cfg.hookload.calibrate_string_weight),
            "calibration_scale": None if calibration is None else calibration.scale,
            "calibration_reason": None if calibration is None else
            (calibration.reason or None)}


def _warnings(well_problem: str, withheld: list, problems: dict, block: BlockWeight,
              calibration: Calibration | None, cfg: Config,
              ratio: float | None = None) -> list[str]:
    out = []
    if well_problem:
        # calibration is advised only where it could apply (the DSATS example's 0.21× had
        # been told to allow it, and then refused as outside the range)
        rescalable = ratio is not None and CALIBRATION_RANGE[0] <= ratio <= CALIBRATION_RANGE[1]
        fix = ("check [[string.sections]] (linear masses, lengths), the mud density and the "
               "hook-load channel" + (", or allow hookload.calibrate_string_weight"
                                      if rescalable and not cfg.hookload.calibrate_string_weight
                                      else ""))
        extra = f" ({calibration.reason})" if calibration and calibration.reason else ""
        out.append(f"friction factors withheld: {well_problem}{extra}; {fix}")
    elif withheld:
        out.append(f"friction factors of {_segments(withheld)} withheld: "
                   f"their hook load contradicts the configured string "
                   f"({problems[withheld[0]]})")
    if calibration is not None and calibration.scale is not None:
        out.append(f"string weight calibrated from the hook load: buoyed weight × "
                   f"{calibration.scale:.3f} ({calibration.segments} off-bottom segments; "
                   f"{block.text(cfg.segmentation.slips_hookload_N)})")
    if block.weight_N is None and not well_problem:
        out.append(f"friction factors withheld: {_unverified(block)}; give "
                   "hookload.block_weight_N (the rig's block, hook and top drive; 0 for a hook "
                   "load zeroed on the empty block), or a log with the string in the slips")
    return out


# --------------------------------------------------------------------------- calibration
class StringWeightCalibration:
    """The string-weight calibration as the log streams (``hookload.calibrate_string_weight``).

    Each off-bottom rotating segment adds a point — its bit depth, median hook load and the
    modelled string weight there — as it closes; :meth:`current` gives the calibration the
    rows seen so far support: the block weight (:func:`block_weight_of`: the plateaus found
    so far, else ``hookload.block_weight_N``) and the scale, the median of (H − B)/W_model.
    Not applied (the hook-load check then withholds) without a block weight or when the
    scale is outside
    :data:`CALIBRATION_RANGE`. Later rows may move the scale: the run then revises the
    segments estimated with another one (docs/theory.md §2.1).

    Parameters
    ----------
    well : Well
        The well as opened (its configured string).
    """

    def __init__(self, well):
        self.well = well
        self.td = torque_drag.TDSettings.from_config(well.config)
        self.points: list[tuple] = []

    def add(self, done) -> None:
        """Take the points of finished segments ``done`` (segment, rows)."""
        self.points += _points(done, self.td, self.well.survey)

    def current(self, plateaus: list[Plateau]):
        """The well with its string's buoyed weight scaled to the hook load (else
        unchanged) and the :class:`Calibration`."""
        well, cfg = self.well, self.well.config
        points = pd.DataFrame(self.points,
                              columns=["bit_depth_m", "hookload_N", "hookload_model_N"])
        block = block_weight_of(plateaus, points, cfg)
        if block.weight_N is None or not len(points):
            why = block.reason if block.weight_N is None else "no off-bottom rotating hook load"
            return well, Calibration(None, block, len(points), f"not calibrated: {why}")
        scale = float(np.median((points["hookload_N"] - block.weight_N)
                                / points["hookload_model_N"]))
        if not CALIBRATION_RANGE[0] <= scale <= CALIBRATION_RANGE[1]:
            return well, Calibration(None, block, len(points), (
                f"not calibrated: a scale of {scale:.2f} is outside {CALIBRATION_RANGE[0]:g}–"
                f"{CALIBRATION_RANGE[1]:g}, the string is too far off to rescale"))
        sections = scaled_sections(cfg.sections, scale, cfg.fluid.mud_density_kg_m3,
                                   cfg.inner_mud_density_kg_m3)
        return replace(well, config=replace(cfg, sections=sections)), Calibration(
            scale, block, len(points))

    def state(self) -> dict:
        """The points (an array of rows [bit_depth_m, hookload_N, hookload_model_N])."""
        return {"points": np.array(self.points, float).reshape(-1, 3)}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self.points = [tuple(map(float, p)) for p in np.asarray(state["points"]).reshape(-1, 3)]


def _points(done, td: torque_drag.TDSettings, path) -> list[tuple]:
    """(bit depth, median hook load, modelled string weight) of finished off-bottom
    segments."""
    out = []
    for seg, rows in done:
        if seg.kind != Kind.OFF_BOTTOM or seg.status != Status.OK or \
                not np.isfinite(seg.bit_depth_m) or "hookload_N" not in rows:
            continue
        hook = rows["hookload_N"].to_numpy(float)
        if not np.isfinite(hook).any():
            continue
        if path is not None and seg.bit_depth_m > path.md_max_m:
            continue
        out.append((seg.bit_depth_m, float(np.nanmedian(hook)),
                    modelled_string_weight_N(td, path, seg.bit_depth_m)))
    return out
