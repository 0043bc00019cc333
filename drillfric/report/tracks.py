"""Time tracks of the whole log (Pason/Totco style) from tracks.parquet.

Stacked tracks on one time axis — hook load, surface torque, rotary speed, bit and hole
depth, block position, standpipe pressure, WOB, flow, in the report's display units — each
drawn as its min–max envelope per time bin (a one-sample spike stays visible) with the bin
mean as a line; below them a strip with the rig state of every bin and the segments the
run estimated. Segments are also shaded across every track. Clock time (UTC) is on the
axis when the log had it.

:func:`tracks_plot` is the interactive (Bokeh) version for report.html,
:func:`tracks_figure` the static (matplotlib) one for the PDF. tracks.parquet is written by
:mod:`drillfric.io.tracks`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from drillfric.segmentation import RIG_STATES

from .display import SI, Units
from .interactive import (
    TimeAxis,
    float32,
    time_axis,
    time_figure,
    time_label,
    time_values,
)


@dataclass(frozen=True)
class Trace:
    """One channel of a track: column prefix in tracks.parquet, legend, quantity (its
    display unit: :class:`~drillfric.report.display.Units`), colour."""

    column: str
    label: str
    quantity: str
    color: str


@dataclass(frozen=True)
class Panel:
    """One track: its name, the quantity of its axis and the channels drawn in it."""

    name: str
    quantity: str
    traces: tuple[Trace, ...]
    invert: bool = False

    def label(self, units: Units) -> str:
        """Axis label in display units, e.g. ``"hook load [klbf]"``."""
        return units.axis(self.name, self.quantity)


#: The tracks, top to bottom.
PANELS = (
    Panel("hook load", "force", (Trace("hookload_N", "hook load", "force", "#1f5fa8"),)),
    Panel("torque", "torque", (Trace("surface_torque_Nm", "surface torque", "torque",
                                     "#c0392b"),)),
    Panel("rotary speed", "rotary speed", (Trace("surface_rpm", "surface speed",
                                                 "rotary speed", "#2e7d32"),)),
    Panel("depth", "length", (Trace("hole_depth_m", "hole depth", "length", "#555555"),
                              Trace("bit_depth_m", "bit depth", "length", "#8e44ad")),
          invert=True),
    Panel("block", "length", (Trace("block_position_m", "block position", "length",
                                    "#8c6d31"),)),
    Panel("SPP", "pressure", (Trace("standpipe_pressure_Pa", "standpipe pressure", "pressure",
                                    "#d35400"),)),
    Panel("WOB", "force", (Trace("wob_N", "weight on bit", "force", "#16a085"),)),
    Panel("flow in", "flow rate", (Trace("flow_in_m3_s", "flow in", "flow rate",
                                         "#2980b9"),)),
)
#: Colour of each rig state (index into drillfric.segmentation.RIG_STATES).
STATE_COLORS = ("#9ecae1", "#3182bd", "#fdae6b", "#a1d99b", "#d9d9d9", "#f7f7f7", "#9e9ac8",
                "#fdd0a2", "#c994c7")
#: Shading of segments on the tracks by kind.
SEGMENT_COLORS = {"off_bottom_rotating": "#1f5fa8", "on_bottom_rotating": "#e67e22"}
_TRACK_PX = 120


def panels_present(tracks: pd.DataFrame) -> list[Panel]:
    """The panels with at least one channel holding data in ``tracks``."""
    out = []
    for panel in PANELS:
        traces = tuple(t for t in panel.traces if f"{t.column}_mean" in tracks
                       and tracks[f"{t.column}_max"].notna().any())
        if traces:
            out.append(Panel(panel.name, panel.quantity, traces, panel.invert))
    return out


def with_breaks(tracks: pd.DataFrame) -> pd.DataFrame:
    """``tracks`` with an all-NaN row in every logging gap (> 3 median bin spacings), so
    lines and envelopes stop at a gap instead of bridging it."""
    t = tracks["time_s"].to_numpy(float)
    if t.size < 3:
        return tracks.reset_index(drop=True)
    step = np.diff(t)
    gaps = np.flatnonzero(step > 3.0 * np.median(step))
    if not gaps.size:
        return tracks.reset_index(drop=True)
    filler = pd.DataFrame({c: np.nan for c in tracks.columns if c not in ("time_s",
                                                                          "timestamp")},
                          index=range(gaps.size))
    filler["time_s"] = 0.5 * (t[gaps] + t[gaps + 1])
    filler["rig_state"] = -1
    out = pd.concat([tracks.drop(columns=["timestamp"], errors="ignore"), filler],
                    ignore_index=True)
    return out.sort_values("time_s", kind="stable").reset_index(drop=True)


def state_runs(time_s: np.ndarray, codes: np.ndarray) -> pd.DataFrame:
    """Runs of equal rig state: ``t0_s, t1_s, code`` (bins extend half-way to neighbours;
    gap rows, code −1, end a run)."""
    t = np.asarray(time_s, dtype=float)
    codes = np.asarray(codes, dtype=int)
    if not t.size:
        return pd.DataFrame({"t0_s": [], "t1_s": [], "code": []})
    edges = np.r_[t[0], 0.5 * (t[1:] + t[:-1]), t[-1]]
    change = np.flatnonzero(np.r_[True, codes[1:] != codes[:-1]])
    ends = np.r_[change[1:], t.size]
    runs = pd.DataFrame({"t0_s": edges[change], "t1_s": edges[ends], "code": codes[change]})
    return runs[runs["code"] >= 0].reset_index(drop=True)


# ------------------------------------------------------------------------------ Bokeh
def tracks_sources(tracks: pd.DataFrame, segments: pd.DataFrame,
                   origin: pd.Timestamp | TimeAxis | None, units: Units = SI
                   ) -> dict[str, dict[str, np.ndarray]]:
    """The data of every Bokeh source of the time tracks, by source name.

    ``trace:COLUMN`` (``x``, ``lo``, ``hi``, ``mean`` of one channel in display ``units``,
    float32) for the channels of :func:`panels_present`, ``states`` (``left``, ``right``,
    ``color``, ``what``: runs of rig state), and with estimated-or-not segments that have a
    time span ``shading`` (``x0``, ``x1``, ``color``) and ``bands`` (the strip's segment
    row: ``left``, ``right``, ``color``, ``what``).
    """
    data = with_breaks(tracks)
    x = time_values(data["time_s"], origin)
    out = {}
    for panel in panels_present(tracks):
        for trace in panel.traces:
            scale = units.factor(trace.quantity)
            out[f"trace:{trace.column}"] = {
                "x": x, "lo": float32(data[f"{trace.column}_min"] * scale),
                "hi": float32(data[f"{trace.column}_max"] * scale),
                "mean": float32(data[f"{trace.column}_mean"] * scale)}
    seg = segments[np.isfinite(segments["t_start_s"]) & np.isfinite(segments["t_end_s"])]
    left, right = time_values(seg["t_start_s"], origin), time_values(seg["t_end_s"], origin)
    colors = [SEGMENT_COLORS.get(k, "#777777") for k in seg["kind"]]
    if len(seg):
        out["shading"] = {"x0": left, "x1": right, "color": colors}
    runs = state_runs(data["time_s"].to_numpy(float), data["rig_state"].fillna(-1))
    out["states"] = {
        "left": time_values(runs["t0_s"], origin), "right": time_values(runs["t1_s"], origin),
        "color": [STATE_COLORS[c] for c in runs["code"]],
        "what": [RIG_STATES[c].replace("_", " ") for c in runs["code"]]}
    if len(seg):
        out["bands"] = {
            "left": left, "right": right, "color": colors,
            "what": [f"segment {i}: {str(k).replace('_', ' ')}, bit at "
                     f"{units.text(d, 'length')} {units.label('length')}, μ_k {m:.3f}, {s}"
                     for i, k, d, m, s in
                     zip(seg["id"], seg["kind"], seg["bit_depth_m"].fillna(np.nan),
                         seg["mu_k"].fillna(np.nan), seg["status"], strict=True)]}
    return out


def tracks_signature(tracks: pd.DataFrame, sources: dict[str, dict], axis: TimeAxis,
                     units: Units = SI) -> tuple:
    """What the layout of :func:`tracks_plot` depends on besides the sources' data."""
    panels = tuple((p.name, tuple(t.column for t in p.traces))
                   for p in panels_present(tracks))
    return ("tracks", panels, axis.kind, units.system,
            tuple((name, tuple(cols)) for name, cols in sources.items()))


def tracks_plot(tracks: pd.DataFrame, sources: dict[str, dict], axis: TimeAxis,
                units: Units = SI):
    """Interactive time tracks (a Bokeh layout) from :func:`tracks_sources` in display
    ``units``; each ColumnDataSource is named like its key there. Zoom/pan in time on any
    track zooms all; hover gives the bin's min, mean and max; the bottom strip's hover
    names the rig state and the segment (id, kind, bit depth, μ_k). ``tracks`` decides
    which panels are drawn (:func:`panels_present`), not what they show."""
    from bokeh.layouts import gridplot
    from bokeh.models import ColumnDataSource

    shading = ColumnDataSource(sources["shading"], name="shading") \
        if "shading" in sources else None
    figs = []
    x_range = None
    for panel in panels_present(tracks):
        fig = time_figure(_TRACK_PX, panel.label(units), x_range=x_range, axis=axis)
        x_range = fig.x_range
        for trace in panel.traces:
            name = f"trace:{trace.column}"
            source = ColumnDataSource(sources[name], name=name)
            fig.varea("x", "lo", "hi", source=source, color=trace.color, alpha=0.25)
            line = fig.line("x", "mean", source=source, color=trace.color, line_width=1,
                            legend_label=trace.label)
            _hover(fig, line, trace.label, axis)
        fig.legend.location = "top_left"
        fig.legend.label_text_font_size = "10px"
        fig.legend.background_fill_alpha = 0.6
        fig.legend.click_policy = "hide"
        if panel.invert:
            fig.y_range.flipped = True
        if shading is not None:  # every segment as a full-height band: one glyph per track
            fig.vstrip(x0="x0", x1="x1", color="color", source=shading, alpha=0.08,
                       line_alpha=0)
        figs.append(fig)
    figs.append(_strip(sources, x_range, axis))
    return gridplot([[f] for f in figs], merge_tools=True, toolbar_location="right",
                    sizing_mode="stretch_width")


def _hover(fig, renderer, label: str, axis: TimeAxis) -> None:
    from bokeh.models import HoverTool

    when, formatters = axis.hover()
    fig.add_tools(HoverTool(renderers=[renderer], mode="vline",
                            tooltips=[when, (label, "@mean{0.00} (min @lo{0.00}, "
                                                    "max @hi{0.00})")],
                            formatters=formatters))


def _strip(sources: dict[str, dict], x_range, axis: TimeAxis):
    """Rig states (lower row) and segments (upper row) as coloured bands with hover."""
    from bokeh.models import ColumnDataSource, FixedTicker, HoverTool

    fig = time_figure(130, "", x_range=x_range, axis=axis, x_label=axis.label)
    quads = [fig.quad(left="left", right="right", bottom=0.0, top=1.0, color="color",
                      line_alpha=0, legend_field="what",
                      source=ColumnDataSource(sources["states"], name="states"))]
    legend = fig.legend[0]  # the rig states' colours, one entry per state present
    legend.orientation = "horizontal"
    legend.label_text_font_size = "10px"
    legend.padding = legend.margin = 2
    legend.title = "rig state:"
    legend.title_location = "left"
    legend.title_text_font_size = "10px"
    fig.center = [r for r in fig.center if r is not legend]
    fig.add_layout(legend, "below")
    if "bands" in sources:
        quads.append(fig.quad(left="left", right="right", bottom=1.2, top=2.2,
                              source=ColumnDataSource(sources["bands"], name="bands"),
                              color="color", alpha=0.6, line_color="#333333",
                              line_width=0.5))
    fig.add_tools(HoverTool(renderers=quads, tooltips=[("", "@what")]))
    fig.yaxis.ticker = FixedTicker(ticks=[0.5, 1.7])
    fig.yaxis.major_label_overrides = {0.5: "rig state", 1.7: "segments"}
    fig.y_range.start, fig.y_range.end = -0.1, 2.3
    fig.ygrid.visible = False
    return fig


# ------------------------------------------------------------------------- matplotlib
def tracks_figure(tracks: pd.DataFrame, segments: pd.DataFrame,
                  origin: pd.Timestamp | TimeAxis | None,
                  size: tuple[float, float] = (11.69, 8.27), units: Units = SI) -> Figure:
    """Static time tracks (the PDF page) in display ``units``: envelopes, means, segments
    and rig states."""
    from matplotlib.patches import Patch

    panels = panels_present(tracks)
    data = with_breaks(tracks)
    x = time_values(data["time_s"], origin)
    fig = Figure(figsize=size)
    ratios = [1.0] * len(panels) + [0.35]
    fig.subplots_adjust(left=0.08, right=0.985, top=1 - 0.95 / size[1], bottom=0.7 / size[1],
                        hspace=0.08)
    axes = fig.subplots(len(panels) + 1, 1, sharex=True,
                        gridspec_kw={"height_ratios": ratios}, squeeze=False)[:, 0]
    for ax, panel in zip(axes, panels, strict=False):
        for trace in panel.traces:
            scale = units.factor(trace.quantity)
            lo = data[f"{trace.column}_min"] * scale
            hi = data[f"{trace.column}_max"] * scale
            ax.fill_between(x, lo, hi, color=trace.color, alpha=0.25, linewidth=0)
            ax.plot(x, data[f"{trace.column}_mean"] * scale, color=trace.color,
                    linewidth=0.7, label=trace.label)
        ax.set_ylabel(panel.label(units), fontsize=8)
        ax.tick_params(labelsize=7)
        if panel.invert:
            ax.invert_yaxis()
        if len(panel.traces) > 1:
            ax.legend(fontsize=6, loc="upper left")
        for row in segments.itertuples():
            if np.isfinite(row.t_start_s) and np.isfinite(row.t_end_s):
                left, right = time_values([row.t_start_s, row.t_end_s], origin)
                ax.axvspan(left, right, color=SEGMENT_COLORS.get(row.kind, "#777777"),
                           alpha=0.1, linewidth=0)
    strip = axes[-1]
    runs = state_runs(data["time_s"].to_numpy(float), data["rig_state"].fillna(-1))
    lefts, rights = time_values(runs["t0_s"], origin), time_values(runs["t1_s"], origin)
    for left, right, code in zip(lefts, rights, runs["code"], strict=True):
        strip.axvspan(left, right, ymax=0.45, color=STATE_COLORS[code], linewidth=0)
    for row in segments.itertuples():
        if np.isfinite(row.t_start_s) and np.isfinite(row.t_end_s):
            left, right = time_values([row.t_start_s, row.t_end_s], origin)
            strip.axvspan(left, right, ymin=0.55, color=SEGMENT_COLORS.get(row.kind,
                                                                          "#777777"))
    strip.set_yticks([0.25, 0.75], ["rig state", "segments"], fontsize=7)
    strip.set_xlabel(time_label(origin), fontsize=8)
    time_axis(origin).style_matplotlib(strip)
    strip.tick_params(labelsize=7)
    used = sorted(set(runs["code"]))
    fig.legend(handles=[Patch(color=STATE_COLORS[c], label=RIG_STATES[c].replace("_", " "))
                        for c in used], loc="upper center", ncol=len(used) or 1, fontsize=7,
               frameon=False, title="rig state", title_fontsize=7,
               bbox_to_anchor=(0.5, 1 - 0.38 / size[1]))
    return fig
