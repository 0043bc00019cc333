"""The fleet report (``fleet.html``): failures first, one row per well with a link to its
report, and μ_k versus depth of every well in one interactive figure (Bokeh, inlined).
Depths are in the wells' common ``[well] units`` (SI when they differ)."""

from __future__ import annotations

import math
import os
from pathlib import Path
from urllib.parse import quote

from drillfric._version import __version__
from drillfric.io.atomic import write_text_replacing
from drillfric.io.text import plural
from drillfric.result import Flag, well_friction_columns
from drillfric.vocabulary import Status, WellStatus

from .data import segments_frame
from .display import fmt, report_units, row_flags
from .friction import fleet_plot, off_bottom_mu_k
from .interactive import Embedder
from .render import environment, mu_s_text, now_utc


def _worst(segments: list[dict]) -> dict:
    """Worst diagnostics of a well's segments (largest residual, spread, severity — "severe"
    where any is withheld as beyond its validated range, docs/bit_speed.md; counts)."""
    ok = [s for s in segments if s.get("status") == Status.OK]

    def largest(key: str) -> float | None:
        values = [float(s[key]) for s in ok if isinstance(s.get(key), int | float)
                  and math.isfinite(float(s[key]))]
        return max(values) if values else None

    return {"residual": fmt(largest("residual_rms_rpm"), ".2f"),
            "spread": fmt(largest("mu_k_spread")),
            "severity": ("severe" if any(Flag.STICK_SLIP_BEYOND_VALIDATED in row_flags(s)
                                         for s in ok)
                         else fmt(largest("stick_slip_severity"), ".2f")),
            "unconverged": sum(not s.get("converged") for s in ok),
            "failed": sum(s.get("status") == Status.FAILED for s in segments)}


def _link(out_dir: Path, result_dir) -> str | None:
    """Relative URL of a well's report.html from ``out_dir`` (percent-encoded), or None.

    ``result_dir`` may be absolute, relative to ``out_dir``, or relative to the working
    directory (e.g. ``OUT/NAME`` when ``out_dir`` is ``OUT``).
    """
    if result_dir is None:
        return None
    target = Path(result_dir)
    if not target.is_absolute() and not (out_dir / target).exists() and target.exists():
        target = target.resolve()  # relative to the working directory, not to out_dir
    if target.is_absolute():
        try:
            target = Path(os.path.relpath(target, Path(out_dir).resolve()))
        except ValueError:  # another drive (Windows): an absolute file URL then
            return (target / "report.html").as_uri()
    return "./" + quote((target / "report.html").as_posix())


#: How a well's status is shown: an unchanged well's results are ok, from an earlier run.
STATUS_TEXT = {"ok": "ok", "skipped": "ok (unchanged)", "failed": "failed"}
#: Badge of a well that ran but some of whose segments failed ("partial: N of M segments
#: failed"): not the green "ok" (issue 35).
PARTIAL = "unconverged"


def _row(out_dir: Path, well: dict) -> dict:
    summary = well.get("summary") or {}
    counts = summary.get("counts") or {}
    status = str(well.get("status", "failed"))
    stale = well.get("stale_dir")
    message = str(well.get("message") or "")
    if stale is not None:
        message += (f" — the results in {Path(stale).name}/ are an earlier run's, marked "
                    "stale (STALE.json, summary.json stale)")
    worst = _worst(summary.get("segments") or [])
    failed = int(well.get("failed_segments") or worst["failed"] or 0)
    text = STATUS_TEXT.get(status, status)
    badge = WellStatus.OK if status == WellStatus.SKIPPED else status
    if status != WellStatus.FAILED and failed:
        # issue 35: F-9 showed "ok" with 9 of its 23 segments failed
        text = (f"{text.replace('ok', 'partial', 1)}: "
                f"{failed} of {plural(counts.get('segments', failed), 'segment')} failed")
        badge = PARTIAL
    friction = well_friction_columns(summary)
    return {"well": str(well.get("well", "?")), "status": status,
            "status_text": text, "partial": badge == PARTIAL,
            "badge": badge,
            "mu_apparent": fmt(friction["well_mu_apparent"]),
            "mu_apparent_n": friction["well_mu_apparent_segments"],
            "mu_drag": fmt(friction["well_mu_drag"]),
            "mu_drag_n": friction["well_mu_drag_connections"],
            "message": message,
            "stale_link": _link(out_dir, stale) if stale is not None else None,
            "segments": counts.get("segments", "—"), "estimated": counts.get("estimated", "—"),
            "converged": counts.get("converged", "—"),
            "mu_k": fmt(summary.get("mu_k")),
            "zone": str(summary.get("friction_zone") or "").replace("_", " "),
            "mu_s": mu_s_text(summary.get("mu_s"), summary.get("mu_s") is not None,
                              summary.get("mu_s_lower_bound")) if summary else "—",
            "indicative": bool(summary.get("indicative")),
            "worst": worst,
            "link": _link(out_dir, well.get("result_dir")) if summary else None}


def write_fleet_report(out_dir: Path, wells: list[dict], units: str | None = None) -> Path:
    """Write ``out_dir/fleet.html``: the morning overview of many wells.

    Parameters
    ----------
    out_dir : Path
        Fleet output directory (links to the wells' reports are relative to it).
    wells : list of dict
        One per well: ``{"well": str, "status": "ok"|"failed"|"skipped", "message": str,
        "result_dir": Path or None (relative link target), "summary": dict or None
        (summary.json), "stale_dir": Path or None (a failed well's earlier results, marked
        stale), "changes": list of str (optional: what changed since the last night, shown
        first)}``; "skipped" (unchanged since an ok run) is shown "ok (unchanged)".
    units : {"si", "field"}, optional
        Display units of the depths; default: the ``[well] units`` all wells share, else SI.

    Returns
    -------
    Path
        The path of fleet.html.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = [_row(out_dir, w) for w in wells]
    logs = [(str(w.get("well", "?")), segments_frame(w["summary"].get("segments") or []))
            for w in wells if w.get("summary") and w["summary"].get("segments")]
    shown = report_units({}, units or _common_units(wells))
    embed = Embedder()
    plot_id = embed.add(fleet_plot(logs, shown), "fleet") if any(
        len(off_bottom_mu_k(seg)) for _, seg in logs) else None
    counts = {k: sum(r["status"] == k and not r["partial"] for r in rows)
              for k in ("ok", "failed", "skipped")}
    counts["partial"] = sum(r["partial"] for r in rows)
    # a well's first night has nothing to compare with: named as such, not as news
    first = [str(w.get("well", "?")) for w in wells if w.get("first_run")]
    news = [(str(w.get("well", "?")), w["changes"]) for w in wells
            if w.get("changes") and not w.get("first_run")]
    html = environment().get_template("fleet_report.html.j2").render(
        rows=rows, failed=[r for r in rows if r["status"] == WellStatus.FAILED], counts=counts,
        news=news, first=first, everyone_first=len(first) == len(wells),
        plot_id=plot_id, bokeh=embed.head, version=__version__, built=now_utc())
    out = out_dir / "fleet.html"
    write_text_replacing(out, html)
    return out


def _common_units(wells: list[dict]) -> str:
    """The ``[well] units`` every well's run recorded, or "si" when they differ."""
    systems = {report_units(w["summary"]).system for w in wells if w.get("summary")}
    return systems.pop() if len(systems) == 1 else "si"
