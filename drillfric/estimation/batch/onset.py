"""A lower bound on μ_s from the stick-slip onset (docs/theory.md §6.2, §6.4).

Where stick-slip data hold no creep that identifies μ_s, the model is run on the start-up
and the next :data:`SCAN_COMPARED_S` of rotation of one run for μ_s on a grid above μ_k:
the highest μ_s below which the model's bit never sticks, lowered by
:data:`ONSET_MODEL_MARGIN` for the model's form, bounds the truth from below. None
is given where sticking is not monotone in μ_s (bistable) or never happens below
``observer.mu_max``.
"""

from __future__ import annotations

from dataclasses import dataclass

from drillfric.estimation.batch.harness import Model, Window, sticks
from drillfric.estimation.batch.settings import (
    SCAN_COMPARED_S,
    SCAN_CONFIRM,
    SCAN_STEP,
)
from drillfric.friction import CASED_STATIC
from drillfric.result import Flag


def onset_scan(model: Model, win: Window, mu_k: float,
               cells: int) -> tuple[float | None, bool, list]:
    """Lower bound on μ_s from the stick-slip onset (docs/theory.md §6.2, §6.4).

    Scans μ_s = μ_k + 0.02 j upward (to ``observer.mu_max``) until the model's bit sticks,
    then checks that the next :data:`SCAN_CONFIRM` points stick too. Returns (bound,
    bistable, scan): the bound is the highest grid value at which the model does not stick
    (μ_k itself when the first point sticks), None when sticking is not monotone (bistable)
    or never happens.
    """
    scan, first = [], None
    mu_s = mu_k
    while mu_s + SCAN_STEP <= model.settings.mu_max + 1e-9:
        mu_s = round(mu_s + SCAN_STEP, 10)
        _, bit = model.simulate(win, mu_s, mu_k, cells)
        stuck = sticks(bit[win.used - win.sim0], model.omega_c)
        scan.append((mu_s, stuck))
        if stuck and first is None:
            first = len(scan) - 1
        if not stuck and first is not None:
            return None, True, scan
        if first is not None and len(scan) - 1 - first >= SCAN_CONFIRM:
            break
    if first is None:
        return None, False, scan
    return (scan[first - 1][0] if first > 0 else mu_k), False, scan


#: Share the onset bound is lowered by for the model's form [-]: where the bit first
#: sticks depends on how the string is discretised and damped, and on a lumped plant of
#: 25-m segments (benchmarks/plants/lumped.py) it stuck at μ_s up to 3.6 % below the
#: highest μ_s at which drillfric's model did not — bounds of 0.26, 0.32, 0.38 over truths
#: of 0.251, 0.314, 0.376 (docs/validation.md "The second plant family"); with its top drive
#: 2.5× the configured inertia (a gear change, the motor torque logged) up to 7.6 % below
#: (0.3375 over 0.3135; docs/validation.md "Departures on the second plant family").
ONSET_MODEL_MARGIN = 0.10


@dataclass(frozen=True)
class BoundOutcome:
    """What the onset stage found.

    Attributes
    ----------
    bound : float or None
        Lower bound on μ_s [-] (None: bistable, or the model never sticks).
    scan : list of (float, bool)
        (μ_s, the model's bit sticks) of every scan point, both hypotheses.
    flags : tuple of Flag
    messages : tuple of str
    """

    bound: float | None
    scan: list
    flags: tuple[Flag, ...] = ()
    messages: tuple[str, ...] = ()


def onset_bound(model: Model, wins: list[Window], mu_k: float, cells: int,
                had_creep: bool = False) -> BoundOutcome:
    """Stick-slip-onset lower bound on μ_s over the start-up and the first
    :data:`SCAN_COMPARED_S` after it of the longest run. With a cased zone of unknown
    static friction the scan runs under both hypotheses and the lower bound is kept (a
    bound above the truth is a false claim)."""
    w = max(wins, key=lambda w: w.used.size)
    last = min(w.end, w.used[0] + int(round(SCAN_COMPARED_S / model.data.dt)))
    scan_win = Window(w.sim0, last, w.used[w.used <= last])
    bound, bistable, scan = onset_scan(model, scan_win, mu_k, cells)
    if not model.profile.static_known and bound is not None and not bistable:
        other, bistable, more = onset_scan(model.assuming(CASED_STATIC[1]), scan_win, mu_k,
                                           cells)
        scan += more
        bound = None if other is None else min(bound, other)
    if bistable:
        return BoundOutcome(None, scan, (Flag.BISTABLE_REGIME,), (
            "whether the model sticks is not monotone in μ_s near the onset: no lower bound "
            "given",))
    if bound is None:
        return BoundOutcome(None, scan, (Flag.STICK_SLIP_NOT_REPRODUCED,), (
            f"the model does not stick-slip for μ_s ≤ {model.settings.mu_max}: no lower "
            "bound",))
    bound = max(mu_k, bound * (1.0 - ONSET_MODEL_MARGIN))
    weak = " (the model sticks for any μ_s above μ_k: no more than μ_s ≥ μ_k)" \
        if bound == mu_k else ""
    why = "no creep fit passed its checks" if had_creep else "no creep"
    return BoundOutcome(bound, scan, (), (
        f"μ_s not identifiable (stick-slip, {why}); μ_s ≥ {bound:.2f} from the stick-slip "
        f"onset{weak}",))
