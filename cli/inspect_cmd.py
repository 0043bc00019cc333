"""`drillfric inspect WELL` (docs/cli.md): what was recognised in a well's files."""

from __future__ import annotations

import json
import re

import click
import numpy as np

from drillfric.io.text import plural, terminal_text
from drillfric.units import number
from drillfric.vocabulary import Status

from .common import unit_system, units_option

#: Channel quantities shown in the display units of ``--units`` (kN, kN·m, bar … in SI;
#: the others, e.g. time and rotary speed, as stored).
_SHOWN = {"length": "length", "force": "force", "torque": "torque",
          "rotary speed": "rotary speed", "pressure": "pressure", "flow rate": "flow rate",
          "speed": "speed"}


@click.command("inspect")
@click.argument("well", type=click.Path(path_type=str))
@click.option("--config", "config_file", type=click.Path(path_type=str),
              help="Well configuration TOML (overrides the NAME.toml sidecar).")
@click.option("--survey", "survey_file", type=click.Path(path_type=str),
              help="Survey file (overrides the NAME.survey.* sidecar).")
@click.option("--string", "string_file", type=click.Path(path_type=str),
              help="WITSML tubular file read as the drill string (overrides the "
                   "NAME.tubular.xml sidecar; for a configuration without [[string.sections]]).")
@click.option("--json", "as_json", is_flag=True, help="Print machine-readable JSON (SI).")
@units_option
def command(well: str, config_file: str | None, survey_file: str | None,
            string_file: str | None, as_json: bool, units: str | None) -> None:
    """Show the channels, units, rate, gaps, time span and survey recognised in WELL.

    WELL is a data file (.parquet, .csv, .h5, .las, .xml, .dlis, .xlsx) with optional
    NAME.toml and NAME.survey.csv sidecars, an HDF5 file with /surface, /survey and
    /config, or a directory holding well.toml. For a depth-indexed log: the depth span and
    the windows of its friction log instead of the time base and segments.

    Ends with what 'drillfric run' will do, from run's own checks before it estimates: the
    segments (windows) it estimates (usable), skips and fails, with the reasons, or the
    error it would stop the log with (exit code 2); and whether run's hook-load check will
    withhold their friction factors (the string against the measured hook load).
    """
    from drillfric.io.well import open_well

    opened = open_well(well, config=config_file, survey=survey_file, string=string_file)
    refused = None
    if opened.depth_indexed:
        summary = summarize_depth_log(opened)
    else:
        from drillfric.runner.preview import refusal

        data = opened.load()
        summary = summarize(opened, data)
        refused = refusal(opened, data.surface, data.timebase.duplicates_dropped)
        summary["run_refuses"] = None if refused is None else refused.message
    if as_json:
        click.echo(json.dumps(summary, indent=2))
    else:
        system = unit_system(units, opened.config)
        text = render_depth_log(summary, system) if opened.depth_indexed else \
            render(summary, system)
        click.echo(terminal_text(text))  # the result: printed even with --quiet
    if refused is not None:  # what `run` would refuse: the same line and exit code
        raise refused


def summarize(well, data) -> dict:
    """The ``inspect --json`` document (docs/cli.md keys first, then extras) of the opened
    ``well`` and its loaded ``data``; its segments are those run cuts, each with what run
    does with it before estimating (:func:`drillfric.runner.preview.segment_verdicts`)."""
    from drillfric.io.timebase import spacing_summary
    from drillfric.runner.preview import segment_rows, string_weight_check

    tb = data.timebase
    channels = {}
    for name, info in data.channels.items():
        total = tb.rows if name != "time_s" else (tb.rows + tb.untimed_dropped
                                                  + tb.duplicates_dropped
                                                  + tb.conflicts_dropped)
        channels[name] = _channel(name, info.column, info.unit, info.source,
                                  info.null_fraction, total, data.surface)
    assumed = data.config.assumed_with(data.survey)
    verdicts = segment_rows(well, data.surface, assumed)
    segments = [_segment(seg, pre) for seg, _, pre in verdicts]
    string_check = string_weight_check(well, data.surface, verdicts)
    return {
        "channels": channels, "rows": tb.rows, "t_start_s": tb.t_start_s,
        "t_end_s": tb.t_end_s, "rate_hz": tb.rate_hz, "gaps": [list(g) for g in tb.gaps],
        "survey": _survey(data.survey),
        "well": data.name, "files": {k: str(v) for k, v in data.files.items()},
        "duplicates_dropped": tb.duplicates_dropped, "untimed_dropped": tb.untimed_dropped,
        "conflicts_dropped": tb.conflicts_dropped,
        "origin": None if tb.origin is None else tb.origin.isoformat(),
        "source_start_s": tb.source_start_s,
        "spacing_s": spacing_summary(data.surface["time_s"].to_numpy()),
        "max_gap_s": data.config.segmentation.max_gap_s,
        "assumed": assumed, "segments": segments, "string_check": string_check,
    }


def _channel(name: str, column, unit: str, source: str, null_fraction: float, total: int,
             frame) -> dict:
    """One channel of the ``inspect --json`` document."""
    from drillfric.io.channels import BY_NAME, SUFFIX_UNITS

    values = frame[name].to_numpy(dtype=float)
    finite = values[np.isfinite(values)]
    return {"column": str(column), "unit": unit, "unit_source": source,
            "si_unit": SUFFIX_UNITS[BY_NAME[name].key], "null_fraction": null_fraction,
            "null_count": int(round(null_fraction * total)),
            "min": float(finite.min()) if finite.size else None,
            "median": float(np.median(finite)) if finite.size else None,
            "max": float(finite.max()) if finite.size else None}


def _survey(path) -> dict | None:
    if path is None:
        return None
    return {"stations": int(len(path.md_m)), "md_max_m": path.md_max_m,
            "inc_max_deg": float(np.degrees(np.max(path.inc_rad))),
            "tvd_max_m": float(np.max(path.tvd_m))}


def summarize_depth_log(well) -> dict:
    """The ``inspect --json`` document of a depth-indexed log: the interface's keys (no time
    base: ``t_start_s``, ``t_end_s``, ``rate_hz`` null), ``index = "depth"``, the depth span
    and the windows of its friction log (:mod:`drillfric.estimation.friction_log`)."""
    from drillfric.estimation.friction_log import check_window, read_depth_log, windows

    log = read_depth_log(well)
    channels = {m.channel.name: _channel(m.channel.name, m.column, m.unit, m.source,
                                         float(log[m.channel.name].isna().mean()), len(log),
                                         log)
                for m in well.mappings.values()}
    md = log["measured_depth_m"].to_numpy(float)
    found, assumed = windows(log, well.config)
    files = {k: str(v) for k, v in (("data", well.files.data), ("config", well.files.config),
                                     ("survey", well.files.survey)) if v is not None}
    return {
        "channels": channels, "rows": len(log), "t_start_s": None, "t_end_s": None,
        "rate_hz": None, "gaps": [], "survey": _survey(well.survey), "well": well.name,
        "files": files, "index": "depth", "md_start_m": float(md.min()),
        "md_end_m": float(md.max()),
        "md_step_m": float(np.median(np.diff(np.sort(md)))) if md.size > 1 else None,
        "window_m": well.config.friction_log.window_m,
        "assumed": [n for n in well.assumed if not n.startswith("top-drive")] + assumed,
        "segments": [_window(w, *check_window(w, well)) for w in found],
    }


def _window(window, status, message: str) -> dict:
    """One window of a depth log as JSON, with run's verdict before back-calculating it
    (:func:`drillfric.estimation.friction_log.check_window`; status ``ok``: run estimates
    it)."""
    return {"id": window.id, "kind": window.kind.value, "md_top_m": window.md_top_m,
            "md_bottom_m": window.md_bottom_m, "rows": window.rows,
            "bit_depth_m": window.bit_depth_m, "status": status.value, "message": message}


def _segment(seg, pre) -> dict:
    """One segment as JSON (NaN → null): its span, the bit depth run estimates it at, and
    run's verdict before estimating (:class:`drillfric.runner.estimator.Precheck`; status
    ``ok``: run estimates it)."""
    def num(x):
        return None if x is None or not np.isfinite(x) else float(x)

    return {"id": seg.id, "kind": seg.kind, "t_start_s": num(seg.t_start_s),
            "t_end_s": num(seg.t_end_s), "duration_s": num(seg.duration_s),
            "bit_depth_m": num(pre.bit_depth_m), "status": pre.status.value,
            "message": pre.message}


def _num(value: float | None, resolution: float | None = None) -> str:
    """A table value (:func:`drillfric.units.number`): 4 significant digits, never finer
    than ``resolution``, a numerical zero as 0, no exponent below 1e9.

    Examples
    --------
    >>> _num(24999.4), _num(254.93), _num(None), _num(3e12), _num(1.173e-34, 0.1)
    ('24999', '254.9', '—', '3e+12', '0')
    """
    return number(value, resolution)


#: Resolution of the channels shown in their own unit (not a display quantity).
_RESOLUTION = {"time": 1e-3, "percentage": 0.1, "pump rate": 0.1}


def _channel_table(s: dict, units: str) -> list[str]:
    """The channel table: source column and unit, nulls, min/median/max in the display unit
    of ``units`` (kN, not 2.549e+05 N), else the unit of the canonical column."""
    from drillfric.io.channels import BY_NAME
    from drillfric.units import display_factor, display_resolution, display_unit

    head = ("channel", "column", "unit", "from", "shown in", "nulls", "min", "median", "max")
    rows = [head]
    for name, c in s["channels"].items():
        kind = BY_NAME[name].kind
        quantity = _SHOWN.get(kind)
        shown, scale, step = ((display_unit(quantity, units), display_factor(quantity, units),
                               display_resolution(quantity, units))
                              if quantity else (c["si_unit"], 1.0, _RESOLUTION.get(kind)))
        rows.append((name, c["column"], c["unit"], c["unit_source"], shown,
                     f"{c['null_count']} ({100 * c['null_fraction']:.1f}%)",
                     *(_num(None if c[k] is None else c[k] * scale, step)
                       for k in ("min", "median", "max"))))
    widths = [max(len(str(r[i])) for r in rows) for i in range(len(head))]
    return ["  ".join(str(v).ljust(w) for v, w in zip(r, widths, strict=True)).rstrip()
            for r in rows]


def _survey_line(sv: dict | None, units: str) -> str:
    from drillfric.units import format_value

    if sv is None:
        return "survey     none — a vertical well is assumed (see below)"
    return (f"survey     {plural(sv['stations'], 'station')} to "
            f"{format_value(sv['md_max_m'], 'length', units)} MD, max inclination "
            f"{sv['inc_max_deg']:.1f}°, TVD {format_value(sv['tvd_max_m'], 'length', units)}")


def render(s: dict, units: str = "si") -> str:
    """Human-readable table of an inspect summary (physical values in ``units``)."""
    lines = [f"well       {s['well']}"]
    lines += [f"{k:<10} {v}" for k, v in s["files"].items()]
    lines += [""] + _channel_table(s, units) + [""]
    dropped = []
    if s["duplicates_dropped"]:
        dropped.append(f"{plural(s['duplicates_dropped'], 'repeated timestamp')} dropped")
    if s.get("conflicts_dropped"):
        dropped.append(f"{plural(s['conflicts_dropped'], 'row')} of timestamps repeated with "
                       "other values dropped")
    if s["untimed_dropped"]:
        dropped.append(f"{plural(s['untimed_dropped'], 'row')} without a time dropped")
    lines.append(f"rows       {s['rows']}" + (f" ({'; '.join(dropped)})" if dropped else ""))
    span = s["t_end_s"] - s["t_start_s"]
    start = (f"from {s['origin']}" if s["origin"] else
             f"file time {_num(s['source_start_s'])} s at time_s = 0")
    lines.append(f"time span  {s['t_start_s']:.6g} … {s['t_end_s']:.6g} s "
                 f"({span / 3600:.2f} h), {start}")
    sp = s["spacing_s"]
    spacing = (f" (spacing median {sp['median']:.3g} s, 5–95 % {sp['p05']:.3g}–{sp['p95']:.3g}"
               f" s, min {sp['min']:.3g} s, max {sp['max']:.3g} s)") if sp else ""
    lines.append(f"rate       {s['rate_hz']:.4g} Hz nominal{spacing}")
    gaps = s["gaps"]
    shown = ", ".join(f"{a:.6g}–{b:.6g} s" for a, b in gaps[:5]) + (" …" if len(gaps) > 5 else "")
    lines.append(f"gaps       {len(gaps)} longer than max_gap_s = {s['max_gap_s']:.3g} s (a "
                 "segment ends at each)" + (f": {shown}" if gaps else ""))
    lines.append(_survey_line(s["survey"], units))
    if s["run_refuses"]:
        lines.append(f"segments   {len(s['segments'])} rotating, none estimated: run refuses "
                     "the log (the error below)")
    else:
        lines += _segments_lines(s["segments"], units)
        if (s.get("string_check") or {}).get("line"):
            lines.append(f"string     {s['string_check']['line']}")
    return "\n".join(lines + _assumed_lines(s["assumed"], units))


def _segments_lines(segments: list[dict], units: str = "si") -> list[str]:
    """What run does with the segments: how many it estimates (the usable ones), skips and
    fails, and why (:func:`_reasons`)."""
    ok = [g for g in segments if g["status"] == Status.OK]
    seconds = sum(g["duration_s"] or 0.0 for g in ok)
    return [f"segments   {len(segments)} rotating: {len(ok)} usable"
            + (f" ({_kinds(ok)}; {seconds / 3600:.2f} h)" if ok else "")
            + _counts(segments)] + _reasons(segments, units)


def _kinds(ok: list[dict]) -> str:
    """'16 off bottom rotating, 13 on bottom rotating' of the usable segments or windows."""
    kinds = {k: sum(g["kind"] == k for g in ok) for k in sorted({g["kind"] for g in ok})}
    return ", ".join(f"{n} {k.replace('_', ' ')}" for k, n in kinds.items())


def _counts(items: list[dict]) -> str:
    """', N skipped' and, when any failed, ', N failed'."""
    skipped = sum(g["status"] == Status.SKIPPED for g in items)
    failed = sum(g["status"] == Status.FAILED for g in items)
    return f", {skipped} skipped" + (f", {failed} failed" if failed else "")


def _reasons(items: list[dict], units: str = "si") -> list[str]:
    """One line per reason run does not estimate segments (windows) for, whatever its
    numbers: how many, skipped or failed, and the first one's message (its quantities in
    ``units``)."""
    from drillfric.units import message_text

    groups: dict[tuple[str, str], list[dict]] = {}
    for g in items:
        if g["status"] != Status.OK:
            groups.setdefault((g["status"], re.sub(r"\d+(\.\d+)?", "#", g["message"])),
                              []).append(g)
    return [f"{'':10} {len(group)} {status} like segment {group[0]['id']}: "
            f"{message_text(group[0]['message'], units)}"
            for (status, _), group in groups.items()]


def render_depth_log(s: dict, units: str = "si") -> str:
    """Human-readable summary of a depth-indexed log (:func:`summarize_depth_log`)."""
    from drillfric.units import format_value

    lines = [f"well       {s['well']}"]
    lines += [f"{k:<10} {v}" for k, v in s["files"].items()]
    lines.append("index      depth-indexed log (no time base): `run` gives a static friction "
                 "log by torque-and-drag back-calculation per depth window — no observer, "
                 "no μ_s, no bit speed")
    lines += [""] + _channel_table(s, units) + [""]
    lines.append(f"rows       {s['rows']}")
    step = "" if s["md_step_m"] is None else (
        f" (step median {format_value(s['md_step_m'], 'length', units, '.3g')})")
    lines.append(f"depth      {format_value(s['md_start_m'], 'length', units)} … "
                 f"{format_value(s['md_end_m'], 'length', units)} MD{step}")
    lines.append(_survey_line(s["survey"], units))
    ok = [w for w in s["segments"] if w["status"] == Status.OK]
    lines.append(f"windows    {len(s['segments'])} of "
                 f"{format_value(s['window_m'], 'length', units, '.0f')}: {len(ok)} usable"
                 + (f" ({_kinds(ok)})" if ok else "") + _counts(s["segments"]))
    lines += _reasons(s["segments"], units)
    return "\n".join(lines + _assumed_lines(s["assumed"], units))


def _assumed_lines(notes: list[str], units: str) -> list[str]:
    """What was assumed, its quantities in the display units of ``units`` (issue 35: "WOB
    ≤ 10 kN" of a field-units inspect reads "WOB ≤ 2.25 klbf")."""
    from drillfric.units import display_text, message_text

    return [f"assumed    {message_text(display_text(note, units), units)}" for note in notes]
