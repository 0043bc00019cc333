"""The per-well report: ``report.html`` (self-contained, interactive) and ``report.pdf``.

The HTML draws the time tracks, the friction log and each segment's evidence with Bokeh
(zoom, hover; :mod:`drillfric.report.interactive`), the broomstick, well path and profiles
as PNG; the PDF draws everything with matplotlib on A4 landscape pages
(:mod:`drillfric.report.pdf`). Lengths, forces and torques are shown in the display units
of :func:`drillfric.report.display.report_units` (the files stay SI). Sections whose files
or columns a result directory lacks (older results) are left out with a one-line note.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from drillfric.errors import ConfigError, DrillfricError

from . import broomstick as broom
from . import figures
from .data import ResultData, load_result, segment_estimates
from .display import Units, fmt, report_units
from .evidence import (
    evidence_figure,
    evidence_plot,
    evidence_sources,
    has_column,
    signature,
    starts_text,
)
from .friction import friction_plot, friction_signature, friction_sources
from .interactive import Embedder
from .pdf import table_pages, write_pdf
from .render import (
    MESSAGE_FOLD_CHARS,
    bit_speed_text,
    bit_speed_unresolved,
    clock,
    clock_span,
    config_rows,
    diagnostic_columns,
    diagnostic_rows,
    environment,
    figure_uri,
    flag_items,
    interval_text,
    message_parts,
    mu_s_text,
    now_utc,
    string_table,
    written_at,
    zone_text,
)
from .tracks import (
    panels_present,
    tracks_figure,
    tracks_plot,
    tracks_signature,
    tracks_sources,
)

#: Segments drawn in full by default (the worst and the latest); ``segments="all"`` draws
#: every estimated one. Every segment is in the diagnostics table.
MAX_SEGMENT_FIGURES = 10
_NO_TRACKS = ("No time tracks: this result directory has no tracks.parquet (results written "
              "before drillfric wrote it); rerun 'drillfric run' to get them.")


def segment_limit(segments: int | str) -> int | None:
    """The number of segments to draw from ``"all"`` (None: no limit) or a positive int.

    Raises
    ------
    ConfigError
        Anything else.
    """
    if isinstance(segments, str) and segments.strip().lower() == "all":
        return None
    try:
        limit = int(segments)
    except (TypeError, ValueError):
        limit = 0
    if limit < 0 or str(segments).strip() not in (str(limit), f"{limit}.0"):
        raise ConfigError(f"segments must be 'all' or a number ≥ 0, got '{segments}'",
                          fix="e.g. --segments all or --segments 20")
    return limit


def select_segments(segments: pd.DataFrame, limit: int | None = MAX_SEGMENT_FIGURES
                    ) -> list[int]:
    """Ids of the estimated segments drawn in full, in id order.

    All of them when ``limit`` is None or there are at most ``limit``; otherwise half the
    places go to the worst (not converged first, then the largest residual RMS) and the
    rest to the latest.
    """
    ok = segments[segments["status"] == "ok"]
    if limit is None or len(ok) <= limit:
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


@dataclass
class Broomstick:
    """The broomstick section: the model table (None when it cannot be computed), the
    measured points, the string-weight check and a note when something is missing."""

    table: pd.DataFrame | None
    points: pd.DataFrame
    check: dict
    note: str | None


def _header(data: ResultData, units: Units) -> dict:
    summary, seg = data.summary, data.segments
    inputs = summary.get("inputs") or {}
    files = [(kind, str(v.get("path", "—")), str(v.get("sha256", "—")))
             for kind, v in inputs.items() if isinstance(v, dict)]
    origin = data.time_origin
    span = None
    if len(seg) and origin is not None:
        span = tuple(f"{origin + pd.Timedelta(seconds=float(t)):%Y-%m-%d %H:%M:%S} UTC"
                     for t in (seg["t_start_s"].min(), seg["t_end_s"].max()))
    elif len(seg):
        span = (clock(seg["t_start_s"].min()), clock(seg["t_end_s"].max()))
    string_columns, string_rows = string_table(summary.get("config") or {}, units)
    zone = str(summary.get("friction_zone") or "").replace("_", " ") or zone_text(seg)
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
        "zone": zone, "profile": str(summary.get("friction_profile") or ""),
        "units": units.system,
        "counts": summary.get("counts") or {}, "assumed": [str(a) for a in
                                                           summary.get("assumed") or []],
        "indicative": bool(summary.get("indicative", bool(summary.get("assumed")))),
        "warnings": [str(w) for w in summary.get("warnings") or []],
        "config": config_rows(summary.get("config") or {}),
        "string": (string_columns, string_rows),
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


def config_from_summary(summary: dict):
    """The run's effective configuration rebuilt from summary.json (null keys dropped: the
    schema's defaults apply, as they did in the run)."""
    from drillfric.config import config_from_dict

    raw = {}
    for table, values in (summary.get("config") or {}).items():
        if table == "string" and isinstance(values, dict):
            raw[table] = {"sections": [{k: v for k, v in s.items() if v is not None}
                                       for s in values.get("sections") or []]}
        elif isinstance(values, dict):
            raw[table] = {k: v for k, v in values.items() if v is not None}
    return config_from_dict(raw, file="summary.json")


def _broomstick(data: ResultData, units: Units) -> Broomstick:
    """Model lines from the run's configuration and well path, measured points from the
    segments, and the string-weight check."""
    from drillfric.wellpath import minimum_curvature

    points = broom.measured_points(data.segments)
    if not len(points):
        return Broomstick(None, points, broom.weight_check(points, units=units), (
            "No measured hook load or torque per segment in these results (written before "
            "drillfric recorded them); rerun 'drillfric run' to get them."))
    try:
        cfg = config_from_summary(data.summary)
        wp = data.wellpath
        path = None if wp is None or "inc_rad" not in wp else \
            minimum_curvature(wp["md_m"], wp["inc_rad"], wp["azi_rad"])
        deepest = float(points["bit_depth_m"].max())
        if path is not None:
            deepest = min(deepest, path.md_max_m)
        table = broom.model_table(cfg, path, broom.default_depths(cfg, deepest))
    except DrillfricError as exc:
        return Broomstick(None, points, broom.weight_check(points, units=units),
                          f"Model lines not drawn: {exc.message}")
    return Broomstick(table, points, broom.weight_check(points, table, units=units), None)


def _broomstick_note(check: dict, units: Units) -> str | None:
    if not check["checked"]:
        return None
    if check["warning"]:
        return check["warning"]
    return (f"String weight consistent with the hook load in {check['checked']} off-bottom "
            f"segment(s): implied travelling-block weight "
            f"{units.text(check['block_weight_N'], 'force')} {units.label('force')} (median "
            "measured − modelled).")


def _segment_head(row: dict, origin, units: Units) -> dict:
    """What a segment's header shows (display units)."""
    row = dict(row)
    row["mu_s_text"] = mu_s_text(row["mu_s"], row["mu_s_identifiable"], row["mu_s_lower_bound"])
    row["span"] = clock_span(row, origin)
    row["depth"] = f"{units.text(row['bit_depth_m'], 'length')} {units.label('length')}"
    row["torque"] = units.pair(row.get("torque_rms_misfit_Nm"), row.get("torque_swing_Nm"),
                               "torque", ".1f")
    row["quality"] = fmt(row.get("fit_quality"), ".2f")
    row["hookload"] = units.pair(row.get("hookload_N"), row.get("hookload_model_N"), "force")
    row["bit_speed"] = bit_speed_text(row)
    row["bit_unresolved"] = bit_speed_unresolved(row)
    row["interval"] = interval_text(row)
    row["interval_swing"] = fmt(row.get("interval_torque_swing"), ".0%")
    row["zone"] = str(row.get("friction_zone") or "—").replace("_", " ")
    row["starts_text"] = starts_text(row)
    row["notes"] = message_parts(str(row.get("message") or ""))
    row["flag_items"] = flag_items(row)
    return row


@dataclass
class Report:
    """Everything both outputs show, computed once from the result directory."""

    data: ResultData
    head: dict
    drawn: list[int]
    estimates: dict[int, pd.DataFrame]
    broomstick: Broomstick
    diagnostics: list[dict]
    units: Units

    @property
    def segment_rows(self) -> list[dict]:
        """Header rows of the drawn segments that have estimates, in id order."""
        rows = self.data.segments.set_index("id", drop=False)
        return [_segment_head(rows.loc[i].to_dict(), self.data.time_origin, self.units)
                for i in self.drawn if i in self.estimates and len(self.estimates[i])]

    @property
    def has_tracks(self) -> bool:
        tracks = self.data.tracks
        return tracks is not None and len(tracks) > 0 and bool(panels_present(tracks))


def build_report(result_dir: Path, segments: int | str = MAX_SEGMENT_FIGURES,
                 units: str | None = None) -> Report:
    """Read a result directory and prepare the report (no figure drawn yet); ``units``:
    ``"si"``, ``"field"`` or None (the run's ``[well] units``)."""
    limit = segment_limit(segments)
    data = load_result(Path(result_dir))
    shown = report_units(data.summary, units)
    drawn = select_segments(data.segments, limit)
    estimates = segment_estimates(data.result_dir, drawn)
    diag = diagnostic_rows(data.segments, shown, data.time_origin)
    have = {i for i, e in estimates.items() if len(e)}
    for row in diag:
        row["anchor"] = int(row["id"]) in have
    return Report(data, _header(data, shown), drawn, estimates, _broomstick(data, shown), diag,
                  shown)


def _static_sections(report: Report, size=None) -> list[tuple[str, str, object, str | None]]:
    """``(key, title, Figure or None, note)`` of the matplotlib sections."""
    data, seg = report.data, report.data.segments
    kw = {"units": report.units} if size is None else {"size": size, "units": report.units}
    no_survey = _no_survey_note(data.summary)
    no_profile = not figures.profile_depths(seg, data.profiles)
    bs = report.broomstick
    broom_fig = None
    if bs.table is not None:
        from drillfric.torque_drag import broomstick_figure

        broom_fig = broomstick_figure(bs.table, bs.points, size=size or (10.0, 6.5),
                                      units=report.units.system)
    return [
        ("broomstick", "Broomstick: hook load and torque versus depth", broom_fig, bs.note),
        ("wellpath", "Well path", figures.wellpath_figure(data.wellpath, no_survey, **kw),
         no_survey if data.wellpath is None else None),
        ("profiles", "Normal force and F_c profiles",
         figures.profiles_figure(data.profiles, seg, **kw),
         "No torque-and-drag profile: no segment was estimated." if no_profile else None)]


def _html(report: Report) -> str:
    data, units = report.data, report.units
    clock = data.time_origin is not None
    embed = Embedder()
    tracks_id = friction_id = None
    if report.has_tracks:
        bins = tracks_sources(data.tracks, data.segments, data.time_origin, units)
        tracks_id = embed.add_like(tracks_signature(data.tracks, bins, clock, units),
                                   lambda: tracks_plot(data.tracks, bins, clock, units), bins,
                                   "tracks")
    if data.segments["bit_depth_m"].notna().any():
        log = friction_sources(data.segments, units)
        friction_id = embed.add_like(friction_signature(data.segments, log, units),
                                     lambda: friction_plot(data.segments, log, units), log,
                                     "friction")
    segments = []
    for row in report.segment_rows:
        est = report.estimates[int(row["id"])]
        sources = evidence_sources(est, data.time_origin, units, not row["bit_unresolved"])
        div = embed.add_like(signature(sources, clock, units),
                             lambda sources=sources: evidence_plot(sources, clock, units),
                             sources, f"segment-{row['id']}")
        segments.append((row, div, _missing_evidence(est)))
    sections = [(k, t, figure_uri(f) if f is not None else None, n)
                for k, t, f, n in _static_sections(report)]
    return environment().get_template("well_report.html.j2").render(
        head=report.head, bokeh=embed.head, tracks_id=tracks_id, no_tracks=_NO_TRACKS,
        friction_id=friction_id, sections=sections, segments=segments,
        broomstick_check=_broomstick_note(report.broomstick.check, units),
        broomstick_warning=bool(report.broomstick.check["warning"]),
        n_estimated=int((data.segments["status"] == "ok").sum()),
        columns=diagnostic_columns(units), fold=MESSAGE_FOLD_CHARS,
        diagnostics=report.diagnostics,
        u={q: units.label(q) for q in ("length", "force", "torque")})


def _missing_evidence(est: pd.DataFrame) -> str | None:
    """A note when the estimates lack the torque columns (older results)."""
    if has_column(est, "surface_torque_Nm"):
        return None
    return ("No torque evidence: these estimates have no measured or modelled surface "
            "torque (results written before drillfric recorded them); speeds only.")


def write_well_report(result_dir: Path, *, pdf: bool = False,
                      segments: int | str = MAX_SEGMENT_FIGURES,
                      units: str | None = None) -> Path:
    """Write ``report.html`` (and ``report.pdf`` with ``pdf``) into ``result_dir``.

    Only the files of ``result_dir`` are read.

    Parameters
    ----------
    result_dir : Path
        An OUT/NAME directory written by ``drillfric run``.
    pdf : bool
        Also write report.pdf.
    segments : int or "all"
        How many estimated segments get their evidence drawn (default
        :data:`MAX_SEGMENT_FIGURES`: the worst and the latest, :func:`select_segments`);
        "all" draws every one. Every segment is in the diagnostics table.
    units : {"si", "field"}, optional
        Display units of axes and tables (the result files stay SI); default: the run's
        ``[well] units`` (summary.json ``config``), else SI.

    Returns
    -------
    Path
        The path of report.html.

    Raises
    ------
    InputError
        ``result_dir`` is not a readable result directory.
    ConfigError
        ``segments`` is neither "all" nor a number ≥ 0, or ``units`` is unknown.
    """
    report = build_report(result_dir, segments, units)
    out = report.data.result_dir / "report.html"
    _write_text(out, _html(report))
    if pdf:
        from .pdf import PAGE_IN

        write_pdf(report.data.result_dir / "report.pdf", _pdf_pages(report, PAGE_IN),
                  title=f"drillfric — {report.head['well']}",
                  footer=f"drillfric friction report — {report.head['well']}")
    return out


def _pdf_pages(report: Report, size) -> list[tuple[str, object]]:
    from .pdf import blank_page

    head, data, units = report.head, report.data, report.units
    pages = [("", p) for p in table_pages(f"Friction report — {head['well']}",
                                          ["", ""], _header_lines(report), font_pt=9.0)]
    if report.has_tracks:
        pages.append(("Time tracks", tracks_figure(data.tracks, data.segments,
                                                   data.time_origin, size, units)))
    if data.segments["bit_depth_m"].notna().any():
        pages.append(("Friction log", figures.friction_log_figure(data.segments, size,
                                                                  units)))
    for _, title, fig, note in _static_sections(report, size):
        if fig is None:
            fig = blank_page("")
            fig.text(0.5, 0.5, note or "", ha="center", wrap=True, parse_math=False)
        pages.append((title, fig))
    for row in report.segment_rows:
        est = report.estimates[int(row["id"])]
        figure = evidence_figure(est, row, data.time_origin, size, units,
                                 not row["bit_unresolved"], notes=segment_notes(row, units))
        pages.append((f"Segment {row['id']} — bit at {row['depth']}, {row['span']}", figure))
    pages += [("", p) for p in table_pages("Diagnostics",
                                           [h for h, _ in diagnostic_columns(units)],
                                           [r["cells"] for r in report.diagnostics])]
    config = [[table, key, value] for table, items in head["config"] for key, value in items]
    pages += [("", p) for p in table_pages("Configuration: drill string", *head["string"])]
    pages += [("", p) for p in table_pages("Configuration", ["table", "key", "value"], config)]
    return pages


#: Characters per line of a segment page's notes (7 pt on A4 landscape) and most lines.
_NOTE_CHARS, _NOTE_LINES = 190, 7


def segment_notes(row: dict, units: Units) -> list[str]:
    """What a segment's PDF page says above its panels (the HTML header's facts): μ and
    the friction zone, torque fit, hook load, logging interval, bit speed (why not
    resolved), flags and the estimators' notes, wrapped to :data:`_NOTE_CHARS`."""
    import textwrap

    facts = [f"μ_k {fmt(row['mu_k'])} ({row['zone']}), μ_s {row['mu_s_text']}",
             f"torque misfit / swing {row['torque']} {units.label('torque')} "
             f"(fit quality {row['quality']})",
             f"hook load measured / model {row['hookload']} {units.label('force')}"]
    if row["interval"]:
        facts.append(f"logged every {row['interval']}")
    facts.append(f"bit speed {row['bit_speed']}")
    lines = ["; ".join(facts)]
    if row["flag_items"]:
        lines.append("flags: " + ", ".join(flag for flag, _ in row["flag_items"]))
    lines += row["notes"]
    wrapped = [w for line in lines for w in textwrap.wrap(line, _NOTE_CHARS)]
    return wrapped[:_NOTE_LINES - 1] + ["…"] if len(wrapped) > _NOTE_LINES else wrapped


def _header_lines(report: Report) -> list[list[str]]:
    head = report.head
    counts = head["counts"]
    lines = [["well", head["well"]], ["drillfric", head["version"]],
             ["results written", head["written"]], ["report built", head["built"]],
             ["log time span", " – ".join(head["span"]) if head["span"] else "—"],
             ["μ_k (consensus)", head["mu_k"]], ["μ_s (consensus)", head["mu_s"]],
             ["friction zone", " — ".join(x for x in (head["zone"], head["profile"]) if x)
              or "—"],
             ["segments", ", ".join(f"{k} {v}" for k, v in counts.items())],
             ["units", head["units"]]]
    for kind, path, sha in head["files"]:
        lines += [[f"input {kind}", f"{path}\nsha256 {sha}"]]
    lines += [["rows", fmt(head["rows"], ",.0f")], ["resampled to [Hz]", fmt(head["rate_hz"])]]
    lines += [["ASSUMED", a] for a in head["assumed"]] or [["assumed", "nothing"]]
    lines += [["WARNING", w] for w in head["warnings"]]
    check = _broomstick_note(report.broomstick.check, report.units)
    if check:
        lines.append(["WARNING" if report.broomstick.check["warning"] else "string weight",
                      check])
    return lines


def _write_text(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8", errors="replace")  # undecodable file names
    os.replace(tmp, path)

