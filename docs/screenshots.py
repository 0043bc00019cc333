"""Re-make the screenshots of docs/reports.md (docs/img/report-*.png).

    python docs/screenshots.py [--out docs/img]

Runs ``drillfric run`` on the bundled demo well into a temporary directory, builds its
report (HTML and PDF), opens report.html in headless Chromium (Debian: ``apt-get install
chromium``) at 1400 px and saves each section as a PNG; the PDF's pages go through
``pdftoppm`` (poppler-utils). Results written by a drillfric that does not yet record the
issue-16 files (tracks.parquet, torque columns) are completed by
tests/synthetic_results.py (the script says so).
"""

from __future__ import annotations

import argparse
import base64
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

#: Page sections shot, by element id → file name.
SECTIONS = {"tracks": "tracks", "friction": "friction-log", "broomstick": "broomstick",
            "segment-1": "segment", "diagnostics": "diagnostics"}


def _result(tmp: Path) -> tuple[Path, bool]:
    import drillfric

    run = drillfric.run(REPO / "examples" / "demo" / "demo.csv", tmp / "out")
    completed = not (run.out_dir / "tracks.parquet").is_file()
    if completed:
        from tests.synthetic_results import add_evidence_files

        add_evidence_files(run.out_dir, REPO / "examples" / "demo" / "demo.csv",
                           clock="2024-03-01T06:00:00Z")
    return run.out_dir, completed


def _shoot(html: Path, out: Path, tmp: Path) -> list[Path]:
    from tests.test_report_browser import Browser

    exe = next(filter(None, map(shutil.which, ("chromium", "chromium-browser",
                                                 "google-chrome"))), None)
    if exe is None:
        raise SystemExit("no Chromium found (Debian: apt-get install chromium)")
    browser = Browser(exe, tmp / "profile", tmp / "chromium.log")
    ids = json.dumps(list(SECTIONS))
    rects = (f"JSON.stringify(Object.fromEntries({ids}.map(id => {{ const r = "
             "document.getElementById(id).getBoundingClientRect(); return [id, "
             "[r.left, r.top + window.scrollY, r.width, r.height]]; })))")
    try:
        visit = browser.visit(html.as_uri(), {"rects": rects}, width=1400)
        written = []
        for key, (x, y, w, h) in json.loads(visit.values["rects"]).items():
            target = browser.send("Target.createTarget", {"url": html.as_uri()})["targetId"]
            session = browser.send("Target.attachToTarget",
                                   {"targetId": target, "flatten": True})["sessionId"]
            browser.send("Page.enable", session=session)
            browser.send("Emulation.setDeviceMetricsOverride", {
                "width": 1400, "height": 1600, "deviceScaleFactor": 1, "mobile": False},
                session=session)
            browser.wait_event("Page.loadEventFired")
            browser.drain(1.0)
            shot = browser.send("Page.captureScreenshot", {
                "format": "png", "captureBeyondViewport": True,
                "clip": {"x": max(x - 10, 0), "y": y, "width": w + 20,
                         "height": min(h, 2400), "scale": 1}},
                session=session)
            path = out / f"report-{SECTIONS[key]}.png"
            path.write_bytes(base64.b64decode(shot["data"]))
            written.append(path)
            browser.send("Target.closeTarget", {"targetId": target})
        return written
    finally:
        browser.close()


def _pdf_pages(pdf: Path, out: Path) -> list[Path]:
    if shutil.which("pdftoppm") is None:
        print("no pdftoppm (apt-get install poppler-utils): PDF pages not shot")
        return []
    written = []
    for page, name in ((1, "pdf-header"), (None, "pdf-diagnostics")):
        if page is None:
            from pypdf import PdfReader

            texts = [p.extract_text() for p in PdfReader(pdf).pages]
            page = next(i for i, t in enumerate(texts, 1) if t.startswith("Diagnostics"))
        stem = out / f"report-{name}"
        subprocess.run(["pdftoppm", "-png", "-r", "60", "-singlefile", "-f", str(page), "-l",
                        str(page), str(pdf), str(stem)], check=True)
        written.append(stem.with_suffix(".png"))
    return written


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "img")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    from drillfric.report import write_well_report

    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        result, completed = _result(tmp)
        html = write_well_report(result, pdf=True)
        written = _shoot(html, args.out, tmp) + _pdf_pages(result / "report.pdf", args.out)
    note = " (demo results completed by tests/synthetic_results.py)" if completed else ""
    for path in written:
        print(f"wrote {path}{note}")


if __name__ == "__main__":
    main()
