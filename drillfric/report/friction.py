"""The friction log versus depth, interactive (Bokeh): one well, and all wells of a fleet.

Marks follow the static friction log (:func:`drillfric.report.figures.friction_log_figure`,
docs/reports.md): μ_k ● (off bottom), apparent μ ▲ (on bottom: the bit torque is in it, so
it is not μ_k and gets its own mark and legend entry), μ_s ■ where identified, ▷ μ_s lower
bound, × the torque-and-drag back-calculation μ_TD (off bottom), green ✚ the drag-based μ
of the connections (pick-up/slack-off hook loads, docs/theory.md §2.2: a second log,
independent of the torque), grey ◆ segments without an estimate; hollow = not converged;
whiskers = spread across observer starts. Beside it the stick-slip severity versus depth.
Hover names the segment and its numbers. Depths in the report's display units; the μ axis
names the friction zone (open hole, or effective over the whole string) when the
segments share one.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from drillfric.io.text import plural
from drillfric.vocabulary import MOVING_KINDS, Kind, Status

from .display import SI, Units, fmt
from .figures import (
    APPARENT_COLOR,
    BOUND_LABEL,
    DRAG_COLOR,
    DRAG_LABEL,
    MU_K_COLOR,
    MU_S_COLOR,
    NONE_LABEL,
    TD_COLOR,
    drag_rows,
)
from .interactive import MIN_WIDTH_PX
from .render import is_apparent, mu_k_cell, mu_s_text, severity_note, severity_text, zone_text

_TOOLS = "pan,wheel_zoom,box_zoom,reset,save"


def _tips(units: Units) -> list[tuple[str, str]]:
    """Hover fields of a segment's point."""
    return [("segment", "@id (@kind)"), ("bit depth", f"@depth{{0.0}} {units.label('length')}"),
            ("μ_k / apparent μ", "@mu_k_text"), ("μ_s", "@mu_s_text"),
            ("μ_TD", "@mu_td_text"),
            ("severity", "@severity_text"), ("friction zone", "@zone"),
            ("status", "@status")]


def _source_frame(seg: pd.DataFrame, units: Units) -> pd.DataFrame:
    """One row per segment with the hover texts; ``depth`` in display units."""
    rows = seg.copy()
    rows["depth"] = rows["bit_depth_m"] * units.factor("length")
    rows["kind"] = rows["kind"].fillna("—").astype(str).str.replace("_", " ")
    records = rows.to_dict("records")
    rows["mu_k_text"] = [mu_k_cell(r) for r in records]
    rows["apparent"] = np.array([is_apparent(r) for r in records], dtype=bool)
    rows["mu_app"] = rows["mu_k"].where(rows["apparent"])
    rows["mu_s_text"] = [mu_s_text(m, i, b) for m, i, b in
                         zip(rows["mu_s"], rows["mu_s_identifiable"], rows["mu_s_lower_bound"],
                             strict=True)]
    rows["mu_td_text"] = [fmt(v) for v in rows["mu_td"]]
    rows["severity_text"] = [severity_text(r) for r in records]
    rows["zone"] = rows["friction_zone"].fillna("—").astype(str).str.replace("_", " ")
    rows["status"] = rows["status"].astype(str)
    rows["identified"] = rows["mu_s_identifiable"].astype(bool) & rows["mu_s"].notna()
    rows["half_k"] = rows["mu_k_spread"].fillna(0.0) / 2
    rows["half_s"] = rows["mu_s_spread"].fillna(0.0) / 2
    keep = ["id", "depth", "kind", "mu_k", "mu_app", "mu_s", "mu_s_lower_bound", "mu_td",
            "stick_slip_severity", "mu_k_text", "mu_s_text", "mu_td_text", "severity_text",
            "zone", "status", "half_k", "half_s", "converged", "identified", "apparent"]
    return rows[keep].astype({"id": int})


def _cds(frame: pd.DataFrame):
    """A ColumnDataSource of a table's columns (no index column)."""
    from bokeh.models import ColumnDataSource

    return ColumnDataSource({c: frame[c].to_numpy() for c in frame.columns})


def _columns(frame: pd.DataFrame) -> dict[str, np.ndarray]:
    """A table's columns as arrays (a ColumnDataSource's data; no index column)."""
    return {c: frame[c].to_numpy() for c in frame.columns}


def _span(x0, x1, depth) -> dict[str, np.ndarray]:
    """Horizontal strokes from ``x0`` to ``x1`` at ``depth`` (a segment glyph's data)."""
    depth = np.asarray(depth, dtype=float)
    return {"x0": np.asarray(x0, dtype=float), "y0": depth,
            "x1": np.asarray(x1, dtype=float), "y1": depth}


#: Marker, colour and legend of the points of each μ column.
_MARKS = {"mu_k": ("circle", MU_K_COLOR, "μ_k (off bottom)"),
          "mu_app": ("triangle", APPARENT_COLOR, "apparent μ (on bottom, bit torque in it)"),
          "mu_s": ("square", MU_S_COLOR, "μ_s"),
          "mu_td": ("x", TD_COLOR, "μ from torque and drag"),
          "mu_drag": ("plus", DRAG_COLOR, DRAG_LABEL)}


def _drag_tips(units: Units) -> list[tuple[str, str]]:
    """Hover fields of a drag-based point (a connection of drag_log.parquet)."""
    return [("drag-based μ", "@mu_drag_text"), ("from", "@source"),
            ("bit depth", f"@depth{{0.0}} {units.label('length')}"),
            ("evidence", "@evidence")]


def _drag_frame(drag: pd.DataFrame | None, units: Units) -> pd.DataFrame:
    """The connections with a drag-based μ, with hover texts; ``depth`` in display units."""
    rows = drag_rows(drag)
    half = pd.to_numeric(rows["mu_drag_uncertainty"], errors="coerce").fillna(0.0)
    out = pd.DataFrame({"depth": rows["bit_depth_m"].to_numpy(float) * units.factor("length"),
                        "mu_drag": rows["mu_drag"].to_numpy(float),
                        "half": half.to_numpy(float)})
    out["mu_drag_text"] = [f"{m:.3f} ± {h:.3f}" for m, h in zip(out["mu_drag"], out["half"],
                                                                   strict=True)]
    out["source"] = [str(s).replace("_", "-") for s in rows.get("source", [""] * len(rows))]
    out["evidence"] = [_evidence(r) for r in rows.to_dict("records")]
    out["converged"] = True
    return out


def _evidence(row: dict) -> str:
    """Seconds and rows of the pick-up and slack-off a connection rests on."""
    parts = []
    for side in ("pick_up", "slack_off"):
        seconds = row.get(f"{side}_s")
        if seconds is not None and np.isfinite(seconds):
            parts.append(f"{side.replace('_', '-')} {seconds:.0f} s "
                         f"({plural(int(row[f'{side}_rows']), 'row')})")
    return ", ".join(parts)


def _add_points(out: dict, frame: pd.DataFrame, col: str, hollow_unconverged: bool = True
                ) -> None:
    """``points:COL:converged`` and ``points:COL:unconverged`` (drawn hollow) of ``frame``
    where ``col`` has a value; every point counts as converged without
    ``hollow_unconverged``."""
    for conv, name in ((True, "converged"), (False, "unconverged")):
        part = frame[frame["converged"] == conv] if hollow_unconverged else \
            (frame if conv else frame.iloc[:0])
        part = part[part[col].notna()]
        if len(part):
            out[f"points:{col}:{name}"] = _columns(part)


def friction_sources(segments: pd.DataFrame, units: Units = SI,
                     drag: pd.DataFrame | None = None) -> dict[str, dict[str, np.ndarray]]:
    """The data of every Bokeh source of :func:`friction_plot`, by source name, in drawing
    order (only those with rows): ``whisker:mu_k``, ``whisker:mu_app``, ``whisker:mu_s``
    (spreads), the ``points:…`` of μ_k (off bottom), apparent μ (``mu_app``, on bottom),
    identified μ_s and μ_TD (off bottom), ``bound_tail`` and ``bound`` (μ_s lower bounds),
    ``whisker:mu_drag`` and ``points:mu_drag:converged`` (the drag-based μ of ``drag``,
    drag_log.parquet), ``none`` (segments without an estimate) and ``severity``. Depths in
    display ``units``."""
    frame = _source_frame(segments[segments["bit_depth_m"].notna()
                                   & ~segments["kind"].isin(MOVING_KINDS)], units)  # for now
    ok = frame[frame["status"] == Status.OK]
    off = ok[~ok["apparent"]]
    out = {}
    for rows, col, half in ((off, "mu_k", "half_k"), (ok, "mu_app", "half_k"),
                            (ok, "mu_s", "half_s")):
        whisk = rows[rows[col].notna() & (rows[half] > 0)]
        if col == "mu_s":
            whisk = whisk[whisk["identified"]]
        if len(whisk):
            out[f"whisker:{col}"] = _span(whisk[col] - whisk[half], whisk[col] + whisk[half],
                                          whisk["depth"])
    _add_points(out, off, "mu_k")
    _add_points(out, ok, "mu_app")
    _add_points(out, ok[ok["identified"]], "mu_s")
    bound = ok[~ok["identified"] & ok["mu_s_lower_bound"].notna()]
    if len(bound):
        out["bound_tail"] = _span(bound["mu_s_lower_bound"],
                                  bound["mu_s_lower_bound"] + 0.08, bound["depth"])
        out["bound"] = _columns(bound)
    _add_points(out, off, "mu_td", hollow_unconverged=False)
    dragged = _drag_frame(drag, units)
    if len(dragged):
        whisk = dragged[dragged["half"] > 0]
        if len(whisk):
            out["whisker:mu_drag"] = _span(whisk["mu_drag"] - whisk["half"],
                                           whisk["mu_drag"] + whisk["half"], whisk["depth"])
        out["points:mu_drag:converged"] = _columns(dragged)
    none = frame[frame["status"] != Status.OK].assign(zero=0.0)
    if len(none):
        out["none"] = _columns(none)
    severity = ok[ok["stick_slip_severity"].notna()]
    if len(severity):
        out["severity"] = _columns(severity)
    return out


def friction_signature(segments: pd.DataFrame, sources: dict[str, dict],
                       units: Units = SI) -> tuple:
    """What the layout of :func:`friction_plot` depends on besides the sources' data."""
    return ("friction", _zone(segments), units.system,
            tuple((name, tuple(cols)) for name, cols in sources.items()))


def _zone(segments: pd.DataFrame) -> str:
    return zone_text(segments[segments["bit_depth_m"].notna()])


def friction_plot(segments: pd.DataFrame, sources: dict[str, dict], units: Units = SI):
    """μ versus bit depth and stick-slip severity versus bit depth (a Bokeh row) from
    :func:`friction_sources`; each ColumnDataSource is named like its key there.
    ``segments`` give the friction zone of the μ axis' label only."""
    from bokeh.layouts import gridplot
    from bokeh.models import ColumnDataSource, HoverTool, Span
    from bokeh.plotting import figure

    zone = _zone(segments)
    mu = figure(height=520, width=560, tools=_TOOLS,
                x_axis_label=f"friction factor μ{f' ({zone})' if zone else ''} [-]",
                y_axis_label=units.axis("bit depth", "length"))
    mu.y_range.flipped = True
    # a friction factor is ≥ 0: the axis starts just below 0, so that the μ = 0 diamonds
    # (no estimate) are drawn whole, not cut in half by the frame (issue 35)
    mu.x_range.start = -0.03
    cds = {name: ColumnDataSource(columns, name=name) for name, columns in sources.items()}
    renderers, drag_renderers = [], []
    for name, source in cds.items():
        mark, _, col = name.partition(":")
        if mark == "whisker":
            mu.segment("x0", "y0", "x1", "y1", source=source, line_width=1,
                       color=_MARKS[col][1])
        elif mark == "points":
            col, _, part = col.partition(":")
            marker, color, label = _MARKS[col]
            conv = part == "converged"
            (drag_renderers if col == "mu_drag" else renderers).append(mu.scatter(
                col, "depth", source=source, marker=marker, size=9, line_color=color,
                fill_color=color if conv else "white", line_width=2 if col == "mu_drag" else 1,
                legend_label=label + ("" if conv else " (not converged)")))
        elif mark == "bound_tail":
            mu.segment("x0", "y0", "x1", "y1", source=source, color=MU_S_COLOR,
                       line_dash="dotted")
        elif mark == "bound":
            renderers.append(mu.scatter("mu_s_lower_bound", "depth", source=source,
                                        marker="triangle", angle=-np.pi / 2, size=10,
                                        line_color=MU_S_COLOR, fill_color="white",
                                        legend_label=BOUND_LABEL))
        elif mark == "none":
            renderers.append(mu.scatter("zero", "depth", source=source, marker="diamond",
                                        size=10, color="#888888", fill_color="white",
                                        legend_label=NONE_LABEL))
    mu.add_tools(HoverTool(renderers=renderers, tooltips=_tips(units)))
    if drag_renderers:
        mu.add_tools(HoverTool(renderers=drag_renderers, tooltips=_drag_tips(units)))
    mu.legend.location = "bottom_right"
    mu.legend.label_text_font_size = "10px"
    mu.legend.click_policy = "hide"
    sev = figure(height=520, width=300, tools=_TOOLS, y_range=mu.y_range,
                 x_axis_label="stick-slip severity [-]")
    if "severity" in cds:
        line = sev.scatter("stick_slip_severity", "depth", source=cds["severity"],
                           marker="circle", size=8, color="#8e44ad")
        sev.add_tools(HoverTool(renderers=[line], tooltips=_tips(units)))
    else:  # say why the panel is empty (issue 35 item 10)
        sev.title.text = severity_note(segments)
        sev.title.text_font_size = "10px"
        sev.title.text_font_style = "normal"
    sev.add_layout(Span(location=1.0, dimension="height", line_dash="dashed",
                        line_color="#c0392b"))
    sev.x_range.start = 0.0
    return gridplot([[mu, sev]], merge_tools=True, toolbar_location="right")


def off_bottom_mu_k(seg: pd.DataFrame) -> pd.DataFrame:
    """The segments of ``seg`` (segments.parquet's columns) that give an off-bottom μ_k at a
    bit depth — not an on-bottom apparent μ, nor a reaming segment's (kept out of the
    friction log until validated on field data)."""
    return seg[(seg["status"] == Status.OK) & (seg["kind"] == Kind.OFF_BOTTOM)
               & seg["mu_k"].notna() & seg["bit_depth_m"].notna()]


def fleet_plot(logs: list[tuple[str, pd.DataFrame]], units: Units = SI):
    """μ_k versus bit depth (display ``units``) of every well, a colour per well, the μ_k axis
    from 0 (an auto-scaled 0.2768–0.2798 drew three equal wells as a zigzag); legend click
    hides a well. Off-bottom segments only (:func:`off_bottom_mu_k`): an on-bottom apparent μ
    has the bit torque in it — a depth log's 0.15–0.27 had been drawn here as μ_k."""
    from bokeh.models import HoverTool, Legend, LegendItem
    from bokeh.palettes import Category10, Category20
    from bokeh.plotting import figure

    fig = figure(height=560, sizing_mode="stretch_width", min_width=MIN_WIDTH_PX,
                 tools=_TOOLS, active_scroll="wheel_zoom", x_axis_label="μ_k [-]",
                 y_axis_label=units.axis("bit depth", "length"))
    fig.y_range.flipped = True
    fig.x_range.start = 0.0  # from 0, as each well's log: equal wells must not zigzag
    palette = Category10[10] if len(logs) <= 10 else Category20[20]
    items, renderers = [], []
    for index, (name, seg) in enumerate(logs):
        ok = off_bottom_mu_k(seg)
        if not len(ok):
            continue
        color = palette[index % len(palette)]
        frame = _source_frame(ok.sort_values("bit_depth_m"), units).assign(well=name)
        frame["fill"] = np.where(frame["converged"], color, "white")
        source = _cds(frame)
        line = fig.line("mu_k", "depth", source=source, color=color, line_width=1)
        filled = fig.scatter("mu_k", "depth", source=source, size=8, color=color,
                             fill_color="fill")
        renderers.append(filled)
        items.append(LegendItem(label=name, renderers=[line, filled]))
    if items:
        fig.add_layout(Legend(items=items, click_policy="hide", label_text_font_size="10px"),
                       "right")
        fig.add_tools(HoverTool(renderers=renderers,
                                tooltips=[("well", "@well"), *_tips(units)[:3],
                                          ("friction zone", "@zone")]))
    return fig
