"""A time log, stand by stand: the whole file through the incremental engine.

:func:`run_time_log` takes a well opened once (:func:`drillfric.io.well.open_well`) and feeds
its data, chunk by chunk, to an :class:`~drillfric.runner.engine.Engine`, which

1. **checks** the log as it goes (:class:`~drillfric.io.logcheck.LogCheck`) and cuts it into
   rotating segments with their rows (:class:`~drillfric.segmentation.SegmentStream`);
2. **estimates** each segment as it closes with the chain of
   :mod:`drillfric.estimation.chain`, warm-starting from the previous one
   (:class:`~drillfric.runner.estimator.SegmentEstimator`);
3. **collects** each segment's record and output rows into a sink — in memory, or appended
   to the result files as it goes (bounded memory);
4. **revises, pools and finishes** (:mod:`drillfric.runner.finish`): the summary, the result
   files of docs/outputs.md written atomically into ``OUT/NAME`` with the engine's state
   (``OUT/NAME/state/``, so that a later run continues: docs/fleet.md), then the report.

Library code: no printing; progress goes through a callback.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from drillfric.io.seal import seal
from drillfric.io.well import CHUNK_ROWS, Well
from drillfric.result import RunProgress, WellResult

from .engine import Engine
from .finish import DirectorySink, ReportWriter, Sink, deliver
from .resume import mark, resumable, tail, unread
from .resume import resume as continued

#: Folder of a result directory holding the engine's state (docs/outputs.md).
STATE_DIR = "state"


def run_time_log(well: Well, out_root=None, *, rate_hz: float | None = None,
                 report: ReportWriter | None = None,
                 progress: Callable[[RunProgress], None] | None = None,
                 chunk_rows: int = CHUNK_ROWS, resume: bool = False) -> WellResult:
    """:func:`drillfric.runner.run_well` for a time log: steps 1–4 of the module's list,
    into memory or ``out_root/NAME`` (parameters as there)."""
    def run(sink: Sink) -> WellResult:
        total = well.source.rows if well.source.rows is not None else \
            _count_rows(well.files.data)
        kw = dict(rate_hz=rate_hz, progress=progress, total_rows=total)
        engine, why = None, "not asked to continue"
        if resume and isinstance(sink, DirectorySink):
            engine, why = continued(well, Path(out_root) / well.dir_name, sink, **kw)
        engine = engine or Engine(well, sink=sink, **kw)
        if engine.source is None:
            engine.resumed = {"from_row": 0, "reason": why} if resume else None
        for raw in _rows(well, engine, chunk_rows):
            engine.feed_raw(raw)
        ending = tail(well, engine.source, chunk_rows) if resumable(well) else ()
        return finish_engine(engine, sink, ending)

    return deliver(well, out_root, run, report)


def _rows(well: Well, engine: Engine, chunk_rows: int):
    """The source rows the engine has not read — from its ``source`` mark to where the data
    ends now (the new mark) — for data read by position, else the whole source."""
    if not resumable(well):
        return well.source.chunks(chunk_rows)
    before, engine.source = engine.source, mark(well)
    return unread(well, before, engine.source, chunk_rows)


def finish_engine(engine: Engine, sink: Sink, tail=()) -> WellResult:
    """Close ``engine`` into ``sink`` (``tail`` as :meth:`Engine.close`); a result directory
    keeps the state to continue from."""
    result = engine.close(tail)
    if isinstance(sink, DirectorySink):
        engine.save(sink.folder / STATE_DIR)
        seal(sink.folder / STATE_DIR)  # over the state and the result files it carries over
    return result


def _count_rows(data_path: Path) -> int | None:
    """Row count for the progress bar: Parquet metadata, else a fast line count."""
    suffix = data_path.suffix.lower()
    try:
        if suffix in (".parquet", ".pq"):
            import pyarrow.parquet as pq

            return pq.ParquetFile(data_path).metadata.num_rows
        if suffix in (".csv", ".txt", ".tsv"):
            count = 0
            with open(data_path, "rb") as fh:
                while block := fh.read(1 << 22):
                    count += block.count(b"\n") or block.count(b"\r")
            return count
    except OSError:
        return None
    return None
