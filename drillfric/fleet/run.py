"""``drillfric fleet``: many wells, incremental and fault-isolated (issue 8, docs/fleet.md).

The unit of work is a well: :func:`drillfric.fleet.task.process_well` runs
:func:`drillfric.runner.run_well` on a worker, which writes OUT/NAME itself (temporary
directory + rename, so a well directory is either complete or absent). The client only
prepares tasks (input hashes, effective configuration hash), collects small result records
and keeps ``OUT/manifest.json``; the wells come from
:func:`drillfric.fleet.discovery.discover` (a folder or a manifest).

Execution: one code path through :class:`dask.distributed.Client` — a ``LocalCluster`` of
worker processes by default, an existing cluster with ``scheduler``; ``workers=1`` without a
scheduler runs in this process (nothing to start). A task whose worker died is rescheduled
by Dask and, if Dask gives up (``KilledWorker``), resubmitted by the client up to
:data:`MAX_ATTEMPTS` times. With a remote scheduler the inputs and OUT must be on storage
that every worker and the client see under the same absolute paths.

Library code: no printing, no signal handlers (the CLI turns SIGTERM into
``KeyboardInterrupt``; :func:`run_many` then records what finished and re-raises).
"""

from __future__ import annotations

import hashlib
import json
import math
import time
import uuid
import warnings
from collections.abc import Callable, Iterator
from contextlib import ExitStack, closing, contextmanager, nullcontext
from dataclasses import dataclass, field, replace
from pathlib import Path

import pandas as pd

from drillfric import __version__
from drillfric.errors import DrillfricError, InputError, OutputError
from drillfric.fleet import overnight
from drillfric.fleet.discovery import WellSpec
from drillfric.fleet.task import WellTask, now_utc, process_well
from drillfric.io.atomic import own_file, refuse_link, replacing
from drillfric.io.locks import Busy, lock_file
from drillfric.io.results import (
    DISTINCT_FIX,
    collisions,
    file_sha256,
    jsonable,
    mark_stale,
    missing_dirs,
    name_key,
    read_json,
    remove_empty,
    remove_stale,
    write_json,
)
from drillfric.io.text import plural
from drillfric.result import (
    FLEET_SEGMENT_EXTRA,
    FLEET_WELL_COLUMNS,
    SEGMENT_FIELDS,
    segment_is_apparent,
    well_friction_columns,
)
from drillfric.vocabulary import WellStatus

MANIFEST = "manifest.json"
SUMMARY = "fleet_summary.parquet"
REPORT = "fleet.html"
#: Attempts of a well whose worker died (Dask's own rescheduling comes on top).
MAX_ATTEMPTS = 3
#: Seconds between two saves of the manifest while wells complete (always saved at the end).
SAVE_EVERY_S = 2.0
#: Seconds to wait for a ``--scheduler`` to answer.
CONNECT_TIMEOUT_S = 20
_LOCK = ".fleet.lock"


# --------------------------------------------------------------------------- preparation
@dataclass(frozen=True)
class _Job:
    """A well after preparation: its task and fingerprint, or why it cannot run.

    ``named``: the name is known before the well is opened (else it is the data file's
    stem until the worker reports the name stored inside the file).
    """

    index: int
    name: str
    dir_name: str
    task: WellTask | None
    fingerprint: dict
    error: str = ""
    named: bool = True


def _distinct(jobs: list[_Job], wells: list[WellSpec], *, refuse: bool) -> list[_Job]:
    """The jobs, a well that would write the ``OUT/NAME`` of an earlier one failed with a
    line naming both, the others run: one such pair had stopped the whole fleet. A well
    whose name is another's under another spelling (``well``, ``WELL``) fails alone; two
    wells of one name (``A.csv``, ``A.parquet``) both fail, since manifest.json keeps one
    record a name and neither is the well's. With ``refuse`` (``drillfric run``, whose
    wells the user named one by one) any clash is refused before anything is written.

    Raises
    ------
    InputError
        ``refuse`` and two wells would write one directory.
    """
    runnable = [(k, j) for k, j in enumerate(jobs) if j.task is not None and j.named]
    clash = collisions([(j.dir_name, f"well '{j.name}' ({wells[k].data})")
                        for k, j in runnable])
    jobs = list(jobs)
    for i, (first, line) in clash.items():
        if refuse:
            raise InputError(line, fix=DISTINCT_FIX)
        k, job = runnable[i]
        failed = [k]
        if job.name == runnable[first][1].name or job.dir_name == runnable[first][1].dir_name:
            failed.append(runnable[first][0])
        for f in failed:
            jobs[f] = replace(jobs[f], task=None, error=f"{line} — fix: {DISTINCT_FIX}")
    return jobs


def _open_job(index: int, spec: WellSpec, out_root: Path, overrides: dict,
              options: dict) -> _Job:
    """Find the well's files and name from paths and sidecars and make its task; no data
    file is opened here (a hostile one could stall or crash the fleet), the worker opens it."""
    from drillfric.io.text import printable
    from drillfric.io.well import find_well, safe_name

    fallback = printable(spec.name or spec.data.stem, 4096)
    try:
        files, name = find_well(spec.data, config=spec.config, survey=spec.survey,
                                name=spec.name, string=spec.string)
        dir_name = fallback if name is None else safe_name(name, files.config or files.data)
    except DrillfricError as exc:
        return _Job(index, fallback, fallback, None, {}, exc.message)
    except OSError as exc:
        return _Job(index, fallback, fallback, None, {}, _os_line(exc, spec.data))
    # the configuration files are inputs (hashed); defaults change with the version only
    effective = json.dumps(jsonable({"overrides": overrides, "options": options}),
                           sort_keys=True, default=str)
    fingerprint = {"inputs": files.inputs,
                   "drillfric_version": __version__,
                   "config_sha256": hashlib.sha256(effective.encode()).hexdigest()}
    task = WellTask(name, str(Path(spec.data).resolve()), _abs(spec.config),
                    _abs(spec.survey), str(out_root.resolve()), dict(overrides),
                    options.get("rate_hz"), options.get("pdf", False),
                    options.get("report", True), string=_abs(spec.string))
    return _Job(index, name or fallback, dir_name, task, fingerprint, named=name is not None)


def _hashed(job: _Job, known: dict) -> _Job:
    """The job with its input files stamped and hashed (hashes of files unchanged in size
    and mtime since the manifest recorded them are reused; ``known`` gains the new ones)."""
    if job.task is None:
        return job
    try:
        inputs = {role: _file_stamp(p, known) for role, p in job.fingerprint["inputs"].items()}
    except DrillfricError as exc:
        return replace(job, task=None, error=exc.message)
    except OSError as exc:
        return replace(job, task=None, error=_os_line(exc, job.task.data))
    return replace(job, fingerprint=job.fingerprint | {"inputs": inputs})


def _os_line(exc: OSError, path) -> str:
    """One line for an OSError that names the file and the problem even when the error
    carries neither (a FIFO among the wells gave "None: cannot read (None)", issue 30)."""
    from drillfric.io.text import one_line, printable

    where = printable(str(exc.filename if exc.filename is not None else path), 4096)
    problem = exc.strerror or str(exc) or type(exc).__name__
    return one_line(f"{where}: cannot read ({problem})")


def _abs(path) -> str | None:
    return None if path is None else str(Path(path).resolve())


def _file_stamp(path: Path, known: dict) -> dict:
    """Size, modification time and SHA-256 of an input file (hashed again only when size or
    time changed). InputError for anything but a regular file, naming it: a FIFO would hang
    the hash."""
    from drillfric.files import require_file

    require_file(Path(path), "input file", fix="keep only the wells' files in the folder, "
                 "or list the wells in a manifest")
    stat = path.stat()
    key = str(path.resolve())
    stamp = {"path": key, "size": stat.st_size, "mtime_ns": stat.st_mtime_ns}
    old = known.get(key)
    if old and old.get("size") == stat.st_size and old.get("mtime_ns") == stat.st_mtime_ns:
        return stamp | {"sha256": old["sha256"]}
    known[key] = stamp = stamp | {"sha256": file_sha256(path)}
    return stamp


def _same(fingerprint: dict, entry: dict | None, known: dict) -> bool:
    """True when ``entry`` (manifest) was an ok run of the same inputs, config, version:
    the files found now are the ones recorded, and every file the worker read (some are
    only found inside a data file) is unchanged."""
    if not entry or entry.get("status") != WellStatus.OK:
        return False
    outputs = entry.get("outputs", {}).get("summary")
    if (outputs is None or not Path(outputs).is_file()
            or _summary_sha256(Path(outputs)) != entry.get("summary_sha256")
            or not _plausible_summary(Path(outputs))
            or fingerprint["config_sha256"] != entry.get("config_sha256")
            or fingerprint["drillfric_version"] != entry.get("drillfric_version")):
        return False
    recorded = entry.get("inputs", {})
    if any(recorded.get(role, {}).get("sha256") != f["sha256"]
           for role, f in fingerprint["inputs"].items()):
        return False
    extra = [f for role, f in recorded.items() if role not in fingerprint["inputs"]]
    near = [Path(f["path"]).parent for f in fingerprint["inputs"].values()]
    if not all(any(Path(f["path"]).is_relative_to(d) for d in near) for f in extra):
        return False  # a file away from the well's own: not one its worker read
    try:
        return all(_file_stamp(Path(f["path"]), known)["sha256"] == f["sha256"]
                   for f in extra)
    except (OSError, KeyError, TypeError):
        return False


def _summary_sha256(path: Path) -> str | None:
    """The digest of a well's summary.json as it is now (None: unreadable): one the fleet
    did not write (a manual ``run`` into OUT/NAME) differs from the manifest's."""
    try:
        return file_sha256(own_file(path))
    except (OSError, ValueError):
        return None


def _entry(manifest: _Manifest, job: _Job) -> tuple[str, dict | None]:
    """The manifest's name and entry of a job: by name, or — a name still to be read from
    the data file — the entry that read the same data files."""
    if job.named:
        return job.name, manifest.wells.get(job.name)

    def data(inputs: dict) -> set:
        return {f.get("path") for role, f in inputs.items() if role.split()[0] == "data"}

    mine = data(job.fingerprint["inputs"])
    for name, entry in manifest.wells.items():
        if isinstance(entry, dict) and data(entry.get("inputs", {})) == mine:
            return name, entry
    return job.name, None


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class WellOutcome:
    """One well of a fleet run.

    Attributes
    ----------
    well : str
    status : str
        ``"ok"`` (processed now), ``"skipped"`` (unchanged since an ok run) or ``"failed"``.
    message : str
        Why it failed (one line).
    result_dir : Path or None
    summary : dict or None
        summary.json of the well.
    failed_segments : int
    task_s : float
        Time inside the task (0 when skipped) [s].
    attempts : int
    stale_dir : Path or None
        A failed well's OUT/NAME holding an earlier run's results, marked stale.
    new_segments : int or None
        Segments new since the last night (None: the well failed).
    changes : tuple of str
        What changed since the last night (:func:`drillfric.fleet.overnight.changes`).
    first_run : bool
        Processed with no earlier night of this well in the manifest: nothing to compare.
    """

    well: str
    status: str
    message: str = ""
    result_dir: Path | None = None
    summary: dict | None = None
    failed_segments: int = 0
    task_s: float = 0.0
    attempts: int = 0
    stale_dir: Path | None = None
    new_segments: int | None = None
    changes: tuple[str, ...] = ()
    first_run: bool = False


@dataclass(frozen=True)
class FleetResult:
    """A fleet run: outcomes in input order and the fleet files written (None: not written,
    as for ``drillfric run`` on several workers)."""

    out_root: Path
    wells: tuple[WellOutcome, ...]
    wall_s: float
    manifest: Path | None
    summary: Path | None
    report: Path | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)

    def count(self, status: str) -> int:
        """Wells with this status."""
        return sum(w.status == status for w in self.wells)

    @property
    def failed_segments(self) -> int:
        """Failed segments over the wells that ran or were skipped."""
        return sum(w.failed_segments for w in self.wells)

    @property
    def nothing_estimated(self) -> tuple[str, ...]:
        """Wells that ran (or were unchanged) with not one segment estimated: every
        segment skipped, or none found."""
        return tuple(w.well for w in self.wells if w.status != WellStatus.FAILED and w.summary
                     and not (w.summary.get("counts") or {}).get("estimated"))


def _number_or_none(value) -> bool:
    return value is None or isinstance(value, int | float) and not isinstance(value, bool) \
        and math.isfinite(value)


def _sound_night(night) -> bool:
    """A history entry as :func:`drillfric.fleet.overnight.night` writes it."""
    return isinstance(night, dict) and isinstance(night.get("utc"), str) and \
        isinstance(night.get("segments"), int) and _number_or_none(night.get("mu_k"))


def _plausible_summary(path: Path) -> bool:
    """Whether an unchanged well's summary.json has the shape drillfric writes (the fleet
    republishes it: a crafted one with a matching digest in the manifest made internal
    errors, and published text as well_mu_k)."""
    try:
        summary = read_json(path)
    except InputError:
        return False
    segments, counts = summary.get("segments"), summary.get("counts")
    return (isinstance(segments, list) and all(isinstance(g, dict) for g in segments)
            and isinstance(counts, dict)
            and all(isinstance(v, int) for v in counts.values())
            and all(_number_or_none(summary.get(k))
                    for k in ("mu_k", "mu_s", "mu_s_lower_bound", "mu_k_uncertainty")))


def _sound(entry, out_root: Path | None) -> bool:
    """Whether a manifest entry has the shape drillfric writes, with its outputs in OUT/NAME
    (the manifest lies in OUT, where anyone may write: an entry naming files elsewhere would
    make the fleet hash them, hang on a FIFO there, or publish results that are not this
    well's as "unchanged")."""
    if not isinstance(entry, dict) or not isinstance(entry.get("status"), str):
        return False
    inputs, outputs = entry.get("inputs", {}), entry.get("outputs", {})
    history = entry.get("history", [])
    if not (isinstance(inputs, dict) and isinstance(outputs, dict) and
            isinstance(history, list) and all(_sound_night(h) for h in history)):
        return False
    if not all(isinstance(f, dict) and isinstance(f.get("path"), str) and
               isinstance(f.get("sha256"), str) for f in inputs.values()):
        return False
    if not outputs:
        return True
    folder = outputs.get("dir")
    if not isinstance(folder, str) or out_root is None or \
            Path(folder).resolve().parent != Path(out_root).resolve():
        return False
    return all(isinstance(v, str) and Path(v).parent == Path(folder)
               for k, v in outputs.items() if k != "dir")


class _Manifest:
    """OUT/manifest.json: one entry per well, saved atomically (throttled while running).

    Without ``out_root`` the manifest lives in memory only (``drillfric run``).
    """

    def __init__(self, out_root: Path | None):
        self.path = None if out_root is None else out_root / MANIFEST
        try:
            self.data = read_json(self.path) if self.path and self.path.exists() else {}
        except InputError:
            self.data = {}
        if not isinstance(self.data.get("wells"), dict):
            self.data = {"wells": {}}  # unreadable: every well runs again
        self.data["wells"] = {name: entry for name, entry in self.data["wells"].items()
                              if _sound(entry, out_root)}  # a bad entry: that well runs again
        self._saved = 0.0
        self.gone: tuple[str, ...] = ()  # wells of earlier nights not found this time

    @property
    def wells(self) -> dict:
        return self.data["wells"]

    def known_files(self) -> dict:
        """path → stamp of every input file recorded (to reuse hashes)."""
        return {f["path"]: f for e in self.wells.values()
                for f in e.get("inputs", {}).values() if "sha256" in f}

    def save(self, *, now: bool = True) -> None:
        if self.path is None or (not now and time.monotonic() - self._saved < SAVE_EVERY_S):
            return
        self.data.update(drillfric_version=__version__, updated_utc=now_utc())
        with replacing(self.path) as tmp:
            write_json(tmp, self.data)
        self._saved = time.monotonic()


# --------------------------------------------------------------------------- execution
def run_many(wells: list[WellSpec], out_root, *, workers: int, scheduler: str | None = None,
             force: bool = False, progress: Callable[[float], None] | None = None,
             overrides: dict | None = None, rate_hz: float | None = None,
             pdf: bool = False, report: bool = True, fleet_files: bool = True) -> FleetResult:
    """Process wells in parallel, skipping those unchanged since their last ok run.

    Parameters
    ----------
    wells : list of WellSpec
    out_root : str or Path
        OUT: well directories, manifest.json, fleet_summary.parquet, fleet.html.
    workers : int
        Local worker processes (ignored with ``scheduler``); with 1 (or one well to do)
        the wells run in this process.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:8786``); OUT and the inputs must be on
        storage shared with its workers.
    force : bool
        Redo every well.
    progress : callable, optional
        Called with 1 for every well finished or skipped.
    overrides : dict, optional
        ``{"table.key": value}`` for every well.
    rate_hz, pdf
        As for ``drillfric run``.
    report : bool
        Write each well's report (False: ``--no-report``; the fleet report is still written).
    fleet_files : bool
        Keep the fleet's bookkeeping in OUT: the lock, manifest.json (so unchanged wells
        are skipped next time), fleet_summary.parquet and fleet.html. False for
        ``drillfric run --workers N``: OUT then holds the wells' directories only.

    Raises
    ------
    DrillfricError
        OUT is locked by another fleet run or cannot be created.
    KeyboardInterrupt
        Re-raised after the manifest is saved (finished wells stay recorded).
    """
    t0 = time.perf_counter()
    out_root = Path(out_root)
    advance = progress or (lambda amount=1.0: None)
    options = {"rate_hz": rate_hz, "pdf": pdf, "report": report}
    jobs = [_open_job(i, s, out_root, overrides or {}, options) for i, s in enumerate(wells)]
    jobs = _distinct(jobs, wells, refuse=not fleet_files)
    created = missing_dirs(out_root)  # removed again when nothing is left in them
    run = uuid.uuid4().hex[:8]
    try:
        with _locked(out_root) if fleet_files else nullcontext():
            outcomes, manifest = _run_jobs(jobs, out_root, run, workers=workers,
                                           scheduler=scheduler, force=force, advance=advance,
                                           fleet_files=fleet_files)
            summary_path, report_path, notes = None, None, ()
            if fleet_files:
                summary_path = _write_summary(out_root, outcomes)
                report_path, notes = _write_report(out_root, outcomes)
                notes = tuple(notes) + _gone_notes(manifest.gone)
    except DrillfricError:
        if created and fleet_files and not any(p.is_dir() for p in out_root.iterdir()):
            for name in (MANIFEST, _LOCK):  # failed before any well ran: no OUT left behind
                (out_root / name).unlink(missing_ok=True)
        raise
    finally:
        for claim in out_root.glob(f".claim-{run}-*"):
            claim.unlink(missing_ok=True)
        remove_empty(created)  # OUT made here and left empty (e.g. by workers for failed wells)
    return FleetResult(out_root, outcomes, time.perf_counter() - t0, manifest.path,
                       summary_path, report_path, notes)


def _run_jobs(jobs: list[_Job], out_root: Path, run: str, *, workers: int,
              scheduler: str | None, force: bool, advance: Callable,
              fleet_files: bool) -> tuple[tuple[WellOutcome, ...], _Manifest]:
    """Skip the unchanged wells, run the others, record every one; outcomes in input order."""
    if fleet_files:
        remove_stale(out_root)
    manifest = _Manifest(out_root if fleet_files else None)
    known = manifest.known_files()
    jobs = [_hashed(j, known) for j in jobs]
    outcomes: dict[int, WellOutcome] = {}
    todo = []
    for job in jobs:
        name, entry = _entry(manifest, job)
        if job.task is None:
            outcomes[job.index] = _record(manifest, job, {"status": "failed",
                                                          "message": job.error}, 0, known)
            advance(1.0)
        elif not force and _same(job.fingerprint, entry, known):
            outcomes[job.index] = _skipped(name, entry)
            advance(1.0)
        else:
            todo.append(replace(job, task=replace(job.task, resume=not force)))
    if any(not j.named for j in todo):  # their names are resolved (and claimed) by workers
        taken = frozenset({name_key(j.dir_name) for j in jobs if j.named and j.task}
                          | {name_key(Path(o.result_dir).name) for o in outcomes.values()
                             if o.result_dir is not None})
        todo = [j if j.named else replace(j, task=replace(j.task, taken=taken, run=run))
                for j in todo]
    written = []
    try:
        with closing(_execute(todo, workers=workers, scheduler=scheduler)) as done:
            for job, rec, attempts in done:
                outcomes[job.index] = _record(manifest, job, rec, attempts, known)
                written.append(rec.get("dir_name") or job.dir_name)
                manifest.save(now=False)
                advance(1.0)
    finally:
        manifest.save()
        if scheduler is None:  # local workers are gone: what they left is stale
            for dir_name in {j.dir_name for j in jobs} | set(written):
                remove_stale(out_root, dir_name)
    if fleet_files:
        manifest.gone = _gone(manifest, {o.well for o in outcomes.values()})
        manifest.save()
    return tuple(outcomes[j.index] for j in jobs), manifest


def _gone_notes(gone: tuple[str, ...]) -> tuple[str, ...]:
    """The fleet's note on the wells no longer found (none: no note)."""
    if not gone:
        return ()
    shown = ", ".join(gone[:5]) + (f" and {len(gone) - 5} more" if len(gone) > 5 else "")
    return (f"{plural(len(gone), 'well')} of earlier runs not found this time ({shown}): "
            "their results are kept in OUT, marked stale (STALE.json); manifest.json says "
            "since when (missing_since_utc)",)


def _gone(manifest: _Manifest, present: set) -> tuple[str, ...]:
    """The wells of earlier nights whose data this run did not find: each entry gets
    ``missing_since_utc`` and its results in OUT are marked stale (they stay, and no longer
    read as this night's: the eleventh attack of issue 30 found a deleted well reported
    'ok' night after night). A well whose data returns runs again (its summary changed)."""
    out_root = manifest.path.parent.resolve()
    gone = []
    for name, entry in manifest.wells.items():
        if name in present or not isinstance(entry, dict):
            continue
        gone.append(name)
        if entry.get("missing_since_utc"):
            continue
        entry["missing_since_utc"] = now_utc()
        folder = Path(entry.get("outputs", {}).get("dir") or out_root / name)
        try:
            if folder.resolve().parent == out_root and mark_stale(
                    folder, "its data was not among the wells of a later fleet run",
                    entry["missing_since_utc"]):
                entry["stale_outputs"] = str(folder)
        except OSError:
            continue
    return tuple(sorted(gone))


def _record(manifest: _Manifest, job: _Job, rec: dict, attempts: int,
            known: dict) -> WellOutcome:
    """Record a well's outcome in the manifest, under the name its worker resolved, with
    the files it read (those found inside its data file stamped here)."""
    name = rec.get("well") or job.name
    inputs = dict(job.fingerprint.get("inputs", {}))
    for role, path in rec.get("inputs", {}).items():
        if role not in inputs:
            try:
                inputs[role] = _file_stamp(Path(path), known)
            except OSError:
                continue
    entry = {**job.fingerprint, "inputs": inputs, "status": rec["status"],
             "message": rec["message"],
             "attempts": attempts, "failed_segments": rec.get("failed_segments", 0),
             **{k: rec[k] for k in ("started_utc", "finished_utc", "task_s", "worker")
                if k in rec}}
    if "worker_version" in rec:  # a worker on another version: redo it next time
        entry["drillfric_version"] = rec["worker_version"]
    if rec.get("out_dir"):
        out = Path(rec["out_dir"])
        entry["outputs"] = {"dir": str(out), "summary": str(out / "summary.json"),
                            "estimates": str(out / "estimates.parquet"),
                            "segments": str(out / "segments.parquet"),
                            "report": str(out / "report.html")}
        if (out / "summary.json").is_file():  # a run into OUT/NAME by another hand shows
            entry["summary_sha256"] = file_sha256(out / "summary.json")  # next night
        else:
            entry.update(status="failed", message=f"{out}: the worker wrote its result where "
                         "this machine cannot see it — fix: put OUT on storage shared by the "
                         "client and every worker")
    stale = _mark_stale(manifest, name, job, rec, entry) if entry["status"] == WellStatus.FAILED \
        else None
    before = manifest.wells.get(name) or {}
    history = list(before.get("history", [])) if isinstance(before, dict) else []
    summary = rec.get("summary") if entry["status"] == WellStatus.OK else None
    changed = overnight.changes(summary, history, ran=True, data_changed_utc=None,
                                rerun=_rerun_reason(before, job.fingerprint))
    if summary is not None:
        entry["history"] = (history + [overnight.night(summary, now_utc())])[
            -overnight.HISTORY_NIGHTS:]
    elif history:
        entry["history"] = history
    entry["data_changed_utc"] = now_utc()
    manifest.wells[name] = entry
    return WellOutcome(name, entry["status"], entry["message"],
                       Path(rec["out_dir"]) if entry["status"] == WellStatus.OK else None,
                       summary, entry["failed_segments"], rec.get("task_s", 0.0), attempts,
                       stale_dir=stale, new_segments=changed["new_segments"],
                       changes=tuple(changed["notes"]),
                       first_run=summary is not None and not history)


def _rerun_reason(before: dict, fingerprint: dict) -> str | None:
    """Why a well of earlier nights ran again when not for new data (None: new data, or no
    earlier night)."""
    if not isinstance(before, dict) or not before:
        return None
    if before.get("config_sha256") != fingerprint.get("config_sha256"):
        return "its configuration changed"
    if before.get("drillfric_version") != fingerprint.get("drillfric_version"):
        return "drillfric changed"
    return None


def _mark_stale(manifest: _Manifest, name: str, job: _Job, rec: dict,
                entry: dict) -> Path | None:
    """Mark an earlier run's results of a well that failed now as stale (OUT/NAME of its
    earlier entry, else of its name): they stay, marked (docs/fleet.md "Stale results")."""
    if manifest.path is None:
        return None
    out_root = manifest.path.parent.resolve()
    earlier = (manifest.wells.get(name) or {}).get("outputs", {}).get("dir")
    folder = Path(earlier) if earlier else out_root / (rec.get("dir_name") or job.dir_name)
    try:
        if folder.resolve().parent != out_root or \
                not mark_stale(folder, entry["message"], now_utc()):
            return None
    except OSError:
        return None
    entry["stale_outputs"] = str(folder)
    return folder


def _skipped(name: str, entry: dict) -> WellOutcome:
    out = Path(entry["outputs"]["dir"])
    summary = read_json(out / "summary.json")
    changed = overnight.changes(summary, entry.get("history", []), ran=False,
                                data_changed_utc=entry.get("data_changed_utc"))
    return WellOutcome(name, "skipped", "unchanged since the last run", out, summary,
                       entry.get("failed_segments", 0), new_segments=0,
                       changes=tuple(changed["notes"]))


def _execute(jobs: list[_Job], *, workers: int,
             scheduler: str | None) -> Iterator[tuple[_Job, dict, int]]:
    """Yield (job, record, attempts) as wells finish, in completion order."""
    if not jobs:
        return
    if scheduler is None and min(workers, len(jobs)) <= 1:
        for job in jobs:
            yield job, process_well(job.task), 1
        return
    from distributed import as_completed

    with _client(min(workers, len(jobs)), scheduler) as client:
        token = uuid.uuid4().hex[:8]

        def submit(job: _Job, attempt: int):
            return client.submit(process_well, job.task, pure=False,
                                 key=f"drillfric-well-{job.name}-{token}-{attempt}")

        pending = {submit(job, 1): (job, 1) for job in jobs}
        queue = as_completed(list(pending))
        try:
            for future in queue:
                job, attempt = pending.pop(future)
                rec, retry = _outcome(future)
                if retry and attempt < MAX_ATTEMPTS:
                    again = submit(job, attempt + 1)
                    pending[again] = (job, attempt + 1)
                    queue.add(again)
                    continue
                yield job, rec, attempt
        finally:
            client.cancel(list(pending))


def _outcome(future) -> tuple[dict, bool]:
    """The task's record, or a failed record and whether a retry makes sense."""
    from distributed import KilledWorker

    try:
        return future.result(), False
    except KilledWorker as exc:
        return {"status": "failed", "message": f"worker died while processing ({exc})"}, True
    except Exception as exc:  # noqa: BLE001 — e.g. drillfric missing on a remote worker
        return {"status": "failed", "message": f"task failed on the cluster: "
                f"{type(exc).__name__}: {exc}"}, False


@contextmanager
def _client(workers: int, scheduler: str | None):
    """A Dask client: to ``scheduler``, or to a local cluster of worker processes."""
    import logging

    from distributed import Client, LocalCluster

    if scheduler is not None:
        client = _connect(scheduler)
        with client:
            yield client
        return
    import dask
    from distributed.utils import get_mp_context

    with dask.config.set({"distributed.worker.multiprocessing-method": "forkserver"}), \
            warnings.catch_warnings():
        # The scheduler's health endpoint falls back to a free port when 8787 is taken.
        warnings.filterwarnings("ignore", message="Port .* is already in use")
        # Workers fork from a server that imported distributed and the pipeline once
        # (docs/fleet.md: start-up measured faster than spawning each worker).
        get_mp_context().set_forkserver_preload(["distributed", "drillfric.runner.time_log"])
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=None, silence_logs=logging.ERROR) as cluster, \
                Client(cluster) as client:
            yield client


def _connect(address: str):
    """A client of the scheduler at ``address``, checked and probed first (any failure:
    one InputError naming the address)."""
    from distributed import Client

    from drillfric.fleet.scheduler import probe, shown

    probe(address)
    try:
        return Client(address, timeout=f"{CONNECT_TIMEOUT_S}s")
    except (OSError, TimeoutError) as exc:
        raise InputError(f"cannot reach the Dask scheduler ({exc})", file=shown(address),
                         fix="check the address (tcp://HOST:PORT) and that the "
                             "scheduler runs") from None
    except Exception as exc:  # noqa: BLE001 — whatever answered, it is not a scheduler
        raise InputError(f"the address does not answer as a Dask scheduler "
                         f"({type(exc).__name__})", file=shown(address),
                         fix="give the address the scheduler prints (tcp://HOST:8786)"
                         ) from None


@contextmanager
def _locked(out_root: Path):
    """Hold OUT/.fleet.lock: one fleet run at a time per output directory."""
    lock = ExitStack()
    try:
        out_root.mkdir(parents=True, exist_ok=True)
        for name in (_LOCK, MANIFEST, SUMMARY, REPORT):  # refused before any well runs
            refuse_link(out_root / name)
        lock.enter_context(lock_file(out_root / _LOCK))
    except Busy:
        raise InputError("another fleet run is writing to this directory", file=out_root,
                         fix="wait for it to finish or use another --out") from None
    except OSError as exc:
        raise InputError(f"cannot write the output directory ({exc.strerror})",
                         file=out_root, fix="choose a writable --out") from None
    with lock:
        yield


# --------------------------------------------------------------------------- fleet files
def summary_frame(outcomes) -> pd.DataFrame:
    """fleet_summary.parquet: one row per well and segment (a failed well: one row).

    Columns: :data:`drillfric.result.FLEET_WELL_COLUMNS` (well level, prefixed ``well_``),
    then every :class:`~drillfric.result.SegmentRecord` field but ``id`` (as ``segment_id``)
    under its summary.json name, list fields as lists. Wells with something new tonight
    (``well_changes`` other than "no new data") come first.
    """
    seg_fields = [f for f in SEGMENT_FIELDS if f != "id"]
    rows = []
    for o in _changed_first(outcomes):
        s = o.summary or {}
        base = {"well": o.well, "well_status": o.status, "well_message": o.message,
                "well_failed_segments": int(o.failed_segments or 0),
                "well_first_run": bool(o.first_run),
                "well_new_segments": o.new_segments, "well_changes": "; ".join(o.changes),
                "result_dir": None if o.result_dir is None else str(o.result_dir),
                "stale_result_dir": None if o.stale_dir is None else str(o.stale_dir),
                "well_mu_s": s.get("mu_s"), "well_mu_k": s.get("mu_k"),
                "well_mu_s_lower_bound": s.get("mu_s_lower_bound"),
                "drillfric_version": s.get("drillfric_version")} | well_friction_columns(s)
        for seg in s.get("segments") or [{}]:
            row = base | {"segment_id": seg.get("id")}
            row |= {f: seg.get(f) for f in seg_fields}
            if seg and segment_is_apparent(seg):  # apparent μ: its own column, not μ_k
                row["mu_apparent"], row["mu_k"] = row["mu_k"], None
            rows.append(row)
    frame = pd.DataFrame(rows, columns=list(FLEET_WELL_COLUMNS) + seg_fields
                         + list(FLEET_SEGMENT_EXTRA))
    frame["segment_id"] = frame["segment_id"].astype("Int64")
    return frame


def _changed_first(outcomes) -> list:
    """Outcomes with news tonight first (new segments, moves, stick-slip), the others after
    (no new data, failed, nothing new); input order within each."""
    return sorted(outcomes, key=lambda o: not (o.changes and o.status == WellStatus.OK))


def _write_summary(out_root: Path, outcomes) -> Path:
    path = out_root / SUMMARY
    with replacing(path) as tmp:
        summary_frame(outcomes).to_parquet(tmp, index=False)
    return path


def _write_report(out_root: Path, outcomes) -> tuple[Path | None, tuple[str, ...]]:
    """OUT/fleet.html through the report package (when it provides a fleet report)."""
    from drillfric import report

    if not hasattr(report, "write_fleet_report"):
        return None, ("fleet.html not written: this version has no fleet report",)
    items = [{"well": o.well, "status": o.status, "message": o.message,
              "result_dir": o.result_dir, "summary": o.summary, "stale_dir": o.stale_dir,
              "changes": list(o.changes), "failed_segments": o.failed_segments,
              "first_run": o.first_run}
             for o in _changed_first(outcomes)]
    try:
        return report.write_fleet_report(out_root, items), ()
    except OutputError:  # a full disk, a link planted meanwhile: one line, exit 2
        raise
    except Exception as exc:  # noqa: BLE001 — the night's results are already written
        return None, (f"fleet.html not written: {type(exc).__name__}: {exc}",)
