"""The per-well report: ``report.html`` (self-contained) and, on request, ``report.pdf``."""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from . import figures
from .data import ResultData, load_result, segment_estimates
from .pdf import table_pages, write_pdf
from .render import (
    DIAGNOSTIC_COLUMNS,
    clock,
    config_rows,
    diagnostic_rows,
    environment,
    figure_uri,
    fmt,
    mu_s_text,
    now_utc,
    written_at,
)

#: Segments drawn in full (the worst and the latest); the rest are in the diagnostics table.
MAX_SEGMENT_FIGURES = 10


def select_segments(segments: pd.DataFrame, limit: int = MAX_SEGMENT_FIGURES) -> list[int]:
    """Ids of the estimated segments drawn in full, in id order.

    All of them when there are at most ``limit``; otherwise half the places go to the worst
    (not converged first, then the largest residual RMS) and the rest to the latest.
    """
    ok = segments[segments["status"] == "ok"]
    if len(ok) <= limit:
        return [int(i) for i in ok["id"]]
    ranked = ok.assign(_bad=~ok["converged"], _res=ok["residual_rms_rpm"].fillna(float("inf")))
    worst = ranked.sort_values(["_bad", "_res"], ascending=False)["id"].head(limit // 2)
    chosen = [int(i) for i in worst]
    for seg_id in ok["id"].iloc[::-1]:
        if len(chosen) >= limit:
            break
        if int(seg_id) not in chosen:
            chosen.append(int(seg_id))
    return sorted(chosen)


def _header(data: ResultData) -> dict:
    summary, seg = data.summary, data.segments
    inputs = summary.get("inputs") or {}
    files = [(kind, str(v.get("path", "—")), str(v.get("sha256", "—")))
             for kind, v in inputs.items() if isinstance(v, dict)]
    span = (clock(seg["t_start_s"].min()), clock(seg["t_end_s"].max())) if len(seg) else None
    return {
        "well": str(summary.get("well", data.result_dir.name)),
        "version": str(summary.get("drillfric_version", "—")),
        "written": written_at(data.result_dir / "summary.json"), "built": now_utc(),
        "span": span, "files": files, "rows": inputs.get("rows"),
        "rate_hz": inputs.get("resampled_rate_hz"),
        "run_time_s": summary.get("run_time_s"),
        "mu_k": fmt(summary.get("mu_k")),
        "mu_s": mu_s_text(summary.get("mu_s"), summary.get("mu_s") is not None,
                          summary.get("mu_s_lower_bound")),
        "mu_s_identified": summary.get("mu_s") is not None,
        "counts": summary.get("counts") or {}, "assumed": [str(a) for a in
                                                           summary.get("assumed") or []],
        "indicative": bool(summary.get("indicative", bool(summary.get("assumed")))),
        "warnings": [str(w) for w in summary.get("warnings") or []],
        "config": config_rows(summary.get("config") or {}),
    }


def _no_survey_note(summary: dict) -> str:
    """What the well path was taken to be without a survey (from the run's configuration)."""
    survey = (summary.get("config") or {}).get("survey") or {}
    tortuosity = survey.get("tortuosity_deg_30m")
    if not tortuosity:
        return "No survey: the well was taken as vertical."
    return (f"No survey: the well was taken as vertical with a nominal tortuosity of "
            f"{tortuosity:g}°/30 m (a helix about the vertical, docs/torque_drag.md); the "
            "friction factors are indicative.")


def _figures(data: ResultData, limit: int) -> tuple[list, list]:
    """``(sections, segments)``: ``(key, title, Figure, note)`` and ``(id, title, Figure, row)``.

    A section with a note has nothing to draw: the HTML shows the note instead of the figure.
    """
    seg = data.segments
    no_profile = not figures.profile_depths(seg, data.profiles)
    no_survey = _no_survey_note(data.summary)
    main = [("wellpath", "Well path", figures.wellpath_figure(data.wellpath, no_survey),
             no_survey if data.wellpath is None else None),
            ("profiles", "Normal force and F_c profiles",
             figures.profiles_figure(data.profiles, seg),
             "No torque-and-drag profile: no segment was estimated." if no_profile else None),
            ("friction", "Friction log", figures.friction_log_figure(seg),
             None if len(seg) else "No segment: nothing to draw.")]
    ids = select_segments(seg, limit)
    estimates = segment_estimates(data.result_dir, ids)
    rows = seg.set_index("id", drop=False)
    per_segment = [(seg_id, f"Segment {seg_id}", figures.segment_figure(estimates[seg_id],
                                                                         rows.loc[seg_id]),
                    _segment_head(rows.loc[seg_id].to_dict()))
                   for seg_id in ids if seg_id in estimates and len(estimates[seg_id])]
    return main, per_segment


def _segment_head(row: dict) -> dict:
    row["mu_s_text"] = mu_s_text(row["mu_s"], row["mu_s_identifiable"], row["mu_s_lower_bound"])
    return row


def _header_lines(head: dict) -> list[tuple[str, str]]:
    counts = head["counts"]
    lines = [("well", head["well"]), ("drillfric", head["version"]),
             ("results written", head["written"]), ("report built", head["built"]),
             ("log time span", " – ".join(head["span"]) if head["span"] else "—"),
             ("μ_k (consensus)", head["mu_k"]), ("μ_s (consensus)", head["mu_s"]),
             ("segments", ", ".join(f"{k} {v}" for k, v in counts.items()))]
    for kind, path, sha in head["files"]:
        lines += [(f"input {kind}", path), ("sha256", sha)]
    lines += [("rows", fmt(head["rows"], ".0f")), ("resampled to [Hz]", fmt(head["rate_hz"]))]
    lines += [("ASSUMED", a) for a in head["assumed"]] or [("assumed", "nothing")]
    lines += [("WARNING", w) for w in head["warnings"]]
    return lines


def write_well_report(result_dir: Path, *, pdf: bool = False,
                      max_segments: int = MAX_SEGMENT_FIGURES) -> Path:
    """Write ``report.html`` (and ``report.pdf`` with ``pdf``) into ``result_dir``.

    Only the files of ``result_dir`` are read. At most ``max_segments`` segments are drawn
    in full (:func:`select_segments`); every segment is in the diagnostics table.

    Returns
    -------
    Path
        The path of report.html.

    Raises
    ------
    InputError
        ``result_dir`` is not a readable result directory.
    """
    data = load_result(Path(result_dir))
    head = _header(data)
    main, per_segment = _figures(data, max_segments)
    diag = diagnostic_rows(data.segments)
    drawn = {seg_id for seg_id, *_ in per_segment}
    for row in diag:
        row["anchor"] = int(row["id"]) in drawn
    html = environment().get_template("well_report.html.j2").render(
        head=head, sections=[(k, t, None if n else figure_uri(f), n) for k, t, f, n in main],
        segments=[(i, t, figure_uri(f), r) for i, t, f, r in per_segment],
        n_estimated=int((data.segments["status"] == "ok").sum()),
        columns=DIAGNOSTIC_COLUMNS, diagnostics=diag)
    out = data.result_dir / "report.html"
    _write_text(out, html)
    if pdf:
        pages = [("", p) for p in figures.text_pages(f"Friction report — {head['well']}",
                                                     _header_lines(head))]
        pages += [(t, f) for _, t, f, _ in main]
        pages += [(f"{t} — bit at {fmt(r['bit_depth_m'], '.0f')} m", f)
                  for _, t, f, r in per_segment]
        pages += [("", p) for p in table_pages("Diagnostics", list(DIAGNOSTIC_COLUMNS),
                                               [r["cells"] for r in diag])]
        pages += [("", p) for p in figures.text_pages(
            "Configuration", [(f"{t}.{k}" if k else t, v) for t, items in head["config"]
                              for k, v in items], fontsize=7.0, wrap=72)]
        write_pdf(data.result_dir / "report.pdf", pages, title=f"drillfric — {head['well']}")
    return out


def _write_text(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8", errors="replace")  # undecodable file names
    os.replace(tmp, path)
