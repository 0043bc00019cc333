"""`drillfric live SOURCE --out DIR` (docs/live.md): estimates while the well is drilled."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import click

from drillfric.errors import InputError

from .common import UserError, compile_kernels_once, echo


@click.command("live")
@click.argument("source")
@click.option("--out", "out", type=click.Path(path_type=Path), required=True,
              help="Output directory: OUT/NAME as 'drillfric run' writes it (updated as "
                   "segments close) and OUT/live.json (rewritten as rows arrive, at least "
                   "every 0.2 s).")
@click.option("--config", type=click.Path(path_type=Path), help="Well configuration (TOML), "
              "overrides the NAME.toml sidecar.")
@click.option("--name", help="The well's name (OUT/NAME), overriding [well] name.")
@click.option("--until-idle", "until_idle", type=float, metavar="SECONDS",
              help="Finish after SECONDS without new data: close the open segment, write the "
                   "final results and exit 0 (2 when no data ever came). Default: run until "
                   "stopped (Ctrl-C, SIGTERM: the final results are written, exit 130/143).")
@click.option("--report/--no-report", default=True, show_default=True,
              help="Write report.html with the final results.")
@click.option("--serve", metavar="[HOST:]PORT",
              help="Serve the live page at HOST:PORT while live runs (HOST 127.0.0.1 unless "
                   "given: only this machine; [::1]:PORT for IPv6; port 0 picks a free port). "
                   "The address is printed (docs/live.md, 'Live page').")
def command(source: str, out: Path, config: Path | None, name: str | None,
            until_idle: float | None, report: bool, serve: str | None) -> None:
    """Follow SOURCE — a CSV file a rig logger appends to, a well directory into which the
    well's CSV or Parquet files arrive (its well.toml names them: [well] data = "." or a
    sub-folder; read in name order, as 'drillfric run' reads the folder), or
    wits0://HOST:PORT (a WITS level 0 stream, recorded into OUT/NAME.wits0.csv) — and
    estimate its segments as they close. A restarted live run on the same SOURCE and --out
    continues where it stopped."""
    from drillfric.live.run import run_live
    from drillfric.report import write_well_report

    if until_idle is not None and not until_idle > 0:
        raise UserError(f"--until-idle must be positive seconds, got {until_idle:g}")
    kw = {"config": config} if config else {}
    kw |= {"name": name} if name else {}
    if not source.startswith("wits0:") and not Path(source).is_dir() and \
            Path(source).suffix.lower() not in (".csv", ".txt", ".tsv"):
        raise UserError(f"{source}: live follows a delimited text file (.csv, .txt, .tsv), a "
                        "well directory into which the files arrive, or wits0://HOST:PORT "
                        "(docs/live.md)")
    server = _server(serve) if serve is not None else None
    receiver, path = None, Path(source)
    try:
        if source.startswith("wits0:"):
            path, kw, receiver = _wits0(source, out, config, name)
        compile_kernels_once()
        live = run_live(path, out, until_idle_s=until_idle, open_kw=kw,
                        report=partial(write_well_report, pdf=False) if report else None,
                        started=None if server is None else server.start,
                        upstream=None if receiver is None else lambda: receiver.error)
    except InputError as exc:
        if receiver is None or receiver.frames:
            raise
        raise InputError(f"no WITS0 frame arrived in {until_idle:g} s", file=source,
                         fix="check the address and that the recorder streams WITS level 0 "
                             "there") from exc
    finally:
        if receiver is not None:
            receiver.stop.set()
            if (note := receiver.dropped_note()) is not None:
                receiver.warn(note)  # never a frame dropped without its count
        if server is not None:
            server.stop()
    from .run_cmd import _print

    _print(live.result)
    echo(f"live.json: {live.target} (longest gap between its updates "
         f"{live.max_gap_s:.2f} s)")


def _wits0(source: str, out: Path, config: Path | None, name: str | None):
    """The recording a WITS0 source fills, the keywords to open it, and its receiver
    (running)."""
    from drillfric.live import wits0_receiver as wits0

    address = wits0.parse_address(source)
    setup = wits0.setup(address, config, name)
    receiver, _ = wits0.start(address, out, setup)
    return wits0.recording_path(out, setup), setup.open_kw, receiver


def _server(address: str):
    """The live page's server bound at ``address`` (one line and exit 2 when it cannot be)."""
    from drillfric.live.page import serve

    try:
        server = serve(address)
    except ValueError as exc:
        raise UserError(f"--serve: {exc}") from None
    echo(f"live page: {server.url}")
    return server
