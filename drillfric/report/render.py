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

from .display import Units, fmt

#: Resolution of the figures embedded in HTML [dots per inch].
HTML_DPI = 90
#: Columns of the diagnostics table (HTML and PDF), in order: heading, the quantity whose
#: display unit the heading names (None: no unit or a fixed one; at ``{unit}``, else at the
#: end) and the cell's CSS class
#: in the HTML table (``num``: right-aligned number, ``wrap``: text that may wrap).
DIAGNOSTIC_COLUMNS = (
    ("seg.", None, ""), ("kind", None, "wrap"), ("bit depth", "length", "num"),
    ("time", None, "wrap"), ("μ_s", None, "num"), ("μ_k", None, "num"), ("μ_TD", None, "num"),
    ("μ zone", None, "wrap"), ("spread μ_s / μ_k", None, "num"), ("settling [s]", None, "num"),
    ("residual [rpm]", None, "num"), ("misfit / swing {unit} (quality)", "torque", "num"),
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


def observability(row: dict) -> str:
    """Whether the segment identifies μ_s, bounds it, or says nothing about it."""
    if row.get("status") != "ok":
        return "—"
    if row.get("mu_s_identifiable"):
        return "μ_s identified"
    if fmt(row.get("mu_s_lower_bound")) != "—":
        return "μ_s bounded below"
    return "μ_s not observable"


def row_class(row: dict) -> str:
    """CSS class of a segment: failed, skipped, unconverged or ok."""
    if row.get("status") in ("failed", "skipped"):
        return str(row["status"])
    return "ok" if row.get("converged") else "unconverged"


def clock_span(row: dict, origin) -> str:
    """A segment's time span: UTC clock times when known, else log seconds."""
    start, end = row.get("clock_start_utc"), row.get("clock_end_utc")
    if origin is not None and math.isfinite(row.get("t_start_s", math.nan)):
        start = (origin + pd.Timedelta(seconds=float(row["t_start_s"]))).isoformat()
        end = (origin + pd.Timedelta(seconds=float(row["t_end_s"]))).isoformat()
    if isinstance(start, str) and isinstance(end, str):
        a, b = pd.Timestamp(start), pd.Timestamp(end)
        return f"{a:%H:%M:%S}–{b:%H:%M:%S}"
    return f"{fmt(row.get('t_start_s'), '.0f')}–{fmt(row.get('t_end_s'), '.0f')} s"


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
    if row.get("status") != "ok" or resolved is None or pd.isna(resolved):
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


def zone_text(segments: pd.DataFrame) -> str:
    """The friction zone the estimated segments' μ are for ("open hole", "effective"), or
    "" when they differ or the results do not say (older results)."""
    if "friction_zone" not in segments:
        return ""
    zones = set(segments.loc[segments["status"] == "ok", "friction_zone"].dropna())
    return zones.pop().replace("_", " ") if len(zones) == 1 else ""


def message_parts(message: str) -> list[str]:
    """A segment's message as its notes: split at "; " outside parentheses (the notes of
    the estimation steps are joined with "; ", and a note may hold one in brackets)."""
    parts, depth, start = [], 0, 0
    for i, char in enumerate(message):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if depth == 0 and message.startswith("; ", i):
            parts.append(message[start:i])
            start = i + 2
    parts.append(message[start:])
    return [p.strip() for p in parts if p.strip()]


def flag_items(row: dict) -> list[tuple[str, str]]:
    """The segment's flags as ``(flag, meaning)`` (docs/outputs.md, flags); an unknown flag
    (a newer drillfric's) keeps its name with no meaning."""
    from drillfric.result import FLAG_MEANINGS

    meanings = {str(k): v for k, v in FLAG_MEANINGS.items()}
    flags = row.get("flags")
    if not isinstance(flags, list | tuple):
        return []
    return [(str(f), meanings.get(str(f), "")) for f in flags]


def status_text(row: dict) -> str:
    """Status, convergence and method in one cell."""
    if row.get("status") != "ok":
        return str(row.get("status"))
    converged = "converged" if row.get("converged") else "not converged"
    return f"ok, {converged}, {row.get('method') or '—'}"


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


def diagnostic_rows(segments: pd.DataFrame, units: Units, origin=None) -> list[dict]:
    """One dict per segment: ``cells`` (strings in :data:`DIAGNOSTIC_COLUMNS` order, values
    in display ``units``), ``id``, ``cls`` and ``anchor`` (whether the segment has a figure
    section is set by the caller).

    ``origin``: clock time of log time 0 (UTC), when known.
    """
    out = []
    for row in segments.to_dict("records"):
        ok = row["status"] == "ok"
        mu_s = mu_s_text(row["mu_s"], row["mu_s_identifiable"], row["mu_s_lower_bound"])
        flags = ", ".join(row.get("flags") or [])
        unresolved = bit_speed_text(row) if bit_speed_unresolved(row) and ok else ""
        message = "; ".join(x for x in (str(row.get("message") or ""), unresolved, flags)
                            if x)
        kind = str(row.get("kind") or "—").replace("_rotating", "").replace("_", " ")
        cells = [str(row["id"]), kind, units.text(row["bit_depth_m"], "length", ".1f"),
                 clock_span(row, origin), mu_s if ok else "—", fmt(row["mu_k"]),
                 fmt(row["mu_td"]), str(row.get("friction_zone") or "—").replace("_", " "),
                 pair(row["mu_s_spread"], row["mu_k_spread"]),
                 fmt(row["settling_time_s"], ".1f"), fmt(row["residual_rms_rpm"], ".2f"),
                 _torque_fit(row, units), fmt(row["stick_slip_severity"], ".2f"),
                 fmt(row["stuck_fraction"], ".0%"),
                 units.pair(row.get("hookload_N"), row.get("hookload_model_N"), "force"),
                 _bit_speed_cell(row), observability(row), status_text(row), message]
        out.append({"id": row["id"], "cls": row_class(row), "cells": cells})
    return out


def _torque_fit(row: dict, units: Units) -> str:
    """``"misfit / swing (quality)"`` of the torque fit, in display units."""
    text = units.pair(row.get("torque_rms_misfit_Nm"), row.get("torque_swing_Nm"), "torque",
                      ".1f")
    quality = fmt(row.get("fit_quality"), ".2f")
    return text if quality == "—" else f"{text} ({quality})"


def _bit_speed_cell(row: dict) -> str:
    """Resolved or not, with the logging interval that decides it."""
    text, interval = bit_speed_text(row, reason=False), interval_text(row)
    return f"{text} ({interval})" if interval and text != "—" else text


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

    A missing length is the top section's "to the bit"; other missing values are the
    defaults the run computed (steel area, OD/2 contact), shown as "default".
    """
    sections = ((config.get("string") or {}).get("sections")) or []
    rows = []
    for index, section in enumerate(sections):
        row = []
        for key, _, quantity, scale, spec in STRING_COLUMNS:
            value = section.get(key) if isinstance(section, dict) else None
            if value is None:
                row.append("to the bit" if key == "length_m" and index == 0 else "default")
            elif not spec:
                row.append(str(value))
            elif quantity:
                row.append(units.text(value, quantity, spec[units.system]))
            else:
                row.append(fmt(_scaled(value, scale), spec[units.system]))
        rows.append(row)
    return [units.axis(heading, quantity) if quantity else heading
            for _, heading, quantity, _, _ in STRING_COLUMNS], rows


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
