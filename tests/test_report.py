"""Reports (issue 7): the per-well report.html / report.pdf, the fleet report, the CLI.

The bundled example (examples/demo) is run once per test session into a temporary directory
(:func:`demo_result_dir`, shared with tests/test_report_browser.py); other cases are copies
of it with an edited summary.json. The browser checks are in test_report_browser.py.
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
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.figure import Figure

from drillfric.errors import InputError
from drillfric.report import MAX_SEGMENT_FIGURES, figures, write_fleet_report, write_well_report
from drillfric.report.data import load_result, segment_estimates, segments_frame
from drillfric.report.well import select_segments

REPO = Path(__file__).resolve().parents[1]
DEMO = REPO / "examples" / "demo" / "demo.csv"
XSS_NAME = "<script>alert(1)</script>"
_PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def demo_result_dir(tmp_path_factory) -> Path:
    """OUT/demo of ``drillfric run examples/demo/demo.csv``, run once per session (~25 s)."""
    out = tmp_path_factory.getbasetemp() / "report-demo"
    result = out / "demo"
    if not (result / "summary.json").is_file():
        from drillfric.io.well import open_well
        from drillfric.pipeline import run_well

        run_well(open_well(DEMO), out)
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
def demo_html(demo) -> str:
    return write_well_report(demo).read_text(encoding="utf-8")


def _png_images(html: str) -> list[bytes]:
    return [base64.b64decode(m) for m in re.findall(r'src="data:image/png;base64,([^"]+)"',
                                                     html)]


# --- the per-well HTML report ----------------------------------------------------------------

def test_well_report_has_every_section(demo, demo_html):
    """Header, inputs with hashes, configuration, well path, profiles, friction log,
    one open section per estimated segment, the diagnostics table (issue 7, item 1)."""
    summary = json.loads((demo / "summary.json").read_text())
    for heading in ("Inputs and configuration", "Well path", "Normal force and F_c profiles",
                    "Friction log", "Segments", "Diagnostics", "Effective configuration"):
        assert f">{heading}<" in demo_html, heading
    for entry in ("data", "config", "survey"):
        assert summary["inputs"][entry]["sha256"] in demo_html
    assert f"drillfric {summary['drillfric_version']}" in demo_html
    assert f"{summary['mu_k']:.3f}" in demo_html
    estimated = [s for s in summary["segments"] if s["status"] == "ok"]
    assert demo_html.count("<details open>") == len(estimated)
    table = demo_html.split('id="diagnostics-table"')[1].split("</table>")[0]
    assert table.count("<tr") == len(summary["segments"]) + 1


def test_well_report_is_self_contained(demo_html):
    """No external reference: every src/href is a data: URI or an in-page anchor, and every
    embedded image is a PNG (issue 7, item 3)."""
    refs = re.findall(r'(?:src|href)="([^"]*)"', demo_html)
    assert refs and all(r.startswith(("data:image/png;base64,", "#")) for r in refs)
    assert "<link" not in demo_html and "@import" not in demo_html and "url(" not in demo_html
    images = _png_images(demo_html)
    assert len(images) >= 4 and all(i.startswith(_PNG_MAGIC) for i in images)


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
    assert "1 segment(s) failed" in html


def test_result_without_segments_renders(tmp_path, demo):
    """A run that found no rotating segment still gets a report saying so."""
    result = copy_result(demo, tmp_path / "w", lambda s: s.update(segments=[]))
    for name in ("estimates.parquet", "profiles.parquet", "segments.parquet"):
        (result / name).unlink()
    html = write_well_report(result, pdf=True).read_text(encoding="utf-8")
    assert "0 of 0 estimated segment(s) drawn" in html
    assert (result / "report.pdf").stat().st_size > 0


def test_not_a_result_directory_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="not a directory"):
        write_well_report(tmp_path / "missing")
    with pytest.raises(InputError, match="no summary.json"):
        write_well_report(tmp_path)
    (tmp_path / "summary.json").write_text("{not json", encoding="utf-8")
    with pytest.raises(InputError, match="unreadable summary.json"):
        write_well_report(tmp_path)


def test_report_is_fast(demo):
    """Issue 7: the report runs at the end of every nightly run. CPU time (not wall time:
    the machine is shared) of the demo's HTML report; measured ≈ 1.8 s, bound 3× that."""
    write_well_report(demo)
    start = time.process_time()
    write_well_report(demo)
    assert time.process_time() - start < 6.0


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
        assert "<script>" not in page


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
    assert "<script" not in html.lower()


# --- the PDF ---------------------------------------------------------------------------------

def test_pdf_has_a_page_per_section_none_blank(demo):
    """report.pdf: header, well path, profiles, friction log, one page per drawn segment,
    diagnostics, configuration — in that order, each page titled; none blank."""
    from pypdf import PdfReader

    write_well_report(demo, pdf=True)
    pdf = demo / "report.pdf"
    summary = json.loads((demo / "summary.json").read_text())
    n_segments = sum(s["status"] == "ok" for s in summary["segments"])
    expected = (["Friction report — demo", "Well path", "Normal force and F_c profiles",
                 "Friction log"] + [f"Segment {i}" for i in range(1, n_segments + 1)]
                + ["Diagnostics", "Configuration"])
    texts = [page.extract_text() for page in PdfReader(pdf).pages]
    assert len(texts) >= len(expected)
    assert all(title in text for title, text in zip(expected, texts, strict=False))
    assert all("Configuration (continued)" in t for t in texts[len(expected):])
    if shutil.which("pdftoppm") is None:
        assert all(len(t.strip()) > 20 for t in texts)
        return
    for page in range(1, len(texts) + 1):
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
    refs = re.findall(r'(?:src|href)="([^"]*)"', html)
    assert all(r.startswith(("data:image/png;base64,", "./")) for r in refs)


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

def test_figures_build_headless_without_pyplot(demo):
    """Figures build in a fresh interpreter with no display and no backend chosen: no pyplot
    (no window, no global state), PNG and PDF output (issue 7: Agg)."""
    code = f"""
import io, sys
from pathlib import Path
from drillfric.report import figures
from drillfric.report.data import load_result, segment_estimates
d = load_result(Path({str(demo)!r}))
est = segment_estimates(d.result_dir, [1])
row = d.segments.set_index("id", drop=False).loc[1]
figs = [figures.wellpath_figure(d.wellpath), figures.profiles_figure(d.profiles, d.segments),
        figures.friction_log_figure(d.segments), figures.segment_figure(est[1], row),
        figures.fleet_friction_figure([("a", d.segments)])]
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
    assert done.stdout.strip() == "ok 5"


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


def test_segment_figure_draws_every_start_and_shades_stuck_time(demo):
    """Fig. 10 view: one μ_k and one μ_s line per start (+ the seeded pass); stuck shaded."""
    data = load_result(demo)
    row = data.segments.set_index("id", drop=False).loc[2]
    est = segment_estimates(demo, [2])[2]
    fig = figures.segment_figure(est, row)
    n_lines = est["start_id"].nunique()
    assert len(fig.axes[0].get_lines()) == 2 * n_lines
    assert n_lines == len(row["starts"]) + 1
    shaded = fig.axes[2].collections
    assert shaded and est["bit_stuck"].any()


def test_segment_figure_draws_the_ensemble_band(demo, tmp_path):
    """The seeded pass's min–max bit speed (docs/bit_speed.md) is shaded when the results
    have it, and results written before the band existed still render, without it."""
    data = load_result(demo)
    row = data.segments.set_index("id", drop=False).loc[2]
    est = segment_estimates(demo, [2])[2]
    labels = figures.segment_figure(est, row).axes[2].get_legend_handles_labels()[1]
    assert "ensemble band (min–max)" in labels
    old = est.drop(columns=["bit_rpm_est_min", "bit_rpm_est_max"])
    labels = figures.segment_figure(old, row).axes[2].get_legend_handles_labels()[1]
    assert "ensemble band (min–max)" not in labels and "estimated" in labels


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
    from drillfric.report.render import fmt, mu_s_text

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
    (THEORY §6: a creep break-over); with one it does not."""
    for identified in (True, False):
        out = copy_result(demo, tmp_path / str(identified),
                          lambda s, v=identified: s.update(mu_s=0.6 if v else None))
        html = write_well_report(out).read_text(encoding="utf-8")
        assert ("creep break-over" in html) is (not identified)
