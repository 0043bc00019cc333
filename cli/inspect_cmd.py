"""`drillfric inspect WELL` (INTERFACE.md): what was recognised in a well's files."""

from __future__ import annotations

import json

import click
import numpy as np


@click.command("inspect")
@click.argument("well", type=click.Path(path_type=str))
@click.option("--config", "config_file", type=click.Path(path_type=str),
              help="Well configuration TOML (overrides the NAME.toml sidecar).")
@click.option("--survey", "survey_file", type=click.Path(path_type=str),
              help="Survey file (overrides the NAME.survey.* sidecar).")
@click.option("--json", "as_json", is_flag=True, help="Print machine-readable JSON.")
def command(well: str, config_file: str | None, survey_file: str | None, as_json: bool) -> None:
    """Show the channels, units, rate, gaps, time span and survey recognised in WELL.

    WELL is a data file (.parquet, .csv, .h5, .las) with optional NAME.toml and
    NAME.survey.csv sidecars, an HDF5 file with /surface, /survey and /config, or a
    directory holding well.toml.
    """
    from drillfric.io.well import load_well

    data = load_well(well, config=config_file, survey=survey_file)
    summary = summarize(data)
    if as_json:
        click.echo(json.dumps(summary, indent=2))
    else:
        click.echo(render(summary))  # the result: printed even with --quiet


def summarize(data) -> dict:
    """The ``inspect --json`` document (INTERFACE.md keys first, then extras)."""
    from drillfric.io.channels import BY_NAME, SUFFIX_UNITS
    from drillfric.io.timebase import spacing_summary
    from drillfric.segmentation import segment

    tb = data.timebase
    channels = {}
    for name, info in data.channels.items():
        values = data.surface[name].to_numpy(dtype=float)
        finite = values[np.isfinite(values)]
        channels[name] = {
            "column": info.column, "unit": info.unit, "unit_source": info.source,
            "si_unit": SUFFIX_UNITS[BY_NAME[name].key],
            "null_fraction": info.null_fraction,
            "null_count": int(round(info.null_fraction * (tb.rows if name != "time_s" else
                                    tb.rows + tb.untimed_dropped + tb.duplicates_dropped))),
            "min": float(finite.min()) if finite.size else None,
            "median": float(np.median(finite)) if finite.size else None,
            "max": float(finite.max()) if finite.size else None,
        }
    survey = None
    if data.survey is not None:
        survey = {"stations": int(len(data.survey.md_m)), "md_max_m": data.survey.md_max_m,
                  "inc_max_deg": float(np.degrees(np.max(data.survey.inc_rad))),
                  "tvd_max_m": float(np.max(data.survey.tvd_m))}
    return {
        "channels": channels, "rows": tb.rows, "t_start_s": tb.t_start_s,
        "t_end_s": tb.t_end_s, "rate_hz": tb.rate_hz, "gaps": [list(g) for g in tb.gaps],
        "survey": survey,
        "well": data.name, "files": {k: str(v) for k, v in data.files.items()},
        "duplicates_dropped": tb.duplicates_dropped, "untimed_dropped": tb.untimed_dropped,
        "origin": None if tb.origin is None else tb.origin.isoformat(),
        "source_start_s": tb.source_start_s,
        "spacing_s": spacing_summary(data.surface["time_s"].to_numpy()),
        "max_gap_s": data.config.segmentation.max_gap_s,
        "assumed": data.config.assumed_with(data.survey),
        "segments": [_segment(seg) for seg in segment(data.surface, data.config)],
    }


def _segment(seg) -> dict:
    """One segment of :func:`drillfric.segmentation.segment` as JSON (NaN → null)."""
    def num(x):
        return None if x is None or not np.isfinite(x) else float(x)

    return {"id": seg.id, "kind": seg.kind, "t_start_s": num(seg.t_start_s),
            "t_end_s": num(seg.t_end_s), "duration_s": num(seg.duration_s),
            "bit_depth_m": num(seg.bit_depth_m), "status": seg.status, "message": seg.message}


def _num(value: float | None) -> str:
    return "—" if value is None else f"{value:.4g}"


def render(s: dict) -> str:
    """Human-readable table of an inspect summary."""
    lines = [f"well       {s['well']}"]
    lines += [f"{k:<10} {v}" for k, v in s["files"].items()]
    head = ("channel", "column", "unit", "from", "SI unit", "nulls", "min", "median", "max")
    rows = [head] + [
        (name, c["column"], c["unit"], c["unit_source"], c["si_unit"],
         f"{c['null_count']} ({100 * c['null_fraction']:.1f}%)",
         _num(c["min"]), _num(c["median"]), _num(c["max"]))
        for name, c in s["channels"].items()]
    widths = [max(len(str(r[i])) for r in rows) for i in range(len(head))]
    lines.append("")
    lines += ["  ".join(str(v).ljust(w) for v, w in zip(r, widths, strict=True)).rstrip()
              for r in rows]
    lines.append("")
    dropped = []
    if s["duplicates_dropped"]:
        dropped.append(f"{s['duplicates_dropped']} repeated timestamps dropped")
    if s["untimed_dropped"]:
        dropped.append(f"{s['untimed_dropped']} rows without a time dropped")
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
    limit = max(s["max_gap_s"], 5 / s["rate_hz"]) if s["rate_hz"] else s["max_gap_s"]
    gaps = s["gaps"]
    shown = ", ".join(f"{a:.6g}–{b:.6g} s" for a, b in gaps[:5]) + (" …" if len(gaps) > 5 else "")
    lines.append(f"gaps       {len(gaps)} longer than {limit:.3g} s" + (f": {shown}" if gaps
                                                                        else ""))
    sv = s["survey"]
    lines.append("survey     none — a vertical well is assumed (see below)" if sv is None else
                 f"survey     {sv['stations']} stations to {sv['md_max_m']:.1f} m MD, "
                 f"max inclination {sv['inc_max_deg']:.1f}°, TVD {sv['tvd_max_m']:.1f} m")
    lines.append(_segments_line(s["segments"]))
    lines += [f"assumed    {note}" for note in s["assumed"]]
    return "\n".join(lines)


def _segments_line(segments: list[dict]) -> str:
    ok = [g for g in segments if g["status"] == "ok"]
    kinds = {k: sum(g["kind"] == k for g in ok) for k in sorted({g["kind"] for g in ok})}
    detail = ", ".join(f"{n} {k.replace('_', ' ')}" for k, n in kinds.items())
    seconds = sum(g["duration_s"] or 0.0 for g in ok)
    return (f"segments   {len(segments)} rotating: {len(ok)} usable"
            + (f" ({detail}; {seconds / 3600:.2f} h)" if ok else "")
            + f", {len(segments) - len(ok)} skipped")
