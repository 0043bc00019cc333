"""Issue 25, "what a person sees must never mislead": the report's points 2–6 and 11.

Each test is named after what misled a reader: an apparent on-bottom μ drawn as μ_k, a
"converged" segment wearing a "not converged" badge, a fit that keeps stick-slip the data
no longer show, a depth log's report claiming its results were old, a segments-only time
span, a 14-hour axis in seconds, an unnamed rig-state strip, an empty friction log on a
−1…1 axis, and a PDF whose footer sits on the tick labels, whose messages are cut and
whose path is never printed. The demo results come from tests/test_report.py's session
copies; the depth log is tests/test_friction_log.py's synthetic one, run through the CLI.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from drillfric.report import figures, write_well_report
from drillfric.report.well import build_report
from tests.synthetic_results import synthetic_result
from tests.test_report import (
    _segments,
    bokeh_items,
    bokeh_nodes,
    copy_result,
    demo_result_dir,
    evidence_dir,
    sources,
)

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def evidence(tmp_path_factory):
    return evidence_dir(tmp_path_factory)


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    return demo_result_dir(tmp_path_factory)


def _section(html: str, element_id: str) -> str:
    """The text of the element with ``element_id`` up to the next section."""
    start = html.index(f'id="{element_id}"')
    end = html.find("<section", start + 1)
    return html[start:end if end > 0 else None]


def _legend_labels(item: dict) -> list[str]:
    out = []
    for node in bokeh_nodes(item, "LegendItem"):
        label = node["attributes"].get("label")
        if isinstance(label, dict):
            out.append(label.get("value") or label.get("field"))
    return out


# --- point 2: apparent on-bottom μ is not μ_k ----------------------------------------------

def _on_bottom(summary: dict, seg_id: int = 3) -> None:
    seg = summary["segments"][seg_id - 1]
    seg.update(kind="on_bottom_rotating",
               quality_flags=[*seg["quality_flags"], "bit_torque_in_friction"])


def test_apparent_on_bottom_mu_is_drawn_and_named_apart_from_mu_k(evidence, tmp_path):
    """An on-bottom segment's μ (bit torque in it) gets its own mark and legend entry in the
    friction log, "apparent" in the diagnostics, the segment header and the headline; μ_k
    points and the μ_TD crosses hold only off-bottom segments."""
    result = copy_result(evidence, tmp_path / "w", _on_bottom)
    summary = json.loads((result / "summary.json").read_text())
    html = write_well_report(result, segments="all").read_text(encoding="utf-8")
    item = bokeh_items(html)["bk-friction"]
    drawn = sources(item)
    assert list(drawn["points:mu_app:converged"]["id"]) == [3]
    assert 3 not in drawn["points:mu_k:converged"]["id"]
    assert 3 not in drawn.get("points:mu_td:converged", {"id": []})["id"]
    labels = _legend_labels(item)
    assert "μ_k (off bottom)" in labels
    assert any(label.startswith("apparent μ (on bottom") for label in labels)
    mu = summary["segments"][2]["mu_k"]
    assert f"apparent μ {mu:.3f}" in _section(html, "segment-3")
    row = html.split('id="diagnostics-table"')[1].split("<tr")[4]
    assert f"{mu:.3f} apparent" in row
    headline = _section(html, "headline-apparent").split("</span></span>")[0]
    assert f"<b>{mu:.3f}</b>" in headline and "bit torque included" in headline
    fig = figures.friction_log_figure(build_report(result).data.segments)
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert "μ_k (off bottom)" in legend and any(t.startswith("apparent μ") for t in legend)
    assert sum(len(ln.get_xdata()) for ln in fig.axes[0].get_lines()
               if ln.get_marker() == "^") == 1


# --- point 3: converged means one thing ----------------------------------------------------

def test_converged_header_status_and_badges_agree(evidence):
    """The header's count of converged segments equals the segments whose badge says "μ_k
    converged"; a converged segment wears no warning badge saying "not converged" (the
    observer's spread under a batch μ_k is a grey note, named for what it is)."""
    html = write_well_report(evidence, segments="all").read_text(encoding="utf-8")
    summary = json.loads((evidence / "summary.json").read_text())
    converged = sum(s["status"] == "ok" and s["converged"] for s in summary["segments"])
    assert f"{converged} μ<sub>k</sub> converged" in _section(html, "counts")
    badges = re.findall(r'<span class="badge (\w+) status"[^>]*>μ<sub>k</sub> ([\w ]+)</span>',
                        html)
    assert sum(word == "converged" for _, word in badges) == converged
    for seg in summary["segments"]:
        section = _section(html, f"segment-{seg['id']}")
        warnings = re.findall(r'<span class="badge flag"[^>]*>([^<]*)</span>', section)
        if seg["converged"]:
            assert not any("not converged" in w for w in warnings), (seg["id"], warnings)
        if "observer_starts_disagree" in seg["quality_flags"] and seg["method"] == "batch":
            assert "observer starts spread" in section
    cells = [r.split("</td>")[-3] for r in
             html.split('id="diagnostics-table"')[1].split("</table>")[0].split("<tr")[2:]]
    assert all("μ_k converged (batch fit)" in c for c in cells)


# --- point 4: what the fit reproduces ------------------------------------------------------

def _torques(measured, model, rate_hz: float = 10.0) -> pd.DataFrame:
    t = np.arange(len(measured)) / rate_hz
    return pd.DataFrame({"time_s": t, "surface_torque_Nm": measured,
                         "surface_torque_fit_Nm": model})


def test_reproduction_tells_the_four_regimes_apart():
    """Stick-slip (std/mean of the 1-s torque above 0.1) in the model but not the data, the
    other way round, in both, in neither."""
    from drillfric.report.reproduction import reproduction

    t = np.arange(6000) / 10.0
    cycle = 10e3 * np.sin(2 * np.pi * t / 5.0)
    steady = np.full(t.size, 20e3)
    found = reproduction(_torques(steady + cycle * (t < 300), steady + cycle))
    assert found.model_stick_slip and not found.measured_stick_slip
    assert "keeps stick-slip" in found.sentence("0:05:00") and found.quality > 5
    found = reproduction(_torques(steady + cycle, steady))
    assert found.measured_stick_slip and not found.model_stick_slip
    assert "turns steadily" in found.sentence("0:05:00")
    found = reproduction(_torques(steady + cycle, steady + 0.9 * cycle))
    assert found.regime_reproduced and "reproduces the stick-slip" in found.sentence("x")
    assert found.model_swing_Nm == pytest.approx(0.9 * found.measured_swing_Nm, rel=0.02)
    found = reproduction(_torques(steady, steady * 1.02))
    assert found.regime_reproduced and "within 2.0 %" in found.sentence("x")


def test_fit_that_keeps_stick_slip_the_data_lost_is_said(evidence, tmp_path):
    """Segment 3's measured torque turns steady half-way while its fit model keeps a
    ±10 kN·m stick-slip (the bistable case): the segment says so in plain words, in a
    warning box, states the second half's (worse) fit quality, and the diagnostics message
    says it too."""
    result = copy_result(evidence, tmp_path / "w")
    est = pd.read_parquet(result / "estimates.parquet")
    rows = (est["segment_id"] == 3) & (est["start_id"] == -1)
    t = est.loc[rows, "time_s"].to_numpy()
    late = t >= t.min() + 0.5 * (t.max() - t.min())
    cycle = 10e3 * np.sin(2 * np.pi * t / 5.0)
    est.loc[rows, "surface_torque_Nm"] = 20e3 + np.where(late, 0.0, cycle)
    est.loc[rows, "surface_torque_fit_Nm"] = 20e3 + cycle
    est.to_parquet(result / "estimates.parquet", index=False)
    html = write_well_report(result, segments="all").read_text(encoding="utf-8")
    section = _section(html, "segment-3")
    box = section.split('fit-sentence">')[1].split("</p>")[0]
    assert 'class="problem fit-sentence"' in section
    assert "keeps stick-slip" in box and "measured torque is steady" in box
    quality = float(re.search(r"fit quality there (\d+\.\d+)", box).group(1))
    assert quality > 5 and f"fit quality {quality:.2f} over the second half" in section
    message = html.split('id="diagnostics-table"')[1].split("<tr")[4]
    assert "keeps stick-slip" in message and f"({quality:.2f} over the second half" in message
    assert "keeps stick-slip" not in _section(html, "segment-2")


# --- point 5: depth-indexed logs -----------------------------------------------------------

@pytest.fixture(scope="module")
def depth_run(tmp_path_factory):
    """The synthetic depth log of tests/test_friction_log.py (off- and on-bottom windows at
    μ = 0.25, bit torque modelled) run by ``drillfric run --pdf``: (CLI output, result)."""
    from drillfric.cli.main import cli

    from drillfric.config import config_from_dict, read_toml
    from drillfric.io.survey import read_survey
    from tests.test_friction_log import CONFIG, SURVEY, _rows

    folder = tmp_path_factory.mktemp("seen-depth")
    (folder / "d.survey.csv").write_text(SURVEY)
    (folder / "d.toml").write_text(CONFIG)
    cfg = config_from_dict(read_toml(folder / "d.toml"))
    rows = _rows(cfg, read_survey(folder / "d.survey.csv"))
    rows.rename(columns={"MD": "MD [m]", "RPM": "RPM [rpm]", "TORQUE": "TORQUE [kN.m]",
                         "WOB": "WOB [kN]", "HKLD": "HKLD [kN]"}).to_csv(folder / "d.csv",
                                                                       index=False)
    done = CliRunner().invoke(cli, ["run", str(folder / "d.csv"), "--pdf", "--out",
                                    str(folder / "out")])
    assert done.exit_code == 0, done.output
    return done.output, folder / "out" / "d"


def test_depth_log_report_shows_its_apparent_mu_and_no_false_notes(depth_run):
    """A fresh depth log's report: the headline has the off-bottom μ_k and the apparent
    on-bottom μ the run printed, no note claims the results are old, the broomstick draws
    the measured torque of every window, the segments section says why there is no time
    evidence instead of "0 of N drawn"."""
    output, result = depth_run
    summary = json.loads((result / "summary.json").read_text())
    apparent = summary["friction_log"]["mu_apparent"]
    assert f"apparent μ on bottom = {apparent:.3f}" in output
    html = (result / "report.html").read_text(encoding="utf-8")
    assert f"<b>{apparent:.3f}</b>" in _section(html, "headline-apparent")
    assert f"<b>{summary['mu_k']:.3f}</b>" in _section(html, "headline-mu-k")
    assert "written before" not in html and "rerun" not in html
    assert "depth-indexed" in _section(html, "tracks")
    assert " drawn" not in _section(html, "segments").split("</p>")[0]
    assert "depth-indexed" in _section(html, "segments")
    broom = _section(html, "broomstick")
    assert '<img class="fig"' in broom and 'class="note"' not in broom
    points = build_report(result).broomstick.points
    assert len(points) == summary["counts"]["estimated"]
    assert points["surface_torque_Nm"].notna().all()


# --- point 6: time, span, legends, empty states --------------------------------------------

def test_header_span_is_the_logs_not_the_segments(evidence, tmp_path):
    """With the first segment gone, the header still spans the whole log (tracks.parquet),
    starting at its first sample, not at the first segment; the run time says what it
    measures."""
    result = copy_result(evidence, tmp_path / "w",
                         lambda s: s.update(segments=s["segments"][1:]))
    html = write_well_report(result).read_text(encoding="utf-8")
    span = _section(html, "log-span").split("</span>")[0]
    tracks = pd.read_parquet(result / "tracks.parquet")
    first = pd.to_datetime(tracks["timestamp"], utc=True).iloc[0]
    assert span.startswith('id="log-span">log time ') and f"{first:%H:%M}" in span
    summary = json.loads((result / "summary.json").read_text())
    second = summary["segments"][0]["clock_start_utc"]
    assert f"{pd.Timestamp(second):%H:%M:%S} " not in span
    run = _section(html, "run-time").split("</span>")[0]
    assert "not included" in run and "run took" not in html


def test_long_log_without_clock_is_plotted_in_log_clock_time_with_a_rig_state_legend(
        tmp_path):
    """A 2-hour log without clock time: the tracks' axis reads log time as h:mm:ss (issue
    35 item 13: not decimal hours, not 0…7200 s) with ticks on whole minutes or hours, and
    the rig-state strip has a legend naming its colours."""
    result = synthetic_result(tmp_path / "long", hours=2.0, log_rate_hz=2.0, n_segments=2,
                              segment_s=600.0, n_starts=1, estimate_rate_hz=1.0)
    summary = json.loads((result / "summary.json").read_text())
    summary.pop("time_origin_utc")
    (result / "summary.json").write_text(json.dumps(summary))
    tracks = pd.read_parquet(result / "tracks.parquet").drop(columns=["timestamp"])
    tracks.to_parquet(result / "tracks.parquet", index=False)
    html = write_well_report(result).read_text(encoding="utf-8")
    item = bokeh_items(html)["bk-tracks"]
    x = sources(item)["trace:surface_torque_Nm"]["x"]
    text = json.dumps(item, ensure_ascii=False)
    assert 6800 < np.nanmax(x) <= 7200 and "log time [h:mm:ss]" in text
    formats = {f["attributes"]["format"] for f in bokeh_nodes(item, "NumeralTickFormatter")}
    assert formats == {"00:00:00"}  # numbro's h:mm:ss of seconds
    bases = {t["attributes"]["base"] for t in bokeh_nodes(item, "AdaptiveTicker")}
    assert bases == {60, 3600}  # ticks on whole seconds, minutes and hours
    states = [n for n in bokeh_nodes(item, "LegendItem")
              if n["attributes"].get("label") == {"type": "field", "field": "what"}]
    assert len(states) == 1


def test_empty_friction_log_is_a_sentence_not_an_axis(demo, tmp_path):
    """All segments skipped: no friction plot on a −1…1 axis but a note with the counts;
    with estimates the μ axis starts at 0."""
    def skipped(summary):
        for seg in summary["segments"]:
            seg.update(status="skipped", mu_k=None, mu_s=None, mu_td=None, converged=False,
                       message="too short")
    result = copy_result(demo, tmp_path / "w", skipped)
    (result / "drag_log.parquet").unlink(missing_ok=True)  # nor drag-based factors
    html = write_well_report(result).read_text(encoding="utf-8")
    assert "bk-friction" not in bokeh_items(html)
    note = _section(html, "no-friction").split("</p>")[0]
    assert "no segment was estimated with a bit depth (4 segments: 4 skipped)" in note
    item = bokeh_items(write_well_report(demo).read_text(encoding="utf-8"))["bk-friction"]
    ranges = [n["attributes"] for n in bokeh_nodes(item, "DataRange1d")]
    assert any(r.get("start") == 0.0 for r in ranges)


# --- point 11: the PDF ---------------------------------------------------------------------

def _page_texts(pdf) -> list[list[tuple[float, str]]]:
    """Per page, (baseline height [pt], text) of every text run."""
    from pypdf import PdfReader

    pages = []
    for page in PdfReader(pdf).pages:
        runs = []
        page.extract_text(visitor_text=lambda text, cm, tm, font, size, runs=runs: runs.append(
            (float(cm[5]) + float(tm[5]) * float(cm[3]), text)) if text.strip() else None)
        pages.append(runs)
    return pages


def test_pdf_reads_like_a_printed_report(evidence, tmp_path):
    """Page 1 holds the headline and the friction log; the footer is clear of every other
    text (tick labels, axis labels); a 300-word message is printed whole, under its row;
    the configuration is one appendix of the non-default settings (no default key, such as
    observer.kappa1, is listed)."""
    words = " ".join(f"word{i:03d}" for i in range(300))
    result = copy_result(evidence, tmp_path / "w",
                         lambda s: s["segments"][0].update(message=words))
    write_well_report(result, pdf=True)
    pages = _page_texts(result / "report.pdf")
    first = "".join("".join(t for _, t in pages[0]).split())  # runs split at font changes
    assert "offbottom(consensus)" in first and "bitdepth" in first
    for number, runs in enumerate(pages, start=1):
        footer = [y for y, t in runs if t.startswith(("page ", "drillfric friction report"))]
        assert footer, number
        others = [(y, t) for y, t in runs if y > max(footer) + 1 or y < min(footer) - 1]
        assert all(y > max(footer) + 9 for y, _ in others), (number, min(others))
    diagnostics = " ".join(t for runs in pages for _, t in runs
                           if any("Diagnostics" in x for _, x in runs))
    assert all(f"word{i:03d}" in diagnostics for i in range(300))
    config = [" ".join(t for _, t in runs) for runs in pages
              if any("Configuration" in t or "Appendix" in t for _, t in runs)]
    assert len(config) <= 2 and "kappa1" not in " ".join(config)
    assert "settingsthatdifferfromthedefaults" in "".join("".join(config).split())


def test_run_prints_the_pdfs_path(depth_run):
    """``drillfric run --pdf`` names report.pdf as well as report.html."""
    output, result = depth_run
    assert f"report: {result / 'report.pdf'}" in output


def test_friction_log_figure_has_no_mu_k_for_on_bottom_rows():
    """The static friction log (PDF page 1): ● for off-bottom μ_k, ▲ for apparent μ."""
    seg = _segments([{"bit_depth_m": 1000.0},
                     {"bit_depth_m": 1030.0, "kind": "on_bottom_rotating"}])
    fig = figures.friction_log_figure(seg)
    lines = {ln.get_marker(): len(ln.get_xdata()) for ln in fig.axes[0].get_lines()
             if ln.get_marker() in ("o", "^", "x")}
    assert lines == {"o": 1, "^": 1, "x": 1}


def test_fit_overshooting_the_torque_by_38_percent_is_not_said_to_reproduce_it():
    """Issue 35: the report said "The fit reproduces the steady rotation … mean torque
    within 38.0 %". "Reproduces" now follows the stated criterion (mean within
    MEAN_TOLERANCE, same regime, swings within SWING_RATIO); else it says it does not."""
    from drillfric.report.reproduction import MEAN_TOLERANCE, reproduction

    t = np.arange(6000) / 10.0
    steady = np.full(t.size, 20e3)
    found = reproduction(_torques(steady, steady * 1.38))
    assert found.regime_reproduced and not found.mean_reproduced and not found.reproduced
    said = found.sentence("x")
    assert said.startswith("The fit does not reproduce the steady rotation")
    assert "38 % above the measured" in said and f"tolerance {100 * MEAN_TOLERANCE:g} %" in said
    cycle = 10e3 * np.sin(2 * np.pi * t / 5.0)
    found = reproduction(_torques(steady + cycle, 1.38 * steady + cycle))
    assert "does not reproduce its mean torque" in found.sentence("x")
    found = reproduction(_torques(steady * (t < 300) + steady + cycle * (t < 300),
                                  1.5 * steady + cycle))
    assert "neither the regime nor the mean torque" in found.sentence("x")


def test_reproduces_is_said_exactly_when_the_criterion_holds():
    """A property over scaled and stick-slipping pairs: the sentence claims reproduction
    (no "not", "neither") exactly when Reproduction.reproduced."""
    from drillfric.report.reproduction import reproduction

    t = np.arange(6000) / 10.0
    steady = np.full(t.size, 20e3)
    cycle = 10e3 * np.sin(2 * np.pi * t / 5.0)
    for scale in (0.5, 0.85, 0.95, 1.0, 1.05, 1.09, 1.11, 1.2, 1.38):
        for m_cycle, f_cycle in ((0, 0), (1, 1), (1, 0.3), (1, 0), (0, 1)):
            found = reproduction(_torques(steady + m_cycle * cycle,
                                          scale * steady + f_cycle * cycle))
            said = found.sentence("x")
            claims = said.startswith("The fit reproduces") and " but not " not in said \
                and "neither" not in said
            assert claims == found.reproduced, (scale, m_cycle, f_cycle, said)
