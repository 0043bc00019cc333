"""`drillfric run` — the main job (docs/cli.md): friction factors per stand + report."""

from __future__ import annotations

from pathlib import Path

import click

from drillfric.errors import DrillfricError
from drillfric.io.text import plural, share, terminal_text
from drillfric.vocabulary import WellStatus

from .common import (
    Quantity,
    UserError,
    compile_kernels_once,
    context,
    echo,
    error,
    unit_system,
    warn,
    well_progress,
)


def parse_starts(text: str | None) -> list[tuple[float, float]] | None:
    """``"0.3:0.2,0.6:0.4"`` → [(0.3, 0.2), (0.6, 0.4)] (μ_s:μ_k pairs)."""
    if not text:
        return None
    try:
        pairs = [tuple(float(v) for v in item.split(":")) for item in text.split(",")]
    except ValueError:
        pairs = []
    if not pairs or any(len(p) != 2 or not 0 <= p[1] <= p[0] for p in pairs):
        raise UserError(f"--starts '{text[:60]}' must be MU_S:MU_K pairs with 0 ≤ MU_K ≤ "
                        "MU_S, e.g. --starts 0.3:0.2,0.6:0.4")
    return pairs


def _fmt(value, spec=".3f") -> str:
    return "—" if value is None else format(value, spec)


def _depths(segments: list[dict], units: str) -> str:
    """``", bit 2000–2500 m"`` over the segments (in the display units), or ""."""
    from drillfric.units import display_unit, to_display

    depths = [g["bit_depth_m"] for g in segments if g.get("bit_depth_m") is not None]
    if not depths:
        return ""
    low, high = to_display(min(depths), "length", units), to_display(max(depths), "length",
                                                                       units)
    return f", bit {_whole(low)}–{_whole(high)} {display_unit('length', units)}"


def _whole(value: float) -> str:
    """A depth to the metre or foot, ``.4g`` beyond a million (a 1e308 from a broken log
    must not print as a 309-digit number).

    Examples
    --------
    >>> _whole(2512.4), _whole(1e308)
    ('2512', '1e+308')
    """
    return f"{value:.0f}" if abs(value) < 1e6 else f"{value:.4g}"


def _describe(result, units: str = "si") -> str:
    s = result.summary
    c = s["counts"]
    if s.get("index") == "depth":
        return _describe_depth_log(result, units)
    u_s, support = s.get("mu_s_uncertainty"), s.get("mu_s_support") or {}
    mu_s = _fmt(s["mu_s"]) + (f" ± {_fmt(u_s)}" if u_s is not None else "") + (
        f" ({share(support['segments'], support['of'], 'segment')})" if "of" in support
        else "") if s["mu_s"] is not None else (
        f"not identifiable (≥ {s['mu_s_lower_bound']:.2f})" if s["mu_s_lower_bound"]
        else "not identifiable")
    from drillfric.report.render import drag_text

    drag = drag_text(s.get("drag"))
    return (f"{result.well}: {plural(c['segments'], 'segment')} "
            f"({c['estimated']} estimated, "
            f"{c['converged']} converged, {c['skipped']} skipped, {c['failed']} failed"
            f"{_depths(s['segments'], units)}); {_mu_k_text(s)}, μ_s = {mu_s}"
            + (f"; {drag}" if drag else ""))


def _mu_k_text(summary: dict) -> str:
    """The well μ_k with its uncertainty, support and confidence, or why there is none."""
    if summary["mu_k"] is None:
        state = summary.get("mu_k_confidence")
        return f"μ_k {state}" if state in ("withheld", "none") else "μ_k = —"
    u, support = summary.get("mu_k_uncertainty"), summary.get("mu_k_support") or {}
    text = f"μ_k = {_fmt(summary['mu_k'])}" + (f" ± {_fmt(u)}" if u is not None else "")
    if "of" in support:
        text += f" ({share(support['segments'], support['of'], 'off-bottom segment')}"
        text += ", low confidence)" if summary.get("mu_k_confidence") == "low" else ")"
    return text


def _describe_depth_log(result, units: str) -> str:
    """The result line of a depth-indexed log's friction log."""
    from drillfric.units import format_value

    s, c, log = result.summary, result.summary["counts"], result.summary["friction_log"]
    off = (f"μ off bottom = {_fmt(s['mu_k'])}" if s["mu_k"] is not None else
           f"μ off bottom: none ({log.get('mu_k_reason') or 'no off-bottom window'})")
    return (f"{result.well}: friction log of a depth-indexed log, "
            f"{plural(c['segments'], 'window')} of "
            f"{format_value(log['window_m'], 'length', units, '.0f')} ({c['estimated']} "
            f"estimated, {c['skipped']} skipped, {c['failed']} failed"
            f"{_depths(s['segments'], units)}); {off}, apparent "
            f"μ on bottom = {_fmt(log['mu_apparent'])}; μ_s: no observer in depth data")


@click.command("run")
@click.argument("wells", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--out", "out", type=click.Path(path_type=Path),
              default=Path("drillfric-out"),
              show_default=True, help="Output directory; each well goes to OUT/NAME.")
@click.option("--config", type=click.Path(path_type=Path), help="Well configuration (TOML), "
              "overrides the NAME.toml sidecar.")
@click.option("--survey", type=click.Path(path_type=Path), help="Survey file, overrides the "
              "NAME.survey.* sidecar.")
@click.option("--string", "string", type=click.Path(path_type=Path),
              help="WITSML tubular file read as the drill string (overrides the "
                   "NAME.tubular.xml sidecar; for a configuration without [[string.sections]]).")
@click.option("--rate", "rate", type=Quantity("Hz"), help="Resample the input to HZ before "
              "estimation (not above the data's own rate: a higher HZ is ignored with a "
              "warning).")
@click.option("--starts", help="Observer starts MU_S:MU_K,... (overrides observer.starts).")
@click.option("--pdf/--no-pdf", default=False, help="Also write report.pdf.")
@click.option("--report/--no-report", default=True, show_default=True,
              help="Write report.html (--no-report: the result files only).")
@click.option("--workers", type=int, default=1, show_default=True,
              help="Wells processed in parallel (local processes).")
@click.option("--units", "units", type=click.Choice(["si", "field"]),
              help="Units of the printed summary and of the report's axes and tables: si (m, "
                   "kN, kN·m) or field (ft, klbf, kft·lbf, ppg). Default: the configuration's "
                   "[well] units, else si. JSON and result files stay SI.")
def command(wells, out, config, survey, string, rate, starts, pdf, report, workers,
            units) -> None:
    """Estimate friction factors (μ_s, μ_k) and bit speed, stand by stand, for each WELL.

    WELL is a data file (.parquet, .csv, .h5, .las, .xml, .dlis, .xlsx) with optional
    NAME.toml and NAME.survey.csv sidecars, an HDF5 bundle, or a directory with well.toml.
    A depth-indexed log gives a static friction log by depth window instead (torque-and-drag
    back-calculation; no observer, no μ_s).
    """
    if rate is not None and not rate > 0:
        raise UserError(f"--rate must be positive, got {rate:.4g}")
    if workers < 1:
        raise UserError(f"--workers must be at least 1, got {workers}")
    pairs = parse_starts(starts)
    overrides = {"observer.starts": [list(p) for p in pairs]} if pairs else {}
    if units:  # the run's [well] units: its report is drawn in them too
        overrides["well.units"] = units
    if workers > 1 and len(wells) > 1:
        compile_kernels_once()
        _run_parallel(wells, out, config, survey, rate, overrides, pdf, report, workers,
                      string)
        return
    opened, unreadable = _open_all(wells, config, survey, overrides, string)
    compile_kernels_once()
    failures = 0
    for well in opened:
        try:
            with well_progress(well.name) as tick:
                result = _run_one(well, out, rate, pdf, report, tick)
        except DrillfricError as exc:
            if context().debug or len(wells) == 1:
                raise
            error(exc.message)
            unreadable += 1
            continue
        _print(result, units)
        failures += result.failed
    if unreadable == len(wells):
        raise UserError("no well could be read")
    if failures or unreadable:
        raise SystemExit(1)


def _open_all(wells, config, survey, overrides, string=None) -> tuple[list, int]:
    """Open every well once and refuse, before anything is written, two that would write
    the same OUT/NAME; returns the opened wells and how many could not be read."""
    from drillfric.io.results import check_distinct
    from drillfric.io.well import open_well

    opened, unreadable = [], 0
    for path in wells:
        try:
            opened.append(open_well(path, config=config, survey=survey, overrides=overrides,
                                    string=string))
        except DrillfricError as exc:
            if context().debug or len(wells) == 1:
                raise
            error(exc.message)
            unreadable += 1
    check_distinct([(w.dir_name, str(w.files.data)) for w in opened])
    return opened, unreadable


def _run_one(well, out, rate, pdf, report, tick):
    from drillfric.api import run

    return run(well, out, rate_hz=rate, pdf=pdf, report=report, progress=tick)


def _print(result, units: str | None = None) -> None:
    """Warnings, the result line (in ``--units``, else the well's ``[well] units``) and the
    report's path (only when it was written)."""
    from drillfric.estimation.headline import INDICATIVE_WARNING
    from drillfric.units import display_text

    system = unit_system(units, result.summary.get("config", {}))
    for note in result.summary["assumed"]:
        warn(f"{result.well}: assumed {display_text(note, system)} — the numbers are "
             "indicative")
    for note in result.warnings:
        if not note.startswith(INDICATIVE_WARNING):  # the assumed lines above say it
            warn(f"{result.well}: {note}")
    click.echo(terminal_text(_describe(result, system)))  # printed even with --quiet
    if result.report is not None:
        echo(f"report: {result.report}")
        if (pdf := Path(result.report).with_name("report.pdf")).is_file():
            echo(f"report: {pdf}")
    else:
        echo(f"results: {result.out_dir}")


def _run_parallel(wells, out, config, survey, rate, overrides, pdf, report, workers,
                  string=None) -> None:
    """Several wells on local worker processes, through the fleet executor (always redone;
    OUT gets the wells' directories only, none of the fleet files)."""
    from drillfric.fleet.discovery import WellSpec
    from drillfric.fleet.run import run_many

    from .common import progress

    specs = [WellSpec(Path(w), config=config, survey=survey, string=string) for w in wells]
    with progress(f"run ({plural(len(specs), 'well')})", total=len(specs)) as advance:
        result = run_many(specs, out, workers=workers, force=True, progress=advance,
                          overrides=overrides, rate_hz=rate, pdf=pdf, report=report,
                          fleet_files=False)
    for well in result.wells:
        if well.status == WellStatus.FAILED:
            error(f"{well.well}: {well.message}")
        elif well.result_dir is not None:
            for note in (well.summary or {}).get("warnings", []):
                warn(f"{well.well}: {note}")
            page = Path(well.result_dir) / "report.html"
            echo(f"{well.well}: " + (f"report: {page}" if page.is_file()
                                     else f"results: {well.result_dir}"))
    if result.count("failed") == len(result.wells):
        raise UserError("no well could be read")
    if result.count("failed") or result.failed_segments:
        raise SystemExit(1)
