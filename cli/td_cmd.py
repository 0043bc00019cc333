"""`drillfric td` (docs/cli.md): soft-string torque and drag at one bit depth, or a broomstick.

Thin layer: resolve the well (config, survey), build the options into library calls of
:mod:`drillfric.torque_drag`, print a summary or JSON, write the table / plot. With
``--broomstick`` and a well that has a log (a data file, HDF5 bundle or well directory),
the log is segmented and each rotating segment's measured hook load and torque are drawn
on the broomstick, with the string-weight check (:mod:`drillfric.report.broomstick`).
"""

from __future__ import annotations

import json
from pathlib import Path

import click
import numpy as np

from drillfric.files import require_file
from drillfric.io.text import plural, printable

from .common import Quantity, UserError, echo, unit_system, units_option, warn

_TABLE_SUFFIXES = (".csv", ".parquet")
_PLOT_SUFFIXES = (".png", ".svg", ".pdf")
_DEFAULT_FRICTIONS = (0.1, 0.2, 0.3, 0.4, 0.5)


def _load(target: Path, config: str | None, survey: str | None, overrides: dict):
    """(Config, WellPath or None) for a .toml configuration, a data file or a well directory.

    A configuration's survey is ``--survey``, else its ``[survey] file`` (relative to it),
    else ``NAME.survey.csv`` beside ``NAME.toml`` (:func:`drillfric.io.well.open_config`);
    ``--config`` overrides the configuration. Other targets are resolved like every command
    does (:func:`drillfric.io.well.open_well`: sidecars, HDF5 bundles, directories).
    """
    from drillfric.io.well import open_config

    if target.suffix.lower() == ".toml":
        require_file(target, "config file")
        cfg, _, path = open_config(Path(config) if config else target, survey=survey,
                                   overrides=overrides)
        return cfg, path
    from drillfric.io.well import open_well

    well = open_well(target, config=config, survey=survey, overrides=overrides, header=False)
    return well.config, well.survey


def _load_with_log(target: Path, config, survey, overrides):
    """(Config, WellPath or None, measured points) of a well with a log: the log is read
    (:func:`drillfric.io.well.load_well`) and segmented for the measured points."""
    from drillfric.io.well import load_well
    from drillfric.report.broomstick import measured_points_from_log

    well = load_well(target, config=config, survey=survey, overrides=overrides)
    return well.config, well.survey, measured_points_from_log(well.surface, well.config)


#: Most values of one --depths or --frictions list (a range's count is checked before it is
#: made: 0:1e15:1 asked for 7 PiB).
MAX_LIST = 10_000
#: Deepest bit [m] (the configuration's plausible maximum for depths, docs/configuration.md).
MAX_BIT_DEPTH_M = 15_000.0
#: Budget of a broomstick: depths × friction factors × load cases × elements of the deepest
#: string (≈ 20 ns each: 2×10⁹ is about 40 s).
MAX_BROOMSTICK_WORK = 2e9


def _floats(text: str | None, what: str) -> list[float] | None:
    """The finite numbers of a comma list or START:STOP:STEP (None: not given)."""
    if text is None:
        return None
    bad = UserError(f"--{what}: expected comma-separated finite numbers or START:STOP:STEP, "
                    f"got '{printable(text, 60)}' — fix: e.g. --{what} 0.1,0.2,0.3 or "
                    "500:2500:100")
    try:
        if ":" in text:
            start, stop, step = (float(v) for v in text.split(":"))
            if not (np.isfinite([start, stop, step]).all() and step > 0 and stop >= start):
                raise bad
            if (stop - start) / step + 1 > MAX_LIST:
                raise UserError(f"--{what}: {start:.4g}:{stop:.4g}:{step:.4g} gives "
                                f"{(stop - start) / step + 1:.3g} values; at most {MAX_LIST} "
                                "— fix: a larger STEP")
            values = list(np.arange(start, stop + 0.5 * step, step))
        else:
            values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise bad from None
    if not values or len(values) > MAX_LIST or not np.isfinite(values).all():
        raise bad
    return values


def _check_depth(depth_m: float, what: str) -> None:
    """UserError unless ``depth_m`` is a bit depth a well can have (0 < d ≤ 15 km)."""
    if not 0 < depth_m <= MAX_BIT_DEPTH_M:
        raise UserError(f"{what} {depth_m:.4g} m is not a well's: at most "
                        f"{MAX_BIT_DEPTH_M:.0f} m — fix: a bit depth in metres (or with its "
                        "unit, e.g. \"8200 ft\")")


def _check_out(out: Path | None, suffixes: tuple[str, ...]) -> None:
    """UserError for an output path of another type, or where a link, a directory or a
    special file stands — checked for every output before any is written (the table was
    left written when the plot beside it could not be)."""
    if out is not None and out.suffix.lower() not in suffixes:
        raise UserError(f"{out}: unsupported output type '{out.suffix}' — use "
                        f"{' or '.join(suffixes)}")
    if out is not None and (out.is_symlink() or out.exists() and not out.is_file()):
        raise UserError(f"{out}: a link, a directory or a special file stands where the "
                        "output goes (drillfric writes through no link) — fix: remove it or "
                        "give another path")


def _write_table(frame, out: Path) -> None:
    """The table at ``out``, whole or not at all, never through a link (io/atomic)."""
    from drillfric.io.atomic import replacing

    out.parent.mkdir(parents=True, exist_ok=True)
    with replacing(out) as tmp:
        if out.suffix.lower() == ".parquet":
            frame.to_parquet(tmp, index=False)
        else:
            frame.to_csv(tmp, index=False)


@click.command("td")
@click.argument("well_or_config", type=click.Path(path_type=Path))
@click.option("--bit-depth", type=Quantity("m"), help="Bit measured depth [m] (default: the "
              "config's [well] bit_depth_m, else the end of the survey); a number with a unit "
              "is converted, e.g. \"8200 ft\".")
@click.option("--friction", type=float, help="Friction factor μ (default: from the config, "
              "per hole section when casing_shoe_md_m is set).")
@click.option("--load-case", default="rotating_off_bottom", show_default=True,
              type=click.Choice(["rotating_off_bottom", "rotating_on_bottom", "pick_up",
                                 "slack_off", "rotating_pick_up", "rotating_slack_off",
                                 "sliding"]))
@click.option("--wob", type=Quantity("N", limit=1e8), default=0.0, show_default=True,
              help="Weight on bit [N] (on-bottom cases), e.g. 150000 or \"35 klbf\".")
@click.option("--bit-torque", type=Quantity("N·m", limit=1e7), default=0.0, show_default=True,
              help="Torque on bit [N·m] (on-bottom cases), e.g. \"3 kft.lbf\".")
@click.option("--rpm", type=Quantity("RPM", limit=600.0), default=0.0,
              help="Rotary speed [RPM] (combined motion).")
@click.option("--axial-speed", type=Quantity("m/s", limit=100.0), default=0.0,
              help="Trip speed [m/s] (combined motion), e.g. \"60 ft/min\".")
@click.option("--element-length", type=Quantity("m"),
              help="Element length [m] (default: config).")
@click.option("--out", type=click.Path(path_type=Path),
              help="Profile (or broomstick table) file, .csv or .parquet.")
@click.option("--broomstick", is_flag=True, help="Hook load and torque versus bit depth for "
              "a family of friction factors (table to --out, plot beside it or to --plot).")
@click.option("--frictions", help="Broomstick friction factors, e.g. 0.1,0.2,0.3 "
              "(default 0.1–0.5).")
@click.option("--depths", help="Broomstick bit depths [m]: comma list or START:STOP:STEP "
              "(default: 50 depths from the BHA length to the bit depth).")
@click.option("--plot", type=click.Path(path_type=Path),
              help="Broomstick plot file (.png/.svg/.pdf; default: --out with .png).")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@click.option("--config", type=click.Path(), help="Well configuration (overrides sidecars).")
@click.option("--survey", type=click.Path(), help="Survey file (overrides the config's).")
@units_option
def command(well_or_config, bit_depth, friction, load_case, wob, bit_torque, rpm, axial_speed,
            element_length, out, broomstick, frictions, depths, plot, as_json, config,
            survey, units) -> None:
    """Soft-string torque and drag (docs/theory.md §2) for WELL_OR_CONFIG.

    WELL_OR_CONFIG is a well configuration (.toml, with its [survey] file or a
    NAME.survey.csv beside it) or a well on disk (docs/ingestion.md). The bit depth is
    --bit-depth, else the configuration's [well] bit_depth_m, else the survey's last
    station. Without a survey the hole is vertical with the nominal tortuosity
    survey.tortuosity_deg_30m, and --bit-depth (or [well] bit_depth_m) is required.
    """
    overrides = {"model.friction": friction, "model.element_length_m": element_length}
    measured = None
    if broomstick and well_or_config.suffix.lower() != ".toml":
        cfg, path, measured = _load_with_log(well_or_config, config, survey, overrides)
    else:
        cfg, path = _load(well_or_config, config, survey, overrides)
    bit_depth = _bit_depth(bit_depth, cfg, path, measured)
    system = unit_system(units, cfg)
    _warn_assumed(cfg, path, system)
    kw = {"wob_N": wob, "bit_torque_Nm": bit_torque, "rpm": rpm, "axial_speed_m_s": axial_speed}
    if broomstick:
        _broomstick(cfg, path, bit_depth, frictions, depths, out, plot, as_json, kw, system,
                    measured)
    else:
        _profile(cfg, path, bit_depth, friction, load_case, out, as_json, kw, system)


def _bit_depth(option: float | None, cfg, path, measured) -> float:
    """The bit depth [m]: ``--bit-depth``, else ``[well] bit_depth_m``, else (a broomstick
    of a log without survey) the log's deepest, else the survey's last station."""
    depth = option if option is not None else cfg.well.bit_depth_m
    if depth is None and path is None and measured is not None and len(measured):
        depth = float(measured["bit_depth_m"].max())
    if depth is None:
        if path is None:
            raise UserError("no survey: give --bit-depth or [well] bit_depth_m (the hole is "
                            "taken as vertical, with "
                            "the nominal tortuosity survey.tortuosity_deg_30m)")
        depth = path.md_max_m
    _check_depth(depth, "the bit depth")
    return depth


def _warn_assumed(cfg, path, system: str) -> None:
    """A warning per assumption, its quantities in the display units of ``system``."""
    from drillfric.units import display_text

    for note in cfg.assumed_with(path):
        if not note.startswith("top-drive"):  # the rig is irrelevant to torque and drag
            warn(f"assumed {display_text(note, system)}")


def _profile(cfg, path, bit_depth, friction, load_case, out, as_json, kw, units) -> None:
    from drillfric.torque_drag import config_friction, solve_config
    from drillfric.units import format_value as show

    _check_out(out, _TABLE_SUFFIXES)
    result = solve_config(cfg, path, bit_depth, friction=friction, load_case=load_case, **kw)
    mu = config_friction(cfg, friction)
    summary = {"bit_depth_m": result.bit_depth_m,
               "friction_factor": None if callable(mu) else float(mu),
               "load_case": load_case, "surface_torque_Nm": result.surface_torque_Nm,
               "hookload_N": result.hookload_N, "T_N_Nm": result.T_N_Nm,
               "wob_N": kw["wob_N"], "bit_torque_Nm": kw["bit_torque_Nm"],
               "max_normal_force_N_m": float(result.normal_force_N_m.max()),
               "mud_density_kg_m3": cfg.fluid.mud_density_kg_m3,
               "element_length_m": cfg.model.element_length_m,
               "elements": int(result.fc_Nm_m.size), "assumed": cfg.assumed_with(path)}
    if callable(mu):
        summary["friction_by_section"] = {"casing_shoe_md_m": mu.shoe_md_m,
                                          "cased": mu.cased, "open_hole": mu.open_hole}
    if out is not None:
        _write_table(result.to_frame(), out)
    if as_json:
        click.echo(json.dumps(summary, indent=2))
        return
    mu_text = (f"{summary['friction_factor']:g}" if summary["friction_factor"] is not None
               else f"{mu.cased:g} cased above {mu.shoe_md_m:g} m, {mu.open_hole:g} open hole")
    click.echo(f"bit depth        {show(result.bit_depth_m, 'length', units, '10.1f')}   "
               f"({load_case}, μ = {mu_text})")
    click.echo(f"hook load        {show(result.hookload_N, 'force', units, '10.1f')}  "
               "(effective, no block weight)")
    click.echo(f"surface torque   {show(result.surface_torque_Nm, 'torque', units, '10.2f')}")
    click.echo(f"T_N = ∫F_c dx    {show(result.T_N_Nm, 'torque', units, '10.2f')} per unit "
               "friction factor")
    click.echo(f"max side force   "
               f"{show(summary['max_normal_force_N_m'], 'side force', units, '10.1f')}")
    if out is not None:
        echo(f"profile written to {out}")


def _broomstick(cfg, path, bit_depth, frictions, depths, out, plot, as_json, kw,
                units, measured=None) -> None:
    from drillfric.drillstring import build_string
    from drillfric.torque_drag import broomstick, broomstick_figure, config_friction
    from drillfric.vocabulary import LoadCase
    from drillfric.wellpath import no_survey_path

    _check_out(out, _TABLE_SUFFIXES)
    if plot is None and out is not None:
        plot = out.with_suffix(".png")
    _check_out(plot, _PLOT_SUFFIXES)
    mus = _floats(frictions, "frictions") or list(_DEFAULT_FRICTIONS)
    if not all(0 <= m <= 2 for m in mus):
        raise UserError(f"--frictions must lie in [0, 2], got {printable(str(mus), 80)} — "
                        "fix: friction factors such as 0.1,0.2,0.3")
    string = build_string(cfg.sections, bit_depth)
    bha_m = string.bit_depth_m - string.bha_top_m
    grid = _floats(depths, "depths")
    if grid is None:
        grid = list(np.linspace(max(bha_m + 1.0, bit_depth / 50), bit_depth, 50))
    _check_depth(max(grid), "--depths")
    cases = [LoadCase.ROTATING_OFF_BOTTOM, LoadCase.PICK_UP, LoadCase.SLACK_OFF]
    if kw["wob_N"] > 0 or kw["bit_torque_Nm"] != 0:
        cases.append(LoadCase.ROTATING_ON_BOTTOM)
    work = len(grid) * len(mus) * len(cases) * max(grid) / cfg.model.element_length_m
    if work > MAX_BROOMSTICK_WORK:
        raise UserError(f"the broomstick of {_grid_text(grid, mus, cases)} at "
                        f"{cfg.model.element_length_m:g}-m elements "
                        f"is {work:.3g} element solves; the budget is {MAX_BROOMSTICK_WORK:.0e} "
                        "— fix: fewer --depths or --frictions, or a longer --element-length")
    path = no_survey_path(max(grid), cfg.tortuosity_rad_m) if path is None else path
    if callable(config_friction(cfg)):
        warn("broomstick uses one friction factor per curve; cased/open-hole values ignored")
    table = broomstick(path, cfg.sections, grid, mus, cases,
                       mud_out_kg_m3=cfg.fluid.mud_density_kg_m3,
                       mud_in_kg_m3=cfg.inner_mud_density_kg_m3,
                       element_length_m=cfg.model.element_length_m, **kw)
    if out is not None:
        _write_table(table, out)
    check = None
    if measured is not None and len(measured):
        from drillfric.report.broomstick import weight_check

        check = weight_check(measured, table)
        if check["warning"]:
            warn(check["warning"])
    if plot is not None:
        plot.parent.mkdir(parents=True, exist_ok=True)
        from drillfric.io.atomic import replacing

        with replacing(plot) as tmp:  # a path derived from --out: never through a link
            broomstick_figure(table, measured).savefig(tmp, dpi=120)
    if as_json:
        click.echo(table.to_json(orient="records", indent=2))
        return
    from drillfric.units import format_value as show

    if measured is not None:
        echo(f"measured: {plural(len(measured), 'rotating segment')} of the log drawn on the "
             "plot"
             + (f"; implied block weight {check['block_weight_N'] / 1e3:.0f} kN "
                "(median measured − modelled rotating hook load)"
                if check and check["checked"] else ""))
    echo(f"broomstick: {_grid_text(grid, mus, cases)} ({show(grid[0], 'length', units, '.0f')}–"
         f"{show(grid[-1], 'length', units, '.0f')})")
    last = table[table["bit_depth_m"] == table["bit_depth_m"].max()]
    for row in last.itertuples():
        echo(f"  at {show(row.bit_depth_m, 'length', units, '7.1f')}  μ = "
             f"{row.friction_factor:4.2f}  {row.load_case:20s} hook load "
             f"{show(row.hookload_N, 'force', units, '8.1f')}  "
             f"torque {show(row.surface_torque_Nm, 'torque', units, '6.2f')}")
    for target in (out, plot):
        if target is not None:
            echo(f"written {target}")


def _grid_text(grid, mus, cases) -> str:
    """``"50 depths × 3 friction factors × 3 load cases"`` of a broomstick."""
    return (f"{plural(len(grid), 'depth')} × {plural(len(mus), 'friction factor')} × "
            f"{plural(len(cases), 'load case')}")
