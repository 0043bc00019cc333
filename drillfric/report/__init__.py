"""HTML and PDF reports of result directories (issue 7).

:func:`write_well_report` reads only the files of one result directory (so
``drillfric report RESULT_DIR`` can rebuild it); :func:`write_fleet_report` writes the
morning overview of many wells. Figures: :mod:`drillfric.report.figures`.
"""

from __future__ import annotations

from .fleet import write_fleet_report
from .well import MAX_SEGMENT_FIGURES, write_well_report

__all__ = ["MAX_SEGMENT_FIGURES", "write_fleet_report", "write_well_report"]
