"""The PDF report: matplotlib's PdfPages alone (no system library), one page per section."""

from __future__ import annotations

import os
from pathlib import Path

from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure

from .figures import table_page
from .render import quiet_glyphs

#: Rows of the diagnostics table per landscape page.
TABLE_ROWS_PER_PAGE = 28
#: Longest message shown in a PDF table cell [characters] (report.html has them whole).
_MESSAGE_CHARS = 70


def table_pages(title: str, columns: list[str], rows: list[list[str]]) -> list[Figure]:
    """The diagnostics table split over landscape pages of :data:`TABLE_ROWS_PER_PAGE` rows."""
    cut = [[c if len(c) <= _MESSAGE_CHARS else c[:_MESSAGE_CHARS - 1] + "…" for c in row]
           for row in rows]
    chunks = [cut[i:i + TABLE_ROWS_PER_PAGE] for i in range(0, len(cut), TABLE_ROWS_PER_PAGE)]
    return [table_page(title + (f" ({n + 1}/{len(chunks)})" if len(chunks) > 1 else ""),
                       columns, chunk) for n, chunk in enumerate(chunks or [[]])]


def write_pdf(path: Path, pages: list[tuple[str, Figure]], *, title: str) -> Path:
    """Write ``pages`` (``(title, figure)``, in order) to ``path``, atomically.

    Figures without a title of their own get ``title`` as their suptitle, so that every page
    says what it is (and its text can be found in the PDF).
    """
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with PdfPages(tmp, metadata={"Title": title, "Creator": "drillfric"}) as pdf:
        for page_title, fig in pages:
            if page_title:
                fig.suptitle(page_title, fontsize=13, weight="bold").set_parse_math(False)
            with quiet_glyphs():
                pdf.savefig(fig)
    os.replace(tmp, path)
    return path
