"""Interactive figures in a self-contained HTML file: Bokeh, its JavaScript inlined.

The page loads ``bokeh.min.js`` (the core bundle alone, ~1.3 MB: no widgets, tables, WebGL
or MathJax bundles) from an inline ``<script>``, keeps every figure's JSON in a
``<script type="application/json">`` data block (not executed) and embeds them with one
small inline loader. The Content-Security-Policy allows exactly these two scripts by their
SHA-256 hashes (no ``'unsafe-inline'``, no ``'unsafe-eval'``) and no network source at all:
the file makes no request and can be archived or mailed.

Text from users' files (well names, messages) is never put in titles or axis labels —
Bokeh would read ``$$…$$`` there as TeX and needs the MathJax bundle for it — only in
legends and hover fields, which Bokeh shows as plain text.
"""

from __future__ import annotations

import base64
import hashlib
import json
from collections import OrderedDict
from dataclasses import dataclass, field
from functools import cache

import numpy as np
import pandas as pd
from markupsafe import Markup

from drillfric.io.timebase import clock_at

from .render import clock

#: Width of the interactive figures when the page is wider than this [px] (they stretch).
MIN_WIDTH_PX = 600
#: Tools of every time-axis figure: zoom and pan along time, box zoom, reset, hover, save.
TIME_TOOLS = "xpan,xwheel_zoom,box_zoom,reset,save"
#: Most layouts :meth:`Embedder.add_like` keeps per process (a fleet worker meets a few
#: kinds: the time tracks, the friction log, the evidence by the channels a log has).
LAYOUT_CACHE_SIZE = 32
#: ``json_item`` of the layouts built in this process, by signature (least recent first).
_LAYOUTS: OrderedDict = OrderedDict()
_LOADER = ("for (const item of JSON.parse(document.getElementById('bokeh-items').textContent))"
           " { Bokeh.embed.embed_item(item); }")


@cache
def bokeh_js() -> str:
    """The inline text of Bokeh's core bundle, made safe to sit inside ``<script>``."""
    from bokeh.resources import Resources

    text = Resources(mode="inline", components=["bokeh"]).js_raw[0]
    return text.replace("</script", "<\\/script")


def script_hash(text: str) -> str:
    """CSP source expression allowing an inline script with exactly this text."""
    digest = hashlib.sha256(text.encode("utf-8")).digest()
    return "'sha256-" + base64.b64encode(digest).decode("ascii") + "'"


def json_in_script(payload) -> Markup:
    """JSON that can sit inside a ``<script type="application/json">`` element.

    ``<``, ``>`` and ``&`` are written as ``\\u003c`` etc. (still the same JSON), so no
    text from a user's file can close the element.
    """
    text = json.dumps(payload, separators=(",", ":"), allow_nan=False)
    text = text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    return Markup(text)


@dataclass
class Embedder:
    """Collects Bokeh layouts of one page and gives the template what it needs.

    ``add(layout, key)`` returns the id of the ``<div>`` to place; :attr:`head` is what
    goes into the template (scripts, data block, CSP script sources).

    Building and serialising Bokeh models costs 0.1–0.3 s per multi-panel layout, whatever
    the data; a report with 30 segments, or a fleet worker writing a report per well,
    would spend seconds on it. Layouts that differ only in their data (:meth:`add_like`)
    are therefore built and serialised once per ``signature`` and process (the last
    :data:`LAYOUT_CACHE_SIZE` signatures are kept); the others are copies of that JSON
    with the data of their named ColumnDataSources replaced, encoded by Bokeh's own
    serializer.
    """

    items: list = field(default_factory=list)

    def add(self, layout, key: str) -> str:
        """Register a Bokeh layout; returns the element id where it is drawn."""
        from bokeh.embed import json_item

        target = f"bk-{key}"
        self.items.append(json_item(layout, target))
        return target

    def add_like(self, signature, build, data: dict[str, dict], key: str) -> str:
        """Register a layout made by ``build()`` whose ColumnDataSources are named by the
        keys of ``data``; a layout with the same ``signature`` — a hashable value holding
        everything but the sources' data the layout depends on — is not built again."""
        target = f"bk-{key}"
        template = _LAYOUTS.pop(signature, None)
        if template is None:
            self.add(build(), key)
            template = self.items[-1]
        else:
            self.items.append(with_data(template, target, data))
        _LAYOUTS[signature] = template  # now the most recent
        while len(_LAYOUTS) > LAYOUT_CACHE_SIZE:
            _LAYOUTS.popitem(last=False)
        return target

    @property
    def head(self) -> dict:
        """``{"js", "loader", "data", "script_src"}`` for the page (empty without items)."""
        if not self.items:
            return {"js": None, "loader": None, "data": None, "script_src": "'none'"}
        js = bokeh_js()
        return {"js": Markup(js), "loader": Markup(_LOADER),
                "data": json_in_script(self.items),
                "script_src": f"{script_hash(js)} {script_hash(_LOADER)}"}


def forget_layouts() -> None:
    """Empty the process's layout cache (:meth:`Embedder.add_like`)."""
    _LAYOUTS.clear()


def with_data(item: dict, target: str, data: dict[str, dict]) -> dict:
    """A copy of a ``json_item`` drawn at ``target`` whose ColumnDataSources named like the
    keys of ``data`` hold that data instead (structure, styles and ids unchanged: each
    item is its own Bokeh document, so ids may repeat across items)."""
    from bokeh.core.serialization import Serializer

    encode = Serializer(deferred=False).encode
    replaced = set()

    def copy(node):
        if isinstance(node, list):
            return [copy(v) for v in node]
        if not isinstance(node, dict):
            return node
        out = {k: copy(v) for k, v in node.items()}
        name = node.get("attributes", {}).get("name") if node.get("name") == \
            "ColumnDataSource" else None
        if name in data:
            out["attributes"]["data"] = encode({k: v for k, v in data[name].items()})
            replaced.add(name)
        return out

    out = copy(item)
    out["target_id"] = target
    missing = set(data) - replaced
    if missing:
        raise ValueError(f"no ColumnDataSource named {sorted(missing)} in the template")
    return out


#: Logs longer than this without clock time are plotted in log time ``h:mm:ss``, not
#: seconds [s].
LONG_LOG_S = 3600.0
#: Tick spacings of a log-time axis in ``h:mm:ss`` [s]: whole seconds, minutes and hours
#: (never a decimal hour such as 13.76 h).
CLOCK_STEPS_S = (1, 2, 5, 10, 15, 30, 60, 120, 300, 600, 900, 1800,
                 3600, 7200, 10800, 21600, 43200, 86400)


@dataclass(frozen=True)
class TimeAxis:
    """How log time is plotted: clock time (UTC) when the log has it (``origin``, the clock
    time of log time 0), else log time read as ``h:mm:ss`` for a log longer than
    :data:`LONG_LOG_S` (``hours``: ticks on whole minutes and hours), else log seconds."""

    origin: pd.Timestamp | None = None
    hours: bool = False

    @property
    def clock(self) -> bool:
        """Whether the axis shows clock time."""
        return self.origin is not None

    @property
    def kind(self) -> str:
        """``"clock"``, ``"hours"`` or ``"seconds"`` (a layout's signature holds it)."""
        return "clock" if self.clock else ("hours" if self.hours else "seconds")

    def values(self, time_s) -> np.ndarray:
        """Log time [s] as plotted: naive-UTC datetimes, else seconds (an ``h:mm:ss`` axis
        plots seconds and labels them as such)."""
        seconds = np.asarray(time_s, dtype=float)
        if self.origin is not None:
            return clock_at(self.origin.tz_convert("UTC").tz_localize(None), seconds).to_numpy()
        return seconds

    @property
    def label(self) -> str:
        """Axis label."""
        return {"clock": "time [UTC]", "hours": "log time [h:mm:ss]",
                "seconds": "log time [s]"}[self.kind]

    def hover(self) -> tuple[tuple[str, str], dict]:
        """The hover field of the time and its Bokeh formatters."""
        if self.clock:
            return ("time", "@x{%F %T}"), {"@x": "datetime"}
        return ("time", "@x{00:00:00} log time" if self.hours else "@x{0.0} s"), {}

    def style_bokeh(self, fig) -> None:
        """Ticks of an ``h:mm:ss`` axis on whole minutes and hours, labelled ``h:mm:ss``
        (Bokeh's numeral format ``00:00:00``: no script of ours, the page's CSP holds)."""
        if not self.hours or self.clock:
            return
        from bokeh.models import AdaptiveTicker, CompositeTicker, NumeralTickFormatter

        fig.xaxis.formatter = NumeralTickFormatter(format="00:00:00")
        fig.xaxis.ticker = CompositeTicker(tickers=[
            AdaptiveTicker(mantissas=[1, 2, 5, 10, 15, 30], base=60, min_interval=1.0,
                           max_interval=1800.0),
            AdaptiveTicker(mantissas=[1, 2, 3, 6, 12, 24], base=3600, min_interval=3600.0)])

    def style_matplotlib(self, ax) -> None:
        """The same for a static figure: ticks :data:`CLOCK_STEPS_S` apart, labelled
        ``h:mm:ss`` (:func:`drillfric.report.render.clock`)."""
        if not self.hours or self.clock:
            return
        from matplotlib.ticker import FuncFormatter

        ax.xaxis.set_major_locator(_clock_locator())
        ax.xaxis.set_major_formatter(FuncFormatter(lambda seconds, _: clock(seconds)))


def _clock_locator():
    """A matplotlib locator of ticks :data:`CLOCK_STEPS_S` apart, at most 8 on the axis."""
    from matplotlib.ticker import Locator

    class ClockLocator(Locator):
        def __call__(self):
            return self.tick_values(*self.axis.get_view_interval())

        def tick_values(self, vmin, vmax):
            step = next((s for s in CLOCK_STEPS_S if (vmax - vmin) / s <= 8),
                        CLOCK_STEPS_S[-1])
            return np.arange(np.ceil(vmin / step) * step, vmax + step * 1e-6, step)

    return ClockLocator()


def time_axis(origin: pd.Timestamp | TimeAxis | None, span_s: float = 0.0) -> TimeAxis:
    """The :class:`TimeAxis` of a log whose time 0 is at clock time ``origin`` (None: no
    clock) and which lasts ``span_s`` [s]; a TimeAxis is returned as it is."""
    if isinstance(origin, TimeAxis):
        return origin
    return TimeAxis(origin, origin is None and span_s > LONG_LOG_S)


def time_figure(height: int, y_label: str, *, x_range=None, axis: TimeAxis | None = None,
                x_label: str | None = None):
    """A Bokeh figure for a time track: stretches to the page width, shared time axis.

    Parameters
    ----------
    height : int
        Height [px].
    y_label : str
        Axis label (drillfric's text only; see the module docstring).
    x_range : bokeh Range, optional
        Shared with the figures above (zooming one zooms all).
    axis : TimeAxis, optional
        Clock time (UTC), log hours or log seconds (default) on the axis.
    """
    from bokeh.plotting import figure

    axis = axis or TimeAxis()
    kw = {"x_range": x_range} if x_range is not None else {}
    fig = figure(height=height, sizing_mode="stretch_width", min_width=MIN_WIDTH_PX,
                 tools=TIME_TOOLS, active_scroll="xwheel_zoom", active_drag="xpan",
                 x_axis_type="datetime" if axis.clock else "linear", toolbar_location="right",
                 **kw)
    fig.yaxis.axis_label = y_label
    if x_label is not None:
        fig.xaxis.axis_label = x_label
    fig.min_border_left = 70  # aligned y axes in a stack of tracks
    fig.yaxis.axis_label_text_font_size = "11px"
    fig.xaxis.visible = x_label is not None
    fig.grid.grid_line_color = "#e5e5e5"
    axis.style_bokeh(fig)
    return fig


def float32(values) -> np.ndarray:
    """Values as float32 (half the bytes of float64 in the page; 7 digits are plenty)."""
    return np.asarray(values, dtype=np.float32)


def time_values(time_s, origin: pd.Timestamp | TimeAxis | None) -> np.ndarray:
    """Log time [s] as plotted on ``origin``'s axis (:func:`time_axis`)."""
    return time_axis(origin).values(time_s)


def time_label(origin: pd.Timestamp | TimeAxis | None) -> str:
    """Axis label of log time on ``origin``'s axis (:func:`time_axis`)."""
    return time_axis(origin).label
