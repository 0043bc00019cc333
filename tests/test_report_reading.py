"""Issue 35 ("What a newcomer saw"), items 4, 11 and 13: the report reads as an engineer
expects — times as clock or log time h:mm:ss (never "—–— s" or decimal hours), a
diagnostics table whose long cells wrap, each segment led by what was found and what was
withheld and why. These tests build the report's pieces from summary-like records (no run).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from drillfric.report import figures
from drillfric.report.data import segments_frame
from drillfric.report.display import SI
from drillfric.report.lead import segment_lead, short_reason
from drillfric.report.render import DIAGNOSTIC_COLUMNS, clock_span, diagnostic_rows

#: A depth-indexed log's window (volve_usrop_f5): no time at all.
DEPTH_WINDOW = {"id": 1, "kind": "on_bottom_rotating", "t_start_s": None, "t_end_s": None,
                "bit_depth_m": 2831.7, "mu_k": 0.2025, "mu_td": 0.2025, "status": "ok",
                "converged": True, "method": "td_backcalc",
                "quality_flags": ["bit_torque_in_friction"],
                "message": "2804–2835 m window, 65 rotating rows"}


def test_a_depth_window_has_no_time_not_a_dash_pair():
    """F-5's diagnostics read "—–— s" in the time column: a window without time is "—"."""
    cells = diagnostic_rows(segments_frame([DEPTH_WINDOW]), SI)[0]["cells"]
    time = cells[[name for name, _, _ in DIAGNOSTIC_COLUMNS].index("time")]
    assert time == "—"
    assert not any("—–—" in cell for cell in cells)


def test_log_time_without_a_clock_reads_h_mm_ss():
    """DSATS (13.9 h, no clock time): a segment's span reads 13:46:10–13:48:22, not
    49570–49702 s."""
    row = {"t_start_s": 49570.0, "t_end_s": 49702.0}
    assert clock_span(row, None) == "13:46:10–13:48:22"
    origin = pd.Timestamp("2024-03-01T06:00:00Z")
    assert clock_span(row, origin) == "19:46:10–19:48:22"


def test_cells_that_can_grow_wrap():
    """DSATS's diagnostics overflowed 1400 px through "μ_s" ("not identifiable") and the
    torque fit ("1.0 / 1.9 (0.65 over the second half (0.53 over all))"), which did not
    wrap and pushed the message column off the page."""
    classes = {name: cls.split() for name, _, cls in DIAGNOSTIC_COLUMNS}
    for name in ("μ_s", "misfit / swing {unit} (quality)", "time", "status",
                 "bit speed (interval)"):
        assert "wrap" in classes[name], name


#: A DSATS segment the hook-load check withheld (its message as summary.json has it).
WITHHELD = {"id": 3, "kind": "off_bottom_rotating", "status": "ok", "mu_k": None,
            "mu_s": None, "mu_s_identifiable": False, "mu_s_lower_bound": None,
            "converged": False, "method": "batch", "bit_depth_m": 1002.1,
            "t_start_s": 10757.0, "t_end_s": 10862.0,
            "quality_flags": ["too_short_to_converge", "hookload_contradicts_string"],
            "message": "μ_s not identifiable (stick-slip, no creep); only 63 s of rotation "
                       "(< 90 s): not converged; 4 notes stating the withheld friction "
                       "factors left out; friction factors withheld: the hook load "
                       "contradicts the configured string: the string weight it measures "
                       "is 0.21× the modelled one, beyond ±5%"}


def test_lead_of_a_withheld_segment_says_why_first():
    """Issue 35 item 11: the lead names what was withheld and the start of its reason, as
    summary.json's note begins — not the bookkeeping note, not a number it withheld."""
    lead = segment_lead(WITHHELD)
    assert lead.found == "no μ_k; μ_s not identifiable"
    assert lead.withheld == (
        "only 63 s of rotation (< 90 s): not converged",
        "friction factors withheld: the hook load contradicts the configured string …")
    for item in lead.withheld:
        assert item.removesuffix(" …") in WITHHELD["message"]


def test_lead_names_a_bit_speed_the_logging_cannot_resolve():
    row = {**WITHHELD, "message": "", "bit_speed_resolved": False,
           "bit_speed_reason": "bit speed not resolved: 1-s samples give 1.3 per cycle"}
    assert segment_lead(row).withheld == (
        "bit speed not resolved: 1-s samples give 1.3 per cycle",)


def test_lead_of_an_estimated_segment_states_its_numbers():
    """The found line carries summary.json's μ_k (3 decimals), its status and μ_s."""
    row = {**WITHHELD, "mu_k": 0.27853, "converged": True, "quality_flags": [],
           "mu_s": 0.58540, "mu_s_identifiable": True, "stick_slip_severity": 0.84,
           "message": "μ_k = 0.279 ± 0.014 (95 %: the validated 5 %; statistical 2σ)"}
    lead = segment_lead(row)
    assert lead.found == ("μ_k 0.279, converged (batch fit); μ_s 0.585 (identified); "
                          "stick-slip severity 0.84")
    assert lead.withheld == () and lead.lines() == [f"Found: {lead.found}"]


def test_short_reason_cuts_only_outside_brackets():
    note = ("bit speed withheld over 2 of 7 30-s windows (1–31 s: creep; null rows): bit "
            "speed withheld over the creep: μ_s was not identified")
    assert short_reason(note) == ("bit speed withheld over 2 of 7 30-s windows (1–31 s: "
                                  "creep; null rows): bit speed withheld over the creep …")


def _visible_axes_are_labelled(fig) -> bool:
    """No mark without its axes, and every axis drawn has its label (issue 35 item 4:
    DSATS's page 1 drew a column of grey diamonds without axes)."""
    for ax in fig.axes:
        if not ax.axison and (ax.lines or ax.collections or ax.patches):
            return False
        if ax.axison and not ax.get_xlabel():
            return False
    return True


def test_friction_log_of_withheld_segments_is_a_sentence_without_marks():
    """Every friction factor withheld, some segments skipped: the page says why (the note
    given) and draws no mark — no unlabelled diamonds at μ = 0."""
    skipped = {**WITHHELD, "id": 4, "status": "skipped", "message": "too short: 4.7 s < 30 s"}
    segments = segments_frame([WITHHELD, skipped])
    fig = figures.friction_log_figure(segments, empty_note="No friction factor: withheld.")
    assert _visible_axes_are_labelled(fig)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert texts == ["No friction factor: withheld."]


def test_an_empty_severity_panel_says_why():
    """A depth log has no severity: its panel keeps its axis label and says why."""
    segments = segments_frame([{**DEPTH_WINDOW, "friction_zone": "effective"}])
    fig = figures.friction_log_figure(segments)
    assert _visible_axes_are_labelled(fig)
    assert fig.axes[1].get_title(loc="left") == "no severity shown: 1 on bottom"


def test_withholding_leaves_no_fragment_of_a_withheld_mu_k():
    """DSATS: the hook-load check cut "μ_k = 0.038 ± 0.003 (95 %: …; statistical 2σ …)" at
    its bracketed "; ", and the segment's notes kept "statistical 2σ ± 0.004, ±10.9 %: …",
    a number of the μ_k it withheld. The whole note goes."""
    from drillfric.hookload import withhold_friction
    from drillfric.io.text import split_notes
    from drillfric.result import Flag, SegmentRecord

    record = SegmentRecord(mu_k=0.038, message=(
        "fit note; μ_k = 0.038 ± 0.003 (95 %: the validated 5 %; statistical 2σ ± 0.004, "
        "±10.9 %: 12 whole cycles); only 63 s of rotation (< 90 s): not converged"))
    withheld = withhold_friction(record, "the hook load says so",
                                 Flag.HOOKLOAD_CONTRADICTS_STRING)
    notes = split_notes(withheld.message)
    assert notes == ["fit note", "only 63 s of rotation (< 90 s): not converged",
                     "1 note stating the withheld friction factors left out",
                     "friction factors withheld: the hook load says so"]


def test_static_log_time_axis_ticks_whole_hours_and_minutes():
    """The PDF's time axes of a 13.9-h log without clock time: ticks on whole hours read
    h:mm:ss (not 13.76 h); a 12-min segment of it ticks on whole minutes."""
    from matplotlib.figure import Figure

    from drillfric.report.interactive import time_axis

    axis = time_axis(None, span_s=50000.0)
    ax = Figure().subplots()
    for span, step in (((6.0, 49998.0), 7200.0), ((20047.0, 20807.0), 120.0)):
        ax.set_xlim(*span)
        axis.style_matplotlib(ax)
        ticks = ax.xaxis.get_major_locator()()
        assert set(np.diff(ticks)) == {step}
        labels = [ax.xaxis.get_major_formatter()(t, i) for i, t in enumerate(ticks)]
        assert all(re.fullmatch(r"\d+:\d\d:\d\d", label) for label in labels), labels
    assert axis.label == "log time [h:mm:ss]"


def test_a_skipped_segment_has_no_zone_not_nan():
    """DSATS's diagnostics read "nan" in the μ zone column of every skipped segment."""
    skipped = {**WITHHELD, "status": "skipped", "friction_zone": None}
    rows = diagnostic_rows(segments_frame([skipped, {**WITHHELD, "id": 4,
                                                     "friction_zone": "open_hole"}]), SI)
    zone = [name for name, _, _ in DIAGNOSTIC_COLUMNS].index("μ zone")
    assert [r["cells"][zone] for r in rows] == ["—", "open hole"]
    assert not any("nan" in cell for r in rows for cell in r["cells"][:-1])


def test_pdf_segment_page_leads_with_a_regime_the_fit_misses():
    """The HTML shows a fit that misses the data's regime in a red box before the detail;
    the PDF says it above the panels too, wrapped, not in the detail alone."""
    from drillfric.report.lead import Lead
    from drillfric.report.pdf import PAGE_IN
    from drillfric.report.well import segment_lead_lines

    sentence = ("The fit reproduces the mean torque (μ_k) but not the regime: over the "
                "second half its model keeps stick-slip (torque swing 1.1 kN·m) where the "
                "measured torque is steady (0.2 kN·m); read μ_k with care. ") * 2
    row = {"lead": Lead("μ_k 0.279, not converged (batch fit)", ()), "fit_mismatch": True,
           "fit_sentence": sentence.strip()}
    lines = segment_lead_lines(row, PAGE_IN)
    assert lines[0] == "Found: μ_k 0.279, not converged (batch fit)"
    assert " ".join(lines[1:]) == sentence.strip() and len(lines) > 2
    assert segment_lead_lines({**row, "fit_mismatch": False}, PAGE_IN) == lines[:1]


def test_pdf_table_cell_longer_than_a_row_continues_under_it():
    """A cell of 40 lines used to end in "…" after 14: its rest now follows under its row
    (across the full width, onto the next page when it must); every word is printed."""
    from drillfric.report.pdf import table_pages

    long = " ".join(f"word{i}" for i in range(900))
    pages = table_pages("Run details", ["", ""], [["WARNING", long], ["rows", "12"]])
    text = " ".join(t.get_text() for page in pages for t in page.texts)
    text = re.sub(r"\s+", " ", text.replace("(continued below)", "")
                  .replace("WARNING, continued:", ""))
    assert long in text and "…" not in text
