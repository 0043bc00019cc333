"""The per-well report: ``report.html`` (self-contained, interactive) and ``report.pdf``.

The HTML draws the time tracks, the friction log and each segment's evidence with Bokeh
(zoom, hover; :mod:`drillfric.report.interactive`), the broomstick, well path and profiles
as PNG; the PDF draws everything with matplotlib on A4 landscape pages
(:mod:`drillfric.report.pdf`). Lengths, forces and torques are shown in the display units
of :func:`drillfric.report.display.report_units` (the files stay SI). Sections whose files
or columns a result directory lacks (older results) are left out with a one-line note.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from drillfric.errors import ConfigError, DrillfricError
from drillfric.estimation.headline import LOWERING, STRING_WEIGHT_WARNING
from drillfric.io.atomic import write_text_replacing
from drillfric.io.text import plural, share, split_notes
from drillfric.io.timebase import clock_at
from drillfric.vocabulary import Status

from . import broomstick as broom
from . import figures
from .data import ResultData, final_torques, load_result, segment_estimates
from .display import Units, fmt, message_in, report_units
from .evidence import (
    evidence_figure,
    evidence_plot,
    evidence_sources,
    has_column,
    mu_withheld,
    signature,
    starts_text,
)
from .friction import friction_plot, friction_signature, friction_sources
from .interactive import LONG_LOG_S, Embedder
from .lead import segment_lead
from .pdf import table_pages, write_pdf
from .render import (
    CONVERGED_MEANING,
    MESSAGE_FOLD_CHARS,
    bit_speed_text,
    bit_speed_unresolved,
    clock,
    clock_span,
    config_rows,
    diagnostic_columns,
    diagnostic_rows,
    drag_text,
    environment,
    figure_uri,
    flag_items,
    interval_text,
    is_apparent,
    mu_name,
    mu_s_text,
    non_default_rows,
    note_flags,
    now_utc,
    row_zone,
    severity_text,
    status_word,
    string_table,
    written_at,
    zone_text,
)
from .reproduction import Reproduction, reproduction, stated_quality
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
_DEPTH_TRACKS = ("No time tracks: the log is depth-indexed (one row per depth step, no time), "
                 "so there is nothing to draw against time. The friction log and the "
                 "broomstick below are its evidence versus depth.")


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
    ok = segments[segments["status"] == Status.OK]
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
    files = [(kind, str(v["path"]), str(v.get("sha256", "—")))
             for kind, v in inputs.items() if isinstance(v, dict) and "path" in v]
    string_columns, string_rows = string_table(summary.get("config") or {}, units)
    zone = str(summary.get("friction_zone") or "").replace("_", " ") or zone_text(seg)
    return {
        "well": str(summary.get("well", data.result_dir.name)),
        "version": str(summary.get("drillfric_version", "—")),
        "written": written_at(data.result_dir / "summary.json"), "built": now_utc(),
        "span": _log_span(data, units), "files": files, "rows": inputs.get("rows"),
        "rate_hz": inputs.get("resampled_rate_hz"),
        "skew": skew_text(inputs.get("channel_skew")),
        "run_time_s": summary.get("run_time_s"),
        "mu_k": fmt(summary.get("mu_k")), "mu_k_reason": _no_mu_k_reason(data),
        "trust": headline_trust(summary),
        "apparent": _apparent(data),
        "mu_s": _mu_s_headline(summary),
        "mu_s_identified": summary.get("mu_s") is not None,
        "zone": zone, "profile": _profile_text(summary, data.depth_indexed),
        "units": units.system, "depth_indexed": data.depth_indexed,
        "counts": summary.get("counts") or {}, "assumed": [str(a) for a in
                                                           summary.get("assumed") or []],
        "indicative": bool(summary.get("indicative", bool(summary.get("assumed")))),
        "warnings": [str(w) for w in summary.get("warnings") or []],
        "config": config_rows(summary.get("config") or {}),
        "non_default": non_default_rows(summary.get("config") or {}),
        "string": (string_columns, string_rows),
        "converged_meaning": CONVERGED_MEANING,
    }


def skew_text(skew: dict | None) -> str:
    """The torque's lag behind the speed as the inputs section states it (summary.json
    ``inputs.channel_skew``; docs/bit_speed.md, Channel skew).

    Examples
    --------
    >>> skew_text({"lag_s": 0.81, "uncertainty_s": 0.05, "source": "identified",
    ...            "segments_identified": 2})
    '+0.81 ± 0.05 s, identified (2 segments)'
    >>> skew_text({"lag_s": None, "source": "not identified", "reason": "why"})
    'not identified — why'
    """
    if not skew:
        return "—"
    if skew.get("lag_s") is None:
        return f"not identified — {skew.get('reason') or ''}".rstrip(" —")
    if skew.get("source") == "config":
        return f"{skew['lag_s']:+.2f} s, configured ([channels] lag_s)"
    return (f"{skew['lag_s']:+.2f} ± {skew['uncertainty_s']:.2f} s, identified "
            f"({skew.get('segments_identified', 0)} segments)")


def _zone_line(head: dict) -> str:
    """The friction zone and profile in one line, the zone left out where the profile
    starts by naming it ("effective — effective friction factor over …").

    Examples
    --------
    >>> _zone_line({"zone": "effective", "profile": "effective friction factor; step law"})
    'effective friction factor; step law'
    >>> _zone_line({"zone": "open hole", "profile": "cased = 0.8 × open"})
    'open hole — cased = 0.8 × open'
    """
    zone, profile = head["zone"], head["profile"]
    if zone and profile.startswith(zone):
        return profile
    return " — ".join(x for x in (zone, profile) if x)


def _profile_text(summary: dict, depth_indexed: bool) -> str:
    """The friction profile the headline names; a depth log's without the friction law (it
    acts in the dynamic model only: issue 35 item 9)."""
    text = str(summary.get("friction_profile") or "")
    return text.split("; ")[0] if depth_indexed else text


def headline_trust(summary: dict) -> dict:
    """What the headline says about the well μ_k beside its value: ``uncertainty`` ("± 0.012"
    or ""), ``support`` ("4 of 9 off-bottom segments" or ""), ``confidence`` (summary.json
    ``mu_k_confidence``; "" for results without it) and ``reasons`` (the warnings of the
    flags that lower it)."""
    u, support = summary.get("mu_k_uncertainty"), summary.get("mu_k_support") or {}
    has_mu = summary.get("mu_k") is not None
    confidence = str(summary.get("mu_k_confidence") or "")
    flags = set(summary.get("quality_flags") or [])
    lowering = [f.value for f in LOWERING if f.value in flags]
    return {"uncertainty": f"± {fmt(u)}" if has_mu and u is not None else "",
            "support": share(support["segments"], support["of"], "off-bottom segment")
            if has_mu and "of" in support else "",
            "confidence": confidence,
            "reasons": [f.replace("_", " ") for f in lowering] if confidence == "low" else []}


def _log_span(data: ResultData, units: Units) -> tuple[str, str] | None:
    """``(what, span)`` the header shows: the log's time span (clock time when known), a
    depth log's depth range, or — without tracks.parquet (older results) — the segments'
    time span, called so."""
    if data.depth_indexed:
        log = data.summary.get("friction_log") or {}
        top, bottom = log.get("md_start_m"), log.get("md_end_m")
        if top is None or bottom is None:
            return None
        length = units.label("length")
        return ("log depth", f"{units.text(top, 'length')}–{units.text(bottom, 'length')} "
                             f"{length} MD")
    span = data.log_span_s
    if span is None:
        return None
    what = "log time" if data.span_from_tracks else "segments' time"
    origin = data.time_origin
    if origin is None:
        return what, f"{clock(span[0])} – {clock(span[1])} (log time h:mm:ss)"
    spec = "%Y-%m-%d %H:%M" if span[1] - span[0] > LONG_LOG_S else "%Y-%m-%d %H:%M:%S"
    a, b = (clock_at(origin, t) for t in span)
    return what, f"{a:{spec}} – {b:{spec}} UTC"


def _mu_s_headline(summary: dict) -> str:
    """The well μ_s as the run's terminal line gives it: its ± and how many segments it
    rests on (the report had shown "0.585" where the terminal said "0.585 ± 0.059": the
    consensus of one stand of four, without its uncertainty)."""
    text = mu_s_text(summary.get("mu_s"), summary.get("mu_s") is not None,
                     summary.get("mu_s_lower_bound"))
    if summary.get("mu_s") is None:
        return text
    u, support = summary.get("mu_s_uncertainty"), summary.get("mu_s_support") or {}
    text += f" ± {fmt(u)}" if u is not None else ""
    if "of" in support:
        text += f" ({share(support['segments'], support['of'], 'segment')})"
    return text


def _no_mu_k_reason(data: ResultData) -> str:
    """Why the headline has no μ_k ("" when it has one)."""
    summary = data.summary
    if summary.get("mu_k") is not None:
        return ""
    reason = summary.get("mu_k_reason") or (summary.get("friction_log") or {}).get(
        "mu_k_reason")
    if reason:
        return str(reason)
    ok = data.segments[data.segments["status"] == Status.OK]
    if not len(ok):
        return "no segment was estimated"
    off = ok[~ok.apply(lambda r: is_apparent(r.to_dict()), axis=1)]
    if not len(off):
        return "no off-bottom stand was estimated: only apparent friction, on bottom"
    return "no off-bottom stand converged"


def _apparent(data: ResultData) -> dict | None:
    """The headline's apparent (on-bottom) friction factor: a depth log's ``mu_apparent``,
    else the median over the converged on-bottom stands; None when there is none."""
    seg = data.segments
    on = seg[(seg["status"] == Status.OK) & seg["converged"] & seg["mu_k"].notna()]
    on = on[[is_apparent(r) for r in on.to_dict("records")]]
    value = (data.summary.get("friction_log") or {}).get("mu_apparent")
    if value is None and not len(on):
        return None
    if value is None:
        value = float(on["mu_k"].median())
    return {"value": fmt(value), "count": len(on)}


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
    if data.friction_log is not None and not points["surface_torque_Nm"].notna().any():
        points = broom.measured_points_from_windows(data.friction_log)
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
    return Broomstick(table, points, broom.weight_check(_estimated(points, data), table,
                                                        units=units), None)


def _estimated(points: pd.DataFrame, data: ResultData) -> pd.DataFrame:
    """The measured points of the segments the run estimated: summary.json's string-weight
    check weighs those only (Volve F-4's report had warned of "all 8 off-bottom segments"
    — every one skipped — where summary.json said not_checked: issue 35)."""
    seg = data.segments
    if "status" not in seg or "id" not in seg:
        return points
    return points[points["segment_id"].isin(seg.loc[seg["status"] == Status.OK, "id"])]


def _broomstick_note(check: dict, units: Units) -> str | None:
    if not check["checked"]:
        return None
    if check["warning"]:
        return check["warning"]
    return (f"String weight consistent with the hook load in "
            f"{plural(check['checked'], 'off-bottom segment')}: implied travelling-block weight "
            f"{units.text(check['block_weight_N'], 'force')} {units.label('force')} (median "
            "measured − modelled).")


def _segment_head(row: dict, origin, units: Units, fit: Reproduction | None = None) -> dict:
    """What a segment's header shows (display units); ``fit``: what the batch fit
    reproduces over its second half (None: not known)."""
    row = dict(row)
    row["mu_s_text"] = mu_s_text(row["mu_s"], row["mu_s_identifiable"], row["mu_s_lower_bound"])
    row["span"] = clock_span(row, origin)
    row["depth"] = f"{units.text(row['bit_depth_m'], 'length')} {units.label('length')}"
    row["torque"] = units.pair(row.get("torque_rms_misfit_Nm"), row.get("torque_swing_Nm"),
                               "torque", ".1f")
    row["quality"] = quality_text(row, fit)
    row["fit_sentence"] = fit.sentence(_when(fit.t_half_s, origin), units) if fit else ""
    row["fit_mismatch"] = fit is not None and not fit.reproduced
    row["mu_name"] = mu_name(row)
    row["status_word"] = status_word(row)
    row["note_flags"] = note_flags(row)
    row["hookload"] = units.pair(row.get("hookload_N"), row.get("hookload_model_N"), "force")
    row["bit_speed"] = bit_speed_text(row)
    row["bit_unresolved"] = bit_speed_unresolved(row)
    row["interval"] = interval_text(row)
    row["interval_swing"] = fmt(row.get("interval_torque_swing"), ".0%")
    row["zone"] = row_zone(row)
    row["starts_text"] = starts_text(row)
    row["severity_text"] = severity_text(row)
    row["notes"] = split_notes(str(row.get("message") or ""))
    row["flag_items"] = flag_items(row)
    row["lead"] = segment_lead(row)
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

    fits: dict[int, Reproduction]

    @property
    def segment_rows(self) -> list[dict]:
        """Header rows of the drawn segments that have estimates, in id order."""
        rows = self.data.segments.set_index("id", drop=False)
        return [_segment_head(rows.loc[i].to_dict(), self.data.time_origin, self.units,
                              self.fits.get(i))
                for i in self.drawn if i in self.estimates and len(self.estimates[i])]

    @property
    def has_tracks(self) -> bool:
        tracks = self.data.tracks
        return tracks is not None and len(tracks) > 0 and bool(panels_present(tracks))


def _messages_in(data, shown: Units) -> None:
    """The run's messages (SI, summary.json) in the report's units (:func:`message_in`):
    warnings, the reasons of a withheld μ_k and of the hook-load check, each segment's
    message and bit-speed reason (issue 35: a field-units report printed m and kN)."""
    if shown.system == "si":
        return
    summary = data.summary
    for key in ("warnings", "assumed"):
        if isinstance(summary.get(key), list):
            summary[key] = [message_in(w, shown) if isinstance(w, str) else w
                            for w in summary[key]]
    for table in (summary, summary.get("friction_log"), summary.get("hookload")):
        if isinstance(table, dict):
            for key in ("mu_k_reason", "reason"):
                if isinstance(table.get(key), str):
                    table[key] = message_in(table[key], shown)
    for column in ("message", "bit_speed_reason"):
        if column in data.segments:
            data.segments[column] = [message_in(m, shown) if isinstance(m, str) else m
                                     for m in data.segments[column]]


def build_report(result_dir: Path, segments: int | str = MAX_SEGMENT_FIGURES,
                 units: str | None = None) -> Report:
    """Read a result directory and prepare the report (no figure drawn yet); ``units``:
    ``"si"``, ``"field"`` or None (the run's ``[well] units``)."""
    limit = segment_limit(segments)
    data = load_result(Path(result_dir))
    shown = report_units(data.summary, units)
    _messages_in(data, shown)
    drawn = select_segments(data.segments, limit)
    estimates = segment_estimates(data.result_dir, drawn)
    ok = [int(i) for i in data.segments.loc[data.segments["status"] == Status.OK, "id"]]
    fits = {i: found for i, rows in final_torques(data.result_dir, ok).items()
            if (found := reproduction(rows)) is not None}
    rows = data.segments.set_index("id", drop=False)
    texts = {i: (quality_text(rows.loc[i].to_dict(), fit),
                 "" if fit.reproduced else
                 fit.sentence(_when(fit.t_half_s, data.time_origin), shown))
             for i, fit in fits.items()}
    diag = diagnostic_rows(data.segments, shown, data.time_origin, texts)
    have = {i for i, e in estimates.items() if len(e)}
    for row in diag:
        row["anchor"] = int(row["id"]) in have
    broomstick = _broomstick(data, shown)
    head = _header(data, shown)
    if broomstick.check["warning"]:  # said there with display units (#weight-warning)
        head["warnings"] = [w for w in head["warnings"]
                            if not w.startswith(STRING_WEIGHT_WARNING)]
    return Report(data, head, drawn, estimates, broomstick, diag, shown, fits)


def quality_text(row: dict, fit: Reproduction | None) -> str:
    """The fit quality stated for a segment: the worse of the whole segment's and its
    second half's (:func:`~drillfric.report.reproduction.stated_quality`), said which."""
    value, half = stated_quality(row.get("fit_quality"), fit)
    text = fmt(value, ".2f")
    if not half or text == "—":
        return text
    return f"{text} over the second half ({fmt(row.get('fit_quality'), '.2f')} over all)"


def _when(time_s: float, origin) -> str:
    """A log time as shown in a sentence: clock time when known, else h:mm:ss log time."""
    if origin is None:
        return f"{clock(time_s)} log time"
    return f"{clock_at(origin, time_s):%H:%M:%S} UTC"


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
    axis = data.time_axis
    embed = Embedder()
    tracks_id = friction_id = None
    if report.has_tracks:
        bins = tracks_sources(data.tracks, data.segments, axis, units)
        tracks_id = embed.add_like(tracks_signature(data.tracks, bins, axis, units),
                                   lambda: tracks_plot(data.tracks, bins, axis, units), bins,
                                   "tracks")
    if has_friction(data.segments) or len(figures.drag_rows(data.drag_log)):
        log = friction_sources(data.segments, units, data.drag_log)
        friction_id = embed.add_like(friction_signature(data.segments, log, units),
                                     lambda: friction_plot(data.segments, log, units), log,
                                     "friction")
    segments = []
    for row in report.segment_rows:
        est = report.estimates[int(row["id"])]
        sources = evidence_sources(est, axis, units, not row["bit_unresolved"])
        note = mu_withheld(row)
        div = embed.add_like(signature(sources, axis, units, note),
                             lambda sources=sources, note=note: evidence_plot(
                                 sources, axis, units, note),
                             sources, f"segment-{row['id']}")
        segments.append((row, div, _missing_evidence(est)))
    sections = [(k, t, figure_uri(f) if f is not None else None, n)
                for k, t, f, n in _static_sections(report)]
    return environment().get_template("well_report.html.j2").render(
        head=report.head, bokeh=embed.head, tracks_id=tracks_id,
        no_tracks=_DEPTH_TRACKS if data.depth_indexed else _NO_TRACKS,
        friction_id=friction_id, no_friction=no_friction_note(data.segments, units),
        drag_line=drag_text(data.summary.get("drag")),
        sections=sections, segments=segments,
        broomstick_check=_broomstick_note(report.broomstick.check, units),
        broomstick_warning=bool(report.broomstick.check["warning"]),
        n_estimated=int((data.segments["status"] == Status.OK).sum()),
        columns=diagnostic_columns(units), fold=MESSAGE_FOLD_CHARS,
        diagnostics=report.diagnostics,
        u={q: units.label(q) for q in ("length", "force", "torque")})


def has_friction(segments: pd.DataFrame) -> bool:
    """Whether the friction log has a friction factor to draw (an estimated segment with a
    bit depth and a μ)."""
    return bool(((segments["status"] == Status.OK) & segments["bit_depth_m"].notna()
                 & segments["mu_k"].notna()).any())


def no_friction_note(segments: pd.DataFrame, units: Units | None = None) -> str:
    """Why the friction log is empty, with the counts; depths in the report's ``units``
    (a field report said "934–1120 m")."""
    units = units or Units()
    if not len(segments):
        return "No friction log: the run found no rotating segment."
    status = segments["status"].value_counts()
    parts = ", ".join(f"{int(status[k])} {k}" for k in ("skipped", "failed") if k in status)
    estimated = segments[(segments["status"] == Status.OK) & segments["bit_depth_m"].notna()]
    if len(estimated):  # estimated at a depth, their μ withheld (issue 35 item 3)
        why = _withheld_by(estimated)
        verb = "was" if len(estimated) == 1 else "were"
        return (f"No friction factor to draw: {share(len(estimated), len(segments), 'segment')} "
                f"{verb} estimated at "
                f"{units.text(estimated['bit_depth_m'].min(), 'length')}–"
                f"{units.text(estimated['bit_depth_m'].max(), 'length')} {units.label('length')} "
                f"and their friction factors withheld{why}" + (f" ({parts})" if parts else "")
                + "; their reasons are in the diagnostics table.")
    return (f"No friction factor to draw: no segment was estimated with a bit depth "
            f"({plural(len(segments), 'segment')}: {parts or 'no bit depth'}); their depths "
            "and reasons are in the diagnostics table.")


#: Segment flags that withhold its friction factors, and what the friction log says of them.
_WITHHOLDERS = {"hookload_contradicts_string": "the hook-load check",
                "string_weight_unverified": "the hook-load check (string weight unverified)",
                "torque_zero_offset": "the torque-zero check"}


def _withheld_by(segments: pd.DataFrame) -> str:
    """" by …" naming the checks that withheld ``segments``' friction factors, or "" (not
    converged)."""
    flags = {f for row in segments.get("quality_flags", pd.Series(dtype=object))
             for f in (row if row is not None else ())}
    checks = [text for flag, text in _WITHHOLDERS.items() if flag in flags]
    return (" by " + " and ".join(checks)) if checks else " (not converged)"


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
    write_text_replacing(out, _html(report))  # undecodable file names: replaced
    if pdf:
        from .pdf import PAGE_IN

        write_pdf(report.data.result_dir / "report.pdf", _pdf_pages(report, PAGE_IN),
                  title=f"drillfric — {report.head['well']}",
                  footer=f"drillfric friction report — {report.head['well']}")
    return out


def _pdf_pages(report: Report, size) -> list[tuple[str, object]]:
    from .pdf import blank_page

    head, data, units = report.head, report.data, report.units
    axis = data.time_axis
    pages = [(f"Friction report — {head['well']}", _first_page(report, size)),
             *(("", p) for p in table_pages("Run details", ["", ""], _header_lines(report),
                                            font_pt=9.0))]
    if report.has_tracks:
        pages.append(("Time tracks", tracks_figure(data.tracks, data.segments, axis, size,
                                                   units)))
    for _, title, fig, note in _static_sections(report, size):
        if fig is None:
            fig = blank_page("")
            fig.text(0.5, 0.5, note or "", ha="center", wrap=True, parse_math=False)
        pages.append((title, fig))
    for row in report.segment_rows:
        est = report.estimates[int(row["id"])]
        title = f"Segment {row['id']} — bit at {row['depth']}, {row['span']}"
        figure = evidence_figure(est, row, axis, size, units, not row["bit_unresolved"],
                                 notes=segment_lead_lines(row, size))
        pages.append((title, figure))
        pages += [("", p) for p in table_pages(f"{title}: detail", ["", ""],
                                               segment_detail(row, units))]
    columns, rows, notes, common = pdf_diagnostics(report.diagnostics, units)
    lead = ("Each row's message is below it. " + ("In every segment: " + "; ".join(common)
                                                   if common else "")).strip()
    pages += [("", p) for p in table_pages("Diagnostics", columns, rows, notes=notes,
                                           lead=lead)]
    pages += [("", p) for p in table_pages("Appendix: drill string", *head["string"])]
    pages += [("", p) for p in table_pages(
        "Appendix: settings that differ from the defaults", ["setting", "value", "default"],
        head["non_default"],
        lead="Every other setting is the default (docs/configuration.md); report.html holds "
             "the whole effective configuration.")]
    return pages


#: Headline lines of the PDF's first page [in from the top of the page, per line].
_HEADLINE_TOP_IN, _HEADLINE_LINE_IN = 0.75, 0.24
#: Font sizes of the headline's bold and plain lines [pt].
_HEADLINE_PT = {True: 11.0, False: 9.0}


def _first_page(report: Report, size):
    """Page 1: the headline numbers — each line wrapped to the page, never cut (a withheld
    μ_k's reason runs to three lines) — and the friction log versus depth."""
    from .pdf import line_chars, wrap_lines

    width_in = size[0] - 2 * 0.45
    lines = [(part, strong, text.startswith(("INDICATIVE", "WARNING")))
             for text, strong in headline_lines(report.head)
             for part in wrap_lines(text, line_chars(width_in, _HEADLINE_PT[strong], strong))]
    top = _HEADLINE_TOP_IN + _HEADLINE_LINE_IN * len(lines) + 0.35
    data = report.data
    fig = figures.friction_log_figure(
        data.segments, size, report.units, top_in=top, drag=data.drag_log,
        empty_note=no_friction_note(data.segments, report.units))
    for index, (text, strong, warning) in enumerate(lines):
        fig.text(0.45 / size[0], 1 - (_HEADLINE_TOP_IN + _HEADLINE_LINE_IN * index) / size[1],
                 text, fontsize=_HEADLINE_PT[strong], va="top", parse_math=False,
                 weight="bold" if strong else "normal",
                 color="#a04000" if warning else "#222222")
    return fig


def headline_lines(head: dict) -> list[tuple[str, bool]]:
    """The headline of the PDF's first page as ``(text, bold)``, unwrapped; the report's
    HTML headline says the same (a depth log has no withheld dynamic μ_k to warn of)."""
    trust = head["trust"]
    value = head["mu_k"] if head["mu_k"] != "—" or not head["mu_k_reason"] else "none"
    mu_k = " ".join(filter(None, [f"μ_k off bottom (consensus): {value}",
                                  trust["uncertainty"],
                                  f"({trust['support']})" if trust["support"] else ""]))
    lines = [(mu_k + (f" — {head['mu_k_reason']}" if head["mu_k_reason"] else ""), True)]
    if trust["confidence"] == "low" or (trust["confidence"] == "withheld"
                                        and not head["depth_indexed"]):
        lines.append((f"WARNING: μ_k {trust['confidence']}"
                      + (f": {', '.join(trust['reasons'])}" if trust["reasons"] else ""),
                      False))
    if head["apparent"]:
        what = "window" if head["depth_indexed"] else "stand"
        lines.append((f"apparent μ on bottom: {head['apparent']['value']} (bit torque "
                      f"included, not μ_k; median of "
                      f"{plural(head['apparent']['count'], 'converged on-bottom ' + what)})",
                      True))
    lines.append((f"μ_s (consensus): {head['mu_s']}", True))
    zone = _zone_line(head)
    if zone:
        lines.append((f"friction zone: {zone}", False))
    counts = head["counts"]
    converged = "static (torque and drag)" if head["depth_indexed"] else \
        f"{counts.get('converged', '—')} μ_k converged"
    lines.append((f"segments {counts.get('segments', '—')}: {counts.get('estimated', '—')} "
                  f"estimated, {converged}, {counts.get('skipped', '—')} skipped, "
                  f"{counts.get('failed', '—')} failed", False))
    if head["span"]:
        lines.append((f"{head['span'][0]}: {head['span'][1]}", False))
    if head["indicative"]:
        lines.append(("INDICATIVE: defaults were assumed (see Run details)", False))
    if head["warnings"]:
        lines.append((f"WARNING: {plural(len(head['warnings']), 'warning')}, see Run details",
                      False))
    return lines


#: Columns of the PDF's diagnostics table (headings of DIAGNOSTIC_COLUMNS, before units);
#: the message goes under each row.
PDF_DIAGNOSTICS = ("seg.", "kind", "bit depth", "time", "μ_s", "μ_k / apparent μ", "μ_TD",
                   "misfit / swing {unit} (quality)", "severity", "stuck",
                   "bit speed (interval)", "status")


def pdf_diagnostics(diagnostics: list[dict], units: Units
                    ) -> tuple[list[str], list[list[str]], list[str], list[str]]:
    """The diagnostics as the PDF prints them: headings, rows of the
    :data:`PDF_DIAGNOSTICS` columns, each row's message without the notes every row shares,
    and those shared notes (said once above the table)."""
    from .render import DIAGNOSTIC_COLUMNS

    names = [name for name, _, _ in DIAGNOSTIC_COLUMNS]
    keep = [names.index(n) for n in PDF_DIAGNOSTICS]
    headings = [h for h, _ in diagnostic_columns(units)]
    parts = [split_notes(r["cells"][-1]) for r in diagnostics]
    shared = [p for p in parts[0] if all(p in q for q in parts)] if len(parts) > 2 else []
    notes = ["; ".join(p for p in q if p not in shared) for q in parts]
    return ([headings[i] for i in keep], [[r["cells"][i] for i in keep] for r in diagnostics],
            notes, shared)


def segment_lead_lines(row: dict, size) -> list[str]:
    """What a segment's PDF page says above its panels: its lead (what was found, what was
    withheld and why; :mod:`drillfric.report.lead`) and, when the fit misses the data's
    regime, that sentence (the HTML's red box), wrapped to the page, every line kept."""
    from .pdf import line_chars, wrap_lines

    chars = line_chars(size[0] * (0.98 - 0.09), 7.0)
    lines = row["lead"].lines() + ([row["fit_sentence"]] if row["fit_mismatch"] else [])
    return [part for line in lines for part in wrap_lines(line, chars)]


def segment_detail(row: dict, units: Units) -> list[list[str]]:
    """The rest of a segment's section as label–value rows for the page after its panels
    (the HTML's folded detail): the fit's numbers, what the fit reproduces, every flag with
    its meaning and every note of the estimators, in full."""
    rows = [["μ", f"{row['mu_name']} {fmt(row['mu_k'])} ({row['zone']}), μ_s "
                  f"{row['mu_s_text']}, μ_TD {fmt(row['mu_td'])}; μ_k {row['status_word']}"],
            ["torque fit", f"misfit / swing {row['torque']} {units.label('torque')} (fit "
                           f"quality {row['quality']})"],
            ["hook load", f"measured / model {row['hookload']} {units.label('force')}"],
            ["bit speed", row["bit_speed"] + (f" (logged every {row['interval']})"
                                              if row["interval"] else "")],
            ["stick-slip", f"severity {row['severity_text']}"],
            ["observer starts", f"(μ_s, μ_k) {row['starts_text']}"]]
    if row["fit_sentence"]:
        rows.append(["fit", row["fit_sentence"]])
    rows += _labelled("flags", [f"{label}: {meaning}" if meaning else label
                                for _, label, meaning in row["flag_items"]])
    rows += _labelled("notes (not warnings)", [f"{label}: {meaning}"
                                               for _, label, meaning in row["note_flags"]])
    return rows + _labelled("estimator notes", row["notes"])


def _labelled(label: str, texts: list[str]) -> list[list[str]]:
    """Rows of a label–value table: ``label`` beside the first of ``texts`` only."""
    return [[label if i == 0 else "", text] for i, text in enumerate(texts)]


def _header_lines(report: Report) -> list[list[str]]:
    head = report.head
    counts = head["counts"]
    lines = [["well", head["well"]], ["drillfric", head["version"]],
             ["results written", head["written"]], ["report built", head["built"]],
             [head["span"][0] if head["span"] else "log time", head["span"][1]
              if head["span"] else "—"],
             ["μ_k off bottom (consensus)", head["mu_k"] + (f" — {head['mu_k_reason']}"
                                                            if head["mu_k_reason"] else "")],
             ["apparent μ on bottom", head["apparent"]["value"] + " (bit torque included)"
              if head["apparent"] else "—"],
             ["μ_s (consensus)", head["mu_s"]],
             ["friction zone", _zone_line(head)
              or "—"],
             ["segments", ", ".join(f"{k} {v}" for k, v in counts.items())],
             ["units", head["units"]]]
    for kind, path, sha in head["files"]:
        lines += [[f"input {kind}", f"{path}\nsha256 {sha}"]]
    lines += [["rows", fmt(head["rows"], ",.0f")], ["resampled to [Hz]", fmt(head["rate_hz"])],
              ["torque lag behind speed", head["skew"]]]
    lines += [["ASSUMED", a] for a in head["assumed"]] or [["assumed", "nothing"]]
    lines += [["WARNING", w] for w in head["warnings"]]
    check = _broomstick_note(report.broomstick.check, report.units)
    if check:
        lines.append(["WARNING" if report.broomstick.check["warning"] else "string weight",
                      check])
    return lines

