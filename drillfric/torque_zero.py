"""The torque sensor's zero: what the torque channel reads with the string in the slips.

With the string set in the slips the top drive carries no string torque, so its torque
channel reads zero, give or take its noise. A zero offset ΔT adds ΔT to every rotating
torque, and the friction factor — the mean string torque over T_N, the torque per unit
friction factor (docs/theory.md §2.1, §6.4) — moves by ΔT/T_N with it: 2.5 kN·m added to
the demo's torque printed μ_k 0.322 for 0.28 with status ok (issue 30, the sixth attack).

The rows at rest (top drive at or below ``segmentation.rotating_stop_rpm``) are binned by
hook load and torque (:class:`TorqueAtRest`, bounded memory, any chunking); at the end the
rows whose hook load lies within the block weight's plateau band are the string in the slips
(the block weight of docs/theory.md §2.1, found from the same hook load), and their median
torque is the zero the log shows (:func:`zero_check`). Where it exceeds
:data:`ZERO_SHARE` of the median rotating torque (and :data:`ZERO_FLOOR_NM`), every friction
factor is withheld with the offset named: a zero offset is a calibration fault the estimator
cannot tell from friction.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from drillfric.hookload import band_N, withhold_friction
from drillfric.result import Flag
from drillfric.vocabulary import Kind, Status

if TYPE_CHECKING:
    from drillfric.config import Config

#: Hook-load bins [N]: 3 % wide from 10 kN to 10 MN (a block weighs 10–60 t).
HOOK_EDGES_N = np.geomspace(1e4, 1e7, 235)
#: Torque bins [N·m]: ±(0…25 N·m), then 15 % wide up to ±60 kN·m, then the overflow bins.
_SIDE = 25.0 * 1.15 ** np.arange(57)
TORQUE_EDGES_NM = np.concatenate((-_SIDE[::-1], _SIDE))
#: A zero offset larger than this share of the median rotating torque is withheld [-]: it
#: moves μ_k by as much, and μ_k's validated tolerance is 5 % (docs/validation.md).
ZERO_SHARE = 0.03
#: Smallest offset judged [N·m]: below, sensor noise and quantisation (0.1–0.3 kN·m).
ZERO_FLOOR_NM = 300.0
#: Fewest rows in the slips to judge the zero from.
MIN_ROWS = 10


class TorqueAtRest:
    """Torque of the rows at rest, binned by hook load and torque (see module docstring).

    Parameters
    ----------
    cfg : Config
        ``segmentation.rotating_stop_rpm`` is the speed at or below which a row is at rest.
    """

    def __init__(self, cfg: Config):
        self._stop_rpm = float(cfg.segmentation.rotating_stop_rpm)
        self.counts = np.zeros((HOOK_EDGES_N.size + 1, TORQUE_EDGES_NM.size + 1), np.int64)

    def feed(self, chunk: pd.DataFrame, states=None) -> None:
        """Count the chunk's rows at rest (canonical SI columns)."""
        if not {"surface_rpm", "hookload_N", "surface_torque_Nm"} <= set(chunk.columns):
            return
        rpm = chunk["surface_rpm"].to_numpy(float)
        hook = chunk["hookload_N"].to_numpy(float)
        torque = chunk["surface_torque_Nm"].to_numpy(float)
        rest = (np.abs(rpm) <= self._stop_rpm) & np.isfinite(hook) & np.isfinite(torque)
        np.add.at(self.counts, (np.searchsorted(HOOK_EDGES_N, hook[rest]),
                                np.searchsorted(TORQUE_EDGES_NM, torque[rest])), 1)

    def state(self) -> dict:
        """The non-zero bins as rows [hook bin, torque bin, count]."""
        i, j = np.nonzero(self.counts)
        return {"bins": np.column_stack((i, j, self.counts[i, j])).astype(np.int64)}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self.counts[:] = 0
        bins = np.asarray(state["bins"], np.int64).reshape(-1, 3)
        ok = (bins[:, 0] >= 0) & (bins[:, 0] < self.counts.shape[0]) & \
            (bins[:, 1] >= 0) & (bins[:, 1] < self.counts.shape[1]) & (bins[:, 2] >= 0)
        self.counts[bins[ok, 0], bins[ok, 1]] = bins[ok, 2]

    def in_band(self, low_N: float, high_N: float) -> tuple[float | None, int]:
        """Median torque [N·m] of the rows whose hook load lies in [low_N, high_N] (the
        bins overlapping it; the median's bin centre, ±8 %) and their count."""
        lo = int(np.searchsorted(HOOK_EDGES_N, low_N))
        hi = int(np.searchsorted(HOOK_EDGES_N, high_N))
        torque_counts = self.counts[lo:hi + 1].sum(axis=0)
        n = int(torque_counts.sum())
        if n == 0:
            return None, 0
        k = int(np.searchsorted(np.cumsum(torque_counts), 0.5 * n))
        return _centre(k), n


def _centre(k: int) -> float:
    """The middle of torque bin ``k`` [N·m] (the overflow bins: their inner edge)."""
    edges = TORQUE_EDGES_NM
    if k == 0:
        return float(edges[0])
    if k >= edges.size:
        return float(edges[-1])
    a, b = edges[k - 1], edges[k]
    return float(0.0 if a < 0 < b else np.sign(a) * np.sqrt(a * b))


@dataclass(frozen=True)
class ZeroCheck:
    """What the in-slips torque says of the torque channel's zero (summary.json
    ``torque_zero``).

    Attributes
    ----------
    verdict : str
        ``ok``, ``offset`` (friction factors withheld) or ``unchecked`` (no block weight,
        too few rows at rest in the slips with a torque, or no rotating torque to compare).
    in_slips_torque_Nm : float or None
        Median torque of the rows in the slips [N·m].
    rows : int
        Rows it rests on.
    rotating_torque_Nm : float or None
        Median of the estimated off-bottom segments' mean rotating torque [N·m].
    reason : str
        Why (unchecked) or what was found (offset).
    """

    verdict: str
    in_slips_torque_Nm: float | None = None
    rows: int = 0
    rotating_torque_Nm: float | None = None
    reason: str = ""

    def summary(self) -> dict:
        """summary.json ``torque_zero`` (docs/outputs.md)."""
        return {"verdict": self.verdict, "in_slips_torque_Nm": self.in_slips_torque_Nm,
                "rows": self.rows, "rotating_torque_Nm": self.rotating_torque_Nm,
                "reason": self.reason or None}

    def warnings(self) -> list[str]:
        """The warning of an offset (none otherwise)."""
        if self.verdict != "offset":
            return []
        return [f"friction factors withheld: {self.reason}; re-zero the torque channel (or "
                f"correct the log) and run again"]

    def mu_k_reason(self, mu_k: float | None) -> str | None:
        """Why the well μ_k is null when the offset withheld it (None otherwise)."""
        if mu_k is not None or self.verdict != "offset":
            return None
        return f"withheld by the torque-zero check (docs/theory.md §2.1): {self.reason}"


def zero_check(rest: TorqueAtRest, block_N: float | None, records) -> ZeroCheck:
    """Judge the torque channel's zero from the rows at rest whose hook load is the block
    weight ``block_N`` [N] within its plateau band (the string in the slips) against the
    median rotating torque of the estimated off-bottom ``records`` (module docstring)."""
    torques = [abs(r.surface_torque_mean_Nm) for r in records
               if r.status is Status.OK and r.kind is Kind.OFF_BOTTOM
               and r.surface_torque_mean_Nm is not None
               and np.isfinite(r.surface_torque_mean_Nm)]
    rotating = float(np.median(torques)) if torques else None
    if block_N is None:
        return ZeroCheck("unchecked", rotating_torque_Nm=rotating,
                         reason="no block weight: the rows in the slips are not known")
    band = band_N(block_N)
    zero, n = rest.in_band(block_N - band, block_N + band)
    if zero is None or n < MIN_ROWS or not rotating:
        return ZeroCheck("unchecked", zero, n, rotating, "fewer than 10 rows at rest in the "
                         "slips with a torque, or no estimated off-bottom rotation")
    if abs(zero) <= max(ZERO_SHARE * rotating, ZERO_FLOOR_NM):
        return ZeroCheck("ok", zero, n, rotating)
    return ZeroCheck("offset", zero, n, rotating, (
        f"the torque reads {zero / 1e3:.2f} kN·m with the string in the slips ({n} rows at "
        f"the block's hook load, top drive at rest) where it should read zero: a zero offset "
        f"of {100 * abs(zero) / rotating:.0f} % of the rotating torque "
        f"({rotating / 1e3:.1f} kN·m), which moves μ by as much"))


def withhold_offset(records: list, check: ZeroCheck) -> list:
    """``records`` with every estimated segment's friction factors withheld when the
    torque channel's zero is off (flag ``torque_zero_offset``)."""
    if check.verdict != "offset":
        return list(records)
    return [withhold_friction(r, check.reason, Flag.TORQUE_ZERO_OFFSET)
            if r.status is Status.OK and r.mu_k is not None else r for r in records]
