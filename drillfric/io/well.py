"""A well on disk (INTERFACE.md) read into one in-memory representation in SI units.

A well is one of

- a data file ``NAME.{parquet,csv,h5,hdf5,las}`` with optional sidecars found by name:
  ``NAME.toml`` (configuration) and ``NAME.survey.{csv,parquet}`` (survey);
- an HDF5 file holding the surface table ``/surface``, the survey ``/survey`` and the
  configuration ``/config`` (a TOML text dataset, a ``toml`` attribute, or attributes
  named ``table.key``);
- a directory holding ``well.toml``, whose ``[well] data`` and ``[survey] file`` name its
  files (relative to the directory).

Precedence: ``--config``/``--survey`` > the configuration's ``[survey] file`` > sidecars
by name > tables inside an HDF5 file. Without a survey, ``survey`` is None and the
pipeline assumes a vertical well with the nominal tortuosity ``survey.tortuosity_deg_30m``.

:func:`load_well` reads everything; :func:`iter_surface` streams the same canonical
columns chunk by chunk with one time origin, so large files never need to fit in memory.
"""

from __future__ import annotations

import tomllib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.config import Config, config_from_dict, load_config, read_toml
from drillfric.errors import ConfigError, InputError
from drillfric.io.channels import Mapping, find_column, map_channels
from drillfric.io.readers import FORMATS, NULL_VALUES, RawSource, data_format, open_source
from drillfric.io.timebase import TimeBase, TimeTracker, check_plausible_rate, summarize
from drillfric.wellpath import WellPath

#: Rows per chunk of :func:`iter_surface` (a few tens of MB for a dozen channels).
CHUNK_ROWS = 200_000
_SURVEY_EXT = (".csv", ".parquet")
_HDF5_EXT = (".h5", ".hdf5")


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
        ``"default"`` or ``"name suffix"``.
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


# --------------------------------------------------------------------------- resolving
def resolve_well(path, *, config=None, survey=None) -> tuple[Path, Path | None, Path | None]:
    """Find a well's data, configuration and survey files without reading the data.

    Parameters
    ----------
    path : str or Path
        Data file, HDF5 bundle or well directory.
    config, survey : str or Path, optional
        Explicit files (``--config``, ``--survey``) overriding sidecars.

    Returns
    -------
    data_path, config_path, survey_path : Path, Path or None, Path or None
        For an HDF5 bundle, ``config_path``/``survey_path`` may be the HDF5 file itself
        (meaning its ``/config`` and ``/survey``).

    Raises
    ------
    InputError
        Missing path, unknown extension, a directory without ``well.toml``, or a file a
        configuration names that does not exist.
    """
    path = Path(path)
    if not path.exists():
        raise InputError("file not found", file=path, fix="check the path")
    config_path = None if config is None else Path(config)
    if path.is_dir():
        data_path, dir_config = _directory_data(path)
        config_path = config_path or dir_config
    else:
        data_format(path)
        data_path = path
        sidecar = path.with_suffix(".toml")
        config_path = config_path or (sidecar if sidecar.is_file() else None)
    if config_path is not None and not config_path.is_file():
        raise InputError("config file not found", file=config_path, fix="check the path")
    if config_path is None and _h5_has(data_path, "config"):
        config_path = data_path
    survey_path = Path(survey) if survey is not None else _find_survey(data_path, config_path)
    if survey_path is not None and not survey_path.is_file():
        raise InputError("survey file not found", file=survey_path, fix="check the path")
    return data_path, config_path, survey_path


def _directory_data(folder: Path) -> tuple[Path, Path]:
    well_toml = folder / "well.toml"
    if not well_toml.is_file():
        found = sorted(p.name for p in folder.iterdir() if p.suffix.lower() in FORMATS)
        raise InputError("well directory has no well.toml", file=folder,
                         fix='add well.toml with [well] data = "FILE"'
                             + (f" (data files here: {', '.join(found)})" if found else ""))
    data = read_toml(well_toml).get("well", {}).get("data")
    if not isinstance(data, str):
        raise ConfigError("well.toml does not name its data file", file=well_toml,
                          fix='add [well] data = "surface.parquet" (relative to the folder)')
    data_path = folder / data
    if not data_path.is_file():
        raise InputError("data file named by well.toml not found", file=data_path,
                         fix=f"fix [well] data in {well_toml}")
    data_format(data_path)
    return data_path, well_toml


def _find_survey(data_path: Path, config_path: Path | None) -> Path | None:
    if config_path is not None and config_path.suffix.lower() == ".toml":
        named = read_toml(config_path).get("survey", {}).get("file")
        if isinstance(named, str):
            return config_path.parent / named
    stem = data_path.with_suffix("")
    for ext in _SURVEY_EXT:
        candidate = stem.with_name(stem.name + ".survey" + ext)
        if candidate.is_file():
            return candidate
    return data_path if _h5_has(data_path, "survey") else None


def _h5_has(path: Path, key: str) -> bool:
    if path.suffix.lower() not in _HDF5_EXT or not path.is_file() or path.stat().st_size == 0:
        return False
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            return key in h5
    except OSError as exc:
        raise InputError("not a readable HDF5 file (truncated or corrupt)", file=path,
                         fix="re-export or re-copy the file") from exc


# --------------------------------------------------------------------------- config, survey
def _load_config(config_path: Path | None, config, overrides) -> Config:
    if isinstance(config, Config):
        return config
    if config_path is None:
        return load_config(None, overrides=overrides)
    if config_path.suffix.lower() in _HDF5_EXT:
        return config_from_dict(_h5_config(config_path), file=f"{config_path}:/config",
                                overrides=overrides)
    return load_config(config_path, overrides=overrides)


def _h5_config(path: Path) -> dict:
    """The ``/config`` of an HDF5 bundle as a raw TOML mapping."""
    import h5py

    where = f"{path}:/config"
    with h5py.File(path, "r") as h5:
        node = h5["config"]
        if isinstance(node, h5py.Dataset) or "toml" in node.attrs:
            text = node[()] if isinstance(node, h5py.Dataset) else node.attrs["toml"]
            text = text.decode() if isinstance(text, bytes) else str(text)
            try:
                return tomllib.loads(text)
            except tomllib.TOMLDecodeError as exc:
                raise ConfigError(f"not valid TOML ({exc})", file=where) from exc
        raw: dict = {}
        for group in [node] + [g for g in node.values() if isinstance(g, h5py.Group)]:
            prefix = "" if group is node else group.name.rsplit("/", 1)[-1] + "."
            for key, value in group.attrs.items():
                table, _, name = (prefix + key).rpartition(".")
                if not table:
                    raise ConfigError(f"attribute '{key}' of /config is not 'table.key'",
                                      file=where,
                                      fix="name attributes like fluid.mud_density_kg_m3")
                raw.setdefault(table, {})[name] = _plain(value)
        return raw


def _plain(value):
    """HDF5 attribute value as a plain Python value for the TOML validator."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    return value.item() if isinstance(value, np.generic) else value


def _load_survey(survey_path: Path | None) -> WellPath | None:
    if survey_path is None:
        return None
    from drillfric.io import survey as survey_io

    if survey_path.suffix.lower() in _HDF5_EXT:
        raw = open_source(survey_path, hdf_key="survey")
        frame = pd.concat(list(raw.chunks(CHUNK_ROWS)), ignore_index=True)
        table = survey_io.survey_table_from_frame(frame, file=f"{survey_path}:/survey")
        return survey_io.wellpath_from_table(table)
    return survey_io.read_survey(survey_path)


# --------------------------------------------------------------------------- surface data
def _open(data_path: Path, cfg: Config) -> tuple[RawSource, dict[str, Mapping]]:
    raw = open_source(data_path)
    if raw.depth_index is not None and find_column(raw.columns, "time", cfg.channels,
                                                   file=str(data_path)) is None:
        raise InputError(f"depth-indexed LAS log (index curve {raw.depth_index}) without a "
                         "time curve; drillfric needs time-indexed logs", file=data_path,
                         fix="export the time-based log (1 s or faster) from the rig's "
                             "recorder, or map a time curve of this file with [channels] "
                             'time = { column = "NAME", unit = "s" }')
    return raw, map_channels(raw.columns, raw.units, cfg.channels, file=str(data_path))


def _numeric(values: pd.Series) -> np.ndarray:
    """A source column as float64 with null markers → NaN (text that is not a number → NaN)."""
    if pd.api.types.is_numeric_dtype(values) and not pd.api.types.is_bool_dtype(values):
        out = values.to_numpy(dtype=float, na_value=np.nan).copy()
    else:
        out = _text_numbers(values.astype("string").str.strip())
    out[np.isin(out, NULL_VALUES)] = np.nan
    return out


_DECIMAL_COMMA = r"^-?(?:\d{1,3}(?:\.\d{3})+|\d+),\d+$"  # 17.730,5 or 1234,5


def _text_numbers(text: pd.Series) -> np.ndarray:
    """Numbers from text; a column read as text because of one bad token may still use a
    decimal comma (and thousands dots), which are read as such (only the bad cell is NaN).

    Examples
    --------
    >>> _text_numbers(pd.Series(["1,5", "17.730,25", "***", "2.5"], dtype="string")).tolist()
    [1.5, 17730.25, nan, 2.5]
    """
    out = pd.to_numeric(text, errors="coerce").to_numpy(dtype=float, na_value=np.nan)
    comma = text.str.fullmatch(_DECIMAL_COMMA).fillna(False).to_numpy(dtype=bool)
    if comma.any():
        fixed = text[comma].str.replace(".", "", regex=False).str.replace(",", ".", regex=False)
        out[comma] = pd.to_numeric(fixed, errors="coerce").to_numpy(dtype=float,
                                                                    na_value=np.nan)
    return out


def _convert(chunk: pd.DataFrame, mappings: dict[str, Mapping],
             tracker: TimeTracker) -> pd.DataFrame:
    """Canonical SI columns of one raw chunk (time checked by ``tracker``)."""
    time_s, keep = tracker.step(chunk[mappings["time"].column])
    out = {"time_s": time_s}
    if tracker.origin is not None:
        out["timestamp"] = tracker.origin + pd.to_timedelta(time_s, unit="s")
    for key, m in mappings.items():
        if key != "time":
            out[m.channel.name] = _numeric(chunk[m.column])[keep] * m.factor
    return pd.DataFrame(out)


def _stream(raw: RawSource, mappings: dict[str, Mapping], tracker: TimeTracker,
            chunk_rows: int) -> Iterator[pd.DataFrame]:
    for chunk in raw.chunks(chunk_rows):
        yield _convert(chunk, mappings, tracker)


def iter_surface(source, *, config=None, survey=None,
                 chunk_rows: int = CHUNK_ROWS) -> Iterator[pd.DataFrame]:
    """Stream a well's surface data as canonical SI chunks with one time origin.

    Parameters
    ----------
    source : str, Path or WellData
        A well on disk (read chunk by chunk: Parquet record batches, CSV chunks, HDF5 row
        slices) or an already loaded well (sliced).
    config : str, Path or Config, optional
        Configuration overriding the sidecar (for the ``[channels]`` mapping).
    survey : str or Path, optional
        Accepted for symmetry with :func:`load_well` (the survey is not streamed).
    chunk_rows : int
        Rows read per chunk; a chunk may be shorter after dropping duplicate timestamps.

    Yields
    ------
    pandas.DataFrame
        The columns of :attr:`WellData.surface`; concatenated they equal it.
    """
    if isinstance(source, WellData):
        return _slices(source.surface, chunk_rows)
    # Files are found and opened now, so that a bad well fails at the call, not mid-loop.
    data_path, config_path, _ = resolve_well(
        source, config=None if isinstance(config, Config) else config, survey=survey)
    cfg = _load_config(config_path, config, None)
    raw, mappings = _open(data_path, cfg)
    tracker = TimeTracker(mappings["time"].factor, file=str(data_path),
                          column=mappings["time"].column)
    return _stream(raw, mappings, tracker, chunk_rows)


def _slices(frame: pd.DataFrame, chunk_rows: int) -> Iterator[pd.DataFrame]:
    for start in range(0, len(frame), chunk_rows):
        yield frame.iloc[start:start + chunk_rows].reset_index(drop=True)


def load_well(path, *, config=None, survey=None, overrides=None,
              chunk_rows: int = CHUNK_ROWS) -> WellData:
    """Read a well (data, configuration, survey) into SI units.

    Parameters
    ----------
    path : str or Path
        Data file, HDF5 bundle or well directory (INTERFACE.md "A well on disk").
    config : str, Path or Config, optional
        Configuration file (``--config``) or an already built :class:`Config`.
    survey : str or Path, optional
        Survey file (``--survey``).
    overrides : dict, optional
        ``{"table.key": value}`` from the command line.
    chunk_rows : int
        Rows per read chunk.

    Raises
    ------
    InputError, ConfigError
        One line naming the file, the problem and the fix.
    """
    data_path, config_path, survey_path = resolve_well(
        path, config=None if isinstance(config, Config) else config, survey=survey)
    cfg = _load_config(config_path, config, overrides)
    raw, mappings = _open(data_path, cfg)
    tracker = TimeTracker(mappings["time"].factor, file=str(data_path),
                          column=mappings["time"].column)
    chunks = list(_stream(raw, mappings, tracker, chunk_rows))
    surface = pd.concat(chunks, ignore_index=True) if chunks else pd.DataFrame()
    if surface.empty:
        raise InputError("no data rows with a time", file=data_path,
                         fix="give a file with data rows (and a readable time column)")
    check_plausible_rate(surface["time_s"].to_numpy(), file=data_path)
    timebase = summarize(surface["time_s"].to_numpy(), max_gap_s=cfg["segmentation.max_gap_s"],
                         duplicates_dropped=tracker.duplicates, untimed_dropped=tracker.untimed,
                         origin=tracker.origin, source_start_s=tracker.source_start_s)
    files = {"data": data_path}
    if config_path is not None or isinstance(config, Config) and config.source is not None:
        files["config"] = config_path or config.source
    if survey_path is not None:
        files["survey"] = survey_path
    well_name = cfg["well.name"] or (Path(path).name if Path(path).is_dir() else data_path.stem)
    return WellData(name=well_name, surface=surface, survey=_load_survey(survey_path),
                    config=cfg, channels=_channel_infos(mappings, surface, tracker),
                    timebase=timebase, files=files)


def _channel_infos(mappings: dict[str, Mapping], surface: pd.DataFrame,
                   tracker: TimeTracker) -> dict[str, ChannelInfo]:
    out = {}
    for key, m in mappings.items():
        if key == "time":
            total = len(surface) + tracker.untimed + tracker.duplicates
            nulls = tracker.untimed / total if total else 0.0
            unit = "ISO 8601" if tracker.origin is not None else m.unit
            source = "header" if tracker.origin is not None else m.source
        else:
            nulls = float(surface[m.channel.name].isna().mean())
            unit, source = m.unit, m.source
        out[m.channel.name] = ChannelInfo(m.channel.name, str(m.column), unit, source, nulls)
    return out



def load_setup(path, *, config=None, survey=None,
               overrides=None) -> tuple[Config, WellPath | None]:
    """Configuration and survey of a well without reading its surface data.

    For commands that need the string and the well path but not the log (``td``). Files
    are found as in :func:`resolve_well`.
    """
    _, config_path, survey_path = resolve_well(
        path, config=None if isinstance(config, Config) else config, survey=survey)
    return _load_config(config_path, config, overrides), _load_survey(survey_path)


def channel_mappings(path, cfg: Config, *, config=None) -> dict[str, Mapping]:
    """How each channel of a well's data file is read (column, unit and where the unit came
    from), keyed by canonical name. Reads only the file's header."""
    data_path, _, _ = resolve_well(path, config=None if isinstance(config, Config) else config)
    _, mappings = _open(data_path, cfg)
    return {m.channel.name: m for m in mappings.values()}


def assumed_units(mappings: dict[str, Mapping]) -> list[str]:
    """Channels whose unit nothing stated (file, config or name): the documented default
    was assumed — for the run summary's ``assumed`` list."""
    return [f"unit of {m.channel.name} (column {m.column}): {m.unit}, the default — nothing "
            "in the file or the config says" for m in mappings.values() if m.source == "default"]
