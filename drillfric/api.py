"""The public Python API: open a well, run it, read results back, torque and drag, simulate.

For notebooks and scripts (docs/api.md). Nothing is written unless asked (``out=``):

>>> import drillfric
>>> well = drillfric.open_well("examples/demo/demo.csv")          # doctest: +SKIP
>>> result = drillfric.run(well)                                  # doctest: +SKIP
>>> result.segments[["id", "mu_k", "mu_s", "converged"]]          # doctest: +SKIP

Each function is a thin front of the library layer it names; the command line calls the
same layers.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import pandas as pd

from drillfric.errors import InputError
from drillfric.io.results import read_json
from drillfric.io.well import Well, open_well
from drillfric.result import RunProgress, WellResult, segments_from_json
from drillfric.runner import run_well
from drillfric.runner.engine import Engine

__all__ = ["open_well", "run", "load_result", "torque_and_drag", "simulate", "Well",
           "WellResult", "RunProgress", "Engine"]


def run(well, out=None, *, rate_hz: float | None = None, pdf: bool = False,
        report: bool = True, progress=None, resume: bool = False, **open_kw) -> WellResult:
    """Estimate friction factors and bit speed for one well (``drillfric run`` in Python).

    Parameters
    ----------
    well : Well, str or Path
        An opened well (:func:`open_well`) or a path to one (opened here with ``open_kw``:
        ``config``, ``survey``, ``overrides``, ``name``).
    out : str or Path, optional
        Output directory: results written to ``out/NAME`` (summary.json, estimates.parquet,
        segments.parquet, report.html). None: nothing is written; the results are returned.
    rate_hz : float, optional
        Resample to this rate first (not above the data's own).
    pdf, report : bool
        Report options (with ``out``).
    progress : callable, optional
        Called with :class:`RunProgress` events.
    resume : bool
        With ``out``: continue from ``out/NAME/state`` when the data only grew (docs/fleet.md).

    Returns
    -------
    WellResult
        ``.summary`` (dict), ``.segments`` and ``.estimates`` (DataFrames), ``.warnings``.
    """
    if not isinstance(well, Well):
        well = open_well(well, **open_kw)
    return run_well(well, out, rate_hz=rate_hz, report=_report_writer(pdf) if report else None,
                    progress=progress, resume=resume)


def _report_writer(pdf: bool):
    """The run's report: report.html (and report.pdf with ``pdf``) of its result directory."""
    from drillfric.report import write_well_report

    return partial(write_well_report, pdf=pdf)


def load_result(result_dir) -> WellResult:
    """A result directory written by ``drillfric run`` (or :func:`run` with ``out``).

    Raises
    ------
    InputError
        Not a result directory (no readable summary.json).
    """
    folder = Path(result_dir)
    if not (folder / "summary.json").is_file():
        raise InputError("not a drillfric result directory (no summary.json)", file=folder,
                         fix="give OUT/NAME of a 'drillfric run'")
    summary = read_json(folder / "summary.json", fix="give OUT/NAME of a 'drillfric run'")
    segments = pd.read_parquet(folder / "segments.parquet") if (
        folder / "segments.parquet").is_file() else segments_from_json(
        summary.get("segments", []))
    return WellResult(summary.get("well", folder.name), summary, segments, out_dir=folder,
                      failed=summary.get("counts", {}).get("failed", 0),
                      warnings=list(summary.get("warnings", [])))


def torque_and_drag(well, bit_depth_m: float | None = None, *, friction: float | None = None,
                    load_case: str = "rotating_off_bottom", **kw):
    """Soft-string torque and drag at one bit depth (``drillfric td`` in Python).

    Parameters
    ----------
    well : Well, str or Path
        A well (its string, survey and mud are used) or a path to one.
    bit_depth_m : float, optional
        Bit depth [m] (default: the configuration's ``[well] bit_depth_m``, else the
        survey's last station).
    friction : float, optional
        Friction factor (default: the configuration's, per hole section).
    load_case : str
        ``rotating_off_bottom``, ``rotating_on_bottom``, ``pick_up``, ``slack_off``, …
    **kw
        Passed to :func:`drillfric.torque_drag.solve` (``wob_N``, ``bit_torque_Nm``, …).

    Returns
    -------
    drillfric.torque_drag.TDResult
        Tension, torque, normal force and F_c along the string; hook load, surface torque
        and T_N = ∫F_c dx.
    """
    from drillfric.torque_drag import solve_config

    if not isinstance(well, Well):
        well = open_well(well, header=False)
    if bit_depth_m is None:
        bit_depth_m = well.config.well.bit_depth_m
    if bit_depth_m is None:
        if well.survey is None:
            raise InputError("no survey: give bit_depth_m", file=well.files.data)
        bit_depth_m = well.survey.md_max_m
    return solve_config(well.config, well.survey, bit_depth_m, friction=friction,
                        load_case=load_case, **kw)


def simulate(config, *, out=None, **settings):
    """Synthetic surface data with ground truth (``drillfric simulate`` in Python).

    Parameters
    ----------
    config : str or Path
        A well configuration (TOML) naming the string, survey and ``[simulate]`` settings.
    out : str or Path, optional
        Data file to write (``.parquet``, ``.csv``, ``.h5``) with its sidecars; None: only
        returned.
    **settings
        ``[simulate]`` keys overriding the configuration (``mu_s``, ``mu_k``,
        ``bit_depth_m``, ``duration_s``, ``rate_hz``, ``seed``, …).

    Returns
    -------
    drillfric.sim.run.Simulation
        ``.frame()`` the surface channels, ``.truth()`` the ground truth.
    """
    from drillfric.sim.run import simulate_config

    return simulate_config(config, out=out, overrides={f"simulate.{k}": v
                                                       for k, v in settings.items()})
