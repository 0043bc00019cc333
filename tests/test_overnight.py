"""What changed since the last night (issue 23 §3): the headlines of a fleet's morning."""

from __future__ import annotations

from drillfric.fleet.overnight import changes, night


def _summary(mu_k, severities):
    return {"mu_k": mu_k, "segments": [{"id": i + 1, "stick_slip_severity": s}
                                       for i, s in enumerate(severities)]}


def test_new_segments_and_severe_stick_slip_in_them_only():
    history = [night(_summary(0.25, [1.5, 0.2]), "d1")]
    out = changes(_summary(0.25, [1.5, 0.2, 0.4, 1.3]), history, ran=True,
                  data_changed_utc=None)
    assert out["new_segments"] == 2
    assert out["notes"] == ["2 new segments",
                            "severe stick-slip (the bit stops) in 1 segment: 4"]


def test_mu_k_moved_beyond_its_own_spread_needs_three_nights():
    history = [night(_summary(mu, [0.2]), f"d{i}") for i, mu in enumerate((0.25, 0.27, 0.26))]
    within = changes(_summary(0.28, [0.2]), history, ran=True, data_changed_utc=None)
    assert within["notes"] == []  # 0.02 from the median: inside the spread 0.02
    moved = changes(_summary(0.30, [0.2]), history, ran=True, data_changed_utc=None)
    assert moved["notes"][0].startswith("μ_k moved to 0.300 from 0.260")
    assert changes(_summary(0.40, [0.2]), history[:2], ran=True,
                   data_changed_utc=None)["notes"] == []  # two nights: no judgement


def test_a_well_whose_data_did_not_change_says_since_when():
    out = changes(_summary(0.25, [0.2]), [], ran=False, data_changed_utc="2026-11-20T02:00:00")
    assert out == {"new_segments": 0, "notes": ["no new data since 2026-11-20T02:00:00"]}


def test_severe_stick_slip_with_statistics_withheld_is_still_noted():
    """Issue 22: beyond the validated severity the number is null, the flag says why; the
    night's note still names the segment."""
    summary = _summary(0.25, [0.2, None])
    summary["segments"][1]["quality_flags"] = ["stick_slip_beyond_validated"]
    out = changes(summary, [], ran=True, data_changed_utc=None)
    assert "severe stick-slip (the bit stops) in 1 segment: 2" in out["notes"]


def test_wells_whose_friction_rose_within_a_new_segment_are_named():
    """Issue 34 item 6: a new segment flagged mu_k_drift with a rising rate is named with the
    steepest rate; a drift down (a cleaned hole) and an old segment's drift are not."""
    history = [night(_summary(0.25, [0.2]), "d1")]
    summary = _summary(0.25, [0.2, 0.2, 0.2, 0.2])
    for seg, rate in zip(summary["segments"], (0.3, 0.1, -0.2, 0.05), strict=True):
        seg["quality_flags"] = ["mu_k_drift"]
        seg["mu_k_drift_per_h"] = rate
    out = changes(summary, history, ran=True, data_changed_utc=None)
    assert out["notes"][-1].startswith("friction rose within 2 segments: 2, 4")
    assert "+0.100/h" in out["notes"][-1]
    summary["segments"][1]["quality_flags"] = []
    summary["segments"][3]["quality_flags"] = []
    assert not any("friction rose" in n for n in changes(summary, history, ran=True,
                                                         data_changed_utc=None)["notes"])


def test_a_well_re_run_for_its_configuration_is_listed_though_nothing_moved():
    """Regression (the fourth newcomer): demo3, re-run after its mud density changed (μ_k
    0.279 → 0.281, within its spread, no new segment), was left out of "What changed" while
    the two unchanged wells were listed. A re-run says why; a first night says nothing."""
    from drillfric.fleet.run import _rerun_reason

    history = [night(_summary(0.279, [0.2]), "d1")]
    before = {"config_sha256": "a", "drillfric_version": "1"}
    why = _rerun_reason(before, {"config_sha256": "b", "drillfric_version": "1"})
    out = changes(_summary(0.281, [0.2]), history, ran=True, data_changed_utc=None, rerun=why)
    assert out["notes"] == ["re-run: its configuration changed"]
    assert _rerun_reason(before, {"config_sha256": "a", "drillfric_version": "1"}) is None
    first = changes(_summary(0.281, [0.2]), [], ran=True, data_changed_utc=None, rerun=why)
    assert not any(n.startswith("re-run") for n in first["notes"])
