"""Reports (issues 7 and 16): report.html / report.pdf, the fleet report, the CLI.

The bundled example (examples/demo) is run once per test session into a temporary directory
(:func:`demo_result_dir`, shared with tests/test_report_browser.py). :func:`evidence_dir`
completes a copy of it with the issue-16 files and columns (tracks.parquet, torque columns,
new segment keys: tests/synthetic_results.py); the plain demo stands for older results.
Other cases are copies with an edited summary.json. The browser checks are in
test_report_browser.py.
"""

from __future__ import annotations

import base64
import json
import math
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.figure import Figure

from drillfric.errors import ConfigError, InputError
from drillfric.report import MAX_SEGMENT_FIGURES, figures, write_fleet_report, write_well_report
from drillfric.report.data import extreme_rows, segment_estimates, segments_frame
from drillfric.report.interactive import script_hash
from drillfric.report.well import select_segments
from tests.synthetic_results import (
    UNRESOLVED_REASON,
    UNRESOLVED_SEGMENT,
    add_evidence_files,
    older_result,
)

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[1]
DEMO = REPO / "examples" / "demo" / "demo.csv"
XSS_NAME = "<script>alert(1)</script>"
_PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def demo_result_dir(tmp_path_factory) -> Path:
    """OUT/demo of ``drillfric run examples/demo/demo.csv``, run once per session (~25 s)."""
    out = tmp_path_factory.getbasetemp() / "report-demo"
    result = out / "demo"
    if not (result / "summary.json").is_file():
        import drillfric

        drillfric.run(DEMO, out)
    return result


#: Clock time given to the evidence copy of the demo log.
CLOCK = "2024-03-01T06:00:00+00:00"


def evidence_dir(tmp_path_factory) -> Path:
    """A copy of the demo results with the issue-16 files and columns, once per session."""
    result = tmp_path_factory.getbasetemp() / "report-evidence" / "demo"
    if not (result / "tracks.parquet").is_file():
        shutil.rmtree(result, ignore_errors=True)
        shutil.copytree(demo_result_dir(tmp_path_factory), result)
        add_evidence_files(result, DEMO, clock=CLOCK)
    return result


def copy_result(src: Path, dst: Path, edit=None) -> Path:
    """A copy of a result directory, its summary.json passed through ``edit(summary)``."""
    shutil.copytree(src, dst)
    if edit is not None:
        summary = json.loads((dst / "summary.json").read_text(encoding="utf-8"))
        edit(summary)
        (dst / "summary.json").write_text(json.dumps(summary), encoding="utf-8")
    return dst


def renamed_result(tmp_path: Path, name: str, src: Path) -> Path:
    """A copy of the results ``src`` whose well is called ``name`` (directory ``xss``)."""
    return copy_result(src, Path(tmp_path) / "xss", lambda s: s.update(well=name))


def fleet_wells(out: Path, demo: Path) -> list[dict]:
    """Three copies of the demo well (alpha, bravo, charlie) and one failed well."""
    wells = []
    for index, name in enumerate(("alpha", "bravo", "charlie")):
        def edit(summary, name=name, shift=0.02 * index):
            summary["well"] = name
            for seg in summary["segments"]:
                seg["mu_k"] = None if seg["mu_k"] is None else seg["mu_k"] + shift
        result = copy_result(demo, out / name, edit)
        wells.append({"well": name, "status": "ok", "message": "", "result_dir": Path(name),
                      "summary": json.loads((result / "summary.json").read_text())})
    wells.append({"well": "delta", "status": "failed", "result_dir": None, "summary": None,
                  "message": "delta.csv: disk full — fix: free space and rerun"})
    return wells


@pytest.fixture(scope="module")
def demo(tmp_path_factory) -> Path:
    return demo_result_dir(tmp_path_factory)


@pytest.fixture(scope="module")
def evidence(tmp_path_factory) -> Path:
    return evidence_dir(tmp_path_factory)


@pytest.fixture(scope="module")
def demo_html(evidence) -> str:
    return write_well_report(evidence).read_text(encoding="utf-8")


def bokeh_items(html: str) -> dict[str, dict]:
    """The Bokeh items of a report, by target element id."""
    text = html.split('<script type="application/json" id="bokeh-items">')[1]
    return {item["target_id"]: item for item in json.loads(text.split("</script>")[0])}


def bokeh_nodes(item, name: str):
    """Every model named ``name`` in a Bokeh item's JSON, depth first."""
    if isinstance(item, list):
        for v in item:
            yield from bokeh_nodes(v, name)
    elif isinstance(item, dict):
        if item.get("name") == name:
            yield item
        for v in item.values():
            yield from bokeh_nodes(v, name)


def decoded(v) -> np.ndarray:
    """A column of a ColumnDataSource as an array (Bokeh's wire format: base64 bytes,
    gzip-compressed when large; or a plain list)."""
    import gzip

    if isinstance(v, dict) and v.get("type") == "ndarray":
        if isinstance(v["array"], list):
            return np.asarray(v["array"])
        raw = base64.b64decode(v["array"]["data"])
        raw = gzip.decompress(raw) if raw[:2] == b"\x1f\x8b" else raw
        return np.frombuffer(raw, dtype=v["dtype"])
    return np.asarray(v)


def sources(item: dict) -> dict[str, dict[str, np.ndarray]]:
    """Named ColumnDataSources of a Bokeh item, decoded to arrays."""
    return {node["attributes"]["name"]: {k: decoded(v) for k, v in
                                         node["attributes"]["data"]["entries"]}
            for node in bokeh_nodes(item, "ColumnDataSource")
            if node.get("attributes", {}).get("name")}


def _png_images(html: str) -> list[bytes]:
    return [base64.b64decode(m) for m in re.findall(r'src="data:image/png;base64,([^"]+)"',
                                                     html)]


# --- the per-well HTML report ----------------------------------------------------------------

def test_well_report_has_every_section(evidence, demo_html):
    """Header, time tracks, friction log, broomstick, one open section per estimated
    segment, diagnostics, well path, profiles, inputs with hashes, the string as a table,
    the configuration (issues 7 and 16)."""
    demo = evidence
    summary = json.loads((demo / "summary.json").read_text())
    for heading in ("Time tracks", "Friction log", "Broomstick: hook load and torque versus "
                    "depth", "Segments", "Diagnostics", "Well path",
                    "Normal force and F_c profiles", "Inputs and configuration",
                    "Drill string", "Effective configuration"):
        assert f">{heading}<" in demo_html, heading
    items = bokeh_items(demo_html)
    assert {"bk-tracks", "bk-friction"} <= set(items)
    assert {f"bk-segment-{s['id']}" for s in summary["segments"]} <= set(items)
    for target in items:
        assert f'id="{target}"' in demo_html
    assert "5 7/8in DP" in demo_html.split('id="string-table"')[1].split("</table>")[0]
    for entry in ("data", "config", "survey"):
        assert summary["inputs"][entry]["sha256"] in demo_html
    assert f"drillfric {summary['drillfric_version']}" in demo_html
    assert f"{summary['mu_k']:.3f}" in demo_html
    estimated = [s for s in summary["segments"] if s["status"] == "ok"]
    assert demo_html.count("<details open>") == len(estimated)
    table = demo_html.split('id="diagnostics-table"')[1].split("</table>")[0]
    assert table.count("<tr") == len(summary["segments"]) + 1


def test_well_report_is_self_contained(demo_html):
    """No external reference outside the scripts: every src/href is a data: URI or an
    in-page anchor, every image a PNG (issue 7, item 3); exactly three scripts — Bokeh's
    core bundle, the figures' JSON (not executed) and the loader — and the
    Content-Security-Policy allows exactly the two executed ones by hash, no
    'unsafe-inline', no 'unsafe-eval', no network source (issue 16, item 5)."""
    scripts = re.findall(r"<script([^>]*)>(.*?)</script>", demo_html, flags=re.S)
    assert [attrs for attrs, _ in scripts] == ["", ' type="application/json" id="bokeh-items"',
                                                ""]
    outside = re.sub(r"<script[^>]*>.*?</script>", "", demo_html, flags=re.S)
    refs = re.findall(r'(?:src|href)="([^"]*)"', outside)
    assert refs and all(r.startswith(("data:image/png;base64,", "#")) for r in refs)
    assert "<link" not in outside and "@import" not in outside and "url(" not in outside
    images = _png_images(outside)
    assert len(images) >= 3 and all(i.startswith(_PNG_MAGIC) for i in images)
    from html import unescape

    csp = unescape(re.search(r'Content-Security-Policy" content="([^"]*)"', demo_html).group(1))
    policy = dict(part.strip().split(" ", 1) for part in csp.split(";"))
    assert policy["default-src"] == "'none'"
    assert policy["script-src"].split() == [script_hash(scripts[0][1]),
                                            script_hash(scripts[2][1])]
    assert "unsafe" not in policy["script-src"] and "http" not in csp


def test_assumed_defaults_are_highlighted(demo, tmp_path):
    """Every assumed default is listed in the highlighted box; none → no box."""
    notes = ["a vertical well with a nominal tortuosity of 1.0°/30 m, no survey found",
             "bit depth 2500 m: neither the log nor a survey"]
    result = copy_result(demo, tmp_path / "w", lambda s: s.update(assumed=notes,
                                                                  indicative=True))
    (result / "wellpath.parquet").unlink()
    html = write_well_report(result).read_text(encoding="utf-8")
    box = html.split('id="assumed"')[1].split("</div>")[0]
    assert all(note in box for note in notes)
    assert "indicative" in box
    assert ('<p class="note">No survey: the well was taken as vertical with a nominal '
            "tortuosity of 1°/30 m") in html

    def untortuous(summary):
        summary.update(assumed=["vertical well: no survey found"], indicative=True)
        summary["config"]["survey"]["tortuosity_deg_30m"] = 0.0

    plain = copy_result(demo, tmp_path / "v", untortuous)
    (plain / "wellpath.parquet").unlink()
    html = write_well_report(plain).read_text(encoding="utf-8")
    assert '<p class="note">No survey: the well was taken as vertical.</p>' in html
    assert "indicative: defaults assumed" in html
    assert 'id="assumed"' not in write_well_report(demo).read_text(encoding="utf-8")


def test_failed_and_skipped_segments_are_reported(demo, tmp_path):
    """Segments without estimates (None everywhere) still get a diagnostics row, coloured,
    with their message; they get no figure section."""
    def edit(summary):
        for seg, status in zip(summary["segments"][:2], ("failed", "skipped"), strict=True):
            for key in ("mu_s", "mu_k", "mu_s_lower_bound", "mu_s_spread", "mu_k_spread",
                        "settling_time_s", "residual_rms_rpm", "stick_slip_severity",
                        "mu_td", "stuck_fraction"):
                seg[key] = None
            seg.update(status=status, converged=False, method="none",
                       message=f"{status} because <b>reasons</b>", flags=[], starts=[])
        summary["counts"]["failed"] = 1
    result = copy_result(demo, tmp_path / "w", edit)
    html = write_well_report(result).read_text(encoding="utf-8")
    assert '<tr class="failed">' in html and '<tr class="skipped">' in html
    assert "failed because &lt;b&gt;reasons&lt;/b&gt;" in html
    assert 'id="segment-1"' not in html and 'id="segment-2"' not in html
    assert 'id="segment-3"' in html
    assert "1 segment failed" in html


def test_result_without_segments_renders(tmp_path, demo):
    """A run that found no rotating segment still gets a report saying so."""
    result = copy_result(demo, tmp_path / "w", lambda s: s.update(segments=[]))
    for name in ("estimates.parquet", "profiles.parquet", "segments.parquet"):
        (result / name).unlink()
    html = write_well_report(result, pdf=True).read_text(encoding="utf-8")
    assert "0 of 0 estimated segments drawn" in html
    assert (result / "report.pdf").stat().st_size > 0


def test_not_a_result_directory_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="not a directory"):
        write_well_report(tmp_path / "missing")
    with pytest.raises(InputError, match="no summary.json"):
        write_well_report(tmp_path)
    (tmp_path / "summary.json").write_text("{not json", encoding="utf-8")
    with pytest.raises(InputError, match="unreadable summary.json"):
        write_well_report(tmp_path)


# --- escaping of what comes from users' files ------------------------------------------------

def test_script_in_well_name_renders_as_text(demo, tmp_path):
    """A well named <script>alert(1)</script> is escaped in report.html and fleet.html."""
    result = renamed_result(tmp_path, XSS_NAME, demo)
    html = write_well_report(result).read_text(encoding="utf-8")
    fleet = write_fleet_report(tmp_path, [{
        "well": XSS_NAME, "status": "failed", "message": XSS_NAME, "result_dir": None,
        "summary": None}]).read_text(encoding="utf-8")
    for page in (html, fleet):
        assert "&lt;script&gt;alert(1)&lt;/script&gt;" in page
        assert "<script>alert" not in page
        # in the figures' JSON the name is data: its "<" cannot close the script element
        data = page.split('id="bokeh-items">')[1].split("</script>")[0] \
            if "bokeh-items" in page else ""
        assert "<" not in data


def test_user_text_with_dollar_signs_does_not_break_figures(demo, tmp_path):
    """Matplotlib would parse "$...$" as mathtext; names from users are drawn verbatim."""
    result = renamed_result(tmp_path, "well $\\frac{a}{$ odd", demo)
    summary = json.loads((result / "summary.json").read_text())
    write_well_report(result, pdf=True)
    write_fleet_report(tmp_path, [{"well": summary["well"], "status": "ok", "message": "",
                                   "result_dir": Path("xss"), "summary": summary}])


@settings(max_examples=15, deadline=None)
@given(name=st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=40))
def test_any_well_name_is_escaped_in_fleet_report(name):
    """Property: whatever a well is called, fleet.html shows exactly its escaped text, has no
    script element and its friction-log figure (legend with the name) still draws."""
    from markupsafe import escape

    summary = {"well": name, "mu_k": 0.3, "mu_s": None, "mu_s_lower_bound": 0.4,
               "segments": [{"id": 1, "kind": "off_bottom_rotating", "status": "ok",
                             "bit_depth_m": 1000.0, "mu_k": 0.3, "mu_s": None,
                             "mu_s_identifiable": False, "mu_s_lower_bound": 0.4,
                             "converged": True, "message": name}]}
    with tempfile.TemporaryDirectory() as tmp:
        path = write_fleet_report(Path(tmp), [
            {"well": name, "status": "ok", "message": name, "result_dir": Path("w"),
             "summary": summary},
            {"well": name, "status": "failed", "message": name, "result_dir": None,
             "summary": None}])
        with open(path, encoding="utf-8", newline="") as fh:  # keep "\r" as written
            html = fh.read()
    assert str(escape(name)) in html
    outside = re.sub(r"<script[^>]*>.*?</script>", "", html, flags=re.S)
    assert "<script" not in outside.lower()
    data = html.split('id="bokeh-items">')[1].split("</script>")[0]
    assert "<" not in data
    labels = [i["attributes"]["label"]["value"] for i in _legend_items(json.loads(data))]
    assert labels == [name]


# --- the PDF ---------------------------------------------------------------------------------

def test_pdf_pages_are_a4_landscape_numbered_and_in_order(evidence):
    """report.pdf: headline with the friction log, run details, time tracks, broomstick,
    well path, profiles, one page per drawn segment and its detail page, diagnostics, the
    string and the non-default settings as appendices — every
    page A4 landscape (one size), titled, numbered "page n of N", none blank (issue 16,
    item 6). A table longer than a page carries on a "(continued)" page under its title."""
    from pypdf import PdfReader

    write_well_report(evidence, pdf=True)
    pdf = evidence / "report.pdf"
    summary = json.loads((evidence / "summary.json").read_text())
    n_segments = sum(s["status"] == "ok" for s in summary["segments"])
    expected = (["Friction report — demo", "Run details", "Time tracks", "Broomstick",
                 "Well path", "Normal force and F_c profiles"]
                + [page for i in range(1, n_segments + 1)
                   for page in (f"Segment {i} — bit at", ": detail")]
                + ["Diagnostics", "Appendix: drill string", "Appendix: settings"])
    reader = PdfReader(pdf)
    texts = [page.extract_text() for page in reader.pages]
    first_pages = [t for t in texts if "(continued)" not in t]
    assert len(first_pages) == len(expected)
    assert all(title in text for title, text in zip(expected, first_pages, strict=True))
    sizes = {(round(float(p.mediabox.width)), round(float(p.mediabox.height)))
             for p in reader.pages}
    assert sizes == {(842, 595)}  # A4 landscape in points: 297 × 210 mm
    for number, text in enumerate(texts, start=1):
        assert f"page {number} of {len(texts)}" in text
    string_page = next(t for t in texts if "Appendix: drill string" in t)
    assert "5 7/8in DP" in string_page and "OD [mm]" in string_page
    assert not any('[{"' in t or '{"name"' in t for t in texts)  # no raw JSON
    _assert_pages_not_blank(pdf, len(texts))


def test_pdf_diagnostics_wrap_instead_of_shrinking(evidence, tmp_path):
    """A long message wraps over lines at the table's font size (7.5 pt) instead of being
    cut or shrinking the font (the old table shrank to fit its widest row); every word of
    it is on the page."""
    from pypdf import PdfReader

    words = " ".join(f"word{i:02d}" for i in range(40))
    result = copy_result(evidence, tmp_path / "w", lambda s: s["segments"][0].update(
        message=words))
    write_well_report(result, pdf=True)
    pages = PdfReader(result / "report.pdf").pages
    diag = " ".join(p.extract_text() for p in pages if "Diagnostics" in p.extract_text())
    assert all(f"word{i:02d}" in diag for i in range(40))
    sizes = set()
    for page in pages:
        if "Diagnostics" in page.extract_text():
            page.extract_text(visitor_operand_before=lambda op, args, cm, tm: sizes.add(
                round(float(args[1]), 1)) if op == b"Tf" else None)
    assert 7.5 in sizes and min(sizes) >= 7.0  # table text 7.5 pt; footer 7 pt


def _assert_pages_not_blank(pdf: Path, count: int) -> None:
    if shutil.which("pdftoppm") is None:
        return
    for page in range(1, count + 1):
        png = subprocess.run(["pdftoppm", "-r", "20", "-gray", "-f", str(page), "-l",
                              str(page), str(pdf)], capture_output=True, check=True).stdout
        pixels = np.frombuffer(png.split(b"\n", 3)[3], dtype=np.uint8)  # PGM body
        assert pixels.min() < 128 and (pixels < 250).mean() > 0.003, f"page {page} is blank"


# --- the fleet report ------------------------------------------------------------------------

def test_fleet_report_rows_links_and_failures_first(demo, tmp_path):
    """One row per well, failed wells with their messages above the table, relative links
    to each well's report, consensus μ of each well (issue 7, item 2)."""
    wells = fleet_wells(tmp_path, demo)
    html = write_fleet_report(tmp_path, wells).read_text(encoding="utf-8")
    assert html.index('id="failed-wells"') < html.index('id="wells-table"')
    assert "delta.csv: disk full" in html.split('id="wells-table"')[0]
    table = html.split('id="wells-table"')[1].split("</table>")[0]
    assert table.count("<tr") == len(wells) + 1
    for well in wells[:3]:
        assert f'href="./{well["well"]}/report.html"' in table
        assert (tmp_path / well["well"] / "report.html").is_file()
        assert f'{well["summary"]["mu_k"]:.3f}' in table
    outside = re.sub(r"<script[^>]*>.*?</script>", "", html, flags=re.S)
    refs = re.findall(r'(?:src|href)="([^"]*)"', outside)
    assert all(r.startswith(("data:image/png;base64,", "./")) for r in refs)
    wells_plotted = {s["attributes"]["label"]["value"] for s in _legend_items(
        bokeh_items(html)["bk-fleet"])}
    assert wells_plotted == {"alpha", "bravo", "charlie"}


def test_fleet_friction_axis_starts_at_zero(tmp_path):
    """Issue 35: three wells with the same μ_k (0.2768–0.2798 over their stands) were drawn on
    an auto-scaled axis of that span, a zigzag; the μ_k axis starts at 0 as a well's does."""
    segments = [{"id": i + 1, "kind": "off_bottom_rotating", "status": "ok",
                 "bit_depth_m": 2000.0 + 30 * i, "mu_k": mu, "converged": True}
                for i, mu in enumerate((0.2768, 0.2798, 0.2771, 0.2795))]
    wells = [{"well": name, "status": "ok", "message": "", "result_dir": Path(name),
              "summary": {"well": name, "mu_k": 0.278, "segments": segments}}
             for name in ("a", "b", "c")]
    html = write_fleet_report(tmp_path, wells).read_text(encoding="utf-8")
    ranges = list(bokeh_nodes(bokeh_items(html)["bk-fleet"], "DataRange1d"))
    depth = [r for r in ranges if r.get("attributes", {}).get("flipped")]
    mu = [r for r in ranges if "start" in r.get("attributes", {}) and r not in depth]
    assert len(depth) == 1 and len(mu) == 1, ranges
    assert mu[0]["attributes"]["start"] == 0.0


def test_fleet_report_partial_wells_apparent_and_drag_mu_and_first_night(tmp_path):
    """Issue 35 (a newcomer's fleet of demo, F-9 and F-5): F-9 showed "ok" with 9 of its 23
    segments failed; the μ_k of the summary mixed F-5's apparent μ with the demo's μ_k and
    the drag μ was nowhere; the first night said "What changed since the last night". Now:
    "partial: 9 of 23 segments failed" (not the green ok), apparent μ and μ drag in their
    own columns (μ_k stays the consensus), and a first night says so."""
    demo = [{"id": i + 1, "kind": "off_bottom_rotating", "status": "ok", "mu_k": 0.28,
             "bit_depth_m": 2000.0 + 30 * i, "converged": True} for i in range(4)]
    f9 = [{"id": i + 1, "kind": "off_bottom_rotating", "status": "failed" if i < 9 else
           "skipped", "mu_k": None, "bit_depth_m": 150.0} for i in range(23)]
    f5 = [{"id": i + 1, "kind": "on_bottom_rotating", "status": "ok", "mu_k": mu,
           "bit_depth_m": 3000.0 + 30 * i, "converged": True}
          for i, mu in enumerate((0.15, 0.17, 0.19))]
    drag = {"log": [{"mu_drag": 0.21}, {"mu_drag": None}, {"mu_drag": 0.25}]}
    wells = [
        {"well": "demo", "status": "ok", "result_dir": Path("demo"), "first_run": True,
         "summary": {"mu_k": 0.28, "segments": demo, "counts": {"segments": 4},
                     "drag": drag}, "changes": ["4 new segments"]},
        {"well": "F-9", "status": "ok", "result_dir": Path("F-9"), "failed_segments": 9,
         "first_run": True, "summary": {"mu_k": None, "segments": f9,
                                        "counts": {"segments": 23}}},
        {"well": "F-5", "status": "ok", "result_dir": Path("F-5"), "first_run": True,
         "summary": {"mu_k": None, "segments": f5, "counts": {"segments": 3}}}]
    html = write_fleet_report(tmp_path, wells).read_text(encoding="utf-8")
    assert "What changed since the last night" not in html
    assert '<h2 class="first" id="overnight">First run</h2>' in html
    table = html.split('id="wells-table"')[1].split("</table>")[0]
    rows = {r.split("<b>")[1].split("</b>")[0]: r for r in table.split("<tr")[2:]}
    assert "partial: 9 of 23 segments failed" in rows["F-9"]
    assert 'badge ok"' not in rows["F-9"]
    assert "1 partial (some segments failed)" in html
    assert re.search(r'mu-apparent">0\.170 \(3\)', rows["F-5"])
    assert re.search(r'mu-drag">0\.230 \(2\)', rows["demo"])
    assert re.search(r'mu-apparent">—', rows["demo"])
    wells[1]["first_run"] = False
    html = write_fleet_report(tmp_path, wells).read_text(encoding="utf-8")
    assert "What changed since the last night" in html
    assert "first run (nothing to compare with): demo, F-5" in html


def test_fleet_summary_keeps_apparent_mu_out_of_mu_k():
    """Issue 35: fleet_summary.parquet's mu_k held a depth log's apparent μ beside other wells'
    μ_k; apparent μ is in mu_apparent, and the well's failed segments and drag μ are columns."""
    from drillfric.fleet.run import WellOutcome, summary_frame

    seg = [{"id": 1, "kind": "on_bottom_rotating", "status": "ok", "mu_k": 0.18},
           {"id": 2, "kind": "off_bottom_rotating", "status": "ok", "mu_k": 0.27},
           {"id": 3, "kind": "off_bottom_rotating", "status": "failed", "mu_k": None}]
    frame = summary_frame([WellOutcome("A", "ok", summary={
        "mu_k": 0.27, "segments": seg, "drag": {"log": [{"mu_drag": 0.3}]}},
        failed_segments=1, first_run=True)])
    assert pd.isna(frame["mu_k"].iloc[0])
    assert frame["mu_apparent"].iloc[0] == 0.18 and pd.isna(frame["mu_apparent"].iloc[1])
    assert frame["mu_k"].iloc[1] == 0.27
    assert (frame["well_failed_segments"] == 1).all() and frame["well_first_run"].all()
    assert (frame["well_mu_apparent"] == 0.18).all() and (frame["well_mu_drag"] == 0.3).all()


def test_fleet_link_is_relative_and_encoded(tmp_path, monkeypatch):
    """Absolute result directories become relative links; odd characters are encoded (a
    directory called "javascript:x" must not become a javascript: link); a directory relative
    to the working directory (OUT/NAME) is made relative to the fleet directory."""
    from drillfric.report.fleet import _link

    assert _link(tmp_path, tmp_path / "a b") == "./a%20b/report.html"
    assert _link(tmp_path, Path("javascript:x")) == "./javascript%3Ax/report.html"
    assert _link(tmp_path, None) is None
    (tmp_path / "out" / "w1").mkdir(parents=True)
    monkeypatch.chdir(tmp_path)
    assert _link(Path("out"), Path("out") / "w1") == "./w1/report.html"
    assert _link(Path("out"), Path("w1")) == "./w1/report.html"


# --- figures ---------------------------------------------------------------------------------

def test_figures_build_headless_without_pyplot(evidence):
    """Figures build in a fresh interpreter with no display and no backend chosen: no pyplot
    (no window, no global state), PNG and PDF output (issue 7: Agg)."""
    code = f"""
import io, sys
from pathlib import Path
from drillfric.report import figures
from drillfric.report.data import load_result, segment_estimates
from drillfric.report.evidence import evidence_figure
from drillfric.report.tracks import tracks_figure
from drillfric.report.well import build_report
d = load_result(Path({str(evidence)!r}))
est = segment_estimates(d.result_dir, [2])
row = d.segments.set_index("id", drop=False).loc[2]
from drillfric.torque_drag import broomstick_figure
bs = build_report(d.result_dir).broomstick
figs = [figures.wellpath_figure(d.wellpath), figures.profiles_figure(d.profiles, d.segments),
        figures.friction_log_figure(d.segments), evidence_figure(est[2], row, d.time_origin),
        tracks_figure(d.tracks, d.segments, d.time_origin),
        broomstick_figure(bs.table, bs.points)]
for f in figs:
    for fmt in ("png", "pdf"):
        f.savefig(io.BytesIO(), format=fmt)
assert "matplotlib.pyplot" not in sys.modules, "pyplot imported"
print("ok", len(figs))
"""
    env = {k: v for k, v in __import__("os").environ.items()
           if k not in ("DISPLAY", "WAYLAND_DISPLAY", "MPLBACKEND")}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, cwd=REPO, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "ok 6"


def _segments(rows: list[dict]) -> pd.DataFrame:
    base = {"kind": "off_bottom_rotating", "status": "ok", "message": "", "method": "batch",
            "converged": True, "mu_s_identifiable": True, "mu_s": 0.5, "mu_k": 0.3,
            "mu_s_lower_bound": None, "mu_s_spread": 0.02, "mu_k_spread": 0.01,
            "mu_td": 0.29, "residual_rms_rpm": 1.0, "bit_depth_m": 1000.0}
    return segments_frame([{**base, "id": i + 1, **row} for i, row in enumerate(rows)])


def _markers(fig: Figure) -> dict[str, int]:
    """Marker → number of points drawn with it (line markers and error-bar markers)."""
    counts: dict[str, int] = {}
    for line in fig.axes[0].get_lines():
        marker = line.get_marker()
        if marker not in (None, "None", "", " "):
            counts[marker] = counts.get(marker, 0) + len(line.get_xdata())
    return counts


def test_friction_log_marks_bounds_unconverged_and_missing_differently():
    """μ_s lower bounds as ▷ (not as points), T&D crosses, missing stands as diamonds;
    not-converged points hollow."""
    seg = _segments([{"bit_depth_m": 1000.0},
                     {"bit_depth_m": 1030.0, "mu_s_identifiable": False, "mu_s": None,
                      "mu_s_lower_bound": 0.45},
                     {"bit_depth_m": 1060.0, "converged": False},
                     {"bit_depth_m": 1090.0, "status": "failed", "mu_k": None, "mu_s": None,
                      "mu_td": None}])
    fig = figures.friction_log_figure(seg)
    marks = _markers(fig)
    assert marks[">"] == 1  # the one lower bound
    assert marks["s"] == 2  # μ_s points: identified segments 1 and 3 only
    assert marks["o"] == 3  # μ_k of the three estimated segments
    assert marks["x"] == 3 and marks["d"] == 1
    hollow = [ln for ln in fig.axes[0].get_lines() if ln.get_markerfacecolor() == "none"
              and ln.get_marker() in ("o", "s")]
    assert sorted(len(ln.get_xdata()) for ln in hollow) == [1, 1]  # segment 3: μ_k and μ_s


def _final_rows(result: Path, seg_id: int) -> pd.DataFrame:
    est = pd.read_parquet(result / "estimates.parquet")
    return est[(est["segment_id"] == seg_id) & (est["start_id"] == -1)].sort_values("time_s")


@pytest.mark.parametrize("seg_id", [1, 2, 3])
def test_evidence_plot_data_equal_estimates(evidence, demo_html, seg_id):
    """Issue 16, item 1: what the evidence figure of a segment draws is estimates.parquet's
    columns — measured, observer and fit torque, their residuals, measured and estimated
    speed, the speed residual, the bit speed and its band — at the rows it keeps (float32
    in the page: 7 significant digits). Segment 1's fit did not simulate (NaN): no fit
    series. Segment UNRESOLVED_SEGMENT's bit speed is not resolved: no bit-speed panel.
    Segments with the same panels reuse one serialised layout with their own data."""
    data = sources(bokeh_items(demo_html)[f"bk-segment-{seg_id}"])
    final = _final_rows(evidence, seg_id)
    origin_ms = pd.Timestamp(CLOCK).value / 1e6
    torque = data["panel:torque"]
    time_s = (torque["x"] - origin_ms) / 1e3
    rows = final.set_index(final["time_s"].round(3)).loc[np.round(time_s, 3)]
    for name, col in (("measured", "surface_torque_Nm"), ("observer", "surface_torque_est_Nm"),
                      ("fit", "surface_torque_fit_Nm")):
        if seg_id == 1 and name == "fit":
            assert name not in torque
            continue
        np.testing.assert_allclose(torque[name] * 1e3, rows[col], rtol=2e-7, atol=1e-3)
        if name == "measured":
            continue
        np.testing.assert_allclose(data["panel:torque_residual"][name] * 1e3,
                                   rows["surface_torque_Nm"] - rows[col], rtol=1e-6, atol=2e-3)
    speed = data["panel:speed"]
    np.testing.assert_allclose(speed["measured"], rows["surface_rpm"], rtol=2e-7, atol=1e-5)
    np.testing.assert_allclose(speed["estimated"], rows["surface_rpm_est"], rtol=2e-7,
                               atol=1e-5)
    np.testing.assert_allclose(data["panel:speed_residual"]["residual"], rows["residual_rpm"],
                               rtol=2e-7, atol=1e-5)
    if seg_id == UNRESOLVED_SEGMENT:  # bit speed not resolved: no bit trace is drawn
        assert "panel:bit" not in data and "stuck" not in data
        assert final["bit_rpm_est"].isna().all()
    else:
        bit = data["panel:bit"]
        np.testing.assert_allclose(bit["estimated"], rows["bit_rpm_est"], rtol=2e-7,
                                   atol=1e-5)
        np.testing.assert_allclose(bit["low"], rows["bit_rpm_est_min"], rtol=2e-7, atol=1e-5)
        np.testing.assert_allclose(bit["measured"], rows["bit_rpm"], rtol=2e-7, atol=1e-5)
    starts = {k for k in data if k.startswith("start:")}
    assert len(starts) == final_start_count(evidence, seg_id)


def final_start_count(result: Path, seg_id: int) -> int:
    est = pd.read_parquet(result / "estimates.parquet", columns=["segment_id", "start_id"])
    return est.loc[est["segment_id"] == seg_id, "start_id"].nunique()


def test_evidence_keeps_the_extremes_of_a_long_segment():
    """Decimating 36 000 rows (1 h at 10 Hz) of 5-s stick-slip to ≤ 1500: every cycle is
    shorter than the kept spacing, yet the global and per-bucket extremes stay, so the
    drawn swing equals the data's (a stride would alias it)."""
    t = np.arange(0.0, 3600.0, 0.1)
    rng = np.random.default_rng(3)
    frame = pd.DataFrame({"time_s": t,
                          "surface_torque_Nm": 1e4 + 5e3 * np.sin(2 * np.pi * t / 5.0)
                          + 100 * rng.standard_normal(t.size),
                          "surface_rpm": 60 + 40 * np.sin(2 * np.pi * t / 5.0),
                          "bit_rpm_est": np.maximum(0, 60 + 120 * np.sin(2 * np.pi * t / 5.0))})
    rows = extreme_rows(frame, 1500)
    assert len(rows) <= 1500 and np.all(np.diff(rows) > 0)
    kept = frame.iloc[rows]
    for col in ("surface_torque_Nm", "surface_rpm", "bit_rpm_est"):
        assert kept[col].max() == frame[col].max() and kept[col].min() == frame[col].min()
    # per ~2.4-min bucket the drawn swing is the data's (a stride of 24 samples loses it)
    strided = frame.iloc[::24]
    assert strided["surface_torque_Nm"].max() < frame["surface_torque_Nm"].max()


def test_old_results_degrade_to_notes(demo, tmp_path):
    """Results written before issue 16 (no tracks.parquet, no torque columns, no hook load
    per segment) still render: each missing section is a one-line note."""
    old = older_result(demo, tmp_path / "old")
    html = write_well_report(old).read_text(encoding="utf-8")
    assert "No time tracks: this result directory has no tracks.parquet" in html
    assert "No measured hook load or torque per segment" in html
    assert html.count("No torque evidence") == 4
    assert "bk-friction" in bokeh_items(html)


def test_tracks_plot_draws_tracks_parquet(evidence, demo_html):
    """Issue 16, item 2: each track draws tracks.parquet's min/max envelope and mean (in
    display units), and the strip names every rig state present."""
    tracks = pd.read_parquet(evidence / "tracks.parquet")
    item = bokeh_items(demo_html)["bk-tracks"]
    text = json.dumps(item)
    drawn = [d for d in _unnamed_sources(item) if "lo" in d]
    assert len(drawn) == 5  # hook load, torque, speed, hole depth, bit depth
    hook = next(d for d in drawn if np.nanmax(d["hi"]) > 700)  # kN
    finite = np.isfinite(hook["hi"])
    np.testing.assert_allclose(hook["hi"][finite] * 1e3, tracks["hookload_N_max"], rtol=1e-6)
    for state in ("rotating off bottom", "tripping", "idle"):
        assert state in text


def _unnamed_sources(item: dict) -> list[dict]:
    """Every ColumnDataSource's array columns (named or not)."""
    return [{k: decoded(v) for k, v in node["attributes"]["data"]["entries"]
             if isinstance(v, dict) and v.get("type") == "ndarray"}
            for node in bokeh_nodes(item, "ColumnDataSource")]


def _legend_items(item: dict) -> list[dict]:
    return list(bokeh_nodes(item, "LegendItem"))


def test_estimates_are_decimated_per_start(demo):
    full = pd.read_parquet(demo / "estimates.parquet")
    small = segment_estimates(demo, [1, 2], max_points=100)
    assert sorted(small) == [1, 2]
    for seg_id, frame in small.items():
        per_start = frame.groupby("start_id").size()
        assert per_start.max() <= 100
        assert set(per_start.index) == set(full.loc[full["segment_id"] == seg_id, "start_id"])


def test_select_segments_keeps_worst_and_latest():
    """With more estimated segments than the limit: the worst half and the latest rest."""
    rows = [{"residual_rms_rpm": float(i)} for i in range(25)]
    rows[3].update(converged=False)
    rows[7].update(status="failed")
    chosen = select_segments(_segments(rows), 10)
    assert len(chosen) == 10 and chosen == sorted(chosen)
    assert 4 in chosen and 8 not in chosen  # unconverged kept, failed never drawn
    assert {21, 22, 23, 24, 25} <= set(chosen)  # the worst by residual are also the latest
    assert select_segments(_segments(rows[:5]), 10) == [1, 2, 3, 4, 5]
    assert MAX_SEGMENT_FIGURES == 10


def test_fmt_handles_missing_values():
    from drillfric.report.display import fmt
    from drillfric.report.render import mu_s_text

    assert fmt(None) == "—" and fmt(math.nan) == "—" and fmt("x") == "—"
    assert fmt(0.12345) == "0.123" and fmt(True) == "yes"
    assert mu_s_text(0.5, True, None) == "0.500"
    assert mu_s_text(None, False, 0.4) == "≥ 0.400"
    assert mu_s_text(None, False, None) == "not identifiable"


# --- the CLI ---------------------------------------------------------------------------------

def test_report_command_rebuilds_html_and_pdf(demo, tmp_path):
    from drillfric.cli.main import cli

    result = copy_result(demo, tmp_path / "w")
    for name in ("report.html", "report.pdf"):
        (result / name).unlink(missing_ok=True)
    done = CliRunner().invoke(cli, ["report", str(result), "--pdf"])
    assert done.exit_code == 0, done.output
    assert (result / "report.html").is_file() and (result / "report.pdf").is_file()
    assert str(result / "report.html") in done.output


@pytest.mark.parametrize("make", [lambda p: p / "missing", lambda p: p])
def test_report_command_bad_directory_is_one_line_exit_2(tmp_path, make):
    from drillfric.cli.main import cli

    done = CliRunner().invoke(cli, ["report", str(make(tmp_path))])
    assert done.exit_code == 2
    assert len(done.output.strip().splitlines()) == 1
    assert "Traceback" not in done.output



def test_mu_s_advice_only_when_not_identified(demo, tmp_path):
    """Without an identified μ_s the report tells drillers how to make it measurable
    (docs/theory.md §6: a creep break-over); with one it does not."""
    for identified in (True, False):
        out = copy_result(demo, tmp_path / str(identified),
                          lambda s, v=identified: s.update(mu_s=0.6 if v else None))
        html = write_well_report(out).read_text(encoding="utf-8")
        assert ("creep break-over" in html) is (not identified)


# --- issue 16: segments option, string-weight check, diagnostics ---------------------------

def test_segments_option_draws_all_or_n(evidence, tmp_path):
    """`segments="all"` draws every estimated segment, an int that many (worst and latest),
    the default keeps MAX_SEGMENT_FIGURES; anything else is a ConfigError."""
    result = copy_result(evidence, tmp_path / "w")
    for segments, count in (("all", 4), (2, 2), (0, 0), ("3", 3)):
        html = write_well_report(result, segments=segments).read_text(encoding="utf-8")
        assert html.count('<section class="segment"') == count, segments
    for bad in ("some", -1, 1.5):
        with pytest.raises(ConfigError, match="segments"):
            write_well_report(result, segments=bad)


def test_report_command_segments_option(evidence, tmp_path):
    from drillfric.cli.main import cli

    result = copy_result(evidence, tmp_path / "w")
    done = CliRunner().invoke(cli, ["report", str(result), "--segments", "1"])
    assert done.exit_code == 0, done.output
    assert (result / "report.html").read_text().count('<section class="segment"') == 1
    done = CliRunner().invoke(cli, ["report", str(result), "--segments", "many"])
    assert done.exit_code == 2 and len(done.output.strip().splitlines()) == 1


def _points(measured_kN, model_kN, kinds=None) -> pd.DataFrame:
    n = len(measured_kN)
    return pd.DataFrame({"segment_id": np.arange(1, n + 1),
                         "kind": kinds or ["off_bottom_rotating"] * n,
                         "bit_depth_m": 1000.0 + 30 * np.arange(n),
                         "hookload_N": np.asarray(measured_kN) * 1e3,
                         "surface_torque_Nm": np.full(n, 1e4),
                         "hookload_model_N": np.asarray(model_kN) * 1e3})


def test_weight_check_rule_and_tolerance():
    """The hook carries string + block, so model ≤ measured. Flag a segment when the model
    exceeds the measurement by more than 5 % (HOOKLOAD_TOLERANCE); the implied block weight
    is the median of measured − model. On-bottom segments (WOB unloads the hook) are not
    checked."""
    from drillfric.report.broomstick import HOOKLOAD_TOLERANCE, weight_check

    assert HOOKLOAD_TOLERANCE == 0.05
    ok = weight_check(_points([800, 820, 840], [700, 720, 745]))
    assert ok["warning"] is None and ok["checked"] == 3
    assert ok["block_weight_N"] == pytest.approx(100e3)
    edge = weight_check(_points([800, 800], [800 * 1.049, 800 * 1.051]))
    assert edge["violations"] == [2] and "segment 2" in edge["warning"]
    on_bottom = weight_check(_points([500], [800], ["on_bottom_rotating"]))
    assert on_bottom["checked"] == 0 and on_bottom["warning"] is None


def test_weight_check_counts_only_segments_with_their_own_model_as_summary_does():
    """Issue 35 item 2 (DSATS): the report's notice counted a skipped segment (no modelled
    hook load of its own) with the broomstick table's value and named it the worst, while
    summary.json, which counts only the segments' own, said otherwise. The table fills in
    only for results with no segment's own model (older results)."""
    from drillfric.report.broomstick import weight_check

    table = pd.DataFrame({"load_case": ["rotating_off_bottom"] * 2,
                          "friction_factor": [0.2, 0.2], "bit_depth_m": [0.0, 3000.0],
                          "hookload_N": [0.0, 3e6]})
    points = _points([800, 820], [700, np.nan])
    check = weight_check(points, table)
    assert check["checked"] == 1 and check["warning"] is None
    older = weight_check(_points([800, 820], [np.nan, np.nan]), table)
    assert older["checked"] == 2


def test_report_warns_when_the_string_is_heavier_than_the_hook_load(evidence, tmp_path):
    """A modelled rotating hook load 20 % above the measured one is shown as a warning at
    the top and beside the broomstick; the consistent demo gets the implied block weight."""
    html = write_well_report(evidence).read_text(encoding="utf-8")
    assert 'id="weight-warning"' not in html and "implied travelling-block weight" in html

    def heavier(summary):
        for seg in summary["segments"]:
            seg["hookload_model_N"] = 1.2 * seg["hookload_N"]

    result = copy_result(evidence, tmp_path / "w", heavier)
    html = write_well_report(result).read_text(encoding="utf-8")
    warning = html.split('id="weight-warning">')[1].split("</li>")[0]
    assert "string weight inconsistent with the hook load" in warning
    assert "in all 4 off-bottom segments" in warning


def test_broomstick_measured_points_from_a_log():
    """`td --broomstick WELL` points: one per rotating segment of the log, its median hook
    load and mean torque over the segment's rows at its median bit depth."""
    from drillfric.config import load_config
    from drillfric.io.well import load_well
    from drillfric.report.broomstick import measured_points_from_log
    from drillfric.segmentation import segment

    well = load_well(DEMO)
    points = measured_points_from_log(well.surface, well.config)
    segs = segment(well.surface, well.config)
    assert len(points) == len(segs) == 4
    for seg, row in zip(segs, points.itertuples(), strict=True):
        rows = well.surface.iloc[seg.i_start:seg.i_end]
        assert row.hookload_N == rows["hookload_N"].median()
        assert row.surface_torque_Nm == pytest.approx(rows["surface_torque_Nm"].mean())
        assert row.bit_depth_m == seg.bit_depth_m
    assert load_config  # the demo's own configuration was used (sidecar demo.toml)


def test_diagnostics_fold_long_messages_and_name_unresolved_bit_speed(evidence, demo_html):
    """Messages longer than MESSAGE_FOLD_CHARS fold into a <details>; a segment whose bit
    speed is not resolved says so in its row, with the reason in its message."""
    from drillfric.report.render import MESSAGE_FOLD_CHARS

    table = demo_html.split('id="diagnostics-table"')[1].split("</table>")[0]
    rows = table.split("<tr")[2:]
    from markupsafe import escape

    reason = UNRESOLVED_REASON.split(":", 1)[1].strip()  # "bit speed not resolved:" once
    unresolved = rows[UNRESOLVED_SEGMENT - 1]
    assert "not resolved (10 s)" in unresolved
    assert f"not resolved: {escape(reason)}" in unresolved
    long = [r for r in rows if 'class="msg"' in r]
    for row in long:
        summary = row.split("<summary>")[1].split("</summary>")[0]
        assert len(summary) <= MESSAGE_FOLD_CHARS


def test_report_command_default_segments_is_the_library_default():
    from drillfric.cli.main import cli

    option = next(p for p in cli.commands["report"].params if p.name == "segments")
    assert option.default == str(MAX_SEGMENT_FIGURES)


def test_fleet_worst_severity_is_severe_where_one_is_withheld():
    """Regression (second reader): the fleet table's largest severity skipped a segment whose
    severity was withheld as beyond its validated range (≥ 2.1) and showed the mild 0.90 of
    another — a false "worst". docs/bit_speed.md."""
    from drillfric.report.fleet import _worst

    mild = {"status": "ok", "stick_slip_severity": 0.9, "quality_flags": []}
    severe = {"status": "ok", "stick_slip_severity": None,
              "quality_flags": ["stick_slip_beyond_validated"]}
    assert _worst([mild])["severity"] == "0.90"
    assert _worst([mild, severe])["severity"] == "severe"


def test_empty_friction_log_names_estimated_but_withheld_segments():
    """Issue 35 item 3 (DSATS): the friction log said "none of the 76 segment(s) was
    estimated with a bit depth (47 skipped)" where 29 had been estimated at 934–1120 m and
    withheld by the hook-load check. It now says so."""
    from drillfric.report.well import no_friction_note

    seg = pd.DataFrame({"status": ["ok", "ok", "skipped"],
                        "bit_depth_m": [934.0, 1120.0, None], "mu_k": [None, None, None],
                        "quality_flags": [["hookload_contradicts_string"],
                                          ["hookload_contradicts_string"], []]})
    note = no_friction_note(seg)
    assert "2 of 3 segments were estimated at 934–1120 m" in note
    assert "withheld by the hook-load check" in note and "1 skipped" in note
    skipped = no_friction_note(seg.assign(status=["skipped"] * 3))
    assert "no segment was estimated with a bit depth (3 segments: 3 skipped)" in skipped
    from drillfric.report.display import Units

    assert "estimated at 3064–3675 ft" in no_friction_note(seg, Units("field"))  # not m


def test_an_empty_severity_panel_says_why():
    """Issue 35 item 10: the stick-slip severity panel was empty in every friction log
    (demo, DSATS, F-5, live) with no note why. It now counts the reasons: severe stick-slip
    (beyond the validated range), undetermined, bit speed not resolved or withheld, on
    bottom."""
    from drillfric.report.render import severity_note

    seg = pd.DataFrame({"status": ["ok", "ok", "ok", "ok", "skipped"],
                        "kind": ["off_bottom_rotating"] * 3 + ["on_bottom_rotating"] * 2,
                        "quality_flags": [["stick_slip_beyond_validated"],
                                          ["stick_slip_undetermined"], [], [], []],
                        "bit_speed_resolved": [True, True, False, False, None]})
    assert severity_note(seg) == (
        "no severity shown: 1 severe (beyond the validated range), 1 undetermined, "
        "1 bit speed not resolved or withheld, 1 on bottom")


def test_mu_s_mark_on_axis_edge_in_friction_log():
    """Issue 35 (fourth newcomer): the friction log drew its largest μ_s on the axis edge
    (half cut) and the μ = 0 diamonds of segments without an estimate on the spine. The
    limits now hold every drawn mark — points, spread bars, bound tails — with a margin."""
    seg = _segments([{"bit_depth_m": 1000.0, "mu_s": 0.9, "mu_s_spread": 0.1},
                     {"bit_depth_m": 1030.0, "mu_s_identifiable": False, "mu_s": None,
                      "mu_s_lower_bound": 0.85},
                     {"bit_depth_m": 1090.0, "status": "failed", "mu_k": None, "mu_s": None,
                      "mu_td": None}])
    ax = figures.friction_log_figure(seg).axes[0]
    (x0, x1), (y_low, y_high) = ax.get_xlim(), sorted(ax.get_ylim())
    xs = [x for line in ax.get_lines() for x in np.asarray(line.get_xdata(), float)]
    ys = [y for line in ax.get_lines() for y in np.asarray(line.get_ydata(), float)]
    for collection in ax.collections:  # the spread bars
        for path in collection.get_segments():
            xs += list(np.asarray(path)[:, 0])
            ys += list(np.asarray(path)[:, 1])
    pad_x, pad_y = 0.02 * (x1 - x0), 0.02 * (y_high - y_low)
    assert x0 + pad_x < min(xs) and max(xs) < x1 - pad_x, (x0, x1, min(xs), max(xs))
    assert y_low + pad_y < min(ys) and max(ys) < y_high - pad_y, (y_low, y_high)
    assert ax.yaxis_inverted()


@pytest.mark.parametrize("stuck", [True, False])
def test_pdf_legend_lacks_estimated_stuck(stuck):
    """Issue 35 (fourth newcomer): the bit-speed panel's stuck shading had a legend entry
    in the HTML ("estimated stuck") and none in the PDF. Both name it when it is drawn,
    and neither when no period is stuck."""
    from matplotlib.figure import Figure

    from drillfric.report.evidence import STUCK_LABEL, _series_axes, evidence_sources, panel_data

    t = np.arange(0.0, 20.0, 0.5)
    bit_rpm = np.where((t > 5) & (t < 8), 0.0, 60.0) if stuck else np.full(t.size, 60.0)
    est = pd.DataFrame({"time_s": t, "start_id": -1, "surface_rpm": 60.0,
                        "surface_rpm_est": 60.0, "bit_rpm_est": bit_rpm,
                        "bit_stuck": bit_rpm < 1.0, "mu_k": 0.3, "mu_s": 0.5})
    ax = Figure().subplots()
    data = panel_data(est)
    _series_axes(ax, "bit", data["bit"], t, t, est, None)
    labels = ax.get_legend_handles_labels()[1]
    sources = evidence_sources(est, None)
    assert (STUCK_LABEL in labels) is stuck and labels.count(STUCK_LABEL) <= 1
    assert ("stuck" in sources) is stuck
