"""What changed since the last night, per well of a fleet: fleet.html and
fleet_summary.parquet lead with it (docs/fleet.md "What changed overnight").

Each well's manifest entry keeps the last :data:`HISTORY_NIGHTS` nights it ran (μ_k and
segment count, :func:`night`); tonight's outcome is compared with them
(:func:`changes`): new segments, a well μ_k beyond the well's own recent spread, severe
stick-slip in a new segment, friction that rose within a new segment (``mu_k_drift``), and
wells whose data did not change (no new rows arrived).
"""

from __future__ import annotations

import numpy as np

from drillfric.io.text import plural
from drillfric.result import Flag

#: Nights of history kept per well.
HISTORY_NIGHTS = 7
#: Nights of history a μ_k must have before a move is judged against them.
MIN_HISTORY = 3
#: Smallest μ_k move reported, whatever the recent spread [-] (the third decimal is noise).
MU_K_FLOOR = 0.01
#: Stick-slip severity (ω_max − ω_min)/(2·ω_mean) above which the bit stops (docs/outputs.md).
SEVERE_STICK_SLIP = 1.0


def night(summary: dict, utc: str) -> dict:
    """One night's entry of a well's history (from its summary.json)."""
    return {"utc": utc, "mu_k": summary.get("mu_k"),
            "segments": len(summary.get("segments") or [])}


def changes(summary: dict | None, history: list[dict], *, ran: bool,
            data_changed_utc: str | None, rerun: str | None = None) -> dict:
    """What changed for one well tonight.

    Parameters
    ----------
    summary : dict or None
        The well's summary.json (None: it failed).
    history : list of dict
        The earlier nights (:func:`night`), oldest first, not tonight.
    ran : bool
        Whether the well was processed tonight (else its data had not changed).
    data_changed_utc : str or None
        When its data last changed (for a well that did not run).
    rerun : str or None
        Why a well with earlier nights ran again though its data had not grown ("its
        configuration changed", "drillfric changed"): the first note, so the well is listed
        even when nothing else moved (the fourth newcomer's demo3, re-run for its mud density,
        was left out of "What changed").

    Returns
    -------
    dict
        ``new_segments`` (int or None), ``notes`` (list of str, the headlines).
    """
    if not ran:
        since = f" since {data_changed_utc}" if data_changed_utc else ""
        return {"new_segments": 0, "notes": [f"no new data{since}"]}
    if summary is None:
        return {"new_segments": None, "notes": []}
    segments = summary.get("segments") or []
    before = history[-1]["segments"] if history else 0
    notes = [f"re-run: {rerun}"] if rerun and history else []
    notes += [plural(len(segments) - before, "new segment")] if len(segments) > before else []
    notes += _moved(summary.get("mu_k"), [h["mu_k"] for h in history[-HISTORY_NIGHTS:]
                                          if h.get("mu_k") is not None])
    severe = [s["id"] for s in segments[before:] if (s.get("stick_slip_severity") or 0.0)
              > SEVERE_STICK_SLIP
              or Flag.STICK_SLIP_BEYOND_VALIDATED in (s.get("quality_flags") or ())]
    if severe:
        notes.append(f"severe stick-slip (the bit stops) in {plural(len(severe), 'segment')}: "
                     f"{', '.join(map(str, severe))}")
    notes += _friction_rose(segments[before:])
    return {"new_segments": max(len(segments) - before, 0), "notes": notes}


def _friction_rose(segments: list[dict]) -> list[str]:
    """A note naming the new segments whose friction rose within them (flag ``mu_k_drift``
    with a rising ``mu_k_drift_per_h``, docs/theory.md §6.6) and the steepest rate."""
    rose = [(s["id"], s["mu_k_drift_per_h"]) for s in segments
            if Flag.MU_K_DRIFT in (s.get("quality_flags") or ())
            and (s.get("mu_k_drift_per_h") or 0.0) > 0]
    if not rose:
        return []
    steepest = max(rate for _, rate in rose)
    return [f"friction rose within {plural(len(rose), 'segment')}: "
            f"{', '.join(str(i) for i, _ in rose)} (mu_k_drift, up to {steepest:+.3f}/h: "
            "cuttings bed or pack-off?)"]


def _moved(mu_k: float | None, recent: list[float]) -> list[str]:
    """A note when μ_k left the recent nights' spread (needs :data:`MIN_HISTORY` nights)."""
    if mu_k is None or len(recent) < MIN_HISTORY:
        return []
    centre, spread = float(np.median(recent)), max(recent) - min(recent)
    if abs(mu_k - centre) <= max(spread, MU_K_FLOOR):
        return []
    return [f"μ_k moved to {mu_k:.3f} from {centre:.3f} (beyond its spread of "
            f"{spread:.3f} over {plural(len(recent), 'night')})"]
