"""Issue 35 ("What a newcomer saw"), items 4, 11 and 13: the report reads as an engineer
expects — times as clock or log time h:mm:ss (never "—–— s" or decimal hours), a
diagnostics table whose long cells wrap, each segment led by what was found and what was
withheld and why. These tests build the report's pieces from summary-like records (no run).
"""

from __future__ import annotations

import pandas as pd

from drillfric.report.data import segments_frame
from drillfric.report.display import SI
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
