"""`drillfric report RESULT_DIR [--pdf] [--segments all|N] [--units si|field]` (docs/cli.md):
rebuild reports.

Thin layer over :func:`drillfric.report.write_well_report`, which reads only the files of
the result directory (so reports can be rebuilt after an upgrade, or with a PDF later).
"""

from __future__ import annotations

from pathlib import Path

import click

from .common import echo


@click.command("report")
@click.argument("result_dir", type=click.Path(path_type=Path))
@click.option("--pdf/--no-pdf", default=False, show_default=True,
              help="Also write report.pdf (A4 landscape, matplotlib only).")
@click.option("--segments", default="10", show_default=True, metavar="all|N",
              help="How many estimated segments get their evidence drawn: 'all', or N "
                   "(the worst and the latest). Every segment is in the diagnostics table.")
@click.option("--units", "units", type=click.Choice(["si", "field"]),
              help="Units of the report's axes and tables: si (m, kN, kN·m, bar) or field "
                   "(ft, klbf, kft·lbf, psi). Default: the run's [well] units, else si. The "
                   "result files stay SI.")
def command(result_dir: Path, pdf: bool, segments: str, units: str | None) -> None:
    """Rebuild report.html (and report.pdf) of RESULT_DIR, an OUT/NAME of 'drillfric run'."""
    from drillfric.report import write_well_report

    html = write_well_report(result_dir, pdf=pdf, segments=segments, units=units)
    echo(f"report: {html}")
    if pdf:
        echo(f"report: {html.with_name('report.pdf')}")
