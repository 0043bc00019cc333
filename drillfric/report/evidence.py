"""The evidence of one segment: what was measured against what the fitted model gives.

Panels on one time axis, from estimates.parquet (final seeded pass, ``start_id`` −1,
unless stated):

1. surface torque — measured string torque, the observer's modelled torque and the batch
   fit's speed-driven model torque at the fitted factors (its break-over peak and
   stick-slip swing against the data's);
2. torque residual — measured − fit and measured − observer;
3. surface speed — measured and estimated;
4. speed residual — measured − estimated;
5. bit speed — estimated (the seeded ensemble's mean with its min–max band), stuck periods
   shaded, the measured downhole speed where the input had one, and with a declared mud
   motor the BHA's speed beneath the bit's (docs/theory.md §2.4); left out where the logging
   rate does not resolve the stick-slip cycle (``bit_speed_resolved`` false: the report
   gives the reason instead — no trace is drawn from such data);
6. μ_k and μ_s of every observer start (the paper's Fig. 10 view) and the final pass, whose
   μ_k is μ_k(t) of the windowed re-fits with its 95 % band (docs/theory.md §6.6; gaps
   where it is withheld).

Torques are drawn in the report's display units (:mod:`drillfric.report.display`), speeds
in rpm. Panels whose columns the file does not hold (results older than the torque columns)
are left out. :func:`evidence_plot` is the Bokeh version, :func:`evidence_figure` the PDF one.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from .data import FINAL_START_ID
from .display import SI, Units, row_flags
from .interactive import (
    TimeAxis,
    float32,
    time_axis,
    time_figure,
    time_label,
    time_values,
)

MEASURED = "#555555"
#: Legend of the seeded pass in the μ panel: its μ_k is μ_k(t), its μ_s the seed.
FINAL_LABEL = "final pass: μ_k(t), μ_s seeded"
OBSERVER = "#1f5fa8"
FIT = "#e67e22"
STUCK = "#f4b6b6"
#: Legend of the stuck periods, in the HTML's and the PDF's bit-speed panel alike.
STUCK_LABEL = "estimated stuck"
BHA = "#8e44ad"
_PX = 150


def has_column(frame: pd.DataFrame, name: str) -> bool:
    """Whether ``frame`` has ``name`` with at least one value."""
    return name in frame and bool(frame[name].notna().any())


def final_pass(est: pd.DataFrame) -> pd.DataFrame:
    """Rows of the final (seeded) pass, in time order."""
    return est[est["start_id"] == FINAL_START_ID].sort_values("time_s", kind="stable")


def stuck_flags(rows: pd.DataFrame) -> np.ndarray:
    """``bit_stuck`` of ``rows`` as booleans (null — bit speed not resolved — is not
    stuck)."""
    return rows["bit_stuck"].astype("boolean").fillna(False).to_numpy(bool)


def stuck_runs(time_s: np.ndarray, stuck: np.ndarray) -> list[tuple[float, float]]:
    """``(t0, t1)`` of every run of samples where the estimated bit is stuck [s]."""
    stuck = np.asarray(stuck, dtype=bool)
    if not stuck.any():
        return []
    edges = np.diff(np.r_[0, stuck.astype(np.int8), 0])
    first, last = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return [(float(time_s[a]), float(time_s[b])) for a, b in zip(first, last, strict=True)]


def panel_data(est: pd.DataFrame, units: Units = SI, bit: bool = True
               ) -> dict[str, dict[str, np.ndarray]]:
    """What each panel draws, by panel key and series name (SI → display ``units``).

    Keys present only when the file has the columns: ``torque`` (``measured``,
    ``observer``, ``fit``), ``torque_residual`` (``fit``, ``observer``), ``speed``
    (``measured``, ``estimated`` [rpm]), ``speed_residual`` (``residual``), ``bit``
    (``estimated``, ``low``, ``high``, ``measured`` [rpm], ``bha`` — the string's bottom —
    where a declared mud motor makes it differ from the bit's; only with ``bit`` — False where
    the bit speed is not resolved — and an estimated bit speed in the file). Every array
    is the file's column at the rows of ``est`` (scaled), so a figure shows the file's
    numbers.
    """
    best = final_pass(est)
    out: dict[str, dict[str, np.ndarray]] = {"time_s": {"t": best["time_s"].to_numpy(float)}}
    scale = units.factor("torque")
    if has_column(best, "surface_torque_Nm"):
        measured = best["surface_torque_Nm"].to_numpy(float)
        torque = {"measured": measured * scale}
        residual = {}
        for name, col in (("observer", "surface_torque_est_Nm"),
                          ("fit", "surface_torque_fit_Nm")):
            if has_column(best, col):
                torque[name] = best[col].to_numpy(float) * scale
                residual[name] = (measured - best[col].to_numpy(float)) * scale
        out["torque"] = torque
        if residual:
            out["torque_residual"] = residual
    out["speed"] = {"measured": best["surface_rpm"].to_numpy(float),
                    "estimated": best["surface_rpm_est"].to_numpy(float)}
    if has_column(best, "residual_rpm"):
        out["speed_residual"] = {"residual": best["residual_rpm"].to_numpy(float)}
    if not (bit and has_column(best, "bit_rpm_est")):
        return out
    speeds = {"estimated": best["bit_rpm_est"].to_numpy(float)}
    if has_column(best, "bha_rpm_est"):
        bha = best["bha_rpm_est"].to_numpy(float)
        if not np.array_equal(bha, speeds["estimated"], equal_nan=True):
            speeds["bha"] = bha  # a declared mud motor turns the bit faster
    if has_column(best, "bit_rpm_est_min"):
        speeds["low"] = best["bit_rpm_est_min"].to_numpy(float)
        speeds["high"] = best["bit_rpm_est_max"].to_numpy(float)
    if has_column(best, "bit_rpm"):
        speeds["measured"] = best["bit_rpm"].to_numpy(float)
    out["bit"] = speeds
    return out


def _label(key: str, units: Units) -> str:
    """Axis label of a panel."""
    torque = units.label("torque")
    return {"torque": f"torque [{torque}]", "torque_residual": f"Δ torque [{torque}]",
            "speed": "surface [rpm]", "speed_residual": "Δ speed [rpm]",
            "bit": "bit [rpm]", "mu": "μ [-]"}[key]


#: Height of a line of notes at 7 pt [in].
_NOTE_LINE_IN = 0.13
_STYLE = {"measured": (MEASURED, 1.0), "observer": (OBSERVER, 1.0), "fit": (FIT, 1.2),
          "estimated": (OBSERVER, 1.0), "residual": (MEASURED, 0.8), "bha": (BHA, 1.0)}
_LEGEND = {("torque", "measured"): "measured", ("torque", "observer"): "observer model",
           ("torque", "fit"): "fit model (fitted μ)",
           ("torque_residual", "fit"): "measured − fit",
           ("torque_residual", "observer"): "measured − observer",
           ("speed", "measured"): "measured", ("speed", "estimated"): "estimated",
           ("speed_residual", "residual"): "measured − estimated",
           ("bit", "estimated"): "estimated", ("bit", "measured"): "measured downhole",
           ("bit", "bha"): "BHA (string's bottom, without the motor)"}


# ------------------------------------------------------------------------------ Bokeh
def evidence_sources(est: pd.DataFrame, origin: pd.Timestamp | TimeAxis | None,
                     units: Units = SI,
                     bit: bool = True) -> dict[str, dict[str, np.ndarray]]:
    """The data of every Bokeh source of a segment's evidence, by source name.

    ``panel:KEY`` (``x`` and the series of :func:`panel_data`, float32), ``stuck``
    (``x0``, ``x1``: stuck periods, with the bit panel; absent when there are none),
    ``start:ID`` (``x``, ``mu_k``, ``mu_s`` of one observer start; ``start:-1`` the final
    pass).
    """
    data = panel_data(est, units, bit)
    t = data.pop("time_s")["t"]
    x = time_values(t, origin)
    out = {f"panel:{key}": {"x": x, **{k: float32(v) for k, v in series.items()}}
           for key, series in data.items()}
    runs = np.array(stuck_runs(t, stuck_flags(final_pass(est))) if "bit" in data
                    else []).reshape(-1, 2)
    if len(runs):  # none: no "estimated stuck" legend entry, as in the PDF
        out["stuck"] = {"x0": time_values(runs[:, 0], origin),
                        "x1": time_values(runs[:, 1], origin)}
    for start_id, rows in est.groupby("start_id", sort=True):
        out[f"start:{int(start_id)}"] = {"x": time_values(rows["time_s"], origin),
                                         "mu_k": float32(rows["mu_k"]),
                                         "mu_s": float32(rows["mu_s"]),
                                         **_mu_k_band(rows)}
    return out


def _mu_k_band(rows: pd.DataFrame) -> dict[str, np.ndarray]:
    """``low``/``high``: μ_k(t) ∓ its 95 % half-width (the seeded rows' windowed re-fits,
    docs/theory.md §6.6); none where the rows hold no half-width."""
    if not has_column(rows, "mu_k_half_width") or not rows["mu_k_half_width"].notna().any():
        return {}
    mu, half = rows["mu_k"].to_numpy(float), rows["mu_k_half_width"].to_numpy(float)
    return {"low": float32(mu - half), "high": float32(mu + half)}


#: Segment flags under which the segment's friction factors are withheld although the
#: observer's μ̂ traces are drawn (docs/outputs.md, the hook-load check).
WITHHELD_MU_FLAGS = ("hookload_contradicts_string", "string_weight_unverified")


def mu_withheld(segment: dict) -> str:
    """The μ̂ panel's title where the segment's friction factors are withheld ("" else): the
    traces are the observer's adaptation on the configured string, not a result."""
    flags = row_flags(segment)
    flag = next((f for f in WITHHELD_MU_FLAGS if f in flags), None)
    if flag is None:
        return ""
    return (f"friction factors withheld ({flag.replace('_', ' ')}): μ̂ of the observer on "
            "the configured string, not a result")


def signature(sources: dict[str, dict], axis: TimeAxis, units: Units = SI,
              mu_note: str = "") -> tuple:
    """What the layout of :func:`evidence_plot` depends on besides the sources' data."""
    return ("evidence", axis.kind, units.system, mu_note,
            tuple((name, tuple(cols)) for name, cols in sources.items()))


def evidence_plot(sources: dict[str, dict], axis: TimeAxis, units: Units = SI,
                  mu_note: str = ""):
    """A segment's evidence as a Bokeh layout (panels share the time axis), from
    :func:`evidence_sources` in display ``units``; each ColumnDataSource is named like its
    key there. ``mu_note``: the μ̂ panel's title (:func:`mu_withheld`)."""
    from bokeh.layouts import gridplot
    from bokeh.models import ColumnDataSource, HoverTool

    figs, x_range = [], None
    for name, columns in sources.items():
        if not name.startswith("panel:"):
            continue
        key = name.split(":", 1)[1]
        fig = time_figure(_PX if key in ("torque", "bit") else 100, _label(key, units),
                          x_range=x_range, axis=axis)
        x_range = fig.x_range
        source = ColumnDataSource(columns, name=name)
        if key == "bit" and "stuck" in sources:
            fig.vstrip(x0="x0", x1="x1", source=ColumnDataSource(sources["stuck"],
                                                                   name="stuck"),
                       color=STUCK, alpha=0.6, line_alpha=0, legend_label=STUCK_LABEL)
            if "low" in columns:
                fig.varea("x", "low", "high", source=source, color=OBSERVER, alpha=0.18,
                          legend_label="ensemble band (min–max)")
        series = [c for c in columns if c not in ("x", "low", "high")]
        lines = [fig.line("x", c, source=source, color=_color(key, c),
                          line_width=_STYLE.get(c, (MEASURED, 1.0))[1],
                          line_dash="dashed" if (key, c) == ("bit", "measured") else "solid",
                          legend_label=_LEGEND.get((key, c), c)) for c in series]
        when, formatters = axis.hover()
        tips = [when, *((_LEGEND.get((key, c), c), f"@{{{c}}}{{0.00}}") for c in series)]
        fig.add_tools(HoverTool(renderers=lines[:1], mode="vline", tooltips=tips,
                                formatters=formatters))
        _legend(fig)
        figs.append(fig)
    figs.append(_mu_plot(sources, axis, x_range, mu_note))
    return gridplot([[f] for f in figs], merge_tools=True, toolbar_location="right",
                    sizing_mode="stretch_width")


def _color(key: str, name: str) -> str:
    if key.endswith("residual"):
        return {"fit": FIT, "observer": OBSERVER}.get(name, MEASURED)
    return _STYLE.get(name, (MEASURED, 1.0))[0]


def _legend(fig) -> None:
    fig.legend.location = "top_left"
    fig.legend.orientation = "horizontal"
    fig.legend.label_text_font_size = "10px"
    fig.legend.background_fill_alpha = 0.7
    fig.legend.click_policy = "hide"
    fig.legend.padding = 2
    fig.legend.margin = 2


def _mu_plot(sources: dict[str, dict], axis: TimeAxis, x_range, note: str = ""):
    from bokeh.models import ColumnDataSource, HoverTool
    from bokeh.palettes import Category10

    fig = time_figure(_PX, _label("mu", SI), x_range=x_range, axis=axis, x_label=axis.label)
    if note:
        fig.title.text = note
        fig.title.text_color = "#c9302c"
    lines = []
    for name, columns in sources.items():
        if not name.startswith("start:"):
            continue
        start_id = int(name.split(":", 1)[1])
        final = start_id == FINAL_START_ID
        color = "black" if final else Category10[10][start_id % 10]
        label = FINAL_LABEL if final else f"start {start_id}"
        source = ColumnDataSource(columns, name=name)
        width = 1.8 if final else 1.0
        if "low" in columns:
            fig.varea("x", "low", "high", source=source, color="black", alpha=0.12,
                      legend_label="μ_k(t) 95 % band")
        lines.append(fig.line("x", "mu_k", source=source, color=color, line_width=width,
                              legend_label=label))
        fig.line("x", "mu_s", source=source, color=color, line_dash="dashed",
                 line_width=width, legend_label=label)
    fig.add_tools(HoverTool(renderers=lines, tooltips=[("μ_k", "@mu_k{0.000}"),
                                                       ("μ_s", "@mu_s{0.000}")]))
    _legend(fig)
    return fig


def starts_text(segment: dict) -> str:
    """The observer starts' initial values, for the segment's header."""
    starts = segment.get("starts") or []
    return ", ".join(f"{i}: ({s:.2f}, {k:.2f})" for i, (s, k) in enumerate(starts)) or "—"


def start_label(segment: dict, start_id: int) -> str:
    """Legend of an observer start: its initial (μ_s, μ_k)."""
    starts = segment.get("starts") or []
    if 0 <= start_id < len(starts):
        mu_s, mu_k = starts[start_id]
        return f"start {start_id}: ({mu_s:.2f}, {mu_k:.2f})"
    return f"start {start_id}"


# ------------------------------------------------------------------------- matplotlib
def evidence_figure(est: pd.DataFrame, segment: dict,
                    origin: pd.Timestamp | TimeAxis | None = None,
                    size: tuple[float, float] = (9.0, 9.0), units: Units = SI,
                    bit: bool = True, notes: list[str] | None = None) -> Figure:
    """The segment's evidence as a static figure (the PDF page) in display ``units``;
    ``bit`` False leaves the bit speed out (not resolved); ``notes``: lines of text drawn
    above the panels (under the page title)."""
    data = panel_data(est, units, bit)
    t = data.pop("time_s")["t"]
    x = time_values(t, origin)
    keys = [*data, "mu"]
    fig = Figure(figsize=size)
    notes = notes or []
    if notes:
        fig.text(0.09, 1 - 0.55 / size[1], "\n".join(notes), ha="left", va="top", fontsize=7,
                 parse_math=False, color="#333333")
    top_in = 0.8 + _NOTE_LINE_IN * len(notes)
    fig.subplots_adjust(left=0.09, right=0.98, top=1 - top_in / size[1], bottom=0.6 / size[1],
                        hspace=0.12)
    ratios = [1.0 if k in ("torque", "bit", "mu") else 0.6 for k in keys]
    axes = fig.subplots(len(keys), 1, sharex=True, gridspec_kw={"height_ratios": ratios})
    for ax, key in zip(axes, keys, strict=True):
        if key == "mu":
            _mu_axes(ax, est, segment, origin)
        else:
            _series_axes(ax, key, data[key], x, t, est, origin)
        ax.set_ylabel(_label(key, units), fontsize=7)
        ax.tick_params(labelsize=7)
        ax.grid(True, color="#dddddd", linewidth=0.6)
        ax.legend(fontsize=6, loc="upper right", ncol=3)
    axes[-1].set_xlabel(time_label(origin), fontsize=8)
    time_axis(origin).style_matplotlib(axes[-1])
    return fig


def _series_axes(ax, key: str, series: dict, x, t, est, origin) -> None:
    if key == "bit":
        for index, (t0, t1) in enumerate(stuck_runs(t, stuck_flags(final_pass(est)))):
            left, right = time_values([t0, t1], origin)  # one legend entry, as the HTML's
            ax.axvspan(left, right, color=STUCK, linewidth=0,
                       label=STUCK_LABEL if index == 0 else None)
        if "low" in series:
            ax.fill_between(x, series["low"], series["high"], color=OBSERVER, alpha=0.18,
                            linewidth=0, label="ensemble band (min–max)")
    for name, values in series.items():
        if name in ("low", "high"):
            continue
        color, width = _STYLE.get(name, (MEASURED, 1.0))
        if key.endswith("residual"):
            color = {"fit": FIT, "observer": OBSERVER}.get(name, color)
        ax.plot(x, values, color=color, linewidth=0.8 * width,
                linestyle="--" if (key, name) == ("bit", "measured") else "-",
                label=_LEGEND.get((key, name), name))


def _mu_axes(ax, est: pd.DataFrame, segment: dict, origin) -> None:
    note = mu_withheld(segment)
    if note:  # inside the axes: a title would run into the panel above
        ax.text(0.005, 0.97, note, transform=ax.transAxes, fontsize=7, color="#c9302c",
                va="top", ha="left", parse_math=False, zorder=5,
                bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "none"})
    for start_id, rows in est.groupby("start_id", sort=True):
        final = start_id == FINAL_START_ID
        kw = {"color": "black", "linewidth": 1.4} if final else {"linewidth": 0.8}
        x = time_values(rows["time_s"], origin)
        line, = ax.plot(x, rows["mu_k"], label=FINAL_LABEL if final
                        else start_label(segment, int(start_id)), **kw)
        band = _mu_k_band(rows) if final else {}
        if band:
            ax.fill_between(x, band["low"], band["high"], color="black", alpha=0.12,
                            linewidth=0, label="μ_k(t) 95 % band")
        ax.plot(x, rows["mu_s"], linestyle="--", **{**kw, "color": line.get_color()})
