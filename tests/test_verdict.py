"""What a segment may claim: :func:`drillfric.estimation.verdict.decide` and
:func:`~drillfric.estimation.verdict.decide_trace`, rule by rule.

A pure function, so every branch is a row of a table: the evidence changed from a plain
converged stick-slip segment, what the verdict must then say, and why (the rules are in
drillfric/estimation/verdict.py and docs/batch_refinement.md).
"""

from __future__ import annotations

from dataclasses import replace

import pytest

from drillfric.estimation.bit_trace import KinematicCheck, WindowVerdict
from drillfric.estimation.sampling import Resolution
from drillfric.estimation.verdict import (
    DISAGREEMENT,
    MIN_CONVERGED_ROTATION_S,
    TYPICAL_MU,
    Evidence,
    TraceEvidence,
    decide,
    decide_trace,
)
from drillfric.result import Flag
from drillfric.vocabulary import Method

#: Off bottom, batch μ_k 0.2 agreeing with the observer's 0.21, 120 s of rotation, a bound
#: 0.3, the model's regime μ_s 0.5, no creep μ_s.
PLAIN = Evidence(batch_mu_k=0.2, batch_flags=(), batch_messages=("fit note",),
                 mu_s_lower_bound=0.3, mu_s_model=0.5, mu_s=None, observer_mu_k=0.21,
                 observer_converged=True, observer_flags=(), turning_s=120.0,
                 on_bottom=False)

CASES = [
    ("plain", {}, dict(mu_k=0.2, method=Method.BATCH, converged=True, bound=0.3, seed=0.5,
                       adapt=False, flags=()),
     "batch μ_k reported, converged, bound shown, seeded with the model's regime μ_s"),
    ("batch_not_converged", dict(batch_flags=(Flag.MU_K_NOT_CONVERGED,)),
     dict(converged=False, flags=(Flag.MU_K_NOT_CONVERGED,)),
     "the fit's own flag makes the μ_k not converged (the number stays)"),
    ("estimators_disagree", dict(observer_mu_k=0.2 * DISAGREEMENT * 1.01),
     dict(mu_k=0.2, converged=False, flags=(Flag.ESTIMATORS_DISAGREE,)),
     "batch and observer differ by more than the factor DISAGREEMENT"),
    ("estimators_disagree_other_way", dict(observer_mu_k=0.2 / (DISAGREEMENT * 1.01)),
     dict(converged=False, flags=(Flag.ESTIMATORS_DISAGREE,)),
     "the ratio counts either way"),
    ("estimators_just_agree", dict(observer_mu_k=0.2 * DISAGREEMENT * 0.99),
     dict(converged=True, flags=()),
     "inside the factor: still converged"),
    ("too_short", dict(turning_s=MIN_CONVERGED_ROTATION_S - 1.0),
     dict(converged=False, flags=(Flag.TOO_SHORT_TO_CONVERGE,)),
     "less rotation than a mean torque needs"),
    ("no_batch_mu_k", dict(batch_mu_k=None, observer_converged=False),
     dict(mu_k=0.21, method=Method.OBSERVER, converged=False, adapt=True),
     "without a fit the observer consensus is reported, converged only as the observer "
     "says, and the seeded pass keeps adapting"),
    ("no_batch_mu_k_observer_converged", dict(batch_mu_k=None),
     dict(mu_k=0.21, method=Method.OBSERVER, converged=True, flags=()),
     "without a fit the observer's own convergence stands on a long rotation"),
    ("no_batch_mu_k_observer_converged_too_short", dict(batch_mu_k=None, turning_s=20.0),
     dict(mu_k=0.21, method=Method.OBSERVER, converged=False,
          flags=(Flag.TOO_SHORT_TO_CONVERGE,)),
     "regression (docs/validation.md 'Drilling records', 20-s rotations at 1-s means): the "
     "observer's convergence was let stand on 20 s of rotation; the rotation rule is now "
     "either estimator's"),
    ("low_mu_k", dict(batch_mu_k=0.04, observer_mu_k=0.04, mu_s_model=None,
                      mu_s_lower_bound=None),
     dict(mu_k=0.04, flags=(Flag.OUTSIDE_TYPICAL_RANGE,), seed=0.04, bound=None),
     "below TYPICAL_MU: flagged, not changed; with nothing else the seed is μ_k"),
    ("high_mu_k", dict(batch_mu_k=0.85, observer_mu_k=0.85),
     dict(mu_k=0.85, flags=(Flag.OUTSIDE_TYPICAL_RANGE,), seed=0.85),
     "above TYPICAL_MU: flagged; a seed below μ_k is raised to μ_k"),
    ("on_bottom", dict(on_bottom=True),
     dict(bound=None, flags=(Flag.BIT_TORQUE_IN_FRICTION,), seed=0.5),
     "on bottom the bit drives the swings: no bound, friction apparent"),
    ("regime_mismatch", dict(batch_flags=(Flag.REGIME_MISMATCH,)),
     dict(bound=None, converged=True, flags=(Flag.REGIME_MISMATCH,)),
     "a model not in the data's regime gives no trustworthy bound"),
    ("bistable", dict(batch_flags=(Flag.BISTABLE_REGIME,)),
     dict(bound=None, flags=(Flag.BISTABLE_REGIME,)), "bistable onset: no bound"),
    ("not_reproduced", dict(batch_flags=(Flag.STICK_SLIP_NOT_REPRODUCED,)),
     dict(bound=None, flags=(Flag.STICK_SLIP_NOT_REPRODUCED,)),
     "the model never stick-slips: no bound"),
    ("other_batch_flag_keeps_bound", dict(batch_flags=(Flag.CREEP_RATE_TOO_LOW,)),
     dict(bound=0.3, converged=True, flags=(Flag.CREEP_RATE_TOO_LOW,)),
     "a flag outside UNRELIABLE_BOUND neither hides the bound nor the convergence"),
    ("creep_mu_s_seeds", dict(mu_s=0.55), dict(seed=0.55),
     "an identified μ_s seeds the final pass before the model's regime value"),
    ("bound_seeds_without_model", dict(mu_s_model=None), dict(seed=0.3),
     "without a regime value the bound seeds"),
    ("pipe_moving", dict(axial_speed_m_s=0.2),
     dict(mu_k=0.2, converged=True, bound=None, seed=0.5, flags=(Flag.PIPE_MOVING,)),
     "issue 36 item 2: while the pipe moves axially no point sticks in torsion once |v| > "
     "ω_c·r_c: μ_s is not identifiable, no onset bound; the batch μ_k stands"),
    ("pipe_moving_observer_left_out",
     dict(axial_speed_m_s=-0.3, observer_mu_k=0.2 * DISAGREEMENT * 1.5),
     dict(converged=True, flags=(Flag.PIPE_MOVING,)),
     "the observer has no axial model (all its friction tangential): its μ_k is left out "
     "of the agreement, not a disagreement"),
    ("pipe_moving_still_needs_rotation",
     dict(axial_speed_m_s=0.5, turning_s=MIN_CONVERGED_ROTATION_S - 1.0),
     dict(converged=False, bound=None, flags=(Flag.PIPE_MOVING, Flag.TOO_SHORT_TO_CONVERGE)),
     "the other rules of the batch μ_k still hold while the pipe moves"),
    ("pipe_moving_uncertain",
     dict(axial_speed_m_s=0.5, batch_mu_k_sigma=0.2),
     dict(converged=False, flags=(Flag.PIPE_MOVING, Flag.MU_K_UNCERTAIN)),
     "…and its statistical uncertainty"),
    ("flags_ordered_and_unique",
     dict(observer_flags=(Flag.OBSERVER_STARTS_DISAGREE,),
          batch_flags=(Flag.MU_K_NOT_CONVERGED, Flag.MU_K_NOT_CONVERGED)),
     dict(flags=(Flag.OBSERVER_STARTS_DISAGREE, Flag.MU_K_NOT_CONVERGED)),
     "observer flags first, then the fit's; each once"),
]


@pytest.mark.parametrize("change, expected, why", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_decide(change, expected, why):
    v = decide(replace(PLAIN, **change))
    got = dict(mu_k=v.mu_k, method=v.method, converged=v.converged,
               bound=v.mu_s_lower_bound, seed=v.mu_s_seed, adapt=v.adapt_final,
               flags=v.flags)
    assert {k: got[k] for k in expected} == expected, why


def test_every_flag_and_withheld_number_is_explained():
    """Each rule that flags or withholds adds its line; the fit's messages come first."""
    v = decide(replace(PLAIN, on_bottom=True, turning_s=10.0, observer_mu_k=0.5,
                       batch_mu_k=0.9))
    text = " | ".join(v.messages)
    assert v.messages[0] == "fit note"
    for words in ("withheld on bottom", "disagree", "of rotation", "outside the range",
                  "bit torque is not separated"):
        assert words in text, words
    assert TYPICAL_MU[1] < 0.9


def test_soft_drive_5hz_segment_off_5pc_states_its_uncertainty_and_is_not_claimed():
    """Regression (issue 22 item 5, benchmarks/validate_soft_drive.py, k_p = ζ,
    k_i = 2500 N·m/rad at 5 Hz): one 90-s segment claimed μ_k = 0.237, 5.1 % below the
    truth, converged. Its 18 whole torque cycles know the mean torque only to ±344 N·m (1σ),
    so μ_k to ±0.017 (2σ, 7 %): the error is within its own uncertainty, which is now stated,
    and a μ_k not known within 5 % is not claimed. The same rotation with twice the cycles'
    precision is."""
    base = Evidence(0.237, (), (), None, 0.6, None, 0.24, True, (), 150.0, False)
    loose = decide(replace(base, batch_mu_k_sigma=0.0085))
    assert not loose.converged and Flag.MU_K_UNCERTAIN in loose.flags
    assert any("0.237 ± 0.017 (2σ)" in m for m in loose.messages)
    tight = decide(replace(base, batch_mu_k_sigma=0.004))
    assert tight.converged and Flag.MU_K_UNCERTAIN not in tight.flags


# ------------------------------------------------------------------ the bit trace's rules
#: Off bottom, logged at a rate that resolves the cycle, the trace keeping to its top drive
#: in every one of 10 windows, converged factors, nothing severe or undetermined.
RESOLVED = Resolution(True, 40.0)
PASSED = KinematicCheck(True, 5.0, 20.0, 0.0, 30.0, 0.1, 20.0)
#: Failed, but by a mean lag under a third of the trace's swing: phase approximate.
DRIFTING = KinematicCheck(False, 60.0, 20.0, 0.0, 30.0, 3.0, 40.0)
FAILED = KinematicCheck(False, 400.0, 20.0, 0.0, 30.0, 30.0, 40.0)
PLAIN_TRACE = TraceEvidence(logging=RESOLVED, on_bottom=False, check=PASSED,
                            windows=WindowVerdict(10), converged=True)
SOME = WindowVerdict(10, ((0.0, 30.0), (30.0, 60.0)), "creep")
MOST = WindowVerdict(10, tuple((30.0 * k, 30.0 * k + 30.0) for k in range(6)), "creep")

TRACE_CASES = [
    ("plain", {}, dict(shown=True, windows=(), statistics=True, converged=True, flags=()),
     "a resolved trace that keeps to its top drive is shown with its statistics"),
    ("not_resolved", dict(logging=Resolution(False, 2.0, "1 Hz")),
     dict(shown=False, statistics=False, flags=()),
     "a log that cannot resolve the cycle shows neither trace nor statistics"),
    ("on_bottom", dict(on_bottom=True), dict(shown=False, statistics=False, flags=()),
     "on bottom the model has no bit–rock torque: trace and statistics withheld"),
    ("check_failed", dict(check=FAILED), dict(shown=False, statistics=True, flags=()),
     "a trace running away from its top drive is withheld; statistics stand apart"),
    ("check_approximate", dict(check=DRIFTING),
     dict(shown=True, flags=(Flag.BIT_SPEED_DRIFT,)),
     "a lag under a third of the swing: shown with its phase approximate"),
    ("some_windows", dict(windows=SOME), dict(shown=True, windows=SOME.withheld, flags=()),
     "a few windows withheld: the trace is shown with those rows null"),
    ("most_windows", dict(windows=MOST), dict(shown=False, windows=(), flags=()),
     "more than half the windows withheld: the whole trace is"),
    ("runaway", dict(runaway_note="runs away"),
     dict(converged=False, flags=(Flag.FACTORS_RUN_AWAY,)),
     "regression (lumped plant, 10 Hz: μ_k 0.125 for 0.157 shown converged): the seeded "
     "trace runs away, so the factors do not describe the record"),
    ("runaway_unconverged", dict(runaway_note="runs away", converged=False),
     dict(converged=False, flags=()), "an unconverged segment is not flagged again"),
    ("severe", dict(severe_note="severe"),
     dict(statistics=False, flags=(Flag.STICK_SLIP_BEYOND_VALIDATED,)),
     "severe stick-slip: statistics withheld as beyond the validated range"),
    ("undetermined", dict(undetermined_note="members disagree"),
     dict(statistics=False, flags=(Flag.STICK_SLIP_UNDETERMINED,)),
     "members that disagree: statistics withheld as undetermined"),
    ("severe_before_undetermined", dict(severe_note="severe", undetermined_note="why"),
     dict(statistics=False, flags=(Flag.STICK_SLIP_BEYOND_VALIDATED,)),
     "one reason is enough: severe is said, not both"),
    ("undetermined_unlogged", dict(undetermined_note="why", logging=Resolution(False, 2.0)),
     dict(statistics=False, flags=()),
     "statistics a log cannot resolve are not flagged as undetermined"),
    ("pipe_moving", dict(moving=True, undetermined_note="why"),
     dict(shown=False, statistics=False, converged=True, flags=()),
     "issue 36 item 2: the observer has no axial model, so neither the trace of a reaming "
     "segment nor its statistics are shown (not validated); the factors stand"),
    ("channel_skew_unidentified", dict(skew_note="channel skew not identified: rivals",
                                       check=DRIFTING, severe_note="severe"),
     dict(shown=False, windows=(), statistics=False, converged=True,
          flags=(Flag.CHANNEL_SKEW_UNIDENTIFIED,)),
     "issue 34 item 1: the trace's phase rests on the channels' timing; a lag the data "
     "cannot fix withholds the trace and its statistics (one flag says why), the factors "
     "stand"),
    ("channel_skew_unresolved", dict(skew_note="why", logging=Resolution(False, 2.0)),
     dict(shown=False, statistics=False, flags=()),
     "a trace the logging cannot resolve is not flagged for its skew as well"),
    ("top_drive_inertia_unconfirmed", dict(inertia_note="top-drive inertia not identified"),
     dict(shown=False, windows=(), statistics=False, converged=True,
          flags=(Flag.TOP_DRIVE_INERTIA_UNCONFIRMED,)),
     "issue 34 item 2: a gear change (true inertia 2.5x the configured) put 5-6 of 7 30-s "
     "windows off on a soft drive: where the inertia correction is material and the data "
     "do not confirm the inertia, the trace and its statistics are withheld"),
    ("top_drive_inertia_contradicted",
     dict(inertia_note="contradicted", inertia_contradicted=True),
     dict(shown=False, statistics=False, flags=(Flag.TOP_DRIVE_INERTIA_CONTRADICTED,)),
     "an inertia the data identify beyond ±25 % of the configured withholds the trace"),
    ("top_drive_inertia_after_skew", dict(skew_note="why", inertia_note="why"),
     dict(shown=False, statistics=False, flags=(Flag.CHANNEL_SKEW_UNIDENTIFIED,)),
     "one reason is enough: the skew is said, the inertia not again"),
]


@pytest.mark.parametrize("change, expected, why", [c[1:] for c in TRACE_CASES],
                         ids=[c[0] for c in TRACE_CASES])
def test_decide_trace(change, expected, why):
    v = decide_trace(replace(PLAIN_TRACE, **change))
    got = dict(shown=v.bit_speed.resolved, windows=v.windows_withheld,
               statistics=v.statistics, converged=v.converged, flags=v.flags)
    assert {k: got[k] for k in expected} == expected, why


def test_every_trace_flag_and_withheld_window_is_explained():
    """Each trace rule that flags or withholds adds its line, in the order of its flag."""
    v = decide_trace(replace(PLAIN_TRACE, check=DRIFTING, windows=SOME,
                             runaway_note="runs away", undetermined_note="members disagree"))
    assert v.flags == (Flag.FACTORS_RUN_AWAY, Flag.BIT_SPEED_DRIFT,
                       Flag.STICK_SLIP_UNDETERMINED)
    assert v.messages[0] == "runs away" and "phase approximate" in v.messages[1]
    assert v.messages[2] == "members disagree"
    assert "withheld over 2 of 10 30-s windows" in v.messages[3]
    withheld = decide_trace(replace(PLAIN_TRACE, windows=MOST))
    assert "6 of its 10 30-s windows fail: creep" in withheld.bit_speed.reason
    moving = decide_trace(replace(PLAIN_TRACE, moving=True))
    assert "no axial model" in moving.bit_speed.reason


def test_a_moving_pipe_says_why_mu_s_and_the_observer_are_left_out():
    """The rule of issue 36 item 2 in words: μ_s not identifiable, the observer's μ_k left
    out; the fit's note of an onset bound it would otherwise have stated is not kept."""
    v = decide(replace(PLAIN, axial_speed_m_s=-0.3, batch_messages=(
        "fit note; μ_s ≥ 0.30 from the stick-slip onset",)))
    text = " | ".join(v.messages)
    assert "μ_s not identifiable: the pipe moves axially (pulling out at 0.3 m/s" in text
    assert "observer has no axial model" in text
    assert v.mu_s_lower_bound is None and "onset" not in v.messages[0]


def test_a_withheld_bound_is_not_stated_in_the_fits_note():
    """Issue 35 item 6 (DSATS segment 64): the notes said both "μ_s ≥ 0.62 from the
    stick-slip onset" and "μ_s lower bound withheld on bottom". Withheld, the bound is no
    longer stated; the rest of the fit's note stays. Shown, it is."""
    note = ("μ_s not identifiable (stick-slip, no creep); μ_s ≥ 0.31 from the stick-slip "
            "onset")
    ev = replace(PLAIN, batch_messages=(note,), mu_s_lower_bound=0.31)
    shown = decide(ev)
    assert shown.mu_s_lower_bound == 0.31 and note in shown.messages
    withheld = decide(replace(ev, on_bottom=True))
    assert withheld.mu_s_lower_bound is None
    assert "μ_s not identifiable (stick-slip, no creep)" in withheld.messages
    assert not any("≥ 0.31" in m for m in withheld.messages)
    assert any("withheld on bottom" in m for m in withheld.messages)
