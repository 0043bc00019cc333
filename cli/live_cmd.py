"""`drillfric live SOURCE --out DIR` (docs/live.md): estimates while the well is drilled."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import click

from .common import UserError, compile_kernels_once, echo


@click.command("live")
@click.argument("source", type=click.Path(path_type=Path))
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
def command(source: Path, out: Path, config: Path | None, name: str | None,
            until_idle: float | None, report: bool) -> None:
    """Follow SOURCE, a CSV file a rig logger appends to, and estimate its segments as they
    close. A restarted live run on the same SOURCE and --out continues where it stopped."""
    from drillfric.live import run_live
    from drillfric.report import write_well_report

    if until_idle is not None and not until_idle > 0:
        raise UserError(f"--until-idle must be positive seconds, got {until_idle:g}")
    if source.suffix.lower() not in (".csv", ".txt", ".tsv"):
        raise UserError(f"{source}: live follows a delimited text file (.csv, .txt, .tsv); "
                        "WITS0 and folder sources are not done yet (docs/live.md)")
    compile_kernels_once()
    kw = {"config": config} if config else {}
    live = run_live(source, out, until_idle_s=until_idle,
                    open_kw=kw | ({"name": name} if name else {}),
                    report=partial(write_well_report, pdf=False) if report else None)
    from .run_cmd import _print

    _print(live.result)
    echo(f"live.json: {live.target} (longest gap between its updates "
         f"{live.max_gap_s:.2f} s)")
