"""``drillfric run`` for one well: which run a well's data call for, and the runs.

- :mod:`.time_log` — a time log, stand by stand: segments, the estimation chain, pooling;
- :mod:`.depth_log` — a depth-indexed log: the static friction log by depth window;
- :mod:`.finish` — what both end with: the summary, the result files, the report;
- :mod:`.segment_output` — a time-log segment's record and output rows;
- :mod:`.preview` — what a run will do with a time log, told without estimating
  (``drillfric inspect``).

The report is written through the writer the caller passes (``report``): this layer
computes and writes results and does not import :mod:`drillfric.report` (the layer
contract in pyproject.toml).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from drillfric.io.well import CHUNK_ROWS, Well
from drillfric.result import RunProgress, WellResult

if TYPE_CHECKING:  # the run's modules load when a run starts (inspect imports .preview)
    from .finish import ReportWriter


def run_well(well: Well, out_root=None, *, rate_hz: float | None = None,
             report: ReportWriter | None = None,
             progress: Callable[[RunProgress], None] | None = None,
             chunk_rows: int = CHUNK_ROWS, resume: bool = False) -> WellResult:
    """Run the whole estimation on one well; write ``out_root/NAME`` when ``out_root`` is given.

    Parameters
    ----------
    well : Well
        An opened well (:func:`drillfric.io.well.open_well`).
    out_root : str or Path, optional
        Output directory; results go to ``out_root/NAME`` atomically. None: results in
        memory only (nothing written).
    rate_hz : float, optional
        Resample the input to this rate before estimation; a rate above the data's own is
        not used (:func:`~drillfric.runner.estimator.effective_rate`: a warning in
        ``summary["warnings"]``).
    report : callable, optional
        Writes the report into the result directory before it is committed (only with
        ``out_root``); None: no report.
    progress : callable, optional
        Called with a :class:`~drillfric.result.RunProgress` as rows are read and segments
        finish.
    chunk_rows : int
        Rows read per chunk.
    resume : bool
        Continue from the state of ``out_root/NAME`` when the data only grew since (a time
        log in a delimited text file): only the new rows are estimated (docs/fleet.md);
        otherwise the well is run from its start and summary.json ``resumed`` says why.

    Raises
    ------
    DrillfricError
        Unreadable or meaningless input, or results that cannot be written (nothing is
        written then).
    """
    if well.depth_indexed:  # no time series: a static friction log by depth
        from .depth_log import run_depth_log

        return run_depth_log(well, out_root, rate_hz=rate_hz, report=report,
                             progress=progress, chunk_rows=chunk_rows)
    from .time_log import run_time_log

    return run_time_log(well, out_root, rate_hz=rate_hz, report=report, progress=progress,
                        chunk_rows=chunk_rows, resume=resume)
