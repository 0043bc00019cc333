"""The PDF report: matplotlib's PdfPages alone (no system library), every page A4 landscape.

Tables are drawn here rather than with ``Axes.table``: their cells wrap to the column width
(instead of the font shrinking until a wide table fits), rows grow to the lines they need,
and a table continues on the next page with its header repeated; a row may carry a note
across the full width (a diagnostics message), wrapped and never cut, and a cell too long
for a page's row continues there. Nothing is cut: text wraps. Every page carries
the well's name and "page n of N" in its footer, below every axis and its tick labels
(:func:`clear_footer`).
"""

from __future__ import annotations

import textwrap
from pathlib import Path

from matplotlib.figure import Figure

from drillfric.io.atomic import replacing

from .render import quiet_glyphs

#: Every page: A4 landscape [in].
PAGE_IN = (11.69, 8.27)
#: Font size of table text [pt] (readable in print; the old tables shrank to ~4 pt).
TABLE_FONT_PT = 7.5
#: Longest cell drawn in its row [lines]; the rest of a longer cell follows under the row,
#: across the full width (a row is never taller than a page, and nothing is cut).
MAX_CELL_LINES = 14
_MARGIN_IN = 0.45
_TOP_IN = 0.85      # room for the page title
_BOTTOM_IN = 0.55   # room for the footer
#: Baseline of the footer [in from the bottom of the page].
FOOTER_IN = 0.22
#: Nothing but the footer below this [in from the bottom of the page].
FOOTER_CLEAR_IN = 0.45
#: Average width of a character of the sans-serif font, in font sizes.
_CHAR_EM = 0.56


def blank_page(title: str) -> Figure:
    """An empty A4 landscape page with a title."""
    fig = Figure(figsize=PAGE_IN)
    fig.text(_MARGIN_IN / PAGE_IN[0], 1 - 0.45 / PAGE_IN[1], title, fontsize=14,
             weight="bold", va="center", parse_math=False)
    return fig


def wrap_cell(text: str, chars: int) -> list[str]:
    """``text`` wrapped to ``chars`` characters a line (long words broken), every line."""
    lines = []
    for part in str(text).splitlines() or [""]:
        lines += textwrap.wrap(part, max(chars, 1), break_long_words=True,
                               break_on_hyphens=False) or [""]
    return lines


def _overflow(cells: list[list[str]], row: list[str], heading: list[str]
              ) -> tuple[list[list[str]], str]:
    """A row's wrapped cells cut to :data:`MAX_CELL_LINES` lines, and the rest of each cut
    cell as a note ("heading, continued: …"; a table without headings names the row by its
    first cell) to print under the row."""
    kept, rest = [], []
    for lines, name in zip(cells, heading, strict=True):
        if len(lines) <= MAX_CELL_LINES:
            kept.append(lines)
            continue
        kept.append([*lines[:MAX_CELL_LINES - 1], "(continued below)"])
        rest.append(f"{name or row[0]}, continued: " + " ".join(lines[MAX_CELL_LINES - 1:]))
    return kept, "\n".join(rest)


def column_chars(columns: list[str], rows: list[list[str]], budget: int) -> list[float]:
    """Column widths [characters] that fit ``budget`` characters a line.

    Each column first gets its longest word (so no word is broken, when the budget allows),
    then the remaining room goes to the columns whose text is longer than that, in
    proportion to what they lack (capped at 60 characters a column).
    """
    cells = [[str(h), *(str(r[i]) for r in rows)] for i, h in enumerate(columns)]
    need = [max(len(w) for c in col for w in (c.split() or [""])) + 1 for col in cells]
    want = [min(max(len(c) for c in col), 60) + 1 for col in cells]
    room = budget - sum(need)
    if room <= 0:
        return [float(n) for n in need]
    lack = [max(w - n, 0) for w, n in zip(want, need, strict=True)]
    share = room / max(sum(lack), 1)
    return [n + min(share, 1.0) * gap for n, gap in zip(need, lack, strict=True)]


#: Most rows of one table in the PDF (about 20 pages of a diagnostics table).
MAX_TABLE_ROWS = 500


def table_pages(title: str, columns: list[str], rows: list[list[str]],
                widths: list[float] | None = None, *, font_pt: float = TABLE_FONT_PT,
                notes: list[str] | None = None, lead: str = "") -> list[Figure]:
    """A table over as many A4 landscape pages as it needs, cells wrapped to their column.

    Parameters
    ----------
    title : str
        Page title ("(continued)" is added on the following pages).
    columns : list of str
        Headings (wrapped too).
    rows : list of list of str
        Cell texts.
    widths : list of float, optional
        Relative column widths (default: :func:`column_chars` — no word is broken).
    font_pt : float
        Font size [pt].
    notes : list of str, optional
        A note under each row, across the full width, wrapped and never cut (it carries on
        to the next page when it must); "" for none.
    lead : str
        A paragraph above the table on its first page (wrapped).

    At most :data:`MAX_TABLE_ROWS` rows are drawn (a summary.json of a million rows asked
    for gigabytes of pages); a last row says how many more there are and where they are.
    """
    if len(rows) > MAX_TABLE_ROWS:
        more = len(rows) - MAX_TABLE_ROWS
        rows = [*rows[:MAX_TABLE_ROWS],
                [f"… and {more} more rows (summary.json and report.html hold them all)",
                 *[""] * (len(columns) - 1)]]
        notes = None if notes is None else [*notes[:MAX_TABLE_ROWS], ""]
    width_in = PAGE_IN[0] - 2 * _MARGIN_IN
    if widths is None:
        widths = column_chars(columns, rows, int(width_in * 72.0 / (_CHAR_EM * font_pt)))
    total = float(sum(widths))
    col_in = [width_in * w / total for w in widths]
    chars = [int(w * 72.0 / (_CHAR_EM * font_pt)) - 1 for w in col_in]
    line_in = 1.22 * font_pt / 72.0
    head = [wrap_cell(h, c) for h, c in zip(columns, chars, strict=True)]
    cut = [_overflow([wrap_cell(v, c) for v, c in zip(r, chars, strict=True)], r, columns)
           for r in rows]
    body = [cells for cells, _ in cut]
    full = int(width_in * 72.0 / (_CHAR_EM * font_pt)) - 4
    wrapped = [wrap_lines("\n".join(filter(None, (rest, note))), full)
               for (_, rest), note in zip(cut, notes or [""] * len(rows), strict=True)]
    pages: list[Figure] = []
    state = {"y": 0.0}

    def new_page() -> Figure:
        fig = blank_page(title + (" (continued)" if pages else ""))
        state["y"] = PAGE_IN[1] - _TOP_IN
        if lead and not pages:
            lines = wrap_lines(lead, full)
            fig.text(_MARGIN_IN / PAGE_IN[0], state["y"] / PAGE_IN[1], "\n".join(lines),
                     fontsize=font_pt, va="top", parse_math=False)
            state["y"] -= len(lines) * line_in + 0.12
        pages.append(fig)
        if any(columns):  # a table of label–value lines has no heading row
            state["y"] = _draw_row(fig, head, col_in, state["y"], line_in, font_pt,
                                   header=True)
        return fig

    fig = None
    for cells, note in zip(body, wrapped, strict=True):
        height = max(len(c) for c in cells) * line_in + 0.06
        need = height + min(len(note), 2) * 0.9 * line_in  # a row keeps a start of its note
        if fig is None or state["y"] - need < _BOTTOM_IN:
            fig = new_page()
        state["y"] = _draw_row(fig, cells, col_in, state["y"], line_in, font_pt)
        while note:
            room = int((state["y"] - _BOTTOM_IN - 0.04) // (0.9 * line_in))
            if room < 1:
                fig = new_page()
                continue
            part, note = note[:room], note[room:]
            fig.text((_MARGIN_IN + 0.3) / PAGE_IN[0], (state["y"] - 0.02) / PAGE_IN[1],
                     "\n".join(part), fontsize=font_pt - 0.5, va="top", ha="left",
                     linespacing=1.0, color="#333333", parse_math=False)
            state["y"] -= len(part) * 0.9 * line_in + 0.06
            fig.add_artist(_hline(fig, _MARGIN_IN / PAGE_IN[0],
                                  (_MARGIN_IN + sum(col_in)) / PAGE_IN[0],
                                  state["y"] / PAGE_IN[1]))
    if fig is None:
        fig = new_page()
        fig.text(_MARGIN_IN / PAGE_IN[0], state["y"] / PAGE_IN[1] - 0.02, "(none)",
                 fontsize=font_pt, parse_math=False)
    return pages


def wrap_lines(text: str, chars: int) -> list[str]:
    """``text`` wrapped to ``chars`` a line, every line kept (nothing is cut: the PDF
    wraps, it never clips); [] for blank text."""
    return [w for part in str(text).splitlines() for w in
            (textwrap.wrap(part, max(chars, 1), break_on_hyphens=False) or [""])] \
        if str(text).strip() else []


def line_chars(width_in: float, font_pt: float, bold: bool = False) -> int:
    """How many characters of the sans-serif font fit on ``width_in`` at ``font_pt``
    (bold about 10 % wider), with a little room to spare."""
    em = _CHAR_EM * (1.1 if bold else 1.0)
    return int(width_in * 72.0 / (em * font_pt)) - 2


def _draw_row(fig: Figure, cells: list[list[str]], col_in: list[float], y_in: float,
              line_in: float, font_pt: float, header: bool = False) -> float:
    """Draw one row with its top at ``y_in`` [in from the bottom]; returns its bottom."""
    height = max(len(c) for c in cells) * line_in + 0.06
    w, h = PAGE_IN
    if header:
        fig.patches.append(_rect(fig, _MARGIN_IN / w, (y_in - height) / h,
                                 sum(col_in) / w, height / h))
    x = _MARGIN_IN
    for lines, width in zip(cells, col_in, strict=True):
        fig.text((x + 0.04) / w, (y_in - 0.03) / h, "\n".join(lines), fontsize=font_pt,
                 va="top", ha="left", linespacing=1.05, parse_math=False,
                 weight="bold" if header else "normal")
        x += width
    fig.add_artist(_hline(fig, _MARGIN_IN / w, (_MARGIN_IN + sum(col_in)) / w,
                          (y_in - height) / h))
    return y_in - height


def _rect(fig: Figure, x: float, y: float, width: float, height: float):
    from matplotlib.patches import Rectangle

    return Rectangle((x, y), width, height, transform=fig.transFigure, facecolor="#eef2f7",
                     edgecolor="none", figure=fig)


def _hline(fig: Figure, x0: float, x1: float, y: float):
    from matplotlib.lines import Line2D

    return Line2D([x0, x1], [y, y], transform=fig.transFigure, color="#c8c8c8",
                  linewidth=0.5)


def write_pdf(path: Path, pages: list[tuple[str, Figure]], *, title: str,
              footer: str = "") -> Path:
    """Write ``pages`` (``(title, figure)``, in order) to ``path``, atomically.

    Every page is made A4 landscape; figures with a title get it as their suptitle, so
    that every page says what it is (and its text can be found in the PDF). The footer
    holds ``footer`` (left) and "page n of N" (right).
    """
    from matplotlib.backends.backend_pdf import PdfPages  # ~0.2 s: only when a PDF is asked

    path = Path(path)
    count = len(pages)
    with replacing(path) as tmp, PdfPages(tmp, metadata={"Title": title,
                                                          "Creator": "drillfric"}) as pdf:
        for number, (page_title, fig) in enumerate(pages, start=1):
            fig.set_size_inches(*PAGE_IN)
            if page_title:
                fig.suptitle(page_title, fontsize=13, weight="bold").set_parse_math(False)
            with quiet_glyphs():
                clear_footer(fig)
            fig.text(_MARGIN_IN / PAGE_IN[0], FOOTER_IN / PAGE_IN[1], footer, fontsize=7,
                     color="#555555", parse_math=False)
            fig.text(1 - _MARGIN_IN / PAGE_IN[0], FOOTER_IN / PAGE_IN[1],
                     f"page {number} of {count}", fontsize=7, color="#555555", ha="right")
            with quiet_glyphs():
                pdf.savefig(fig)
    return path


def clear_footer(fig: Figure) -> None:
    """Move a page's axes up until nothing of them — tick labels, axis labels, legends —
    reaches below :data:`FOOTER_CLEAR_IN` (the footer's band): the axes are squeezed
    towards their top, which stays where it is (a constrained layout is given a rectangle
    above the band instead)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not fig.axes:
        return
    engine = fig.get_layout_engine()
    if engine is not None and hasattr(engine, "set") and "rect" in engine.get():
        low = FOOTER_CLEAR_IN / PAGE_IN[1]  # a constrained layout keeps out of the band
        engine.set(rect=(0.0, low, 1.0, 1.0 - low))
        return
    if fig.canvas is None or not hasattr(fig.canvas, "get_renderer"):
        FigureCanvasAgg(fig)
    renderer = fig.canvas.get_renderer()
    dpi = fig.dpi
    boxes = [ax.get_tightbbox(renderer) for ax in fig.axes if ax.get_visible()]
    boxes += [leg.get_window_extent(renderer) for leg in fig.legends]
    bottom_in = min(b.y0 for b in boxes if b is not None) / dpi
    if bottom_in >= FOOTER_CLEAR_IN:
        return
    top = max(ax.get_position().y1 for ax in fig.axes)
    low = min(ax.get_position().y0 for ax in fig.axes)
    lift = (FOOTER_CLEAR_IN - bottom_in) / PAGE_IN[1]
    scale = (top - low - lift) / (top - low)
    for ax in fig.axes:
        box = ax.get_position()
        y0 = top - (top - box.y0) * scale
        ax.set_position([box.x0, y0, box.width, box.height * scale])
    for legend in fig.legends:  # figure legends at the bottom move up with the axes
        anchor = legend.get_bbox_to_anchor().transformed(fig.transFigure.inverted())
        legend.set_bbox_to_anchor((anchor.x0, anchor.y0 + lift, anchor.width,
                                   anchor.height), transform=fig.transFigure)
