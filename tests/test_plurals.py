"""Issue 35 item 1: every count shown to people agrees with its noun ("1 segment", "2
segments"), through one helper (:func:`drillfric.io.text.plural`)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from drillfric.cli.fleet_cmd import _closing_line

from drillfric.fleet.overnight import changes
from drillfric.io.text import plural, share
from drillfric.report.render import environment
from drillfric.report.well import headline_lines


@pytest.mark.parametrize(("n", "text"), [(0, "0 wells"), (1, "1 well"), (2, "2 wells")])
def test_plural_agrees_with_the_count(n, text):
    assert plural(n, "well") == text


def test_the_templates_count_with_the_same_helper():
    template = environment().from_string("{{ n|plural('well') }}")
    assert template.render(n=1) == "1 well" and template.render(n=3) == "3 wells"


def _fleet(wells: int, failed_segments: int, stale: int):
    rows = [SimpleNamespace(stale_dir="x" if i < stale else None,
                            status="failed" if i < stale else "ok",
                            failed_segments=failed_segments if i == 0 else 0)
            for i in range(wells)]
    return SimpleNamespace(wells=rows, failed_segments=failed_segments, wall_s=1.0,
                           manifest="OUT/manifest.json", out_root="OUT",
                           count=lambda s: {"ok": wells - stale, "failed": stale}.get(s, 0))


def test_fleet_closing_line_says_one_well_and_one_segment():
    line = _closing_line(_fleet(1, 1, 1))
    assert line.startswith("fleet: 1 well — ")
    assert "1 failed well keeps an earlier run's results" in line
    assert "1 segment failed" in line and "segments" not in line


def test_fleet_closing_line_plural():
    line = _closing_line(_fleet(3, 2, 2))
    assert line.startswith("fleet: 3 wells — ")
    assert "2 failed wells keep" in line and "2 segments failed" in line


def test_overnight_notes_one_new_segment():
    summary = {"mu_k": 0.25, "segments": [{"id": 1, "stick_slip_severity": 0.1},
                                          {"id": 2, "stick_slip_severity": 1.5}]}
    history = [{"segments": 1, "mu_k": 0.25}]
    notes = changes(summary, history, ran=True, data_changed_utc=None)["notes"]
    assert notes == ["1 new segment", "severe stick-slip (the bit stops) in 1 segment: 2"]


def test_report_headline_one_warning():
    head = {"trust": {"uncertainty": "", "support": "", "confidence": "high", "reasons": []},
            "mu_k": "0.280", "mu_k_reason": None, "apparent": {"value": "0.31", "count": 1},
            "depth_indexed": False, "mu_s": "—", "zone": "", "profile": "",
            "counts": {"segments": 1}, "span": None, "indicative": False,
            "warnings": ["one"]}
    text = " | ".join(line for line, _ in headline_lines(head))
    assert "WARNING: 1 warning, see" in text
    assert "median of 1 converged on-bottom stand)" in text



@pytest.mark.parametrize(("part", "whole", "text"), [
    (1, 1, "the only off-bottom segment"), (4, 4, "all 4 off-bottom segments"),
    (7, 9, "7 of 9 off-bottom segments"), (0, 1, "0 of 1 off-bottom segment")])
def test_a_share_reads_as_said(part, whole, text):
    """Issue 35: the warnings said "rests on 1 of 1 off-bottom segments"."""
    assert share(part, whole, "off-bottom segment") == text


def test_well_warnings_count_naturally():
    """The headline's warnings of one stand, one default, one failed segment: no "(s)"
    and no "1 of 1 … segments"."""
    from drillfric.estimation.headline import judge

    segment = {"id": 1, "kind": "off_bottom_rotating", "status": "failed", "mu_k": None,
               "quality_flags": []}
    summary = {"mu_k": 0.25, "mu_k_uncertainty": 0.01, "counts": {"estimated": 1},
               "mu_k_support": {"segments": 1, "of": 1}, "assumed": ["mud density"],
               "warnings": [], "segments": [segment]}
    text = " | ".join(judge(summary)["warnings"])
    assert "rests on the only off-bottom segment" in text
    assert "1 default assumed" in text and "1 segment failed (segment 1)" in text
    assert "(s)" not in text and "1 of 1" not in text
