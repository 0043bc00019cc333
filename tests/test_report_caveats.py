"""Issue 35 items 4 and 11 on the demo's report: nothing the report says is cut in the PDF
(the page-1 headline and every note of every segment are in its text, whole), and each
segment leads with what was found and what was withheld, as summary.json says it, its
detail folded in the HTML and following the panels in the PDF."""

from __future__ import annotations

import json
import re

import pytest
from markupsafe import escape

from drillfric.io.text import split_notes
from drillfric.report import write_well_report
from drillfric.report.lead import segment_lead
from tests.test_report import copy_result, demo_result_dir

#: Several seconds a test (the demo's run, a PDF): not in the fast lane.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    return demo_result_dir(tmp_path_factory)


def pdf_pages(result) -> list[str]:
    """The text of each page of ``result``'s report.pdf (written now), whitespace
    collapsed (a wrapped line joins its next)."""
    from pypdf import PdfReader

    write_well_report(result, pdf=True)
    return [squeeze(page.extract_text()) for page in PdfReader(result / "report.pdf").pages]


def squeeze(text: str) -> str:
    return re.sub(r"\s+", " ", text).strip()


def test_pdf_holds_every_note_of_every_segment_whole(demo):
    """The demo's segment 1 stopped after "μ_s = 0.605 from 1 creep start-up(s) …": now
    each note of each drawn segment is in the PDF in full, the segment's lead on its
    panels' page and its detail on the page after."""
    pages = pdf_pages(demo)
    summary = json.loads((demo / "summary.json").read_text(encoding="utf-8"))
    for seg in summary["segments"]:
        first = next(i for i, p in enumerate(pages) if f"Segment {seg['id']} — bit at" in p)
        for line in segment_lead(seg).lines():
            assert squeeze(line) in pages[first], (seg["id"], line)
        detail = pages[first + 1]
        assert detail.startswith(f"Segment {seg['id']} — ") and ": detail" in detail
        for note in split_notes(seg["message"]):
            assert squeeze(note) in detail, (seg["id"], note)
    assert "the creep fit's μ_s is not reported" in " ".join(pages)


def test_pdf_headline_keeps_a_long_withheld_reason_whole(demo, tmp_path):
    """DSATS's withheld reason ran off page 1: the headline wraps it, whole, and says
    "none", not "— —" (the HTML's headline too)."""
    reason = ("withheld by the hook-load check (docs/theory.md §2.1): the hook load "
              "contradicts the configured string: the string weight it measures is 0.21× "
              "the modelled one (median of 16 off-bottom segments; block weight 147 kN: "
              "median hook load of the in-slips plateaus, those below "
              "segmentation.slips_hookload_N = 178 kN), beyond ±5%")

    def withhold(summary):
        summary.update(mu_k=None, mu_k_uncertainty=None, mu_k_reason=reason,
                       mu_k_confidence="withheld")
        for seg in summary["segments"]:
            seg.update(mu_k=None, mu_s=None, mu_s_lower_bound=None, mu_td=None,
                       converged=False,
                       quality_flags=[*seg["quality_flags"], "hookload_contradicts_string"])
    result = copy_result(demo, tmp_path / "withheld", withhold)
    first = pdf_pages(result)[0]
    assert f"μ_k off bottom (consensus): none — {reason}" in first
    assert "— —" not in first
    assert "No friction factor to draw: all 4 segments were estimated" in first
    assert "withheld by the hook-load check" in first.split("No friction factor")[1]
    html = (result / "report.html").read_text(encoding="utf-8")  # the HTML says it alike
    assert '<b>none</b> <span class="why">— withheld by the hook-load check' in html


def test_html_segment_leads_with_found_and_withheld_and_folds_the_rest(demo):
    """Each segment's section opens on its lead (the same μ_k and withheld reasons as
    summary.json); the fit's numbers, flags and notes are in a closed <details>."""
    html = write_well_report(demo).read_text(encoding="utf-8")
    summary = json.loads((demo / "summary.json").read_text(encoding="utf-8"))
    for seg in summary["segments"]:
        start = html.index(f'id="segment-{seg["id"]}"')
        section = html[start:html.index("</section>", start)]
        lead = segment_lead(seg)
        found = section.index('class="seg-lead found"')
        assert f"μ_k {seg['mu_k']:.3f}" in section[found:section.index("</p>", found)]
        detail = section.index('<details class="seg-detail">')
        assert found < detail and section.index('class="seg-notes"') > detail
        for item in lead.withheld:
            assert str(escape(item)) in section[:detail]
    one = html[html.index('id="segment-1"'):]
    assert str(escape("the creep fit's μ_s is not reported")) in one[:one.index("seg-detail")]
    assert "0.605" not in one[:one.index('id="segment-2"')]  # a μ_s not reported is not printed
