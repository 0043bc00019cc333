"""`drillfric fleet` (docs/cli.md, docs/fleet.md): every well of a directory or manifest.

Thin layer over :func:`drillfric.fleet.run.run_many`: a progress bar over wells, one line per
failed well, a closing summary line. SIGTERM (and Ctrl-C) stop the run cleanly: finished
wells stay recorded in OUT/manifest.json, no half-written well directory is left, and the
next run completes the rest. Exit codes: 0 all ok, 1 some wells or segments failed, 2 bad
usage or no well readable, 128+signal when interrupted.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

from drillfric.io.text import plural
from drillfric.vocabulary import WellStatus

from .common import UserError, compile_kernels_once, echo, interrupted_exit_code, progress


def _default_workers() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else \
        (os.cpu_count() or 1)


def _closing_line(result) -> str:
    """The last line of ``drillfric fleet``: in every outcome — all ok, some unchanged,
    partial, every well failed, nothing estimated — the same words in the same order and
    the same path, OUT/manifest.json (which lists every well; issue 35, fourth newcomer:
    an all-unchanged run named the folder, the others the manifest).

    ``fleet: 3 wells — 2 ok (1 processed, 1 unchanged), 1 failed in 4.2 s — OUT/manifest.json``
    """
    ok, skipped, failed = (result.count(s) for s in ("ok", "skipped", "failed"))
    total = len(result.wells)
    redo = "; --force redoes them" if skipped and skipped == total else ""
    # a well with failed segments is "partial", as fleet.html calls it, not ok
    partial = sum(w.status != WellStatus.FAILED and w.failed_segments > 0
                  for w in result.wells)
    parts = [f"{ok + skipped - partial} ok ({ok} processed, {skipped} unchanged{redo})"]
    if partial:
        parts.append(f"{partial} partial")
    parts.append(f"{failed} failed")
    empty = len(getattr(result, "nothing_estimated", ()))
    if empty:
        parts.append(f"{empty} with nothing estimated")
    stale = sum(w.stale_dir is not None for w in result.wells)
    if stale:
        parts.append(f"{plural(stale, 'failed well')} {'keeps' if stale == 1 else 'keep'} an "
                     "earlier run's results, marked stale")
    if result.failed_segments:
        parts.append(f"{plural(result.failed_segments, 'segment')} failed")
    manifest = result.manifest or Path(result.out_root) / "manifest.json"
    return (f"fleet: {plural(total, 'well')} — {', '.join(parts)} in {result.wall_s:.1f} s — "
            f"{manifest}")


@click.command("fleet")
@click.argument("source", metavar="DIR_OR_MANIFEST", type=click.Path(path_type=Path))
@click.option("--out", "out", required=True, type=click.Path(path_type=Path),
              help="Output directory: OUT/NAME per well, manifest.json, "
                   "fleet_summary.parquet, fleet.html.")
@click.option("--scheduler", metavar="ADDRESS", help="Dask scheduler (tcp://HOST:PORT); "
              "the inputs and OUT must be on storage its workers share.")
@click.option("--workers", type=int, help="Local worker processes (default: all cores).")
@click.option("--force", is_flag=True, help="Redo every well from its start, even unchanged "
              "ones (a well whose data only grew otherwise continues from its saved state).")
@click.option("--report/--no-report", default=True, show_default=True,
              help="Write each well's report.html (the fleet report is always written).")
@click.option("--config", type=click.Path(path_type=Path),
              help="Configuration (TOML) for every well, overriding NAME.toml sidecars "
                   "(not a config a manifest names).")
def command(source: Path, out: Path, scheduler, workers, force, report, config) -> None:
    """Run every well of DIR_OR_MANIFEST (a directory of wells, or a .csv/.json manifest
    with columns well, data, config, survey, string), skipping wells unchanged since their last run.
    """
    from drillfric.fleet.discovery import discover
    from drillfric.fleet.run import run_many

    if workers is not None and workers < 1:
        raise UserError(f"--workers must be at least 1, got {workers}")
    if config is not None and not config.is_file():
        raise UserError(f"{config}: config file not found — fix: check the --config path")
    specs = discover(source, config=config)
    if scheduler is None:  # local workers share this user's kernel cache
        compile_kernels_once()
    try:
        with progress(f"fleet ({plural(len(specs), 'well')})", total=len(specs)) as advance:
            result = run_many(specs, out, workers=workers or _default_workers(),
                              scheduler=scheduler, force=force, progress=advance,
                              report=report)
    except KeyboardInterrupt:
        click.secho(f"interrupted: finished wells are recorded in {out / 'manifest.json'}"
                    "; run the same command again to complete the rest", err=True,
                    fg="yellow")
        sys.exit(interrupted_exit_code())
    for well in result.wells:
        if well.status == WellStatus.FAILED:
            click.secho(f"error: {well.well}: {well.message}", err=True, fg="red")
    for note in result.notes:
        click.secho(f"note: {note}", err=True)
    empty = result.nothing_estimated
    if empty:
        click.secho(f"warning: nothing estimated in {len(empty)} of "
                    f"{plural(len(result.wells), 'well')} (every segment skipped: too short, no "
                    "rotation …): "
                    f"{_some(empty)} — see {result.out_root}/NAME/summary.json", err=True,
                    fg="yellow")
    echo(_closing_line(result))
    if result.count("failed") == len(result.wells):
        raise UserError("no well could be processed — fix: see each well's error above")
    if result.count("failed") or result.failed_segments or \
            len(empty) == len(result.wells) - result.count("failed"):
        sys.exit(1)


def _some(names: tuple[str, ...], shown: int = 5) -> str:
    """The first ``shown`` names, and how many more."""
    more = len(names) - shown
    return ", ".join(names[:shown]) + (f" and {more} more" if more > 0 else "")
