"""`drillfric run` — the main job (INTERFACE.md): friction factors per stand + report."""

from __future__ import annotations

from pathlib import Path

import click

from drillfric.errors import DrillfricError

from .common import UserError, context, echo, progress, warn


def parse_starts(text: str | None) -> list[tuple[float, float]] | None:
    """``"0.3:0.2,0.6:0.4"`` → [(0.3, 0.2), (0.6, 0.4)] (μ_s:μ_k pairs)."""
    if not text:
        return None
    try:
        pairs = [tuple(float(v) for v in item.split(":")) for item in text.split(",")]
    except ValueError:
        pairs = []
    if not pairs or any(len(p) != 2 or p[1] > p[0] or p[1] < 0 for p in pairs):
        raise UserError(f"--starts '{text}' must be MU_S:MU_K pairs with 0 ≤ MU_K ≤ MU_S, "
                        "e.g. --starts 0.3:0.2,0.6:0.4")
    return pairs


def _fmt(value, spec=".3f") -> str:
    return "—" if value is None else format(value, spec)


def _describe(result) -> str:
    s = result.summary
    c = s["counts"]
    mu_s = _fmt(s["mu_s"]) if s["mu_s"] is not None else (
        f"not identifiable (≥ {s['mu_s_lower_bound']:.2f})" if s["mu_s_lower_bound"]
        else "not identifiable")
    return (f"{result.name}: {c['segments']} segments ({c['estimated']} estimated, "
            f"{c['converged']} converged, {c['skipped']} skipped, {c['failed']} failed); "
            f"μ_k = {_fmt(s['mu_k'])}, μ_s = {mu_s}")


@click.command("run")
@click.argument("wells", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--out", "out", type=click.Path(path_type=Path, file_okay=False),
              default=Path("drillfric-out"),
              show_default=True, help="Output directory; each well goes to OUT/NAME.")
@click.option("--config", type=click.Path(path_type=Path), help="Well configuration (TOML), "
              "overrides the NAME.toml sidecar.")
@click.option("--survey", type=click.Path(path_type=Path), help="Survey file, overrides the "
              "NAME.survey.* sidecar.")
@click.option("--rate", "rate", type=float, help="Resample the input to HZ before estimation "
              "(not above the data's own rate: a higher HZ is ignored with a warning).")
@click.option("--starts", help="Observer starts MU_S:MU_K,... (overrides observer.starts).")
@click.option("--pdf/--no-pdf", default=False, help="Also write report.pdf.")
@click.option("--workers", type=int, default=1, show_default=True,
              help="Wells processed in parallel (local processes).")
def command(wells, out, config, survey, rate, starts, pdf, workers) -> None:
    """Estimate friction factors (μ_s, μ_k) and bit speed, stand by stand, for each WELL.

    WELL is a data file (.parquet, .csv, .h5, .las) with optional NAME.toml and
    NAME.survey.csv sidecars, an HDF5 bundle, or a directory with well.toml.
    """
    from drillfric.pipeline import run_well

    if rate is not None and rate <= 0:
        raise UserError(f"--rate must be positive, got {rate}")
    if workers < 1:
        raise UserError(f"--workers must be at least 1, got {workers}")
    pairs = parse_starts(starts)
    _check_unique_names(wells, config)
    if workers > 1 and len(wells) > 1:
        _run_parallel(wells, out, config, survey, rate, pairs, pdf, workers)
        return
    failures = 0
    unreadable = 0
    for well in wells:
        try:
            with progress(f"{well.name}", total=1.0) as advance:
                result = run_well(well, out, config=config, survey=survey, rate_hz=rate,
                                  starts=pairs, pdf=pdf, progress=advance)
        except DrillfricError as exc:
            if context().debug or len(wells) == 1:
                raise
            click.secho(f"error: {exc.message}", err=True, fg="red")
            unreadable += 1
            continue
        except Exception as exc:  # noqa: BLE001 — one well's bug must not stop the others
            if context().debug or len(wells) == 1:
                raise
            click.secho(f"error: {well}: internal error: {type(exc).__name__}: {exc}",
                        err=True, fg="red")
            unreadable += 1
            continue
        for note in result.summary["assumed"]:
            warn(f"{result.name}: assumed {note} — the numbers are indicative")
        for note in result.warnings:
            warn(f"{result.name}: {note}")
        echo(_describe(result))
        echo(f"report: {result.report}")
        failures += result.failed
    if unreadable == len(wells):
        raise UserError("no well could be read")
    if failures or unreadable:
        raise SystemExit(1)


def _run_parallel(wells, out, config, survey, rate, pairs, pdf, workers) -> None:
    """Several wells on local worker processes, through the fleet executor (always redone;
    OUT gets the wells' directories only, none of the fleet files)."""
    from drillfric.fleet import WellSpec, run_many

    specs = [WellSpec(Path(w), config=config, survey=survey) for w in wells]
    overrides = {"observer.starts": [list(p) for p in pairs]} if pairs else None
    with progress(f"run ({len(specs)} wells)", total=len(specs)) as advance:
        result = run_many(specs, out, workers=workers, force=True, progress=advance,
                          overrides=overrides, rate_hz=rate, pdf=pdf, fleet_files=False)
    for well in result.wells:
        if well.status == "failed":
            click.secho(f"error: {well.well}: {well.message}", err=True, fg="red")
        elif well.result_dir is not None:
            for note in (well.summary or {}).get("warnings", []):
                warn(f"{well.well}: {note}")
            echo(f"{well.well}: report: {Path(well.result_dir) / 'report.html'}")
    if result.count("failed") == len(result.wells):
        raise UserError("no well could be read")
    if result.count("failed") or result.failed_segments:
        raise SystemExit(1)


def _check_unique_names(wells, config) -> None:
    """Two wells with one name would overwrite each other's OUT/NAME: refuse up front."""
    from drillfric.pipeline import well_name

    if len(wells) < 2:
        return
    seen: dict[str, Path] = {}
    for well in wells:
        try:
            name = well_name(well, config=config)
        except DrillfricError:
            continue  # unreadable wells are reported when they are run
        if name in seen:
            raise UserError(f"{seen[name]} and {well} would both write OUT/{name} — fix: give "
                            "them distinct [well] name values or file names")
        seen[name] = well
