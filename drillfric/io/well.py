"""A well on disk (docs/ingestion.md) read into one in-memory representation in SI units.

A well is one of

- a data file ``NAME.{parquet,csv,h5,hdf5,las,xml,dlis,xlsx}`` with optional sidecars found
  by name: ``NAME.toml`` (configuration), ``NAME.survey.{csv,parquet,xml}`` (survey; ``.xml``
  a WITSML trajectory) and ``NAME.tubular.xml`` (a WITSML tubular: the string);
- a WITSML log split over numbered files (``00001.xml``, ``00002.xml`` … in one folder, or
  ``NAME_1.xml``, ``NAME_2.xml`` … side by side): the folder or any one of the parts is one
  data file named by the folder (``NAME``) — its parts are read as one log in index order
  (:func:`drillfric.io.witsml.split_log`, :func:`~drillfric.io.witsml.open_witsml_parts`);
- an HDF5 file holding the surface table ``/surface``, the survey ``/survey`` and the
  configuration ``/config`` (a TOML text dataset, a ``toml`` attribute, or attributes
  named ``table.key``);
- a directory holding ``well.toml``, whose ``[well] data`` and ``[survey] file`` name its
  files (relative to the directory); ``[well] data`` may be left out when the directory
  holds the numbered parts of a WITSML log; ``[well] data`` may name a folder of CSV or
  Parquet files of one log (hourly or daily exports), read in name order
  (:mod:`drillfric.io.parts`).

Precedence: ``--config``/``--survey`` > the configuration's ``[survey] file`` > sidecars
by name > objects inside the data file (an HDF5 ``/survey``; a WITSML ``<trajectory>`` or
``<tubular>`` beside the log). Without a survey, ``survey`` is None and the pipeline
assumes a vertical well with the nominal tortuosity ``survey.tortuosity_deg_30m``; the
string is the configuration's ``[[string.sections]]``, else a WITSML tubular, else the
documented default (assumed).

A well may also be data in memory: ``open_well(frame=DataFrame, survey=DataFrame or
WellPath, config=dict or path)`` — a notebook's table from a historian or a warehouse goes
through the same channel mapping, units and checks as a file's (it is read as a data file
is, in blocks of rows), and no sidecar is looked for.

A well is opened **once** (:func:`open_well`): its files found, its configuration and survey
read, its data file's header mapped to channels, and its name fixed — into a :class:`Well`
that ``run``, ``fleet``, ``td`` and ``inspect`` all take. :meth:`Well.chunks` then streams
the canonical SI columns chunk by chunk with one time origin (large files never need to fit
in memory) and :meth:`Well.load` reads everything into a :class:`WellData`.

A well's name is data, not a path: :func:`safe_name` makes it one safe path component
(docs/security.md), the only rule by which an output directory is named.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.config import Config, config_from_dict, read_toml
from drillfric.errors import DrillfricError, InputError
from drillfric.files import require_file
from drillfric.io import witsml, witsml_objects
from drillfric.io.channels import Mapping, candidate_columns, log_index, map_channels, split_unit
from drillfric.io.grouping import grouping_name, misgrouped
from drillfric.io.grouping import text_numbers as _text_numbers
from drillfric.io.parts import PART_ATTR, open_parts
from drillfric.io.readers import open_source
from drillfric.io.source import NULL_VALUES, RawSource
from drillfric.io.text import plural, printable
from drillfric.io.timebase import (
    TimeBase,
    TimeTracker,
    check_plausible_rate,
    holds_timestamps,
    summarize,
)
from drillfric.io.wellfiles import (
    FRAME_LABEL,
    HDF5_EXT,
    WellFiles,
    default_name,
    find_string,
    find_survey,
    frame_files,
    given_file,
    resolve_files,
    safe_name,
)
from drillfric.wellpath import WellPath

#: Rows per chunk of :meth:`Well.chunks` (a few tens of MB for a dozen channels).
CHUNK_ROWS = 200_000
#: Unit shown for a time column of absolute timestamps (not a unit anything assumed).
CLOCK_UNIT = "ISO 8601"
#: The name of a well opened from a DataFrame that nothing names (``name=``, ``[well] name``).
FRAME_NAME = "well"
#: Fewest rows of a file whose header may be quoted as a data log's (:func:`log_shaped`).
LOG_MIN_ROWS = 10
#: Column names of a date beside a time column (a time of day written HHMMSS: messages).
_DATE_NAMES = frozenset({"date", "yyyymmdd", "yymmdd", "ddmmyy", "ddmmyyyy", "day"})
#: Rows read ahead to tell whether a time column without a stated unit holds timestamps.
_PEEK_ROWS = 64


@dataclass(frozen=True)
class ChannelInfo:
    """Where a canonical channel came from.

    Attributes
    ----------
    name : str
        Canonical column, e.g. ``surface_torque_Nm``.
    column : str
        Source column name (its 0-based index as text for headerless files).
    unit : str
        Source unit as found or assumed.
    source : str
        Where the unit came from: ``"header"``, ``"units row"``, ``"config"``,
        ``"default"``, ``"name suffix"`` or ``"values"`` (a time column of timestamps).
    null_fraction : float
        Fraction of rows without a value (empty, NaN, -999.25, -9999) [-].
    """

    name: str
    column: str
    unit: str
    source: str
    null_fraction: float


@dataclass(frozen=True)
class WellData:
    """One well in memory, SI units.

    Attributes
    ----------
    name : str
    surface : pandas.DataFrame
        Canonical columns (``time_s``, ``surface_rpm``, ``surface_torque_Nm``, … and
        ``timestamp`` when the file has absolute times).
    survey : WellPath or None
        Well path by minimum curvature; None when no survey was found (assume vertical,
        with the nominal tortuosity of :func:`drillfric.wellpath.no_survey_path`).
    config : Config
        Effective configuration.
    channels : dict of str to ChannelInfo
        Keyed by canonical column name.
    timebase : TimeBase
    files : dict of str to Path
        ``"data"`` and, when used, ``"config"`` and ``"survey"``.
    """

    name: str
    surface: pd.DataFrame
    survey: WellPath | None
    config: Config
    channels: dict[str, ChannelInfo]
    timebase: TimeBase
    files: dict[str, Path]


@dataclass(frozen=True)
class Well:
    """A well opened once: files, effective configuration, well path, channels and name.

    Built by :func:`open_well`; reading the surface data is left to :meth:`chunks` (streamed)
    or :meth:`load` (whole).

    Attributes
    ----------
    name : str
        The well's name as given (``[well] name``, a manifest's ``well`` column, or the file
        stem / directory name), made printable (control characters → ``?``).
    dir_name : str
        Its output directory name, ``safe_name(name)``: one safe path component.
    files : WellFiles
    config : Config
        Effective configuration (defaults < file < overrides).
    survey : WellPath or None
        Well path by minimum curvature; None without a survey.
    source : RawSource or None
        The opened data file (header read, data not); None when opened without its header
        (``open_well(..., header=False)``: commands that need the string and the well path
        only, like ``td``).
    mappings : dict of str to Mapping
        How each channel is read, keyed by ``[channels]`` key (``"time"``, ``"surface_rpm"``…);
        empty without the header.
    """

    name: str
    dir_name: str
    files: WellFiles
    config: Config
    survey: WellPath | None
    source: RawSource | None = field(default=None, repr=False)
    mappings: dict[str, Mapping] = field(default_factory=dict, repr=False)

    def __repr__(self) -> str:
        """One line: name, data file, index, channels, survey (stations, last MD [m])."""
        survey = "no survey" if self.survey is None else \
            f"survey of {plural(self.survey.md_m.size, 'station')} to {self.survey.md_m[-1]:.0f} m"
        index = "depth-indexed" if self.depth_indexed else "time-indexed"
        channels = ", ".join(self.channels) or "not read"
        return (f"<Well {self.name!r}: {self.files.data.name}, {index}, "
                f"{plural(len(self.mappings), 'channel')} ({channels}), {survey}>")

    @property
    def channels(self) -> dict[str, Mapping]:
        """The channel mappings keyed by canonical column name (``surface_torque_Nm``)."""
        return {m.channel.name: m for m in self.mappings.values()}

    @property
    def depth_indexed(self) -> bool:
        """Whether the data file is a depth-indexed log (per-depth averages, no time base):
        ``run`` turns it into a static friction log (:mod:`drillfric.estimation.friction_log`)."""
        return bool(self.mappings) and "time" not in self.mappings

    @property
    def assumed(self) -> list[str]:
        """What was assumed for this well: configuration defaults, the hole without a
        survey, and channel units nothing stated (docs/ingestion.md)."""
        units = [f"unit of {m.channel.name} (column {printable(m.column)}): {m.unit}, the "
                 "default — nothing in the file or the config says"
                 for m in self.mappings.values() if m.source == "default"]
        chosen = [m.note for m in self.mappings.values() if m.note]
        return self.config.assumed_with(self.survey) + chosen + units

    def time_tracker(self) -> TimeTracker | None:
        """A fresh time-base tracker for one pass over the data (origin, duplicates); None
        for a depth-indexed log."""
        if self.depth_indexed:
            return None
        time = self.mappings["time"]
        dates = [c for c in (self.source.columns if self.source is not None else [])
                 if split_unit(str(c))[0].strip().casefold() in _DATE_NAMES]
        return TimeTracker(time.factor, file=str(self.files.data), column=time.column,
                           date_column=dates[0] if dates else None)

    def chunks(self, chunk_rows: int = CHUNK_ROWS,
               tracker: TimeTracker | None = None) -> Iterator[pd.DataFrame]:
        """Stream the surface data as canonical SI chunks with one time origin.

        Yields DataFrames with the columns of :attr:`WellData.surface`; concatenated they
        equal :meth:`load`'s. Each call reads the file again from the start (pass a
        :meth:`time_tracker` to read the time base's counts afterwards). A depth-indexed
        log yields ``measured_depth_m`` and its other channels, row for row, instead.
        """
        if self.source is None:
            raise ValueError("well opened without its data file's header (header=False)")
        tracker = tracker or self.time_tracker()
        for chunk in self.source.chunks(chunk_rows):
            yield self.canonical(chunk, tracker)
        rest = None if tracker is None else tracker.flush()
        if rest is not None and len(rest):
            yield rest

    def canonical(self, raw: pd.DataFrame, tracker: TimeTracker | None) -> pd.DataFrame:
        """One raw chunk of the data (the source's columns) as canonical SI columns, its
        time checked by ``tracker`` (:meth:`chunks` does this for every chunk).

        The rows of the chunk's last time are held back by ``tracker`` until the next
        chunk shows whether that time repeats (:meth:`~drillfric.io.timebase.TimeTracker.
        settle`); ``tracker.flush()`` hands them out at the end of the data."""
        frame = _convert(raw, self.mappings, tracker, self.files.data)
        return frame if tracker is None else tracker.settle(frame)

    def load(self, chunk_rows: int = CHUNK_ROWS) -> WellData:
        """Read the whole surface log into a :class:`WellData` (SI units); a time log only."""
        if self.depth_indexed:
            raise InputError("a depth-indexed log has no time base", file=self.files.data,
                             fix="read it with drillfric.estimation.friction_log.read_depth_log")
        tracker = self.time_tracker()
        chunks = list(self.chunks(chunk_rows, tracker))
        surface = pd.concat(chunks, ignore_index=True) if chunks else pd.DataFrame()
        tracker.check_conflicts(len(surface))
        if surface.empty:
            raise InputError("no data rows with a time", file=self.files.data,
                             fix="give a file with data rows (and a readable time column)")
        check_plausible_rate(surface["time_s"].to_numpy(), file=self.files.data)
        timebase = summarize(surface["time_s"].to_numpy(),
                             max_gap_s=self.config.segmentation.max_gap_s,
                             duplicates_dropped=tracker.duplicates,
                             untimed_dropped=tracker.untimed, origin=tracker.origin,
                             source_start_s=tracker.source_start_s,
                             conflicts_dropped=tracker.conflicts)
        files = {k: v for k, v in (("data", self.files.data), ("config", self.files.config),
                                   ("survey", self.files.survey),
                                   ("string", self.files.string)) if v is not None}
        return WellData(name=self.name, surface=surface, survey=self.survey,
                        config=self.config,
                        channels=_channel_infos(self.mappings, surface, tracker),
                        timebase=timebase, files=files)


def open_well(path=None, *, frame: pd.DataFrame | None = None, config=None, survey=None,
              overrides=None, name: str | None = None, header: bool = True,
              string=None) -> Well:
    """Open a well once: find its files, read its configuration and survey, map its channels.

    Parameters
    ----------
    path : str or Path, optional
        Data file, HDF5 bundle or well directory (docs/ingestion.md "A well on disk").
    frame : pandas.DataFrame, optional
        The surface data in memory instead of ``path``: columns named as a file's header
        would be (units in the names, or ``[channels]`` in ``config``); an index that is not
        a plain row number (a clock-time index) is a column named by the index. No sidecar
        is looked for.
    config : str, Path, dict or Config, optional
        Configuration file (``--config``), the configuration as a mapping (the TOML's
        tables), or an already built :class:`Config`.
    survey : str, Path, DataFrame or WellPath, optional
        Survey file (``--survey``; the sidecar survey is then not read at all), a survey
        table (columns as a survey file's header) or a computed well path.
    overrides : dict, optional
        ``{"table.key": value}`` from the command line.
    name : str, optional
        The well's name (a manifest's ``well`` column), overriding ``[well] name``.
    header : bool
        Open the data file and map its channels (False: configuration and survey only).
    string : str or Path, optional
        WITSML tubular file read as the string (``--string``; the ``NAME.tubular.xml``
        sidecar is then not read), for a configuration without ``[[string.sections]]``.

    Raises
    ------
    InputError, ConfigError
        One line naming the file, the problem and the fix.
    """
    if (path is None) == (frame is None):
        raise InputError("give a well's data file or its data in memory, one of the two",
                         fix="open_well('well.csv', ...) or open_well(frame=data, ...)")
    files, raw = (resolve_files(path, config, survey, string=string) if frame is None else
                  frame_files(config, survey, string))
    cfg = _config(files.config, raw, config, overrides, files.string)
    given = default_name(path, files.data) if frame is None else FRAME_NAME
    shown = printable(name or cfg.well.name or given, 4096)
    path_m = _checked(_well_path(files.survey, survey), cfg, files.survey)
    source, mappings = _open(files, cfg, frame) if header else (None, {})
    return Well(name=shown, dir_name=safe_name(shown, files.config or files.data),
                files=files, config=cfg, survey=path_m, source=source, mappings=mappings)


def with_parts(well: Well, parts: tuple[Path, ...]) -> Well:
    """``well`` with its log read from ``parts`` — the files of its data folder that have
    arrived so far (``drillfric live`` on a folder, docs/live.md) — its channels mapped from
    their header (every part must have the first part's columns).

    Raises
    ------
    InputError
        A part not readable as the first part is (other columns, not a data file).
    """
    files = replace(well.files, parts=tuple(parts))
    source, mappings = _open(files, well.config)
    return replace(well, files=files, source=source, mappings=mappings)


def find_well(path, *, config=None, survey=None, name: str | None = None, string=None
              ) -> tuple[WellFiles, str | None]:
    """A well's files and name from its paths and sidecars alone: no data file is opened
    (a fleet's parent prepares wells this way; its workers open them, docs/fleet.md).

    Parameters
    ----------
    path, config, survey, string
        As for :func:`open_well`.
    name : str, optional
        The well's name (a manifest's ``well`` column).

    Returns
    -------
    (WellFiles, str or None)
        The files found (a configuration, survey or tubular stored inside the data file is
        not among them) and the name :func:`open_well` gives the well — None when it may be
        stored inside the data file (an HDF5 bundle without a TOML configuration, or the
        numbered folder of a WITSML log, named by the log).

    Raises
    ------
    InputError, ConfigError
        Missing files, an unreadable TOML configuration.
    """
    files, raw = resolve_files(path, config, survey, peek=False, string=string)
    table = raw.get("well") if isinstance(raw.get("well"), dict) else {}
    given = name or table.get("name") or None
    if given is not None:
        return files, printable(given, 4096) if isinstance(given, str) else None
    path = Path(path)
    if path.is_dir() and path.resolve() != files.data.resolve():
        return files, printable(path.resolve().name, 4096)
    inside = files.config is None and files.data.suffix.lower() in HDF5_EXT
    if inside or (files.data.is_dir() and files.data.resolve().name.isdigit()):
        return files, None
    return files, printable(default_name(path, files.data), 4096)


def open_config(config, *, survey=None, overrides=None
                ) -> tuple[Config, Path | None, WellPath | None]:
    """A well configuration on its own (``simulate NAME.toml``, ``td NAME.toml``): the
    configuration read once and its survey — ``survey``, else the configuration's
    ``[survey] file``, else ``NAME.survey.{csv,parquet}`` beside it, as for a data file.

    Returns
    -------
    (Config, survey path or None, WellPath or None)
    """
    path = require_file(Path(config), "config file")
    raw = read_toml(path)
    survey_path = Path(survey) if survey is not None else find_survey(path, path, raw,
                                                                       confined=False)
    if survey_path is not None:
        require_file(survey_path, "survey file")
    cfg = _config(path, raw, None, overrides, find_string(path, raw))
    return cfg, survey_path, _checked(_load_survey(survey_path), cfg, survey_path)


# --------------------------------------------------------------------------- resolving


# --------------------------------------------------------------------------- config, survey


def _config(config_path: Path | None, raw: dict, config, overrides,
            string: Path | None = None) -> Config:
    """The effective configuration: ``config`` when it is a built :class:`Config`, else the
    validated raw mapping with the command line's ``overrides`` and, when the mapping has
    no ``[[string.sections]]``, the sections of the WITSML tubular ``string``."""
    if isinstance(config, Config):
        return config
    where = None if config_path is None else (
        f"{config_path}:/config" if config_path.suffix.lower() in HDF5_EXT else config_path)
    if string is not None:
        table = raw.get("string") if isinstance(raw.get("string"), dict) else {}
        raw = raw | {"string": table | {"sections": witsml_objects.tubular_sections(string)}}
    return config_from_dict(raw, file=where, overrides=overrides)


def _checked(path: WellPath | None, cfg: Config, file) -> WellPath | None:
    """``path`` once its dog-legs pass ``survey.max_dogleg_deg_30m``
    (:func:`drillfric.io.survey.check_doglegs`)."""
    if path is not None:
        from drillfric.io import survey as survey_io

        survey_io.check_doglegs(path, cfg.survey.max_dogleg_deg_30m, file or "survey")
    return path


def _well_path(survey_path: Path | None, given) -> WellPath | None:
    """The well path of the survey file, or of a survey given in memory (a table with a
    survey file's columns, or a :class:`WellPath`)."""
    if given is None or given_file(given) is not None:
        return _load_survey(survey_path)
    if isinstance(given, WellPath):
        return given
    if not isinstance(given, pd.DataFrame):
        raise InputError(f"survey is a {type(given).__name__}", file="survey",
                         fix="give a survey file, a DataFrame (md, inc, azi) or a WellPath")
    from drillfric.io import survey as survey_io

    table = survey_io.survey_table_from_frame(given, file="survey DataFrame")
    return survey_io.wellpath_from_table(table)


def _load_survey(survey_path: Path | None) -> WellPath | None:
    if survey_path is None:
        return None
    from drillfric.io import survey as survey_io

    if survey_path.suffix.lower() in HDF5_EXT:
        raw = open_source(survey_path, hdf_key="survey")
        frame = pd.concat(list(raw.chunks(CHUNK_ROWS)), ignore_index=True)
        table = survey_io.survey_table_from_frame(frame, file=f"{survey_path}:/survey")
        return survey_io.wellpath_from_table(table)
    return survey_io.read_survey(survey_path)


# --------------------------------------------------------------------------- surface data
def _open(files: WellFiles, cfg: Config,
          frame: pd.DataFrame | None = None) -> tuple[RawSource, dict[str, Mapping]]:
    """The opened data file (or log parts, or ``frame``) and its channel mappings, for a
    time or a depth log (:func:`~drillfric.io.channels.log_index`); a depth index found by
    the reader (LAS, WITSML, DLIS) is the measured depth unless ``[channels]
    measured_depth`` says otherwise."""
    raw = (frame_source(frame) if frame is not None else
           open_parts(files.parts) if files.parts and files.parts[0].suffix.lower() != ".xml"
           else witsml.open_witsml_parts(files.parts) if files.parts
           else open_source(files.data))
    file = str(files.data) + (f" ({raw.where})" if raw.where else "")
    index = log_index(raw.columns, cfg.channels, depth_index=raw.depth_index, file=file)
    channels = cfg.channels
    if index == "depth" and raw.depth_index is not None and "measured_depth" not in channels:
        channels = channels | {"measured_depth": {"column": split_unit(raw.depth_index)[0]}}
    mappings = map_channels(raw.columns, raw.units, channels, file=file, index=index,
                            log_shaped=lambda: log_shaped(raw))
    mappings = prefer_live(raw, mappings, channels, file=file, index=index)
    return raw, check_narrow(raw, _clock_time(raw, mappings), file=file)


#: Finest time step a log needs its time column to resolve [s] (a 100-Hz log).
TIME_RESOLUTION_S = 0.01


def check_narrow(raw: RawSource, mappings: dict[str, Mapping], *,
                 file: str) -> dict[str, Mapping]:
    """The mappings once the columns stored narrower than float64 (Parquet float32,
    float16: :attr:`RawSource.narrow`) are known to hold what a run needs. They are read
    widened; but a float32 time resolves only 0.25 s at 2×10⁶ s (every 20-Hz sample then
    repeats a time: the run failed blaming the recorder), a float16 time only 2 s at 2048 s,
    and a float16 value beyond ±65 504 is written as infinity (read as missing: a hook load
    in N was lost in silence).

    Raises
    ------
    InputError
        A mapped time column whose type cannot resolve :data:`TIME_RESOLUTION_S` at the
        largest time it holds (a float16 time always).
    """
    out = dict(mappings)
    for key, m in mappings.items():
        if m.column not in raw.narrow:
            continue
        kind, largest = raw.narrow[m.column]
        step = float(np.spacing(getattr(np, kind)(largest))) * abs(m.factor) \
            if np.isfinite(largest) else np.nan
        if key == "time" and (kind == "float16" or step > TIME_RESOLUTION_S):
            at = f": at {largest * abs(m.factor):.4g} s it resolves only {step:.3g} s" \
                if np.isfinite(step) else ""
            raise InputError(f"time column '{printable(m.column)}' is stored as {kind} "
                             f"({'half' if kind == 'float16' else 'single'} precision){at}, "
                             "so samples closer than that share one time", file=file,
                             fix="write the time column as float64 (double) or as "
                                 "timestamps")
        if kind == "float16" and key != "time":
            lost = (" — its largest values overflowed to infinity when written and are "
                    "read as missing" if not np.isfinite(largest) else "")
            out[key] = replace(m, note=(m.note or "") + (
                f"{m.channel.kind} from a half-precision (float16) column "
                f"'{printable(m.column)}': 3 significant digits, nothing beyond ±65 504"
                f"{lost} — write it as float32 or float64"))
    return out


def prefer_live(raw: RawSource, mappings: dict[str, Mapping], channels: dict, *,
                file: str, index: str = "time") -> dict[str, Mapping]:
    """The mappings with a channel that several columns could be (``RPM`` and ``TDRPM``,
    ``Rotary Speed`` and ``Top Drive Speed``) read from a column whose values change when the
    mnemonic table's choice holds none (empty, or one constant value over the whole log).

    A dead rotary-table speed preferred over the live top-drive speed made a run find nothing
    rotating and exit 0 having estimated nothing (issue 30, tenth attack). The data is read
    only when a channel has several candidates, and only until each chosen column has shown
    two different values (the first block, for a live log). The switch is a note naming both
    columns (:attr:`Well.assumed`); a channel ``[channels]`` names a column for is never
    switched.
    """
    keys = {k: cols for k, m in mappings.items() if k not in ("time", "measured_depth")
            and len(cols := candidate_columns(raw.columns, k, channels, raw.units)) > 1
            and m.column in cols}
    if not keys:
        return mappings
    wanted = sorted({c for cols in keys.values() for c in cols})
    first: dict[str, float] = {}
    live: set[str] = set()
    for chunk in raw.chunks(CHUNK_ROWS):
        for col in wanted:
            if col in live or col not in chunk.columns:
                continue
            values = _numeric(chunk[col], col, file)
            values = values[np.isfinite(values)]
            if values.size:
                ref = first.setdefault(col, float(values[0]))
                if np.any(values != ref):
                    live.add(col)
        if all(mappings[k].column in live for k in keys):
            return mappings
    passed: dict[str, set[str]] = {}
    for key, cols in keys.items():
        if mappings[key].column not in live and any(c in live for c in cols):
            passed[key] = {c for c in cols if c not in live}
    if not passed:
        return mappings
    remapped = map_channels(raw.columns, raw.units, channels, file=file, index=index,
                            passed_over=passed)
    out = dict(mappings)
    for key in passed:
        dead, new = mappings[key], remapped[key]
        held = ("no number" if dead.column not in first else
                f"the one value {first[dead.column]:.4g} throughout")
        out[key] = replace(new, note=(
            f"{dead.channel.kind} from column '{printable(new.column)}': column "
            f"'{printable(dead.column)}', which the mnemonic table prefers, holds {held} — "
            f"to read that one anyway: [channels] {key} = "
            f"{{ column = \"{printable(dead.column)}\" }}"))
    return out


def log_shaped(raw: RawSource, rows: int = 50) -> bool:
    """Whether a data file is recognisably a data log though none of its column names is
    known: its first ``rows`` rows (at least :data:`LOG_MIN_ROWS`) hold numbers in at least
    three columns (time, speed and torque at the least), and in at least half of them, and no
    column name is a ``key=value`` pair (then its header may be quoted in a message,
    docs/security.md; a file named by mistake — a list of secrets — is not a log)."""
    try:
        head = next(iter(raw.chunks(rows)), None)
    except DrillfricError:
        return False
    if head is None or len(head) < LOG_MIN_ROWS or head.shape[1] < 3:
        return False
    if any("=" in str(c) for c in head.columns):
        return False
    numeric = sum(pd.to_numeric(head[c], errors="coerce").notna().mean() >= 0.9
                  for c in head.columns if head[c].notna().any())
    return numeric >= 3 and numeric >= head.shape[1] / 2


def frame_source(frame: pd.DataFrame) -> RawSource:
    """A DataFrame read as a data file is: its columns (labels as text; an index that is not
    a plain row number becomes a column; two levels are (name, unit), as a header and its
    units row, else no stated units), rows in blocks.

    Raises
    ------
    InputError
        Not a DataFrame, columns of several levels, or two columns of one label.
    """
    if not isinstance(frame, pd.DataFrame):
        raise InputError(f"frame is a {type(frame).__name__}, not a pandas DataFrame",
                         file=FRAME_LABEL, fix="give the surface data as a DataFrame")
    units: dict = {}
    if frame.columns.nlevels == 2:  # (name, unit), as a header and its units row
        pairs = [(str(a), str(b).strip()) for a, b in frame.columns]
        units = {a: b for a, b in pairs if b and not b.startswith("Unnamed")}
        frame = frame.set_axis([a for a, _ in pairs], axis=1)
    elif frame.columns.nlevels > 2:
        # the fix had been '_'.join of the levels: 'TORQUE_kft.lbf', a name no channel
        # matches, its unit lost (issue 30, twelfth attack)
        raise InputError(f"the columns have {frame.columns.nlevels} levels (a MultiIndex)",
                         file=FRAME_LABEL, fix="give one label per column, or two levels "
                         "(name, unit) read as a header and its units row")
    if not isinstance(frame.index, pd.RangeIndex):
        frame = frame.reset_index()
    frame = frame.set_axis([str(c) for c in frame.columns], axis=1)
    twice = sorted(set(frame.columns[frame.columns.duplicated()]))
    if twice:
        raise InputError(f"column {twice[0]!r} appears twice", file=FRAME_LABEL,
                         fix="give every column its own label")

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        for start in range(0, len(frame), chunk_rows):
            yield frame.iloc[start:start + chunk_rows]

    return RawSource(FRAME_LABEL, "frame", list(frame.columns), units, len(frame), read)


def _clock_time(raw: RawSource, mappings: dict[str, Mapping]) -> dict[str, Mapping]:
    """The mappings with a time column of absolute timestamps marked as such (unit
    :data:`CLOCK_UNIT`, source ``"values"``): its unit is then nothing assumed. Only a time
    column no unit was stated for is looked at (its first rows)."""
    time = mappings.get("time")
    if time is None or time.source != "default":
        return mappings
    chunks = raw.chunks(_PEEK_ROWS)
    try:
        head = next(chunks, None)
    finally:
        chunks.close()
    if head is None or not holds_timestamps(head[time.column]):
        return mappings
    return mappings | {"time": replace(time, unit=CLOCK_UNIT, source="values")}


def _numeric(values: pd.Series, column=None, file=None) -> np.ndarray:
    """A source column as float64 with null markers, ±inf and magnitudes beyond float32 →
    NaN (text that is not a number → NaN): no rig sensor reads 10³⁹ of anything, and the
    result files store float32, where such a value would become an infinity.

    Raises
    ------
    InputError
        A cell's digits are split by a space or an apostrophe that does not group thousands
        (``2 21,00``): no number can be told (:mod:`drillfric.io.grouping`).
    """
    if pd.api.types.is_numeric_dtype(values) and not pd.api.types.is_bool_dtype(values):
        out = values.to_numpy(dtype=float, na_value=np.nan).copy()
    else:
        text = values.astype("string").str.strip()
        out = _text_numbers(text)
        bad = misgrouped(text, out)
        if bad is not None:
            where = f"column '{printable(column)}'" if column is not None else "a column"
            raise InputError(f"{where} writes '{printable(bad, 20)}': digits split by "
                             f"{grouping_name(bad)} that does not group thousands (groups of "
                             "3 digits), so no number can be told", file=file,
                             fix="export the log without thousands separators (or with "
                                 "groups of exactly 3 digits)")
    out[np.isin(out, NULL_VALUES) | ~(np.abs(out) <= _FLOAT32_MAX)] = np.nan
    return out


_FLOAT32_MAX = float(np.finfo(np.float32).max)
def _convert(chunk: pd.DataFrame, mappings: dict[str, Mapping],
             tracker: TimeTracker | None, file=None) -> pd.DataFrame:
    """Canonical SI columns of one raw chunk (time checked by ``tracker``; None: a depth
    log, every row kept)."""
    out: dict = {}
    keep = slice(None)
    if tracker is not None:
        time_s, keep, stamps = tracker.step(chunk[mappings["time"].column],
                                            part=chunk.attrs.get(PART_ATTR))
        out["time_s"] = time_s
        if stamps is not None:
            out["timestamp"] = stamps.array
    for key, m in mappings.items():
        if key != "time":
            out[m.channel.name] = _numeric(chunk[m.column], m.column, file)[keep] * m.factor
    return pd.DataFrame(out)


def iter_surface(source, *, config=None, survey=None,
                 chunk_rows: int = CHUNK_ROWS) -> Iterator[pd.DataFrame]:
    """Stream a well's surface data as canonical SI chunks (:meth:`Well.chunks`).

    ``source`` is a :class:`Well`, a loaded :class:`WellData` (sliced) or a well on disk
    (opened here with ``config`` and ``survey``, so that a bad well fails at the call).
    """
    if isinstance(source, WellData):
        frame = source.surface
        return (frame.iloc[a:a + chunk_rows].reset_index(drop=True)
                for a in range(0, len(frame), chunk_rows))
    well = source if isinstance(source, Well) else open_well(source, config=config,
                                                             survey=survey)
    return well.chunks(chunk_rows)


def load_well(path, *, config=None, survey=None, overrides=None,
              chunk_rows: int = CHUNK_ROWS) -> WellData:
    """Read a well (data, configuration, survey) into SI units: :func:`open_well` then
    :meth:`Well.load` (parameters as there)."""
    return open_well(path, config=config, survey=survey, overrides=overrides).load(chunk_rows)


def _channel_infos(mappings: dict[str, Mapping], surface: pd.DataFrame,
                   tracker: TimeTracker) -> dict[str, ChannelInfo]:
    out = {}
    for key, m in mappings.items():
        if key == "time":
            total = len(surface) + tracker.untimed + tracker.duplicates + tracker.conflicts
            nulls = tracker.untimed / total if total else 0.0
            clock = tracker.origin is not None
            unit = CLOCK_UNIT if clock else m.unit
            source = "values" if clock and m.source == "default" else m.source
        else:
            nulls = float(surface[m.channel.name].isna().mean())
            unit, source = m.unit, m.source
        out[m.channel.name] = ChannelInfo(m.channel.name, str(m.column), unit, source, nulls)
    return out
