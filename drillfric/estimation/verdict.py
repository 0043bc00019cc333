"""What a segment's estimates may claim: the rules an engineer is most likely to change.

Two pure functions, each a table of rules (issue 31 item 4):

- :func:`decide`, from the estimators' results (:class:`Evidence`) to the numbers reported
  and the words beside them (:class:`Verdict`): which μ_k is reported and by which method,
  whether it counts as converged, whether a μ_s lower bound may be shown, and the flags and
  messages (docs/batch_refinement.md);
- :func:`decide_trace`, from what the checks of the seeded bit trace found
  (:class:`TraceEvidence`) to what of the bit speed and its stick-slip statistics may be
  shown (:class:`TraceVerdict`), and whether the trace's runaway undoes the convergence
  (docs/bit_speed.md).

No model runs here — every rule can be tested on its own (tests/test_verdict.py).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np

from drillfric.estimation.batch.settings import MU_K_CLAIM
from drillfric.estimation.bit_trace import (
    KinematicCheck,
    WindowVerdict,
    bit_speed_claim,
    drift_note,
)
from drillfric.estimation.sampling import Resolution
from drillfric.result import Flag
from drillfric.vocabulary import Method

#: Batch flags under which a stick-slip-onset bound on μ_s is not reported (docs/theory.md
#: §6.4: a bound above the truth is a false claim; prefer none).
UNRELIABLE_BOUND = frozenset({Flag.REGIME_MISMATCH, Flag.BISTABLE_REGIME,
                              Flag.STICK_SLIP_NOT_REPRODUCED, Flag.RELAXATION_CYCLES})
#: Batch flags under which a batch μ_k is not converged (docs/batch_refinement.md).
NOT_CONVERGED = frozenset({Flag.MU_K_NOT_CONVERGED, Flag.RELAXATION_CYCLES,
                           Flag.MU_K_DEPENDS_ON_MU_S})
#: Friction factors usually seen with steel in mud-filled hole; outside, a segment is flagged
#: ``outside_typical_range`` (check string, survey, torque units) but not changed.
TYPICAL_MU = (0.05, 0.8)
#: Ratio between batch and observer μ_k (either way) beyond which a segment is not
#: converged (on synthetic truths the observer consensus is within ~25 %: docs/validation.md).
DISAGREEMENT = 1.5
#: Rotation a segment needs to count as converged [s]: the fit leaves out each run's start-up
#: (~10 s) and its mean torque needs about a minute of stick-slip cycles; shorter pieces
#: count through pooling (docs/batch_refinement.md).
MIN_CONVERGED_ROTATION_S = 90.0


@dataclass(frozen=True)
class Evidence:
    """What the estimators found for one segment.

    Attributes
    ----------
    batch_mu_k : float or None
        μ_k of the speed-driven fit [-] (None: the fit gave none).
    batch_flags : tuple of Flag
    batch_messages : tuple of str
    mu_s_lower_bound : float or None
        The fit's stick-slip-onset bound on μ_s [-].
    mu_s_model : float or None
        μ_s the fit's model used for μ_k (its regime value) [-].
    mu_s : float or None
        μ_s identified by a creep fit [-].
    observer_mu_k : float
        Observer consensus μ_k of the starts pass [-].
    observer_converged : bool
    observer_flags : tuple of Flag
    turning_s : float
        Time the top drive turns faster than ω_c [s].
    on_bottom : bool
    batch_mu_k_sigma : float or None
        Statistical 1-σ uncertainty of the batch μ_k [-] (None: not known).
    axial_speed_m_s : float
        The pipe's axial speed while it turns [m/s] (+ reaming, − back-reaming; 0: in
        place).
    """

    batch_mu_k: float | None
    batch_flags: tuple
    batch_messages: tuple
    mu_s_lower_bound: float | None
    mu_s_model: float | None
    mu_s: float | None
    observer_mu_k: float
    observer_converged: bool
    observer_flags: tuple
    turning_s: float
    on_bottom: bool
    batch_mu_k_sigma: float | None = None
    axial_speed_m_s: float = 0.0


@dataclass(frozen=True)
class Verdict:
    """The numbers a segment reports and the words beside them.

    Attributes
    ----------
    mu_k : float
        Reported kinetic friction factor [-].
    method : Method
    converged : bool
    mu_s_lower_bound : float or None
        Shown bound on μ_s [-] (withheld where unreliable).
    mu_s_seed : float
        μ_s for the seeded observer pass: identified, else the fit's regime value, else the
        bound, else μ_k [-].
    adapt_final : bool
        Whether the seeded pass keeps adapting μ̂ (only when the fit gave no μ_k).
    flags : tuple of Flag
    messages : tuple of str
    """

    mu_k: float
    method: Method
    converged: bool
    mu_s_lower_bound: float | None
    mu_s_seed: float
    adapt_final: bool
    flags: tuple
    messages: tuple


def decide(ev: Evidence) -> Verdict:
    """Apply the rules to one segment's :class:`Evidence`.

    1. μ_k is the batch fit's when it has one (``batch``), else the observer consensus
       (``observer``, converged only if the observer says so and the segment turned at
       least :data:`MIN_CONVERGED_ROTATION_S`);
    2. a batch μ_k is not converged when the fit flags ``mu_k_not_converged`` or
       ``relaxation_cycles`` (:data:`NOT_CONVERGED`), when batch and
       observer differ by more than :data:`DISAGREEMENT`, with less than
       :data:`MIN_CONVERGED_ROTATION_S` of rotation, or when its 2σ statistical uncertainty
       exceeds :data:`~drillfric.estimation.batch.settings.MU_K_CLAIM` of it
       (``mu_k_uncertain``);
    3. a μ_s lower bound is withheld on bottom (the bit drives the swings) and under the
       flags of :data:`UNRELIABLE_BOUND`;
    4. μ_k outside :data:`TYPICAL_MU` is flagged (not changed);
    5. on bottom the friction is apparent (bit torque included);
    6. while the pipe moves axially (reaming, back-reaming: :func:`_pipe_moving`) μ_s is not
       identifiable — no μ_s, no bound — and the observer's μ_k, from a model with no axial
       motion, is left out of rule 2's agreement.

    Examples
    --------
    >>> ev = Evidence(0.2, (), (), 0.3, 0.5, None, 0.21, True, (), 120.0, False)
    >>> v = decide(ev)
    >>> (v.mu_k, v.method.value, v.converged, v.mu_s_lower_bound, v.mu_s_seed)
    (0.2, 'batch', True, 0.3, 0.5)
    """
    flags = list(ev.observer_flags) + list(ev.batch_flags)
    messages = list(ev.batch_messages)
    bound = _shown_bound(ev, messages)
    if ev.axial_speed_m_s != 0.0:
        bound = _pipe_moving(ev, flags, messages)
    if ev.batch_mu_k is not None:
        mu_k, method = ev.batch_mu_k, Method.BATCH
        converged = _batch_converged(ev, flags, messages)
    else:
        mu_k, method, converged = ev.observer_mu_k, Method.OBSERVER, ev.observer_converged
        messages.append("batch refinement gave no μ_k: the observer's consensus stands in "
                        "for it where it converged")
        converged = _long_enough(ev, flags, messages) and converged
    if not TYPICAL_MU[0] <= mu_k <= TYPICAL_MU[1]:
        flags.append(Flag.OUTSIDE_TYPICAL_RANGE)
        messages.append(f"μ_k = {mu_k:.3f} is outside the range usually seen ({TYPICAL_MU[0]}–"
                        f"{TYPICAL_MU[1]}): check the string, the survey and the torque units")
    if ev.on_bottom:
        flags.append(Flag.BIT_TORQUE_IN_FRICTION)
        messages.append("on bottom: the bit torque is not separated, friction is apparent")
    seed = next((float(v) for v in (ev.mu_s, ev.mu_s_model, ev.mu_s_lower_bound)
                 if v is not None), mu_k)
    return Verdict(mu_k=float(mu_k), method=method, converged=bool(converged),
                   mu_s_lower_bound=bound, mu_s_seed=max(seed, mu_k),
                   adapt_final=method is Method.OBSERVER, flags=tuple(dict.fromkeys(flags)),
                   messages=tuple(messages))


#: The fit's note of its onset bound (batch/onset.py), left out where the bound is withheld:
#: "μ_s ≥ 0.62 from the stick-slip onset" beside "μ_s lower bound withheld on bottom" said
#: both (issue 35 item 6).
_BOUND_NOTE = re.compile(r";?\s*μ_s ≥ [\d.]+ from the stick-slip onset(?: \([^)]*\))?")


def _shown_bound(ev: Evidence, messages: list) -> float | None:
    """The onset bound shown, or None with why in ``messages`` (the fit's note of the bound
    then left out of them)."""
    bound = _bound_or_why(ev, messages)
    if bound is None and ev.mu_s_lower_bound is not None:
        messages[:] = [_BOUND_NOTE.sub("", m) for m in messages]
    return bound


def _bound_or_why(ev: Evidence, messages: list) -> float | None:
    if ev.mu_s_lower_bound is None:
        return None
    if ev.on_bottom:
        messages.append("μ_s lower bound withheld on bottom: the bit drives the torque swings")
        return None
    if Flag.RELAXATION_CYCLES in ev.batch_flags:
        messages.append("μ_s lower bound withheld: relaxation cycles (the μ_k the onset scan "
                        "rests on is not converged)")
        return None
    if UNRELIABLE_BOUND.intersection(ev.batch_flags):
        messages.append("μ_s lower bound withheld: the model does not reproduce the data's "
                        "stick-slip regime")
        return None
    return ev.mu_s_lower_bound


def _pipe_moving(ev: Evidence, flags: list, messages: list) -> None:
    """The rule of a segment whose pipe moves axially as it turns: μ_s is not identifiable
    (no bound either, returned as None) and the observer's μ_k is not compared
    (docs/theory.md §3.3: with |v| > ω_c·r_c no cell sticks in torsion, and the observer
    models pure rotation).

    >>> ev = Evidence(0.25, (), (), None, 0.6, None, 0.2, True, (), 120.0, False,
    ...               axial_speed_m_s=-0.3)
    >>> decide(ev).flags, decide(ev).mu_s_lower_bound, decide(ev).converged
    ((<Flag.PIPE_MOVING: 'pipe_moving'>,), None, True)
    """
    flags.append(Flag.PIPE_MOVING)
    messages[:] = [_BOUND_NOTE.sub("", m) for m in messages]
    way = "running in" if ev.axial_speed_m_s > 0 else "pulling out"
    messages.append(f"μ_s not identifiable: the pipe moves axially ({way} at "
                    f"{abs(ev.axial_speed_m_s):.2g} m/s; once |v| > ω_c·r_c no point of the "
                    "string sticks in torsion, docs/theory.md §3.3): no creep fit, no "
                    "stick-slip onset bound")
    messages.append(f"the observer's μ_k ({ev.observer_mu_k:.3f}) is left out: the observer "
                    "has no axial model, its torque takes all the friction as tangential")
    return None


def _batch_converged(ev: Evidence, flags: list, messages: list) -> bool:
    converged = not NOT_CONVERGED.intersection(ev.batch_flags)
    apart = abs(np.log(ev.batch_mu_k / max(ev.observer_mu_k, 1e-6))) > np.log(DISAGREEMENT)
    if apart and ev.axial_speed_m_s == 0.0:  # the observer has no axial model
        converged = False
        flags.append(Flag.ESTIMATORS_DISAGREE)
        messages.append(f"batch μ_k = {ev.batch_mu_k:.3f} and observer μ_k = "
                        f"{ev.observer_mu_k:.3f} disagree: not converged")
    if ev.batch_mu_k_sigma is not None and 2.0 * ev.batch_mu_k_sigma > MU_K_CLAIM * ev.batch_mu_k:
        converged = False
        flags.append(Flag.MU_K_UNCERTAIN)
        messages.append(f"μ_k = {ev.batch_mu_k:.3f} ± {2.0 * ev.batch_mu_k_sigma:.3f} (2σ) is "
                        f"not known within {100 * MU_K_CLAIM:.0f} %: not converged (a longer "
                        "record of the same rotation narrows it as 1/√time)")
    return _long_enough(ev, flags, messages) and converged


def _long_enough(ev: Evidence, flags: list, messages: list) -> bool:
    """The rotation rule of either estimator's μ_k: :data:`MIN_CONVERGED_ROTATION_S` of
    turning, else not converged (shorter pieces count through pooling)."""
    if ev.turning_s >= MIN_CONVERGED_ROTATION_S:
        return True
    flags.append(Flag.TOO_SHORT_TO_CONVERGE)
    messages.append(f"only {ev.turning_s:.0f} s of rotation (< "
                    f"{MIN_CONVERGED_ROTATION_S:.0f} s): not converged")
    return False


def withheld_factors(method: Method, converged: bool, flags: tuple) -> str:
    """Why a segment's friction factors are not shown at all ("" when they are): its μ_k is
    not a fit that merely failed a convergence test but has nothing under it.

    1. the batch fit gave no μ_k and the observer's consensus did not converge (its starts
       disagree, or too little rotation): on the lumped plant such values were +40 % to
       +80 % off at 6000 m (docs/validation.md "Calibrated intervals");
    2. the observer seeded with the fitted factors runs the bit away from the top drive
       (``factors_run_away``): the factors do not describe the record (one was −20 % off).

    Any other μ_k not converged is shown as such, with no interval (its fit stands, e.g.
    the batch μ_k where the observer disagrees with it).

    Examples
    --------
    >>> withheld_factors(Method.BATCH, True, ())
    ''
    >>> withheld_factors(Method.OBSERVER, False, ())[:40]
    'the batch fit gave no μ_k and the observ'
    """
    if method is Method.OBSERVER and not converged:
        return ("the batch fit gave no μ_k and the observer's consensus did not converge "
                "(its starts disagree or the rotation is too short): such a consensus was "
                "off by up to +80 % on a plant it was not built around")
    if Flag.FACTORS_RUN_AWAY in flags:
        return ("the observer seeded with the fitted factors runs the bit away from the top "
                "drive: the factors do not describe this record")
    return ""


@dataclass(frozen=True)
class TraceEvidence:
    """What the checks of a segment's seeded bit trace found (docs/bit_speed.md).

    Attributes
    ----------
    logging : Resolution
        Whether the logging resolves the stick-slip cycle.
    on_bottom : bool
    check : KinematicCheck
        The whole trace's kinematic check.
    windows : WindowVerdict
        The window-by-window check.
    converged : bool
        The segment's friction factors converged (:func:`decide`).
    runaway_note : str or None
        Why the seeded trace runs away from the top drive (None: it does not).
    severe_note : str or None
        Why the stick-slip is beyond the validated range of its statistics (None: within).
    undetermined_note : str or None
        Why the statistics are undetermined: members that disagree, a grazing bit, or
        windows the trace withholds (None: determined).
    moving : bool
        The pipe moves axially as it turns (reaming, back-reaming).
    skew_note : str or None
        Why the torque's lag behind the speed is not known (None: configured or identified,
        :mod:`drillfric.estimation.skew`).
    inertia_note : str or None
        Why the trace may not rest on the configured top-drive inertia (None: it may,
        :mod:`drillfric.estimation.inertia`).
    inertia_contradicted : bool
        The data identify an inertia the configured one is beyond ±25 % of (flagged
        ``top_drive_inertia_contradicted``, else ``top_drive_inertia_unconfirmed``).
    """

    logging: Resolution
    on_bottom: bool
    check: KinematicCheck
    windows: WindowVerdict
    converged: bool
    runaway_note: str | None = None
    severe_note: str | None = None
    undetermined_note: str | None = None
    moving: bool = False
    skew_note: str | None = None
    inertia_note: str | None = None
    inertia_contradicted: bool = False


#: Why the bit speed of a reaming / back-reaming segment is withheld.
NO_AXIAL_OBSERVER = ("bit speed withheld: the pipe moves axially and the observer has no "
                     "axial model (its friction is all tangential, docs/theory.md §3.3); "
                     "the stuck fraction and severity with it")


@dataclass(frozen=True)
class TraceVerdict:
    """What of the bit speed a segment shows.

    Attributes
    ----------
    bit_speed : Resolution
        ``resolved`` (the trace is shown) or the reason it is withheld.
    windows_withheld : tuple of (float, float)
        [t_from_s, t_to_s) of the 30-s windows withheld in a shown trace [s].
    statistics : bool
        Whether the stuck fraction and the stick-slip severity are shown.
    converged : bool
        The segment's convergence after the trace's verdict.
    flags : tuple of Flag
        Flags to add to the segment's.
    messages : tuple of str
        Messages to add, in the order of the flags.
    """

    bit_speed: Resolution
    windows_withheld: tuple
    statistics: bool
    converged: bool
    flags: tuple
    messages: tuple


def decide_trace(ev: TraceEvidence) -> TraceVerdict:
    """Apply the bit-speed and stick-slip rules to one segment's :class:`TraceEvidence`.

    1. The trace is shown where the logging resolves the cycle, off bottom, and the
       kinematic check passes (:func:`~drillfric.estimation.bit_trace.bit_speed_claim`),
       and not when more than half its 30-s windows are withheld;
    2. a shown trace whose check passed only approximately is flagged ``bit_speed_drift``;
    3. a converged segment whose seeded trace runs away is not converged
       (``factors_run_away``);
    4. the stuck fraction and severity are shown only where the logging resolves the
       cycle off bottom, withheld as ``stick_slip_beyond_validated`` in severe stick-slip,
       else as ``stick_slip_undetermined`` where undetermined;
    5. a shown trace with withheld windows says which;
    6. while the pipe moves axially nothing of the trace is shown
       (:data:`NO_AXIAL_OBSERVER`);
    7. where the torque's lag behind the speed is neither configured nor identified, the
       trace and its statistics are withheld (``channel_skew_unidentified``): the trace's
       phase rests on the channels' timing, which the data could not fix;
    8. where the top-drive inertia correction of a motor torque is material and the data do
       not identify the inertia, or identify one beyond ±25 % of the configured, the trace
       and its statistics are withheld (``top_drive_inertia_unconfirmed`` /
       ``top_drive_inertia_contradicted``, :mod:`drillfric.estimation.inertia`).

    Examples
    --------
    >>> from drillfric.estimation.bit_trace import KinematicCheck, WindowVerdict
    >>> check = KinematicCheck(True, 1.0, 5.0, 0.0, 30.0, 0.0)
    >>> v = decide_trace(TraceEvidence(Resolution(True, 40.0), False, check,
    ...                                WindowVerdict(10), True))
    >>> (v.bit_speed.resolved, v.statistics, v.converged, v.flags)
    (True, True, True, ())
    """
    claim = bit_speed_claim(ev.logging, ev.check, ev.on_bottom)
    if ev.moving:
        claim = replace(claim, resolved=False, reason=NO_AXIAL_OBSERVER)
    if claim.resolved and ev.windows.too_many:
        claim = replace(claim, resolved=False, reason=(
            f"bit speed withheld: {len(ev.windows.withheld)} of its {ev.windows.windows} "
            f"30-s windows fail: {ev.windows.reason}"))
    flags, messages = [], []
    logged = ev.logging.resolved and not ev.on_bottom and not ev.moving
    if ev.skew_note and (claim.resolved or logged):
        flags.append(Flag.CHANNEL_SKEW_UNIDENTIFIED)
        messages.append(f"bit speed, stuck fraction and severity withheld: {ev.skew_note}")
        claim = replace(claim, resolved=False, reason=f"bit speed withheld: {ev.skew_note}")
        logged = False
    if ev.inertia_note and (claim.resolved or logged):
        flags.append(Flag.TOP_DRIVE_INERTIA_CONTRADICTED if ev.inertia_contradicted
                     else Flag.TOP_DRIVE_INERTIA_UNCONFIRMED)
        messages.append(f"bit speed, stuck fraction and severity withheld: {ev.inertia_note}")
        claim = replace(claim, resolved=False, reason=f"bit speed withheld: {ev.inertia_note}")
        logged = False
    runaway = ev.converged and ev.runaway_note is not None
    if runaway:
        flags.append(Flag.FACTORS_RUN_AWAY)
        messages.append(ev.runaway_note)
    if claim.resolved and ev.check.approximate:
        flags.append(Flag.BIT_SPEED_DRIFT)
        messages.append(drift_note(ev.check))
    if logged and ev.severe_note:
        flags.append(Flag.STICK_SLIP_BEYOND_VALIDATED)
        messages.append(ev.severe_note)
    elif logged and ev.undetermined_note:
        flags.append(Flag.STICK_SLIP_UNDETERMINED)
        messages.append(ev.undetermined_note)
    if claim.resolved and ev.windows.withheld:
        messages.append(windows_note(ev.windows))
    return TraceVerdict(
        bit_speed=claim, windows_withheld=ev.windows.withheld if claim.resolved else (),
        statistics=logged and not ev.severe_note and not ev.undetermined_note,
        converged=ev.converged and not runaway, flags=tuple(flags), messages=tuple(messages))


def windows_note(windows: WindowVerdict) -> str:
    """The message of a trace shown with some windows withheld."""
    spans = ", ".join(f"{a:.0f}–{b:.0f} s" for a, b in windows.withheld[:6])
    more = f" and {len(windows.withheld) - 6} more" if len(windows.withheld) > 6 else ""
    return (f"bit speed withheld over {len(windows.withheld)} of {windows.windows} 30-s "
            f"windows ({spans}{more}; null rows in estimates.parquet): {windows.reason}")
