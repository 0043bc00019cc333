"""What a fleet's worker runs: one well (:class:`WellTask` in, a small record out).

:func:`process_well` is the unit of work :mod:`drillfric.fleet.run` hands to Dask (or runs
in-process): it opens the well on the worker, claims its output directory where the name is
resolved there, and runs :func:`drillfric.api.run`, which writes OUT/NAME atomically.
"""

from __future__ import annotations

import hashlib
import os
import socket
import sys
import time
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from drillfric import __version__
from drillfric.errors import DrillfricError, InputError
from drillfric.io.results import jsonable, name_key


@dataclass(frozen=True)
class WellTask:
    """What a worker receives: plain, picklable, absolute paths.

    ``name`` is None when the well's name may be stored inside its data file: the worker
    then resolves it and claims its output directory, refusing the names in ``taken``
    (other wells of the fleet) and any name another worker of this run claimed first
    (``OUT/.claim-RUN-…`` files, made with O_EXCL; ``run`` is the run's token).
    """

    name: str | None
    data: str
    config: str | None
    survey: str | None
    out_root: str
    overrides: dict
    rate_hz: float | None = None
    pdf: bool = False
    report: bool = True
    taken: frozenset = frozenset()
    run: str = ""
    resume: bool = True
    string: str | None = None


def process_well(task: WellTask) -> dict:
    """Run one well on a worker and return its small result record (never raises).

    The worker opens the well itself (the fleet's parent never opens a data file) and
    writes OUT/NAME (atomically). The record carries the status, the message of a failure,
    the well's name and output directory name, the files it read, the summary, timings and
    where it ran.
    """
    from drillfric.api import run as run_well
    from drillfric.io.well import open_well

    _one_kernel_thread()
    started = now_utc()
    t0 = time.perf_counter()
    record = {"status": "failed", "message": "", "summary": None, "out_dir": None,
              "failed_segments": 0}
    try:
        well = open_well(task.data, config=task.config, survey=task.survey,
                         overrides=task.overrides, name=task.name, string=task.string)
        record.update(well=well.name, dir_name=well.dir_name,
                      inputs={role: str(p.resolve()) for role, p in well.files.inputs.items()})
        if task.name is None:
            _claim(task, well.dir_name)
        result = run_well(well, task.out_root, rate_hz=task.rate_hz, pdf=task.pdf,
                          report=task.report, resume=task.resume)
        record.update(status="ok", summary=jsonable(result.summary),
                      out_dir=str(result.out_dir), failed_segments=result.failed)
    except DrillfricError as exc:
        record["message"] = exc.message
    except Exception as exc:  # noqa: BLE001 — one bad well must not spoil the night
        record["message"] = f"internal error: {type(exc).__name__}: {exc}"
    record.update(started_utc=started, finished_utc=now_utc(),
                  task_s=time.perf_counter() - t0, worker=f"{socket.gethostname()}:"
                  f"{os.getpid()}", worker_version=__version__)
    return record


def _claim(task: WellTask, dir_name: str) -> None:
    """Claim OUT/``dir_name`` for a well whose name was resolved on this worker."""
    key = name_key(dir_name)
    digest = hashlib.sha256(key.encode()).hexdigest()[:20]
    claim = Path(task.out_root) / f".claim-{task.run}-{digest}"
    try:
        if key in task.taken:
            raise FileExistsError
        Path(task.out_root).mkdir(parents=True, exist_ok=True)
        os.close(os.open(claim, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        raise InputError(f"another well of this fleet writes OUT/{dir_name}: one well's "
                         "results would be lost", file=task.data,
                         fix="give each well its own [well] name (or 'well' column in a "
                             "manifest)") from None


def _one_kernel_thread() -> None:
    """On a Dask worker (one task per core) the compiled kernels run on this thread only:
    numba's parallel observer members (docs/performance.md) would oversubscribe the cores.
    A process that has not imported distributed is no Dask worker (the check then costs
    nothing: importing distributed takes 0.2 s, docs/performance.md)."""
    if "distributed" not in sys.modules:
        return
    try:
        from distributed import get_worker

        get_worker()
    except (ImportError, ValueError):
        return
    import numba

    numba.set_num_threads(1)


def now_utc() -> str:
    """The time now, UTC, to the second (ISO 8601)."""
    return datetime.now(UTC).isoformat(timespec="seconds")
