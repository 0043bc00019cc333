"""Turning results into what the templates show: formatted values, tables, inline images.

Everything a template receives is plain text or numbers; Jinja2 autoescaping is on for
every ``.j2`` template, so well names, paths and messages from users' files are shown as
text. Images are base64 PNG ``data:`` URIs: one self-contained file, no network request.
"""

from __future__ import annotations

import base64
import io
import math
import warnings
from contextlib import contextmanager
from datetime import UTC, datetime
from functools import cache
from importlib.resources import files

import pandas as pd
from jinja2 import Environment, FileSystemLoader, select_autoescape
from matplotlib.figure import Figure

from drillfric.io.text import plural, share
from drillfric.io.timebase import clock_at
from drillfric.result import Flag, segment_is_apparent, well_friction_columns
from drillfric.vocabulary import CONNECTION, Kind, Method, Status

from .display import Units, fmt, row_flags

#: Resolution of the figures embedded in HTML [dots per inch].
HTML_DPI = 90
#: Columns of the diagnostics table (HTML and PDF), in order: heading, the quantity whose
#: display unit the heading names (None: no unit or a fixed one; at ``{unit}``, else at the
#: end) and the cell's CSS class
#: in the HTML table (``num``: right-aligned number, ``wrap``: text that may wrap — every
#: column whose text can grow, so that the table fits the page and the message keeps its
#: room).
DIAGNOSTIC_COLUMNS = (
    ("seg.", None, ""), ("kind", None, "wrap"), ("bit depth", "length", "num"),
    ("time", None, "wrap"), ("μ_s", None, "num wrap"), ("μ_k / apparent μ", None, "num"),
    ("μ_TD", None, "num"),
    ("μ zone", None, "wrap"), ("spread μ_s / μ_k", None, "num"), ("settling [s]", None, "num"),
    ("residual [rpm]", None, "num"),
    ("misfit / swing {unit} (quality)", "torque", "num wrap"),
    ("severity", None, "num"), ("stuck", None, "num"),
    ("hook load", "force", "num"), ("bit speed (interval)", None, "wrap"),
    ("observability", None, "wrap"), ("status", None, "wrap"), ("message", None, ""))
#: Messages longer than this [characters] are folded in the HTML table (click to read).
MESSAGE_FOLD_CHARS = 90


@cache
def environment() -> Environment:
    """The Jinja2 environment of the report templates (autoescaping on for every template);
    one per process, so each template is compiled once."""
    env = Environment(loader=FileSystemLoader(str(files("drillfric.templates"))),
                      autoescape=select_autoescape(["html", "j2"], default=True),
                      trim_blocks=True, lstrip_blocks=True)
    env.filters["num"] = fmt
    env.filters["plural"] = plural
    return env


def figure_uri(fig: Figure, dpi: int = HTML_DPI) -> str:
    """A ``data:image/png;base64,...`` URI of a figure (for an ``<img>`` in the HTML)."""
    buf = io.BytesIO()
    with quiet_glyphs():
        fig.savefig(buf, format="png", dpi=dpi)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


@contextmanager
def quiet_glyphs():
    """Silence matplotlib's "Glyph ... missing from font" warnings while drawing.

    Names from users' files may hold characters the default font lacks; they are drawn as
    boxes, which is the best the figure can do, and not worth a warning every night.
    """
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"Glyph \d+ .*missing from font",
                                category=UserWarning)
        yield


def clock(seconds: float) -> str:
    """Seconds since the start of the log as ``h:mm:ss`` (log time: the data carry no date)."""
    if not math.isfinite(seconds):
        return "—"
    whole = int(round(seconds))
    return f"{whole // 3600}:{whole % 3600 // 60:02d}:{whole % 60:02d}"


def mu_s_text(mu_s, identifiable: bool, lower_bound) -> str:
    """μ_s as shown to users: the value, "≥ bound", or "not identifiable" (docs/theory.md §6)."""
    if identifiable and fmt(mu_s) != "—":
        return fmt(mu_s)
    if fmt(lower_bound) != "—":
        return "≥ " + fmt(lower_bound)
    return "not identifiable"


def severity_text(row: dict) -> str:
    """The stick-slip severity as shown: its value, or "severe" where it is
    withheld as beyond its validated range (flag ``stick_slip_beyond_validated``,
    docs/bit_speed.md), never a bare "—" that reads as "no stick-slip"."""
    if fmt(row.get("stick_slip_severity")) == "—" and \
            Flag.STICK_SLIP_BEYOND_VALIDATED in row_flags(row):
        return "severe"
    return fmt(row.get("stick_slip_severity"), ".2f")


#: Why a segment shows no stick-slip severity, by flag or field, in the order said.
_NO_SEVERITY = (("stick_slip_beyond_validated", "severe (beyond the validated range)"),
                ("stick_slip_undetermined", "undetermined"),
                ("channel_skew_unidentified", "withheld (channel skew not identified)"))


def severity_note(segments: pd.DataFrame) -> str:
    """Why the severity panel is empty: the estimated segments' reasons, counted (severe
    stick-slip, undetermined, bit speed not resolved or withheld, on bottom).

    >>> severity_note(pd.DataFrame({"status": ["ok", "ok"], "kind": ["off_bottom_rotating"] * 2,
    ...     "quality_flags": [["stick_slip_beyond_validated"], []],
    ...     "bit_speed_resolved": [True, False]}))
    'no severity shown: 1 severe (beyond the validated range), 1 bit speed not resolved or withheld'
    """
    ok = segments[segments["status"] == Status.OK] if "status" in segments else segments
    counts: dict[str, int] = {}
    for _, row in ok.iterrows():
        flags = set(row.get("quality_flags") if row.get("quality_flags") is not None else ())
        why = next((text for flag, text in _NO_SEVERITY if flag in flags), None)
        if why is None and row.get("kind") == Kind.ON_BOTTOM:
            why = "on bottom"
        elif why is None and row.get("bit_speed_resolved") is not True:
            why = "bit speed not resolved or withheld"
        if why:
            counts[why] = counts.get(why, 0) + 1
    if not counts:
        return "no severity shown: no estimated segment"
    return "no severity shown: " + ", ".join(f"{n} {why}" for why, n in counts.items())


def observability(row: dict) -> str:
    """Whether the segment identifies μ_s, bounds it, or says nothing about it."""
    if row.get("status") != Status.OK:
        return "—"
    if row.get("mu_s_identifiable"):
        return "μ_s identified"
    if fmt(row.get("mu_s_lower_bound")) != "—":
        return "μ_s bounded below"
    return "μ_s not observable"


def row_class(row: dict) -> str:
    """CSS class of a segment: failed, skipped, unconverged or ok."""
    if row.get("status") in (Status.FAILED, Status.SKIPPED):
        return str(row["status"])
    return "ok" if row.get("converged") else "unconverged"


def clock_span(row: dict, origin) -> str:
    """A segment's time span: UTC clock times when known, else log time ``h:mm:ss``; "—"
    without a time (a depth-indexed log's windows).

    >>> clock_span({"t_start_s": 49570.0, "t_end_s": 49702.0}, None)
    '13:46:10–13:48:22'
    >>> clock_span({"t_start_s": None, "t_end_s": None}, None)
    '—'
    """
    start, end = row.get("clock_start_utc"), row.get("clock_end_utc")
    t0, t1 = (_finite(row.get(key)) for key in ("t_start_s", "t_end_s"))
    if origin is not None and t0 is not None and t1 is not None:
        start, end = clock_at(origin, t0).isoformat(), clock_at(origin, t1).isoformat()
    if isinstance(start, str) and isinstance(end, str):
        a, b = pd.Timestamp(start), pd.Timestamp(end)
        return f"{a:%H:%M:%S}–{b:%H:%M:%S}"
    if t0 is None or t1 is None:
        return "—"
    return f"{clock(t0)}–{clock(t1)}"


def _finite(value) -> float | None:
    """``value`` as a finite float, or None (missing, NaN, not a number)."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) else None


def pair(a, b, spec: str = ".3f") -> str:
    """``"a / b"`` formatted, "—" for a missing one; "—" when both are missing."""
    left, right = fmt(a, spec), fmt(b, spec)
    return "—" if left == right == "—" else f"{left} / {right}"


def _scaled(value, scale: float):
    try:
        return float(value) * scale
    except (TypeError, ValueError):
        return None


def bit_speed_unresolved(row: dict) -> bool:
    """Whether the segment says its bit speed is not resolved (older results: no)."""
    resolved = row.get("bit_speed_resolved")
    return resolved is not None and not pd.isna(resolved) and not bool(resolved)


#: How the estimator's reason begins (drillfric.estimation.sampling); not repeated after
#: "not resolved".
_REASON_PREFIX = "bit speed not resolved:"


def bit_speed_text(row: dict, reason: bool = True) -> str:
    """Whether the segment's bit speed is resolved (and, with ``reason``, why not)."""
    resolved = row.get("bit_speed_resolved")
    if row.get("status") != Status.OK or resolved is None or pd.isna(resolved):
        return "—"
    if not bit_speed_unresolved(row):
        return "resolved"
    why = str(row.get("bit_speed_reason") or "").strip()
    if why.lower().startswith(_REASON_PREFIX):
        why = why[len(_REASON_PREFIX):].strip()
    return "not resolved" + (f": {why}" if why and reason else "")


def interval_text(row: dict) -> str:
    """The segment's effective logging interval, e.g. "0.05 s" ("" when unknown)."""
    interval = fmt(row.get("sample_interval_s"), ".3g")
    return "" if interval == "—" else f"{interval} s"


def row_zone(row: dict) -> str:
    """A segment's friction zone as shown ("open hole", "effective"), "—" when it has none
    (a skipped segment: None in summary.json, NaN in a table — never "nan").

    >>> row_zone({"friction_zone": "open_hole"}), row_zone({"friction_zone": float("nan")})
    ('open hole', '—')
    """
    zone = row.get("friction_zone")
    return zone.replace("_", " ") if isinstance(zone, str) and zone else "—"


def zone_text(segments: pd.DataFrame) -> str:
    """The friction zone the estimated segments' μ are for ("open hole", "effective"), or
    "" when they differ or the results do not say (older results)."""
    if "friction_zone" not in segments:
        return ""
    zones = set(segments.loc[segments["status"] == Status.OK, "friction_zone"].dropna())
    return zones.pop().replace("_", " ") if len(zones) == 1 else ""


def flag_items(row: dict) -> list[tuple[str, str, str]]:
    """The segment's flags as ``(flag, label, meaning)`` (docs/outputs.md, flags); an
    unknown flag (a newer drillfric's) keeps its name with no meaning.

    Flags that do not bear on the reported numbers (:func:`is_note_flag`) are left out:
    they are :func:`note_flags`.
    """
    return [item for item in _flag_items(row) if not is_note_flag(row, item[0])]


def note_flags(row: dict) -> list[tuple[str, str, str]]:
    """The segment's flags that are notes, not warnings (:func:`is_note_flag`), as
    ``(flag, label, meaning)``."""
    return [item for item in _flag_items(row) if is_note_flag(row, item[0])]


def _flag_items(row: dict) -> list[tuple[str, str, str]]:
    from drillfric.result import FLAG_MEANINGS

    meanings = {str(k): v for k, v in FLAG_MEANINGS.items()}
    flags = row.get("quality_flags")
    if not isinstance(flags, list | tuple):
        return []
    out = []
    for flag in map(str, flags):
        label, meaning = flag.replace("_", " "), meanings.get(flag, "")
        if is_note_flag(row, flag) and flag in _NOTE_FLAGS:
            label, meaning = _NOTE_FLAGS[flag]
        out.append((flag, label, meaning))
    return out


#: Flags that are notes, not warnings, where the segment's μ_k is the batch fit's: the
#: observer's starts are a cross-check there (docs/reports.md "Converged"). Label, meaning.
_NOTE_FLAGS = {
    "observer_starts_disagree": (
        "observer starts spread",
        "the observer's starts did not agree (spread above tolerance); μ_k is the batch "
        "fit's, whose convergence is judged on its own (status)"),
    "observer_deadlock_averted": (
        "observer start released",
        "an observer start stuck while the top drive turned was released by the deadlock "
        "guard"),
}


def is_note_flag(row: dict, flag: str) -> bool:
    """Whether ``flag`` says nothing against the segment's reported numbers: the observer's
    flags where μ_k is the batch fit's (the observer is then a cross-check, and a
    disagreement beyond ×1.5 is its own flag, ``estimators_disagree``)."""
    return flag in _NOTE_FLAGS and row.get("method") == Method.BATCH


#: What "converged" means for a segment; the header, the status cell and the badges say it.
CONVERGED_MEANING = (
    "converged = the stand's reported μ_k is settled: from the batch fit, the fit matched "
    "the mean torque within 2 %, agrees with the observer consensus within a factor 1.5 and "
    "had ≥ 90 s of rotation; from the observer (the fit gave none), its starts agreed")


def is_apparent(row: dict) -> bool:
    """Whether the segment's μ is apparent: on bottom, the bit torque is in it."""
    return segment_is_apparent(row)


def mu_name(row: dict) -> str:
    """What the segment's μ_k is called: ``"μ_k"`` or ``"apparent μ"`` (on bottom)."""
    return "apparent μ" if is_apparent(row) else "μ_k"


def mu_k_cell(row: dict) -> str:
    """The segment's μ_k as a table cell; an on-bottom (apparent) value says so."""
    text = fmt(row.get("mu_k"))
    return f"{text} apparent" if text != "—" and is_apparent(row) else text


def status_word(row: dict) -> str:
    """The segment's status in the words of its badge: "converged", "not converged",
    "static" (a depth log's torque-and-drag back-calculation), or skipped / failed."""
    if row.get("status") != Status.OK:
        return str(row.get("status"))
    if row.get("method") == Method.TD_BACKCALC:
        return "static"
    return "converged" if row.get("converged") else "not converged"


def status_text(row: dict) -> str:
    """Status, convergence (:data:`CONVERGED_MEANING`) and method in one cell."""
    word = status_word(row)
    if row.get("status") != Status.OK:
        return word
    if word == "static":
        return "ok, static torque-and-drag back-calculation"
    method = {"batch": "batch fit", "observer": "observer"}.get(str(row.get("method")),
                                                                str(row.get("method") or "—"))
    return f"ok, μ_k {word} ({method})"


def diagnostic_columns(units: Units) -> list[tuple[str, str]]:
    """``(heading, CSS class)`` of the diagnostics table in display ``units``."""
    out = []
    for name, quantity, cls in DIAGNOSTIC_COLUMNS:
        if quantity and "{unit}" in name:
            name = name.replace("{unit}", f"[{units.label(quantity)}]")
        elif quantity:
            name = units.axis(name, quantity)
        out.append((name, cls))
    return out


def diagnostic_rows(segments: pd.DataFrame, units: Units, origin=None,
                    fits: dict[int, tuple[str, str]] | None = None) -> list[dict]:
    """One dict per segment: ``cells`` (strings in :data:`DIAGNOSTIC_COLUMNS` order, values
    in display ``units``), ``id``, ``cls`` and ``anchor`` (whether the segment has a figure
    section is set by the caller).

    ``origin``: clock time of log time 0 (UTC), when known. ``fits``: by segment id, the
    fit quality to state and a sentence on what the fit does not reproduce ("" when it
    does; :mod:`drillfric.report.reproduction`).
    """
    out = []
    for row in segments.to_dict("records"):
        quality, unreproduced = (fits or {}).get(int(row["id"]), (None, ""))
        ok = row["status"] == Status.OK
        mu_s = mu_s_text(row["mu_s"], row["mu_s_identifiable"], row["mu_s_lower_bound"])
        flags = ", ".join([flag for flag, _, _ in flag_items(row)]
                          + [f"{flag} (a note: μ_k is the batch fit's)"
                             for flag, _, _ in note_flags(row)])
        unresolved = bit_speed_text(row) if bit_speed_unresolved(row) and ok else ""
        message = "; ".join(x for x in (unreproduced, str(row.get("message") or ""),
                                        unresolved, flags) if x)
        kind = str(row.get("kind") or "—").replace("_rotating", "").replace("_", " ")
        cells = [str(row["id"]), kind, units.text(row["bit_depth_m"], "length", ".1f"),
                 clock_span(row, origin), mu_s if ok else "—", mu_k_cell(row),
                 fmt(row["mu_td"]), row_zone(row),
                 pair(row["mu_s_spread"], row["mu_k_spread"]),
                 fmt(row["settling_time_s"], ".1f"), fmt(row["residual_rms_rpm"], ".2f"),
                 _torque_fit(row, units, quality), severity_text(row),
                 fmt(row["stuck_fraction"], ".0%"),
                 units.pair(row.get("hookload_N"), row.get("hookload_model_N"), "force"),
                 _bit_speed_cell(row), observability(row), status_text(row), message]
        out.append({"id": row["id"], "cls": row_class(row), "cells": cells})
    return out


def _torque_fit(row: dict, units: Units, quality: str | None = None) -> str:
    """``"misfit / swing (quality)"`` of the torque fit, in display units; ``quality``: the
    quality to state (default: the segment's ``fit_quality``)."""
    text = units.pair(row.get("torque_rms_misfit_Nm"), row.get("torque_swing_Nm"), "torque",
                      ".1f")
    quality = quality or fmt(row.get("fit_quality"), ".2f")
    return text if quality == "—" else f"{text} ({quality})"


def _bit_speed_cell(row: dict) -> str:
    """Resolved or not, with the logging interval that decides it, and the speed a declared
    mud motor adds (or, with the pumps on and none declared, that the trace is the BHA's)."""
    text, interval = bit_speed_text(row, reason=False), interval_text(row)
    text = f"{text} ({interval})" if interval and text != "—" else text
    motor = fmt(row.get("motor_rpm_mean"), ".0f")
    if motor != "—":
        return f"{text}; BHA + motor ≈ {motor} rpm"
    return f"{text}; the BHA's, no motor" if row.get("bit_speed_reason") and \
        not bit_speed_unresolved(row) else text


def config_rows(config: dict) -> list[tuple[str, list[tuple[str, str]]]]:
    """The effective configuration as ``[(table, [(key, value text), ...]), ...]``, without
    the drill string (:func:`string_table`)."""
    out = []
    for table, values in config.items():
        if table == "string":
            continue
        if isinstance(values, dict):
            items = [(str(k), value_text(v)) for k, v in values.items()]
        else:
            items = [("", value_text(values))]
        out.append((str(table), items))
    return out


#: Columns of the drill-string table: config key, heading, the quantity whose display unit
#: the value is shown in (None: the heading's fixed unit and ``scale``), format by unit
#: system.
STRING_COLUMNS = (
    ("name", "section", None, 1.0, {}),
    ("od_m", "OD", "diameter", 1.0, {"si": ".1f", "field": ".3f"}),
    ("id_m", "ID", "diameter", 1.0, {"si": ".1f", "field": ".3f"}),
    ("length_m", "length", "length", 1.0, {"si": ".1f", "field": ".1f"}),
    ("tool_joint_od_m", "tool joint OD", "diameter", 1.0, {"si": ".1f", "field": ".3f"}),
    ("linear_mass_kg_m", "linear mass", "linear mass", 1.0, {"si": ".2f", "field": ".2f"}),
    ("shear_modulus_Pa", "shear modulus [GPa]", None, 1e-9, {"si": ".1f", "field": ".1f"}),
    ("steel_density_kg_m3", "steel density", "density", 1.0, {"si": ".0f", "field": ".2f"}))


def string_table(config: dict, units: Units) -> tuple[list[str], list[list[str]]]:
    """The drill string of a configuration as ``(headings, rows)`` in display ``units``,
    top section first.

    A missing length is the top section's "the rest, to the surface" (it fills the string
    above the sections below it; "to the bit" had read as if it reached the bit); other
    missing values are the defaults the run computed (steel area, OD/2 contact), shown as
    "default".
    """
    sections = ((config.get("string") or {}).get("sections")) or []
    rows = []
    for index, section in enumerate(sections):
        row = []
        for key, _, quantity, scale, spec in STRING_COLUMNS:
            value = section.get(key) if isinstance(section, dict) else None
            if value is None:
                row.append("the rest, to the surface" if key == "length_m" and index == 0
                           else "default")
            elif not spec:
                row.append(str(value))
            elif quantity:
                row.append(units.text(value, quantity, spec[units.system]))
            else:
                row.append(fmt(_scaled(value, scale), spec[units.system]))
        rows.append(row)
    return [units.axis(heading, quantity) if quantity else heading
            for _, heading, quantity, _, _ in STRING_COLUMNS], rows


def non_default_rows(config: dict) -> list[list[str]]:
    """The settings of a run's effective configuration that differ from the schema's
    defaults, as ``[setting, value, default]`` text rows (the drill string is its own
    table: :func:`string_table`); a setting the installed schema does not know is listed
    with default "—"."""
    from drillfric.config import load_config

    defaults = load_config().to_dict()
    rows = []
    for table, values in config.items():
        if table == "string":
            continue
        known = defaults.get(table)
        if not isinstance(values, dict):
            if values != known:
                rows.append([str(table), value_text(values), value_text(known)])
            continue
        known = known if isinstance(known, dict) else {}
        for key, value in values.items():
            default = known.get(key, _UNKNOWN)
            if value != default:
                rows.append([f"{table}.{key}", value_text(value),
                             "—" if default is _UNKNOWN else value_text(default)])
    return rows


_UNKNOWN = object()


def value_text(value) -> str:
    """A configuration value as text: lists of numbers as "(a, b), (c, d)", not JSON."""
    if value is None:
        return "—"
    if isinstance(value, list | tuple):
        if all(isinstance(v, list | tuple) for v in value):
            return ", ".join("(" + ", ".join(value_text(x) for x in v) + ")" for v in value)
        return ", ".join(value_text(v) for v in value)
    if isinstance(value, dict):
        return "; ".join(f"{k} = {value_text(v)}" for k, v in value.items())
    if isinstance(value, float):
        return format(value, "g")
    return str(value)


def written_at(path) -> str:
    """Modification time of a file as ``YYYY-MM-DD HH:MM UTC`` ("—" when missing)."""
    try:
        stamp = path.stat().st_mtime
    except OSError:
        return "—"
    return datetime.fromtimestamp(stamp, UTC).strftime("%Y-%m-%d %H:%M UTC")


def now_utc() -> str:
    """The current time as ``YYYY-MM-DD HH:MM UTC``."""
    return datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")


def drag_text(drag: dict | None) -> str:
    """The drag-based friction of a well in words, as the terminal's result line and the
    report's friction log state it, counting its connections (:data:`~drillfric.vocabulary.
    CONNECTION`) as summary.json ``drag.connections`` does: ``"μ drag = 0.251 (3 of 5
    connections)"``, ``"μ drag withheld (0 of 16 connections)"``; "" for a log without a
    connection.

    Examples
    --------
    >>> drag_text({"connections": 2, "estimated": 2, "log": [{"mu_drag": 0.2},
    ...                                                       {"mu_drag": 0.3}]})
    'μ drag = 0.250 (all 2 connections)'
    >>> drag_text({"connections": 16, "estimated": 0, "log": []}), drag_text(None)
    ('μ drag withheld (0 of 16 connections)', '')
    """
    drag = drag or {}
    total = drag.get("connections") or 0
    if not total:
        return ""
    mu = well_friction_columns({"drag": drag})["well_mu_drag"]
    counted = share(int(drag.get("estimated") or 0), int(total), CONNECTION)
    return f"μ drag withheld ({counted})" if mu is None else f"μ drag = {mu:.3f} ({counted})"
