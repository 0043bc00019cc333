"""Report figures: each function returns a matplotlib :class:`~matplotlib.figure.Figure`.

Figures are built without pyplot (no global state, no window, Agg when saved), so they can
be drawn in a nightly job or a test without a display. Text that comes from users' files
(well names, messages) is drawn with ``parse_math=False`` so a ``$`` cannot break a figure.

Static figures of the report (the PDF pages, and the HTML where no interaction is needed):
well path, torque-and-drag profiles, the friction log with the stick-slip severity, and the
fleet's friction logs. The per-segment evidence (after Figs. 9–11 of Aarsnes et al., JPSE
2019) is in :mod:`drillfric.report.evidence`, the time tracks in
:mod:`drillfric.report.tracks`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from drillfric.vocabulary import MOVING_KINDS, Status

from .display import SI, Units
from .render import is_apparent, severity_note, zone_text

#: Colours of the friction factors (μ_k, μ_s, torque-and-drag back-calculation).
MU_K_COLOR = "#1f5fa8"
MU_S_COLOR = "#c0392b"
#: Colour of apparent (on-bottom) friction factors: the bit torque is in them.
APPARENT_COLOR = "#d35400"
TD_COLOR = "#222222"
#: The drag-based friction factors (pick-up / slack-off hook loads, docs/theory.md §2.2).
DRAG_COLOR = "#16a085"
#: Legend of the drag-based points, in the static and the interactive friction log.
DRAG_LABEL = "drag-based μ of the connections (pick-up/slack-off hook loads)"
#: Legends of the segments without an estimate and of the μ_s lower bounds, likewise.
NONE_LABEL = "no estimate (skipped/failed)"
BOUND_LABEL = "μ_s ≥ lower bound"
SEVERITY_COLOR = "#8e44ad"
_WIDTH_IN = 9.0


def _new(height_in: float, width_in: float = _WIDTH_IN, *, left_in: float = 0.8,
         hspace: float = 0.35, wspace: float = 0.25, top_in: float = 0.75) -> Figure:
    """A figure with fixed margins in inches (room for labels, titles and a page title).

    Fixed margins rather than constrained layout: the report is drawn every night and
    constrained layout doubles the drawing time.
    """
    fig = Figure(figsize=(width_in, height_in))
    fig.subplots_adjust(left=left_in / width_in, right=1 - 0.2 / width_in,
                        bottom=0.55 / height_in, top=1 - top_in / height_in,
                        hspace=hspace, wspace=wspace)
    return fig


def _note(ax, text: str) -> None:
    """An empty axis carrying a sentence instead of a plot."""
    ax.set_axis_off()
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, wrap=True,
            parse_math=False, color="#555555")


def _depth_axis(ax) -> None:
    if not ax.yaxis_inverted():
        ax.invert_yaxis()
    ax.grid(True, color="#dddddd", linewidth=0.6)


def wellpath_figure(wellpath: pd.DataFrame | None,
                    no_survey: str = "No survey: the well was taken as vertical.",
                    size: tuple[float, float] = (_WIDTH_IN, 4.2), units: Units = SI) -> Figure:
    """Vertical section (along the azimuth to the last station) and plan view of the well.

    Parameters
    ----------
    wellpath : DataFrame or None
        wellpath.parquet: ``md_m, tvd_m, north_m, east_m`` [m]. None: no survey.
    no_survey : str
        The note drawn instead when there is no survey (what the path was taken to be).
    size : (float, float)
        Figure size [in].
    units : Units
        Display units of the axes.
    """
    fig = _new(size[1], size[0])
    ax_vs, ax_plan = fig.subplots(1, 2)
    if wellpath is None or wellpath.empty:
        _note(ax_vs, no_survey)
        ax_plan.set_axis_off()
        return fig
    scale, unit = units.factor("length"), units.label("length")
    north = wellpath["north_m"].to_numpy(float) * scale
    east = wellpath["east_m"].to_numpy(float) * scale
    azimuth = np.arctan2(east[-1], north[-1]) if np.hypot(north[-1], east[-1]) > 0 else 0.0
    section = north * np.cos(azimuth) + east * np.sin(azimuth)
    ax_vs.plot(section, wellpath["tvd_m"] * scale, color=MU_K_COLOR)
    ax_vs.set(xlabel=f"vertical section along {np.degrees(azimuth) % 360:.0f}° [{unit}]",
              ylabel=f"TVD [{unit}]", title="Vertical section")
    _depth_axis(ax_vs)
    ax_plan.plot(east, north, color=MU_K_COLOR)
    ax_plan.plot(east[:1], north[:1], "o", color=TD_COLOR, label="surface")
    ax_plan.plot(east[-1:], north[-1:], "s", color=MU_S_COLOR, label="last station")
    ax_plan.set(xlabel=f"east [{unit}]", ylabel=f"north [{unit}]", title="Plan")
    ax_plan.set_aspect("equal", adjustable="datalim")
    ax_plan.grid(True, color="#dddddd", linewidth=0.6)
    ax_plan.legend(fontsize="small")
    return fig


def profile_depths(segments: pd.DataFrame, profiles: pd.DataFrame | None,
                   count: int = 3) -> list[int]:
    """Ids of up to ``count`` profiled segments spread over the bit depths (shallow → deep)."""
    if profiles is None or profiles.empty:
        return []
    have = segments[segments["id"].isin(profiles["segment_id"].unique())]
    have = have.sort_values("bit_depth_m")
    if len(have) <= count:
        return [int(i) for i in have["id"]]
    picks = np.unique(np.linspace(0, len(have) - 1, count).round().astype(int))
    return [int(i) for i in have["id"].to_numpy()[picks]]


def profiles_figure(profiles: pd.DataFrame | None, segments: pd.DataFrame,
                    count: int = 3, size: tuple[float, float] = (_WIDTH_IN, 4.2),
                    units: Units = SI) -> Figure:
    """Normal force per length and F_c = r·F_n (docs/theory.md §5.1) versus MD at a few bit depths.

    Parameters
    ----------
    profiles : DataFrame or None
        profiles.parquet: ``segment_id, md_m, normal_force_N_m, fc_Nm_m``.
    segments : DataFrame
        The segments table (for the bit depths).
    count : int
        Number of bit depths drawn.
    size : (float, float)
        Figure size [in].
    units : Units
        Display units of the axes.
    """
    fig = _new(size[1], size[0])
    ax_fn, ax_fc = fig.subplots(1, 2, sharey=True)
    ids = profile_depths(segments, profiles, count)
    if not ids:
        _note(ax_fn, "No torque-and-drag profile: no segment was estimated.")
        ax_fc.set_axis_off()
        return fig
    depth = segments.set_index("id")["bit_depth_m"]
    length = units.factor("length")
    for seg_id in ids:
        rows = profiles[profiles["segment_id"] == seg_id]
        label = (f"bit at {units.text(depth[seg_id], 'length')} {units.label('length')} "
                 f"(segment {seg_id})")
        md = rows["md_m"] * length
        ax_fn.plot(rows["normal_force_N_m"] * units.factor("side force"), md, label=label)
        ax_fc.plot(rows["fc_Nm_m"] * units.factor("torque per length"), md, label=label)
    ax_fn.set(xlabel=units.axis("normal force F_n", "side force"),
              ylabel=units.axis("MD", "length"), title="Normal force")
    ax_fc.set(xlabel=units.axis("F_c", "torque per length"),
              title="Coulomb torque per unit μ, F_c")
    for ax in (ax_fn, ax_fc):
        _depth_axis(ax)
    ax_fn.legend(fontsize="small")
    return fig


def friction_log_figure(segments: pd.DataFrame,
                        size: tuple[float, float] = (_WIDTH_IN, 5.5),
                        units: Units = SI, top_in: float = 0.75,
                        drag: pd.DataFrame | None = None, empty_note: str = "") -> Figure:
    """μ_s and μ_k versus bit depth, one point per segment (stand), with spread bars, and
    the stick-slip severity versus bit depth beside it.

    μ_k (●) is drawn for off-bottom segments only; an on-bottom segment's factor is
    apparent (the bit torque is in it) and drawn as ▲ with its own legend entry. Reaming
    and back-reaming segments are not drawn for now (docs/outputs.md).

    Filled markers: converged; hollow: not converged. μ_s is drawn as a point only where it
    is identifiable (docs/theory.md §6); where only a lower bound is known it is drawn as a
    right-pointing bound (▷ with a dotted tail: "at least this"). Crosses: the
    torque-and-drag back-calculated μ (``mu_td``). Bars span the spread across starts.
    ``drag`` (drag_log.parquet): the drag-based μ of each connection whose μ is given, a
    green ✚ with its uncertainty as bars and its own legend entry — a second friction log,
    independent of the torque.
    Segments without an estimate are grey diamonds at μ = 0. Markers are not clipped at
    the axes' edges. ``top_in``: room above the axes [in] (a page's headline).
    Right: severity (ω_max − ω_min)/(2 ω_mean) of the
    estimated bit speed; beyond the dashed line at 1 the bit stops; without any, the panel
    says why (:func:`~drillfric.report.render.severity_note`). Depths in display
    ``units``; the μ axis names the friction zone when the segments share one.
    With no friction factor to draw, the figure is ``empty_note`` (default: the counts) and
    no axis: no mark is drawn without its axes and labels.
    """
    fig = _new(size[1], size[0], left_in=0.9, wspace=0.08, top_in=top_in)
    ax, ax_sev = fig.subplots(1, 2, sharey=True, gridspec_kw={"width_ratios": [2.2, 1]})
    seg = segments.assign(depth=segments["bit_depth_m"] * units.factor("length"))
    seg = seg[~seg["kind"].isin(MOVING_KINDS)]  # reaming μ_k: not in the log for now
    ok = seg[seg["status"] == Status.OK]
    apparent = np.array([is_apparent(r) for r in ok.to_dict("records")], dtype=bool)
    for rows, color, marker, name in (
            (ok[~apparent], MU_K_COLOR, "o", "μ_k (off bottom)"),
            (ok[apparent], APPARENT_COLOR, "^", "apparent μ (on bottom, bit torque in it)")):
        _mu_points(ax, rows, "mu_k", "mu_k_spread", rows["converged"].to_numpy(bool), color,
                   marker, name)
    ident = ok[ok["mu_s_identifiable"] & ok["mu_s"].notna()]
    _mu_points(ax, ident, "mu_s", "mu_s_spread", ident["converged"].to_numpy(bool),
               MU_S_COLOR, "s", "μ_s")
    bound = ok[~ok["mu_s_identifiable"] & ok["mu_s_lower_bound"].notna()]
    if len(bound):
        ax.plot(bound["mu_s_lower_bound"], bound["depth"], ">", color=MU_S_COLOR,
                markerfacecolor="none", label=BOUND_LABEL, clip_on=False)
        for x, y in zip(bound["mu_s_lower_bound"], bound["depth"], strict=True):
            ax.plot([x, x + 0.08], [y, y], ":", color=MU_S_COLOR, linewidth=1.2)
    td = ok[~apparent & ok["mu_td"].notna()]
    if len(td):
        ax.plot(td["mu_td"], td["depth"], "x", color=TD_COLOR,
                label="μ from torque and drag", clip_on=False)
    none = seg[(seg["status"] != Status.OK) & seg["depth"].notna()]
    drawn = _drag_points(ax, drag, units)
    if not ok["mu_k"].notna().any() and not drawn:
        ax.clear()
        _note(ax, empty_note or "No friction factor to draw: no segment was estimated "
                                f"({len(none)} without an estimate).")
        ax_sev.set_axis_off()
        return fig
    if len(none):
        ax.plot(np.zeros(len(none)), none["depth"], "d", color="#888888",
                markerfacecolor="none", clip_on=False, label=NONE_LABEL)
    zone = zone_text(segments)
    ax.set(xlabel=f"friction factor μ{f' ({zone})' if zone else ''} [-]",
           ylabel=units.axis("bit depth", "length"))
    _depth_axis(ax)
    ax.legend(fontsize="small", loc="best")
    sev = ok[ok["stick_slip_severity"].notna()]
    ax_sev.plot(sev["stick_slip_severity"], sev["depth"], "o", color=SEVERITY_COLOR,
                clip_on=False)
    ax_sev.axvline(1.0, color=MU_S_COLOR, linestyle="--", linewidth=0.8)
    ax_sev.set(xlabel="stick-slip severity [-]")
    if not len(sev):
        ax_sev.set_title(severity_note(segments), fontsize="small", loc="left", wrap=True)
    ax_sev.set_xlim(left=0.0, right=max(1.2, 1.1 * float(sev["stick_slip_severity"].max()))
                    if len(sev) else 1.2)
    ax_sev.grid(True, color="#dddddd", linewidth=0.6)
    _around_every_mark(ax)
    return fig


def _around_every_mark(ax, margin: float = 0.08) -> None:
    """Limits of the friction log that hold every mark drawn — points, spread bars, bound
    tails, the μ = 0 diamonds — with ``margin`` of the span around them (issue 35: a μ_s
    mark sat on the axis edge, half cut); μ from a little below 0, depth inverted."""
    x0, x1 = ax.dataLim.intervalx
    y0, y1 = ax.dataLim.intervaly
    x0, x1 = min(0.0, x0), max(x1, 0.1)
    pad = margin * (x1 - x0)
    ax.set_xlim(x0 - pad / 2, x1 + pad)
    span = y1 - y0 if y1 > y0 else max(abs(y0) * 0.01, 10.0)
    ax.set_ylim(y1 + margin * span, y0 - margin * span)  # depth down



def drag_rows(drag: pd.DataFrame | None) -> pd.DataFrame:
    """The connections of a drag log with a drag-based μ and a bit depth."""
    if drag is None or "mu_drag" not in drag:
        return pd.DataFrame(columns=["bit_depth_m", "mu_drag", "mu_drag_uncertainty"])
    mu = pd.to_numeric(drag["mu_drag"], errors="coerce")
    return drag[mu.notna() & drag["bit_depth_m"].notna()].assign(mu_drag=mu[mu.notna()])


def _drag_points(ax, drag: pd.DataFrame | None, units: Units) -> bool:
    """Draw the drag-based μ (``drag``: drag_log.parquet); whether any was drawn."""
    rows = drag_rows(drag)
    if not len(rows):
        return False
    half = pd.to_numeric(rows["mu_drag_uncertainty"], errors="coerce").fillna(0.0)
    bars = ax.errorbar(rows["mu_drag"].to_numpy(float),
                       rows["bit_depth_m"].to_numpy(float) * units.factor("length"),
                       xerr=half.to_numpy(float), fmt="P", color=DRAG_COLOR, ecolor=DRAG_COLOR,
                       elinewidth=1.0, capsize=2, label=DRAG_LABEL)
    bars.lines[0].set_clip_on(False)
    return True


def _mu_points(ax, rows: pd.DataFrame, col: str, spread: str, converged: np.ndarray,
               color: str, marker: str, name: str) -> None:
    if not len(rows):
        return
    half = rows[spread].fillna(0.0).to_numpy(float) / 2.0
    for mask, suffix, face in ((converged, "", color), (~converged, " (not converged)", "none")):
        if not mask.any():
            continue
        bars = ax.errorbar(rows[col].to_numpy(float)[mask],
                           rows["depth"].to_numpy(float)[mask], xerr=half[mask],
                           fmt=marker, color=color, markerfacecolor=face, ecolor=color,
                           elinewidth=1.0, capsize=2, label=name + suffix)
        bars.lines[0].set_clip_on(False)
