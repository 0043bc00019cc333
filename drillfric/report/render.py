"""Turning results into what the templates show: formatted values, tables, inline images.

Everything a template receives is plain text or numbers; Jinja2 autoescaping is on for
every ``.j2`` template, so well names, paths and messages from users' files are shown as
text. Images are base64 PNG ``data:`` URIs: one self-contained file, no network request.
"""

from __future__ import annotations

import base64
import io
import json
import math
import warnings
from contextlib import contextmanager
from datetime import UTC, datetime
from importlib.resources import files

import pandas as pd
from jinja2 import Environment, FileSystemLoader, select_autoescape
from matplotlib.figure import Figure

#: Resolution of the figures embedded in HTML [dots per inch].
HTML_DPI = 90
#: Columns of the diagnostics table (HTML and PDF), in order.
DIAGNOSTIC_COLUMNS = ("segment", "kind", "bit depth [m]", "time [s]", "μ_s", "μ_k", "μ_TD",
                      "settling [s]", "spread μ_s", "spread μ_k", "residual RMS [rpm]",
                      "severity", "stuck", "observability", "converged", "method", "status",
                      "message")


def environment() -> Environment:
    """The Jinja2 environment of the report templates (autoescaping on for every template)."""
    env = Environment(loader=FileSystemLoader(str(files("drillfric.templates"))),
                      autoescape=select_autoescape(["html", "j2"], default=True),
                      trim_blocks=True, lstrip_blocks=True)
    env.filters["num"] = fmt
    return env


def fmt(value, spec: str = ".3f") -> str:
    """``value`` formatted with ``spec``, or "—" for None / NaN / non-numbers."""
    if value is None or isinstance(value, bool):
        return "—" if value is None else ("yes" if value else "no")
    try:
        number = float(value)
    except (TypeError, ValueError):
        return "—"
    return "—" if not math.isfinite(number) else format(number, spec)


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
    """μ_s as shown to users: the value, "≥ bound", or "not identifiable" (THEORY.md §6)."""
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


def diagnostic_rows(segments: pd.DataFrame) -> list[dict]:
    """One dict per segment: ``cells`` (strings in :data:`DIAGNOSTIC_COLUMNS` order), ``id``,
    ``cls`` and ``anchor`` (whether the segment has a figure section is set by the caller)."""
    out = []
    for row in segments.to_dict("records"):
        mu_s = mu_s_text(row["mu_s"], row["mu_s_identifiable"], row["mu_s_lower_bound"])
        flags = ", ".join(row.get("flags") or [])
        message = "; ".join(x for x in (str(row.get("message") or ""), flags) if x)
        cells = [str(row["id"]), str(row.get("kind") or "—"), fmt(row["bit_depth_m"], ".1f"),
                 f"{fmt(row['t_start_s'], '.0f')}–{fmt(row['t_end_s'], '.0f')}",
                 mu_s if row["status"] == "ok" else "—", fmt(row["mu_k"]), fmt(row["mu_td"]),
                 fmt(row["settling_time_s"], ".1f"), fmt(row["mu_s_spread"]),
                 fmt(row["mu_k_spread"]), fmt(row["residual_rms_rpm"], ".2f"),
                 fmt(row["stick_slip_severity"], ".2f"), fmt(row["stuck_fraction"], ".0%"),
                 observability(row), fmt(bool(row["converged"])) if row["status"] == "ok"
                 else "—", str(row.get("method") or "—"), str(row["status"]), message]
        out.append({"id": row["id"], "cls": row_class(row), "cells": cells})
    return out


def config_rows(config: dict) -> list[tuple[str, list[tuple[str, str]]]]:
    """The effective configuration as ``[(table, [(key, value text), ...]), ...]``."""
    out = []
    for table, values in config.items():
        if isinstance(values, dict):
            items = [(str(k), _value_text(v)) for k, v in values.items()]
        else:
            items = [("", _value_text(values))]
        out.append((str(table), items))
    return out


def _value_text(value) -> str:
    if value is None:
        return "—"
    if isinstance(value, list | dict):
        return json.dumps(value, ensure_ascii=False)
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
