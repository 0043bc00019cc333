"""Reports (issue 16): display units, the estimate fields of the segment headers, the fleet
figure's data, and progress of `drillfric run` without a terminal.

Display units are checked against the exact definitions of the field units (NIST SP 811,
appendix B: 1 ft = 0.3048 m, 1 lbf = 0.45359237 kg × 9.80665 m/s² = 4.4482216152605 N),
not against the code's own conversion table. Shares the session results of
tests/test_report.py.
"""

from __future__ import annotations

import hashlib
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from markupsafe import escape

from drillfric.errors import ConfigError
from drillfric.report import write_fleet_report, write_well_report
from tests.synthetic_results import UNRESOLVED_REASON, UNRESOLVED_SEGMENT
from tests.test_report import (
    CLOCK,
    DEMO,
    bokeh_items,
    bokeh_nodes,
    copy_result,
    decoded,
    demo_result_dir,
    evidence_dir,
    fleet_wells,
    sources,
)

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

FT_M = 0.3048  # exact, by definition
LBF_N = 0.45359237 * 9.80665  # exact, by definition
KLBF_N = 1e3 * LBF_N
KFT_LBF_NM = 1e3 * FT_M * LBF_N


@pytest.fixture(scope="module")
def evidence(tmp_path_factory) -> Path:
    return evidence_dir(tmp_path_factory)


@pytest.fixture(scope="module")
def demo(tmp_path_factory) -> Path:
    return demo_result_dir(tmp_path_factory)


@pytest.fixture(scope="module")
def field_copy(evidence, tmp_path_factory) -> tuple[Path, dict[str, str], str]:
    """A copy of the evidence results, the SHA-256 of its result files before the report,
    and its report.html drawn in field units."""
    result = copy_result(evidence, tmp_path_factory.mktemp("field") / "w")
    before = _hashes(result)
    html = write_well_report(result, units="field").read_text(encoding="utf-8")
    return result, before, html


def _hashes(result: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in result.iterdir()
            if p.suffix in (".parquet", ".json")}


def _diagnostic_cells(html: str) -> list[list[str]]:
    table = html.split('id="diagnostics-table"')[1].split("</table>")[0]
    return [[re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)]
            for row in table.split("<tr")[2:]]


def _segment_section(html: str, seg_id: int) -> str:
    return html.split(f'id="segment-{seg_id}"')[1].split("</section>")[0]


# --- display units ---------------------------------------------------------------------------

def test_field_units_convert_evidence_tracks_and_tables(field_copy):
    """`units="field"`: the evidence torque is estimates.parquet's N·m over 1 kft·lbf, the
    tracks' hook load tracks.parquet's N over 1 klbf, the diagnostics' bit depth in ft and
    hook load in klbf; the axes say so. float32 in the page: 7 significant digits."""
    result, _, html = field_copy
    items = bokeh_items(html)
    est = pd.read_parquet(result / "estimates.parquet")
    final = est[(est["segment_id"] == 1) & (est["start_id"] == -1)].sort_values("time_s")
    torque = sources(items["bk-segment-1"])["panel:torque"]
    time_s = (torque["x"] - pd.Timestamp(CLOCK).value / 1e6) / 1e3
    rows = final.set_index(final["time_s"].round(3)).loc[np.round(time_s, 3)]
    np.testing.assert_allclose(torque["measured"], rows["surface_torque_Nm"] / KFT_LBF_NM,
                               rtol=2e-7, atol=1e-6)
    tracks = pd.read_parquet(result / "tracks.parquet")
    text = json.dumps(items["bk-tracks"], ensure_ascii=False)
    assert "hook load [klbf]" in text and "torque [kft·lbf]" in text and "depth [ft]" in text
    assert "[kN" not in text
    hook = _track_envelope(items["bk-tracks"], tracks["hookload_N_max"].max() / KLBF_N)
    finite = np.isfinite(hook)
    np.testing.assert_allclose(hook[finite], tracks["hookload_N_max"] / KLBF_N, rtol=1e-6)
    assert "bit depth [ft]" in json.dumps(items["bk-friction"], ensure_ascii=False)
    summary = json.loads((result / "summary.json").read_text())
    for seg, cells in zip(summary["segments"], _diagnostic_cells(html), strict=True):
        assert cells[2] == f"{seg['bit_depth_m'] / FT_M:.1f}"
        assert cells[14] == (f"{seg['hookload_N'] / KLBF_N:.0f} / "
                             f"{seg['hookload_model_N'] / KLBF_N:.0f}")
    assert "<th>bit depth [ft]</th>" in html and "<th>hook load [klbf]</th>" in html
    assert "<th>OD [in]</th>" in html


def _track_envelope(item: dict, peak: float) -> np.ndarray:
    """The ``hi`` column of the track whose maximum is ``peak``."""
    from tests.test_report import _unnamed_sources

    for data in _unnamed_sources(item):
        if "hi" in data and np.isclose(np.nanmax(data["hi"]), peak, rtol=1e-6):
            return data["hi"]
    raise AssertionError(f"no track peaks at {peak}")


def test_result_files_stay_si(field_copy, evidence):
    """The report writes report.html only: Parquet and JSON are untouched (SI)."""
    result, before, _ = field_copy
    assert _hashes(result) == before
    assert before == _hashes(evidence)


def test_units_default_to_the_runs_well_units(evidence, tmp_path):
    """Without `units` the report takes the run's `[well] units` (summary.json config),
    else SI; `units` overrides it; an unknown system is a ConfigError."""
    def field_run(summary):
        summary["config"]["well"]["units"] = "field"

    result = copy_result(evidence, tmp_path / "w", field_run)
    assert "<th>bit depth [ft]</th>" in write_well_report(result).read_text(encoding="utf-8")
    assert "<th>bit depth [m]</th>" in write_well_report(result, units="si").read_text(
        encoding="utf-8")
    with pytest.raises(ConfigError, match="unit system"):
        write_well_report(result, units="imperial")


def test_report_command_units_option(evidence, tmp_path):
    from drillfric.cli.main import cli

    result = copy_result(evidence, tmp_path / "w")
    done = CliRunner().invoke(cli, ["report", str(result), "--units", "field", "--segments",
                                    "0"])
    assert done.exit_code == 0, done.output
    assert "<th>bit depth [ft]</th>" in (result / "report.html").read_text(encoding="utf-8")
    done = CliRunner().invoke(cli, ["report", str(result), "--units", "cgs"])
    assert done.exit_code == 2 and "Traceback" not in done.output


def test_pdf_in_field_units(field_copy, tmp_path):
    """report.pdf draws its segment titles and diagnostics headings in field units."""
    from pypdf import PdfReader

    result = copy_result(field_copy[0], tmp_path / "w")
    write_well_report(result, pdf=True, units="field", segments=1)
    text = "\n".join(p.extract_text() for p in PdfReader(result / "report.pdf").pages)
    assert " ft," in text and "[klbf]" in text and "bit depth [m]" not in text


# --- what the estimators say per segment -----------------------------------------------------

def test_segment_headers_show_zone_interval_bit_speed_and_notes(evidence):
    """Each segment's header names the friction zone its μ is for, the effective logging
    interval, whether the bit speed is resolved — where not, why, and no bit-speed trace
    is drawn — and the estimators' notes (the top-drive identification among them) one
    per line (docs/outputs.md: friction_zone, sample_interval_s, bit_speed_resolved,
    bit_speed_reason, message)."""
    html = write_well_report(evidence, segments="all").read_text(encoding="utf-8")
    summary = json.loads((evidence / "summary.json").read_text())
    zone = summary["friction_zone"].replace("_", " ")
    assert f"μ is the <b>{zone}</b> friction factor" in html
    items = bokeh_items(html)
    for seg in summary["segments"]:
        section = _segment_section(html, seg["id"])
        assert f"friction zone <b>{seg['friction_zone'].replace('_', ' ')}</b>" in section
        assert f"logged every {seg['sample_interval_s']:.3g} s" in section
        notes = re.findall(r"<li>(.*?)</li>", section.split('class="seg-notes"')[1]
                           .split("</ul>")[0], re.S)
        assert "; ".join(notes) == str(escape(seg["message"]))
        drawn = sources(items[f"bk-segment-{seg['id']}"])
        if seg["id"] == UNRESOLVED_SEGMENT:
            reason = UNRESOLVED_REASON.split(":", 1)[1].strip()
            assert f"not resolved: {escape(reason)}" in section
            assert "panel:bit" not in drawn and "stuck" not in drawn
        else:
            assert "bit speed resolved" in section and "panel:bit" in drawn
    assert any(n.startswith(("top drive identified", "top drive not identified"))
               for seg in summary["segments"] for n in seg["message"].split("; "))


def test_flags_are_badges_with_their_meaning(evidence, tmp_path):
    """A creep fit check that failed (mu_s_not_explained) shows in the segment's detail
    with the flag's meaning from docs/outputs.md, and in the diagnostics message."""
    from drillfric.result import FLAG_MEANINGS, Flag

    def unexplained(summary):
        summary["segments"][0]["quality_flags"] = ["mu_s_not_explained"]

    result = copy_result(evidence, tmp_path / "w", unexplained)
    html = write_well_report(result, segments="all").read_text(encoding="utf-8")
    header = _segment_section(html, 1).split('class="seg-flags"')[1].split("</p>")[0]
    meaning = str(escape(FLAG_MEANINGS[Flag.MU_S_NOT_EXPLAINED]))
    assert ">mu s not explained</span>" in header and meaning in header
    assert "mu_s_not_explained" in _diagnostic_cells(html)[0][-1]


# --- the fleet report ------------------------------------------------------------------------

def test_fleet_figure_draws_every_wells_mu_k_versus_depth(demo, tmp_path):
    """fleet.html's figure holds, for each well, exactly its estimated segments' (μ_k, bit
    depth) from summary.json, a row per well links to its report; in field units the depth
    is in ft (issue 16, item 8)."""
    wells = fleet_wells(tmp_path, demo)
    for units, scale, label in ((None, 1.0, "bit depth [m]"), ("field", FT_M, "bit depth [ft]")):
        html = write_fleet_report(tmp_path, wells, units=units).read_text(encoding="utf-8")
        item = bokeh_items(html)["bk-fleet"]
        assert label in json.dumps(item, ensure_ascii=False)
        drawn = _fleet_points(item)
        for well in wells[:3]:
            segs = [s for s in well["summary"]["segments"] if s["status"] == "ok"]
            expect = sorted((s["mu_k"], s["bit_depth_m"] / scale) for s in segs)
            np.testing.assert_allclose(sorted(drawn[well["well"]]), expect, rtol=1e-12)
        rows = html.split('id="wells-table"')[1].split("</table>")[0].split("<tr")[2:]
        assert len(rows) == len(wells)
        for row, well in zip(rows, wells, strict=True):
            assert f"<b>{well['well']}</b>" in row
            assert (f'href="./{well["well"]}/report.html"' in row) is (well["status"] == "ok")


def _fleet_points(item: dict) -> dict[str, list[tuple[float, float]]]:
    """(μ_k, depth) of every point of the fleet figure, by well."""
    out: dict[str, list] = {}
    for node in bokeh_nodes(item, "ColumnDataSource"):
        data = dict(node["attributes"]["data"]["entries"])
        if "well" in data:
            cols = {k: decoded(data[k]) for k in ("well", "mu_k", "depth")}
            for w, m, d in zip(cols["well"], cols["mu_k"], cols["depth"], strict=True):
                out.setdefault(str(w), []).append((float(m), float(d)))
    return out


# --- progress of `drillfric run` without a terminal -----------------------------------------

@pytest.mark.slow
def test_run_progress_lines_without_a_terminal_and_quiet(tmp_path):
    """Issue 16, item 7: with stderr not a terminal, `drillfric run` prints a progress line
    per 10 % crossed ("NAME: P % (E s, about L s left)", P rising, ending at 90–100 %);
    with --quiet no progress line but the result line on stdout stays (~2 × 30 s: the demo,
    no report)."""
    def run(*extra):
        return subprocess.run([sys.executable, "-m", "drillfric.cli.main", *extra, "run",
                               str(DEMO), "--out", str(tmp_path / "out"), "--no-report"],
                              capture_output=True, text=True, timeout=600, check=False)

    loud = run()
    assert loud.returncode == 0, loud.stderr
    lines = re.findall(r"^demo: (\d+) % \((\d+) s, about (\d+) s left\)$", loud.stderr, re.M)
    percents = [int(p) for p, _, _ in lines]
    assert len(percents) >= 2 and percents == sorted(set(percents)) and percents[-1] >= 90
    assert all(p % 10 == 0 for p in percents)
    result_line = next(line for line in loud.stdout.splitlines() if "segments (" in line)
    quiet = run("--quiet")
    assert quiet.returncode == 0, quiet.stderr
    assert " % (" not in quiet.stderr
    assert quiet.stdout.splitlines()[0].split("μ_k")[0] == result_line.split("μ_k")[0]


def test_run_messages_follow_the_report_units():
    """Issue 35 (F-5, a field-units report): messages printed "2804–2835 m window", "WOB ≤
    10 kN" in a report in ft and klbf. Each SI quantity of a message now has its field value
    beside it, in brackets; key names (wob_on_bottom_N) and SI reports are left alone."""
    from drillfric.report.display import Units, message_in

    field = Units("field")
    said = message_in("2804–2835 m window; WOB ≤ 10 kN (segmentation.wob_on_bottom_N); "
                      "torque 25.9 kN·m at 0.2 m/s; block weight 147 kN; mud 1250 kg/m³", field)
    assert "2804–2835 m [9199–9301 ft] window" in said
    assert "10 kN [2.25 klbf] (segmentation.wob_on_bottom_N)" in said
    assert "25.9 kN·m [19.1 kft·lbf]" in said and "0.2 m/s [0.656 ft/s]" in said
    assert "147 kN [33 klbf]" in said and "1250 kg/m³ [10.4 ppg]" in said
    assert message_in("2804–2835 m window", Units("si")) == "2804–2835 m window"


def test_field_report_messages_carry_field_values(field_copy):
    """A property over the field report's diagnostics: every SI quantity a message states
    is followed by its field value (no bare m or kN in a report in ft and klbf)."""
    from drillfric.units import _MESSAGE_QUANTITY as _QUANTITY

    _, _, html = field_copy
    for cells in _diagnostic_cells(html):
        text = cells[-1]
        for match in _QUANTITY.finditer(text):
            assert text[match.end():].startswith(" ["), (match.group(0), text[:300])
