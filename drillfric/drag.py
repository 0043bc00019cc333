"""Drag-based friction: the friction factor that the hook load of pick-ups and slack-offs
gives, a second friction log beside the torque-based one (docs/theory.md §2.2).

Off bottom and not turning, the string slides along the hole: soft-string torque and drag
(docs/theory.md §2, load cases ``pick_up`` / ``slack_off``, σ = ±1) gives the hook load as
a function of μ,

    H_pu = B + F_pu(μ),    H_so = B + F_so(μ),

with B the travelling block (:mod:`drillfric.hookload`) and F the effective tension at
surface. F_pu grows and F_so falls with μ, so each reading, less B, gives μ
(``mu_pick_up``, ``mu_slack_off``). Their difference does not depend on B at all,

    H_pu − H_so = F_pu(μ; d_pu) − F_so(μ; d_so),

and gives μ without a block weight (``mu_pair``); for a straight slant of length L at
inclination θ it is 2μ·w·L·sin θ.

Layers: the streaming :class:`MoveFinder` (steady axial moves of the pipe without
rotation, chunk by chunk, from the rig states and bit depth of
:class:`drillfric.segmentation.SegmentStream`), the pure inversion (:func:`hookload_curves`,
:func:`invert`), and :func:`drag_log`, which pairs the moves at each connection and makes
the log, withholding with the reason what the data cannot give.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from scipy.signal import lfilter

from drillfric import torque_drag
from drillfric.errors import ModelError
from drillfric.segmentation import IDLE, TRIPPING, above_rotary

if TYPE_CHECKING:
    from drillfric.config import Config

#: Relative uncertainty of the hook-load reading (dead-line anchor sensors are specified to
#: ±2–5 % of reading). A scale error multiplies the block's reading too, so it applies to
#: H − B and to H_pu − H_so as a whole.
HOOK_GAIN_UNCERTAINTY = 0.03
#: Least uncertainty of the block weight [N] (a plateau's band, :mod:`drillfric.hookload`).
BLOCK_FLOOR_N = 3e3
#: Smoothed axial speed above which the pipe counts as moving [m/s].
DETECT_M_S = 0.02
#: Time constant of the first-order smoothing of the axial speed [s].
SPEED_TAU_S = 2.0
#: Seconds dropped at the start and end of each move (break-over from static friction,
#: acceleration of the string and block).
SETTLE_S = 5.0
#: Shortest steady part of a move that is used [s] (and at least :data:`MIN_ROWS` rows).
MIN_WINDOW_S = 5.0
MIN_ROWS = 3
#: Longest travel of one window [m]: a longer move is cut (the string length changes).
WINDOW_M = 30.0
#: Slowest mean axial speed that counts as sliding with kinetic friction [m/s].
KINETIC_MIN_M_S = 0.05
#: A pick-up and a slack-off pair (one connection) when they are at most this far apart in
#: time [s] and in bit depth [m].
PAIR_TIME_S = 900.0
PAIR_DEPTH_M = 30.0
#: Largest reported uncertainty (half-width) of μ_drag [-]; beyond it the drag at that depth
#: is too small against the hook load's uncertainty and μ_drag is withheld.
MAX_UNCERTAINTY = 0.1
#: Friction factors on which the model's hook loads are tabulated (inverted by
#: interpolation; the curves are smooth and monotone).
MU_GRID = np.linspace(0.0, 2.0, 201)
#: Least share of the string's free-hanging weight a pick-up's or slack-off's hook load
#: (less the block) must carry to count as drag: friction lightens a slack-off (to ~60 % of
#: the hanging weight at μ = 0.4 in a 60° well), the slips take it all.
HANGING_SHARE = 0.25

PICK_UP, SLACK_OFF = "pick_up", "slack_off"
#: A connection's drag_log.parquet ``status``: its μ stated, or withheld with the reason.
_OK, _WITHHELD = "ok", "withheld"


@dataclass(frozen=True)
class Move:
    """A steady stretch of the pipe moving along the hole without rotation.

    Attributes
    ----------
    direction : str
        ``"pick_up"`` (pulling out) or ``"slack_off"`` (running in).
    t_start_s, t_end_s : float
        First and last row used [s] (after :data:`SETTLE_S` trimmed at both ends).
    rows : int
        Rows used.
    bit_depth_m : float
        Median bit depth [m].
    speed_m_s : float
        Mean axial speed, positive [m/s].
    hookload_N : float
        Median hook load [N].
    spread_N : float
        Half the interquartile range of the hook load [N].
    """

    direction: str
    t_start_s: float
    t_end_s: float
    rows: int
    bit_depth_m: float
    speed_m_s: float
    hookload_N: float
    spread_N: float

    @property
    def duration_s(self) -> float:
        return self.t_end_s - self.t_start_s

    @property
    def kinetic(self) -> bool:
        return self.speed_m_s >= KINETIC_MIN_M_S


# --------------------------------------------------------------------------- moves
class MoveFinder:
    """Pick-ups and slack-offs of a log, fed chunk by chunk (memory: the open move only).

    A row can belong to a move when its rig state is ``tripping`` or ``idle`` (not turning,
    not in the slips, not on bottom: :func:`drillfric.segmentation.classify`) and its time,
    bit depth and hook load are known. A move is a run of such rows whose smoothed axial
    speed (first order, :data:`SPEED_TAU_S`) exceeds :data:`DETECT_M_S` in one direction,
    without a gap longer than ``segmentation.max_gap_s``; its first and last
    :data:`SETTLE_S` are dropped and the rest cut into windows of at most :data:`WINDOW_M`.

    Parameters
    ----------
    cfg : Config
    """

    def __init__(self, cfg: Config):
        self._max_gap_s = float(cfg.segmentation.max_gap_s)
        self._prev = (np.nan, np.nan)  # time and depth of the previous row
        self._zi = np.zeros(1)         # smoothing filter state
        self._open: list[tuple] = []   # (t, depth, hook) arrays of the open move
        self._key = 0                  # its direction: +1 down, −1 up, 0 none
        self.moves: list[Move] = []
        self.too_short = 0             # moves with less than MIN_WINDOW_S steady

    def feed(self, chunk: pd.DataFrame, states: np.ndarray, bit_depth_m: np.ndarray) -> None:
        """Consume the next rows: canonical SI columns, their rig states and bit depths."""
        if not len(chunk) or "hookload_N" not in chunk:
            self._end()
            return
        t = chunk["time_s"].to_numpy(float)
        hook = chunk["hookload_N"].to_numpy(float)
        depth = np.asarray(bit_depth_m, dtype=float)
        dt = np.diff(np.r_[self._prev[0], t])
        step = np.diff(np.r_[self._prev[1], depth])
        self._prev = (t[-1], depth[-1])
        gap = ~(dt <= self._max_gap_s)
        with np.errstate(invalid="ignore", divide="ignore"):
            speed = np.where((dt > 0) & np.isfinite(step), step / dt, 0.0)
        dt_typical = float(np.nanmedian(dt)) if np.isfinite(dt).any() else 1.0
        alpha = min(1.0, max(dt_typical, 0.0) / SPEED_TAU_S) or 1.0
        smooth, self._zi = lfilter([alpha], [1.0, alpha - 1.0], speed, zi=self._zi)
        usable = (np.isin(states, (TRIPPING, IDLE)) & np.isfinite(t) & np.isfinite(hook)
                  & np.isfinite(depth))
        key = np.where(usable & (np.abs(smooth) > DETECT_M_S), np.sign(smooth), 0).astype(int)
        starts = np.flatnonzero(np.r_[True, (key[1:] != key[:-1]) | gap[1:]])
        for a, b in zip(starts, np.r_[starts[1:], key.size], strict=True):
            if key[a] != self._key or gap[a]:
                self._end()
            if key[a] != 0:
                self._key = int(key[a])
                self._open.append((t[a:b], depth[a:b], hook[a:b]))

    def close(self) -> list[Move]:
        """The moves of the whole log, the last one closed."""
        self._end()
        return self.moves

    def state(self) -> dict:
        """What continues the finder on later rows (docs/fleet.md): the previous row, the
        smoothing filter, the open move's rows and the moves found (arrays; a move as the
        row [direction (−1 pick-up, +1 slack-off), t_start_s, t_end_s, rows, bit_depth_m,
        speed_m_s, hookload_N, spread_N])."""
        rows = (np.column_stack([np.concatenate(p) for p in zip(*self._open, strict=True)])
                if self._open else np.empty((0, 3)))
        moves = [[-1.0 if m.direction == PICK_UP else 1.0, m.t_start_s, m.t_end_s, m.rows,
                  m.bit_depth_m, m.speed_m_s, m.hookload_N, m.spread_N] for m in self.moves]
        return {"prev": np.array(self._prev, float), "zi": self._zi.copy(), "open": rows,
                "key": self._key, "too_short": self.too_short,
                "moves": np.array(moves, float).reshape(-1, 8)}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self._prev = tuple(float(v) for v in state["prev"])
        self._zi = np.array(state["zi"], float)
        rows = np.asarray(state["open"], float).reshape(-1, 3)
        self._open = [(rows[:, 0], rows[:, 1], rows[:, 2])] if len(rows) else []
        self._key, self.too_short = int(state["key"]), int(state["too_short"])
        self.moves = [Move(PICK_UP if d < 0 else SLACK_OFF, float(a), float(b), int(n),
                           float(depth), float(v), float(h), float(q))
                      for d, a, b, n, depth, v, h, q in
                      np.asarray(state["moves"], float).reshape(-1, 8)]

    def _end(self) -> None:
        """Close the open move into windows."""
        if self._open:
            t, depth, hook = (np.concatenate(parts) for parts in zip(*self._open, strict=True))
            self._windows(PICK_UP if self._key < 0 else SLACK_OFF, t, depth, hook)
        self._open, self._key = [], 0

    def _windows(self, direction: str, t, depth, hook) -> None:
        keep = (t >= t[0] + SETTLE_S) & (t <= t[-1] - SETTLE_S)
        t, depth, hook = t[keep], depth[keep], hook[keep]
        if not t.size or t[-1] - t[0] < MIN_WINDOW_S:
            self.too_short += 1
            return
        piece = np.floor(np.abs(depth - depth[0]) / WINDOW_M).astype(int)
        for p in np.unique(piece):
            rows = piece == p
            tw, dw, hw = t[rows], depth[rows], hook[rows]
            if tw.size < MIN_ROWS or tw[-1] - tw[0] < MIN_WINDOW_S:
                continue
            q1, q3 = np.percentile(hw, [25, 75])
            self.moves.append(Move(direction, float(tw[0]), float(tw[-1]), int(tw.size),
                                   float(np.median(dw)),
                                   float(abs(dw[-1] - dw[0]) / (tw[-1] - tw[0])),
                                   float(np.median(hw)), float((q3 - q1) / 2)))


def find_moves(frame: pd.DataFrame, cfg: Config) -> tuple[list[Move], int]:
    """The moves of a whole log in memory, and how many were too short
    (:class:`MoveFinder` on :func:`drillfric.segmentation.SegmentStream`'s states)."""
    from drillfric.segmentation import SegmentStream

    stream, finder = SegmentStream(cfg), MoveFinder(cfg)
    stream.feed(frame)
    finder.feed(frame, stream.last_states, stream.last_bit_depth_m)
    return finder.close(), finder.too_short


# --------------------------------------------------------------------------- physics
def hookload_curves(td: torque_drag.TDSettings, path, bit_depth_m: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The model's pick-up and slack-off hook loads, no block, at every μ of
    :data:`MU_GRID` [N] (docs/theory.md §2, one μ along the whole string).

    ``path`` None: the assumed path of :meth:`drillfric.torque_drag.TDSettings.path_to`.
    """
    shoe = td.casing_shoe_md_m
    table = torque_drag.broomstick(
        td.path_to(path, bit_depth_m), td.sections, [bit_depth_m], MU_GRID,
        load_cases=(PICK_UP, SLACK_OFF), mud_out_kg_m3=td.mud_out_kg_m3,
        mud_in_kg_m3=td.mud_in_kg_m3, element_length_m=td.element_length_m,
        extra_nodes_m=() if shoe is None else (shoe,))
    hook = table["hookload_N"].to_numpy(float).reshape(2, MU_GRID.size)
    return hook[0], hook[1]


@dataclass(frozen=True)
class Estimate:
    """μ from one measured quantity: value, uncertainty (half-width) or why not."""

    mu: float | None = None
    uncertainty: float | None = None
    reason: str = ""


def invert(curve_N: np.ndarray, target_N: float, sigma_N: float, what: str) -> Estimate:
    """μ at which the monotone model ``curve_N`` (on :data:`MU_GRID`, rising or falling)
    equals ``target_N``, and the half-width of the μ interval that ``target_N ± sigma_N``
    maps to.

    Withheld (reason, no μ) when the curve changes less than ``sigma_N`` over the grid (no
    drag to measure), when the target lies outside the curve's range by more than
    ``sigma_N``, when the interval reaches the grid's end, or when the half-width exceeds
    :data:`MAX_UNCERTAINTY`. A target just outside the curve's μ = 0 end gives μ = 0
    (friction is never negative).
    """
    sign = 1.0 if curve_N[-1] >= curve_N[0] else -1.0
    curve, target = sign * curve_N, sign * target_N
    lo, hi = float(curve[0]), float(curve[-1])
    if hi - lo <= sigma_N:
        return Estimate(reason=(f"no drag to measure: the model's {what} changes by "
                                f"{(hi - lo) / 1e3:.1f} kN between μ = 0 and {MU_GRID[-1]:g}, "
                                f"within the measurement's uncertainty ±{sigma_N / 1e3:.1f} kN "
                                "(a near-vertical hole has no drag)"))
    if target < lo - sigma_N or target > hi + sigma_N:
        low, high = sorted((float(curve_N[0]), float(curve_N[-1])))
        return Estimate(reason=(f"the measured {what} {target_N / 1e3:.1f} kN is outside "
                                f"the model's {low / 1e3:.1f}–{high / 1e3:.1f} kN for μ in "
                                f"[0, {MU_GRID[-1]:g}] beyond its uncertainty "
                                f"±{sigma_N / 1e3:.1f} kN: the string, the mud or the block "
                                "weight is not what the model assumes"))
    if target + sigma_N > hi:
        return Estimate(reason=f"not resolved: μ from the {what} reaches {MU_GRID[-1]:g} "
                               "within its uncertainty")
    mu = float(np.interp(target, curve, MU_GRID))
    half = (float(np.interp(target + sigma_N, curve, MU_GRID))
            - float(np.interp(target - sigma_N, curve, MU_GRID))) / 2.0
    if half > MAX_UNCERTAINTY:
        return Estimate(reason=(f"not resolved: μ = {mu:.3f} ± {half:.3f} from the {what}, "
                                f"uncertainty above {MAX_UNCERTAINTY:g} (too little drag "
                                "against the hook load's uncertainty)"))
    return Estimate(mu, half)


# --------------------------------------------------------------------------- evidence
@dataclass(frozen=True)
class HookEvidence:
    """What the hook-load check (:func:`drillfric.hookload.judge`) tells the drag log.

    Attributes
    ----------
    block_N : float or None
        Block weight [N]; None when the log gives none.
    block_uncertainty_N : float
        Its uncertainty [N]: half the range of the plateau levels it rests on, at least
        :data:`BLOCK_FLOOR_N`.
    string_uncertainty : float
        Relative uncertainty of the modelled string weight: the measured string weight's
        departure |r − 1| (at least :data:`HOOK_GAIN_UNCERTAINTY`), or the check's tolerance
        where it could not be measured.
    contradicted : str
        Why the configured string is contradicted ("" when it is not).
    unweighed : str
        Why the string's weight is unknown beyond its uncertainty ("" when it is not): the
        built-in default string, which the hook load could not weigh.
    """

    block_N: float | None
    block_uncertainty_N: float
    string_uncertainty: float
    contradicted: str = ""
    unweighed: str = ""

    @classmethod
    def from_summary(cls, hook: dict) -> HookEvidence:
        """From summary.json ``hookload``."""
        block = hook.get("block_weight_N")
        levels = [p[2] for p in (hook.get("block_weight_evidence") or {}).get("plateaus", [])]
        spread = (max(levels) - min(levels)) / 2.0 if levels else 0.0
        ratio = hook.get("string_weight_ratio")
        string = hook["tolerance"] if ratio is None else max(abs(ratio - 1.0),
                                                              HOOK_GAIN_UNCERTAINTY)
        why = (hook.get("reason") or "") if hook.get("verdict") == "contradicted" else ""
        return cls(block, max(spread, BLOCK_FLOOR_N), float(string), why)


# --------------------------------------------------------------------------- the log
#: Columns of drag_log.parquet: (name, unit, meaning) — docs/outputs.md.
DRAG_COLUMNS = (
    ("t_start_s", "s", "first row of the connection's moves used"),
    ("t_end_s", "s", "last row used"),
    ("bit_depth_m", "m", "bit depth (mean of the pick-up's and slack-off's medians)"),
    ("pick_up_depth_m", "m", "median bit depth of the pick-up"),
    ("pick_up_hookload_N", "N", "median hook load of the pick-up (block included)"),
    ("pick_up_speed_m_s", "m/s", "mean speed of the pick-up"),
    ("pick_up_rows", "", "rows of the pick-up used"),
    ("pick_up_s", "s", "seconds of the pick-up used"),
    ("slack_off_depth_m", "m", "median bit depth of the slack-off"),
    ("slack_off_hookload_N", "N", "median hook load of the slack-off (block included)"),
    ("slack_off_speed_m_s", "m/s", "mean speed of the slack-off"),
    ("slack_off_rows", "", "rows of the slack-off used"),
    ("slack_off_s", "s", "seconds of the slack-off used"),
    ("block_weight_N", "N", "block weight subtracted (null: none known)"),
    ("mu_pick_up", "-", "μ from the pick-up hook load less the block weight"),
    ("mu_pick_up_uncertainty", "-", "its uncertainty (half-width)"),
    ("mu_slack_off", "-", "μ from the slack-off hook load less the block weight"),
    ("mu_slack_off_uncertainty", "-", "its uncertainty (half-width)"),
    ("mu_pair", "-", "μ from pick-up − slack-off (no block weight needed)"),
    ("mu_pair_uncertainty", "-", "its uncertainty (half-width)"),
    ("mu_drag", "-", "the drag-based friction factor: mu_pair, else the single one with the "
                     "smaller uncertainty; null when withheld"),
    ("mu_drag_uncertainty", "-", "its uncertainty (half-width)"),
    ("source", "", "pair, pick_up or slack_off (null when withheld)"),
    ("status", "", "ok or withheld"),
    ("reason", "", "why withheld, or why a single estimate is missing"),
)
DRAG_NAMES = tuple(c[0] for c in DRAG_COLUMNS)


def _side(move: Move | None, prefix: str) -> dict:
    if move is None:
        return {f"{prefix}_{k}": None for k in ("depth_m", "hookload_N", "speed_m_s", "rows",
                                                "s")}
    return {f"{prefix}_depth_m": move.bit_depth_m, f"{prefix}_hookload_N": move.hookload_N,
            f"{prefix}_speed_m_s": move.speed_m_s, f"{prefix}_rows": move.rows,
            f"{prefix}_s": move.duration_s}


def pair_moves(moves: list[Move]) -> list[tuple[Move | None, Move | None]]:
    """(pick-up, slack-off) of each connection: every kinetic pick-up takes the nearest
    kinetic slack-off in time within :data:`PAIR_TIME_S` and :data:`PAIR_DEPTH_M` (each
    used once, closest pairs first); the rest stand alone. In time order."""
    ups = [m for m in moves if m.direction == PICK_UP]
    downs = [m for m in moves if m.direction == SLACK_OFF]
    candidates = []
    for i, up in enumerate(ups):
        for j, down in enumerate(downs):
            apart = max(down.t_start_s - up.t_end_s, up.t_start_s - down.t_end_s, 0.0)
            if up.kinetic and down.kinetic and apart <= PAIR_TIME_S and \
                    abs(up.bit_depth_m - down.bit_depth_m) <= PAIR_DEPTH_M:
                candidates.append((apart, i, j))
    used_up, used_down, out = set(), set(), []
    for _, i, j in sorted(candidates):
        if i not in used_up and j not in used_down:
            used_up.add(i)
            used_down.add(j)
            out.append((ups[i], downs[j]))
    out += [(u, None) for i, u in enumerate(ups) if i not in used_up]
    out += [(None, d) for j, d in enumerate(downs) if j not in used_down]
    return sorted(out, key=lambda p: min(m.t_start_s for m in p if m is not None))


def connection_row(up: Move | None, down: Move | None, hook: HookEvidence, curves) -> dict:
    """One row of the drag log (:data:`DRAG_COLUMNS`); ``curves(depth)`` gives the model's
    (pick-up, slack-off) hook loads on :data:`MU_GRID` (:func:`hookload_curves`)."""
    present = [m for m in (up, down) if m is not None]
    row = {"t_start_s": min(m.t_start_s for m in present),
           "t_end_s": max(m.t_end_s for m in present),
           "bit_depth_m": float(np.mean([m.bit_depth_m for m in present])),
           **_side(up, PICK_UP), **_side(down, SLACK_OFF), "block_weight_N": hook.block_N}
    if (out := min(m.bit_depth_m for m in present)) <= 0.0:
        return row | _verdict({}, above_rotary(out))
    slow = [m for m in present if not m.kinetic]
    if hook.contradicted or hook.unweighed or slow:
        why = (f"the hook load contradicts the configured string ({hook.contradicted})"
               if hook.contradicted else hook.unweighed or
               f"{slow[0].direction.replace('_', '-')} at {slow[0].speed_m_s:.3f} m/s is too "
               f"slow for kinetic friction (below {KINETIC_MIN_M_S:g} m/s)")
        return row | _verdict({}, why)
    try:
        models = {m.direction: curves(m.bit_depth_m) for m in present}
    except ModelError as exc:
        return row | _verdict({}, exc.message)
    if why := _not_hanging(present, models, hook):
        return row | _verdict({}, why)
    found = {}
    if up is not None and down is not None:
        found["pair"] = _pair(up, down, models, hook)
    for move in (up, down):
        if move is not None and hook.block_N is not None:
            found[move.direction] = _single(move, models[move.direction], hook)
    return row | _verdict(found, "" if found or hook.block_N is not None else
                          "no block weight and no pick-up/slack-off pair: a single hook load "
                          "gives no μ without the block weight")


def _not_hanging(moves: list[Move], models: dict, hook: HookEvidence) -> str:
    """Why a move's hook load is no drag evidence ("" when every move's string hangs): less
    the block (0 where unknown: the hook load itself bounds the string's share) it must carry
    at least :data:`HANGING_SHARE` of the string's free-hanging weight (the model at μ = 0).
    A string in the slips while the bit depth moves (the block alone on the hook) looked
    like a slack-off against μ ≈ 1.2 and printed it (the demo's connections)."""
    for move in moves:
        hanging = float(models[move.direction][0][0])  # μ = 0: the buoyed string's weight
        carried = move.hookload_N - (hook.block_N or 0.0)
        if not carried >= HANGING_SHARE * hanging:
            return (f"the string was not hanging during the {move.direction.replace('_', '-')}"
                    f" (hook load less the block {carried / 1e3:.0f} kN, below "
                    f"{HANGING_SHARE:.0%} of its free-hanging {hanging / 1e3:.0f} kN): in the "
                    "slips or set down, not dragging")
    return ""


def _pair(up: Move, down: Move, models: dict, hook: HookEvidence) -> Estimate:
    """μ from H_pu − H_so (docs/theory.md §2.2): block-free."""
    target = up.hookload_N - down.hookload_N
    curve = models[PICK_UP][0] - models[SLACK_OFF][1]
    sigma = float(np.hypot.reduce([HOOK_GAIN_UNCERTAINTY * abs(target), up.spread_N,
                                   down.spread_N, hook.string_uncertainty * abs(target)]))
    return invert(curve, target, sigma, "pick-up − slack-off hook load")


def _single(move: Move, model: tuple, hook: HookEvidence) -> Estimate:
    """μ from one hook load less the block (the pick-up's rises with μ, the slack-off's
    falls)."""
    target = move.hookload_N - hook.block_N
    curve = model[0] if move.direction == PICK_UP else model[1]
    sigma = float(np.hypot.reduce([HOOK_GAIN_UNCERTAINTY * abs(target), move.spread_N,
                                   hook.block_uncertainty_N,
                                   hook.string_uncertainty * abs(target)]))
    return invert(curve, target, sigma, move.direction.replace("_", "-") +
                  " hook load less the block")


def _verdict(found: dict[str, Estimate], why: str) -> dict:
    """The μ columns of a row from its estimates (or ``why`` none is possible)."""
    out = {}
    for key in ("pick_up", "slack_off", "pair"):
        est = found.get(key, Estimate())
        out[f"mu_{key}"], out[f"mu_{key}_uncertainty"] = est.mu, est.uncertainty
    good = {k: e for k, e in found.items() if e.mu is not None}
    reasons = [f"{k.replace('_', '-')}: {e.reason}" for k, e in found.items() if e.reason]
    if "pair" in good:
        source = "pair"
    elif good:
        source = min(good, key=lambda k: good[k].uncertainty)
    else:
        return out | {"mu_drag": None, "mu_drag_uncertainty": None, "source": None,
                      "status": _WITHHELD, "reason": why or "; ".join(reasons)}
    return out | {"mu_drag": good[source].mu, "mu_drag_uncertainty": good[source].uncertainty,
                  "source": source, "status": _OK, "reason": "; ".join(reasons) or None}


def drag_log(moves: list[Move], too_short: int, td: torque_drag.TDSettings, path,
             hookload_summary: dict, *, string_assumed: bool = False
             ) -> tuple[dict, pd.DataFrame]:
    """summary.json ``drag`` and drag_log.parquet (:data:`DRAG_COLUMNS`) of a well.

    Parameters
    ----------
    moves, too_short : list of Move, int
        :meth:`MoveFinder.close` and :attr:`MoveFinder.too_short`.
    td : TDSettings
        The well's torque-and-drag settings (its configured string: a string-weight
        calibration's scale enters through ``hookload_summary``'s string ratio).
    path : WellPath or None
    hookload_summary : dict
        summary.json ``hookload`` (:func:`drillfric.hookload.judge`).
    string_assumed : bool
        Whether the string is the built-in default (no ``[[string.sections]]``, no WITSML
        tubular): where the hook load could not weigh it, its weight is unknown beyond the
        ± a drag μ carries, and every connection is withheld (the fourth newcomer's Volve
        F-4: 0.180 ± 0.011 on the default drill pipe, 0.270 ± 0.016 on the well's tubular).
    """
    hook = HookEvidence.from_summary(hookload_summary)
    if string_assumed and hookload_summary.get("string_weight_ratio") is None:
        hook = replace(hook, unweighed=(
            "the string is the built-in default (no [[string.sections]] or WITSML tubular) "
            "and the hook load could not weigh it: a drag μ rests on the string's weight"))
    cache: dict[float, tuple] = {}

    def curves(depth: float):
        key = round(depth, 1)
        if key not in cache:
            cache[key] = hookload_curves(td, path, key)
        return cache[key]

    rows = [connection_row(up, down, hook, curves) for up, down in pair_moves(moves)]
    table = pd.DataFrame(rows, columns=list(DRAG_NAMES))
    ok = table[table["status"] == _OK]
    if not moves:
        reason = ("no axial movement: no pick-up or slack-off without rotation of at least "
                  f"{MIN_WINDOW_S + 2 * SETTLE_S:g} s in the log")
    elif not len(ok):
        reason = "every connection withheld (drag_log reason column)"
    else:
        reason = None
    summary = {"connections": len(table), "estimated": len(ok),
               "pairs": int(table["source"].eq("pair").sum()), "reason": reason,
               "moves_too_short": too_short, "block_weight_N": hook.block_N,
               "block_weight_uncertainty_N": hook.block_uncertainty_N,
               "hook_gain_uncertainty": HOOK_GAIN_UNCERTAINTY,
               "string_weight_uncertainty": hook.string_uncertainty,
               "log": [{k: _plain(v) for k, v in r.items()} for r in rows]}
    return summary, table


def _plain(value):
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value

