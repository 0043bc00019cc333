"""Where a well's files are: its data, configuration, survey and string, found once.

A well is given as a data file with sidecars found by name (``NAME.toml``,
``NAME.survey.{csv,parquet,xml,txt,…}``, ``NAME.tubular.xml``), a folder holding
``well.toml`` (which names its files), a folder or numbered parts of a WITSML log, an HDF5
bundle (``/config``, ``/survey`` inside), or data in memory (:func:`frame_files`).
:func:`resolve_files` finds them without reading the data (``peek=False``: not even the data
file's header), so a fleet's parent can name its wells cheaply (docs/fleet.md);
:func:`safe_name` turns a well's name into one safe directory name. Files found or named
*for* the user must not lead out of their folder (docs/security.md).
"""

from __future__ import annotations

import hashlib
import os
import unicodedata
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drillfric.config import Config, parse_toml, read_toml
from drillfric.errors import ConfigError, InputError
from drillfric.files import require_file, require_inside, special
from drillfric.io import witsml
from drillfric.io.atomic import OUT_FILES, RECORDING_SUFFIX
from drillfric.io.hdf5 import members, node_at
from drillfric.io.parts import folder_parts
from drillfric.io.source import FORMATS, data_format
from drillfric.io.text import printable

#: Longest output directory name [bytes of UTF-8]; longer names are cut and given a hash.
MAX_NAME_BYTES = 100
#: Extensions of HDF5 files (a bundle may hold /config and /survey beside /surface).
HDF5_EXT = (".h5", ".hdf5")
#: Extensions of survey sidecars (NAME.survey.EXT), in the order they are looked for: every
#: extension :func:`drillfric.io.survey.read_survey` reads (a Volve ``F-5.survey.txt`` beside
#: its log had been passed over, and the well run as vertical, its μ 37 % high).
SURVEY_EXT = (".csv", ".parquet", ".xml", ".txt", ".tsv", ".dat", ".prn", ".asc", ".pq")
#: What errors name as the "file" of a well opened from a DataFrame (``open_well(frame=)``).
FRAME_LABEL = Path("<DataFrame>")


@dataclass(frozen=True)
class WellFiles:
    """The files of a well on disk.

    Attributes
    ----------
    data : Path
        Surface data file; for a WITSML log split over numbered files the folder of
        ``00001.xml`` … or ``folder / NAME`` for ``NAME_1.xml`` … (no such file).
    config, survey : Path or None
        Configuration and survey files in effect (for an HDF5 bundle, possibly the data
        file itself: its ``/config`` and ``/survey``; for a WITSML file, the file itself
        when it holds the trajectory beside the log).
    parts : tuple of Path
        The numbered part files of a WITSML log split over several files (by number; read
        in index order), or the CSV/Parquet files of a data folder (by name:
        :mod:`drillfric.io.parts`), else empty.
    string : Path or None
        WITSML tubular read as the string (``NAME.tubular.xml``, or the data file holding a
        ``<tubular>``) when the configuration has no ``[[string.sections]]``.
    in_memory : bool
        The data is a DataFrame (``open_well(frame=)``): ``data`` is :data:`FRAME_LABEL`,
        no file.
    """

    data: Path
    config: Path | None
    survey: Path | None
    parts: tuple[Path, ...] = ()
    string: Path | None = None
    in_memory: bool = False

    @property
    def inputs(self) -> dict[str, Path]:
        """The files read, by role: ``data`` (for a log split over parts one ``data NAME``
        per part instead; none for a DataFrame), ``config``, ``survey``, ``string`` —
        summary.json ``inputs``."""
        data = {f"data {p.name}": p for p in self.parts} if self.parts else {"data": self.data}
        data = {} if self.in_memory else data
        roles = data | {"config": self.config, "survey": self.survey, "string": self.string}
        return {role: path for role, path in roles.items() if path is not None}


def default_name(path, data_path: Path) -> str:
    """A well's name when nothing names it: the directory's name (resolved, so ``.`` is the
    folder it stands for) or the data file's stem. A WITSML log split over ``NAME_1.xml``,
    ``NAME_2.xml`` … is ``NAME``; the folder of a log's numbered parts ``00001.xml`` … is
    named like a directory, except a number (a WITSML store names its folders
    ``log/1/8/1``): then the log's wellbore and log names (``NO 15/9-F-4 GwdTime``)."""
    path = Path(path)
    if path.is_dir() and path.resolve() != data_path.resolve():
        return path.resolve().name
    if data_path.is_dir():
        name = data_path.resolve().name
        if name.isdigit():
            return witsml.log_title(witsml.witsml_log_parts(data_path)[0]) or name
        return name
    return data_path.name if not data_path.exists() else data_path.stem


def safe_name(raw, where=None) -> str:
    """One safe path component from a well name (docs/security.md).

    Path separators, NUL, control characters and blanks inside the name become ``_`` (a
    folder name a shell or a nightly script need not quote; the well keeps its shown name);
    leading and trailing dots and blanks go (no ``.``, ``..`` or hidden names); a name longer than
    :data:`MAX_NAME_BYTES` is cut and ends with a hash of the whole name, so distinct long
    names stay distinct.

    Raises
    ------
    ConfigError
        Nothing usable is left (e.g. ``"."`` or ``"///"``), or the name is one of drillfric's
        own files in OUT (:data:`OUT_FILES`, ``*.wits0.csv``).

    Examples
    --------
    >>> safe_name("../../x"), safe_name("A-12/ST1"), safe_name(".hidden"), safe_name("Well 7 ST")
    ('_.._x', 'A-12_ST1', 'hidden', 'Well_7_ST')
    """
    text = unicodedata.normalize("NFC", str(raw)).strip(". \t")
    text = "".join("_" if c in "/\\" or unicodedata.category(c)[0] in "CZ" else c
                   for c in text).strip(".")
    if not text or set(text) <= {"_", "."}:
        raise ConfigError(f"well name '{printable(raw)}' gives no usable directory name",
                          file=where, fix='name the well, e.g. [well] name = "A-12"')
    if len(text.encode()) > MAX_NAME_BYTES:
        digest = hashlib.sha256(str(raw).encode()).hexdigest()[:10]
        text = text.encode()[:MAX_NAME_BYTES - 11].decode("utf-8", "ignore") + "-" + digest
    if text.casefold() in OUT_FILES or text.casefold().endswith(RECORDING_SUFFIX):
        raise ConfigError(f"well name '{printable(raw)}' is the name of a file drillfric "
                          "writes in OUT beside the wells", file=where,
                          fix='name the well otherwise, e.g. [well] name = "A-12" (or rename '
                              'its file or folder)')
    return text


def resolve_well(path, *, config=None, survey=None) -> WellFiles:
    """Find a well's data, configuration and survey files without reading the data.

    Parameters
    ----------
    path : str or Path
        Data file, HDF5 bundle or well directory.
    config, survey : str or Path, optional
        Explicit files (``--config``, ``--survey``) overriding sidecars.

    Returns
    -------
    WellFiles
        For an HDF5 bundle, ``config``/``survey`` may be the HDF5 file itself (meaning its
        ``/config`` and ``/survey``).

    Raises
    ------
    InputError
        Missing path, unknown extension, a directory without ``well.toml``, or a file a
        configuration names that does not exist.
    """
    return resolve_files(path, config, survey)[0]


def resolve_files(path, config, survey, peek: bool = True,
                  string=None) -> tuple[WellFiles, dict]:
    """The files of a well and its raw configuration mapping, each file read once; a
    configuration or survey given in memory (a mapping, a table) stands for its file
    (``peek=False``: the data file is not opened, so a configuration, survey or tubular
    stored inside it is not found). ``string`` (``--string``): the WITSML tubular read as
    the string instead of a ``NAME.tubular.xml`` sidecar (:func:`given_string`)."""
    path = Path(path)
    if not path.exists():
        raise InputError("file not found", file=path, fix="check the path")
    config_path = given_file(config)
    raw = _mapping(config)
    look = config is None  # find the configuration beside the data (none given)
    if raw is None and config_path is not None and config_path.is_file():
        raw = raw_config(config_path)
    given = config_named(config_path, raw or {}, given_file(survey))
    if path.is_dir() and not (path / "well.toml").is_file() and witsml.split_log(path):
        data_path, parts = _data(path)
        config_path = _sidecar(data_path, ".toml") if look else config_path
    elif path.is_dir():
        data_path, parts, dir_config, dir_raw = _directory_data(path, given)
        if look:
            config_path, raw = dir_config, dir_raw
    else:
        data_path, parts = _data(path, given)
        config_path = _sidecar(data_path, ".toml") if look else config_path
    if config_path is not None:
        require_file(config_path, "config file")
    if look and peek and config_path is None and _h5_has(data_path, "config"):
        config_path = data_path
    if raw is None:
        raw = raw_config(config_path)
    survey_path = given_file(survey) if survey is not None else find_survey(
        data_path, config_path, raw, peek, confined=look)
    if survey_path is not None:
        require_file(survey_path, "survey file")
    string_path = given_string(string, raw) if string is not None else \
        find_string(data_path, raw, peek)
    return WellFiles(data_path, config_path, survey_path, parts, string_path), raw


def given_string(string, raw: dict) -> Path:
    """The tubular file ``--string`` names (read wherever it is, as ``--survey``: the user
    named it), once it is a regular file and the configuration does not also give the
    string's sections (one string, not two: which would be meant cannot be told).

    Raises
    ------
    InputError, ConfigError
        Not a regular file; a configuration with ``[[string.sections]]``.
    """
    path = require_file(Path(string), "string file (--string)",
                        fix="give the WITSML tubular file of the well's string")
    table = raw.get("string")
    if isinstance(table, dict) and "sections" in table:
        raise ConfigError("the configuration gives [[string.sections]] and --string names a "
                          "tubular: which string is meant cannot be told", file=path,
                          fix="drop --string, or the configuration's [[string.sections]]")
    return path


def arriving_data(path: Path) -> Path:
    """Where the data of a well directory ``path`` arrive (``drillfric live`` on a folder):
    the file or folder its ``well.toml`` names (``[well] data``; ``"."`` for the directory's
    own files).

    Raises
    ------
    InputError, ConfigError
        No well.toml, no ``[well] data``, or data named outside the directory.
    """
    path = Path(path)
    well_toml = path / "well.toml"
    if special(well_toml):
        require_file(well_toml, "well.toml")
    if not well_toml.is_file():
        raise InputError("well directory has no well.toml", file=path,
                         fix='add well.toml with [well] data = "." (the files arriving in '
                             'this folder) or the sub-folder they arrive in')
    data = read_toml(well_toml).get("well", {}).get("data")
    if not isinstance(data, str):
        raise ConfigError("well.toml does not name its data", file=well_toml,
                          fix='add [well] data = "." (the files arriving in this folder)')
    return require_inside(path / data, path, "data named by well.toml",
                          fix="let the files arrive inside the well directory")


def frame_files(config, survey, string=None) -> tuple[WellFiles, dict]:
    """The files of a well whose data is a DataFrame: only those given (a configuration
    file's ``[survey] file`` too, ``string`` the tubular), never a sidecar."""
    config_path, raw = given_file(config), _mapping(config)
    if config_path is not None:
        require_file(config_path, "config file")
    if raw is None:
        raw = raw_config(config_path)
    named = raw.get("survey", {}).get("file") if isinstance(raw.get("survey"), dict) else None
    survey_path = given_file(survey) if survey is not None else (
        config_path.parent / named if isinstance(named, str) and config_path else None)
    if survey_path is not None:
        require_file(survey_path, "survey file")
    string_path = None if string is None else given_string(string, raw)
    return WellFiles(FRAME_LABEL, config_path, survey_path, string=string_path,
                     in_memory=True), raw


def given_file(given) -> Path | None:
    """``given`` as a file path when it is one (str or path-like), else None."""
    return Path(given) if isinstance(given, str | os.PathLike) else None


def _mapping(config) -> dict | None:
    """A configuration given as a mapping (the TOML's tables), else None."""
    if config is None or isinstance(config, str | os.PathLike | Config):
        return None
    if not isinstance(config, dict):
        raise ConfigError(f"config is a {type(config).__name__}",
                          fix="give a TOML file, a dict of its tables or a Config")
    return config


def _data(path: Path, named=()) -> tuple[Path, tuple[Path, ...]]:
    """The data of a well given as ``path``: a data file, or the folder and numbered files
    of a WITSML log split over parts (``path`` the folder or one of its parts; the name
    :func:`drillfric.io.witsml.split_log` gives the log and its parts). ``named``: files the
    configuration or the command line names as something else, never parts of the log."""
    split = witsml.split_log(path)
    if split is not None:
        folder, parts = split
        for part in parts:
            require_inside(part, part.parent, "part of the log",
                           fix="copy the parts into the log's folder (a link out of it is not "
                               "followed), or name one part itself as the data: `drillfric "
                               "run PART.xml`, or the data column of a `drillfric fleet` "
                               "manifest (docs/fleet.md)")
        return split
    parts = folder_parts(path, named)
    if parts is not None:
        for part in parts:
            require_inside(part, path, "file of the data folder",
                           fix="copy the files into the data folder")
        return path, parts
    data_format(path)
    return path, ()


#: What to do about a sidecar that is a link out of the data's folder — valid for `run` and
#: for `fleet` alike (issue 35: "give the file with --config/--survey" does not work for a
#: fleet, which has no --survey and whose --config applies to every well).
LINKED_FILE_FIX = ("copy it beside the data (a link out of the folder is not followed), or "
                   "name it: `drillfric run --config/--survey`, or the config/survey columns "
                   "of a `drillfric fleet` manifest (docs/fleet.md)")


def _sidecar(data_path: Path, suffix: str) -> Path | None:
    """``NAME{suffix}`` beside a data file (or the folder or common name of a log's parts)
    when it exists; one that is a device or a FIFO is refused (never opened, never passed
    over in silence)."""
    stem = data_path.stem if data_path.is_file() else data_path.name
    candidate = data_path.with_name(stem + suffix)
    if special(candidate):
        require_file(candidate, "sidecar")
    if not candidate.is_file():
        return None
    return require_inside(candidate, data_path.parent, "sidecar",
                          fix=LINKED_FILE_FIX)


def _directory_data(folder: Path, given=()) -> tuple[Path, tuple[Path, ...], Path, dict]:
    well_toml = folder / "well.toml"
    if special(well_toml):
        require_file(well_toml, "well.toml")
    if not well_toml.is_file():
        found = sorted(p.name for p in folder.iterdir() if p.suffix.lower() in FORMATS)
        raise InputError("well directory has no well.toml", file=folder,
                         fix='add well.toml with [well] data = "FILE"'
                             + (f" (data files here: {', '.join(found)})" if found else ""))
    raw = read_toml(well_toml)
    data = raw.get("well", {}).get("data")
    named = config_named(well_toml, raw) + tuple(given)
    if data is None and witsml.split_log(folder):
        return *_data(folder, named), well_toml, raw
    if not isinstance(data, str):
        raise ConfigError("well.toml does not name its data file", file=well_toml,
                          fix='add [well] data = "surface.parquet" (relative to the folder)')
    data_path = require_inside(folder / data, folder, "data file named by well.toml",
                               fix="give the data file on the command line instead")
    if not data_path.exists() or (data_path.is_dir() and not witsml.split_log(data_path)
                                  and not folder_parts(data_path, named)):
        raise InputError("data file named by well.toml not found", file=data_path,
                         fix=f"fix [well] data in {well_toml}")
    return *_data(data_path, named), well_toml, raw


def config_named(config_path: Path | None, raw: dict, *given) -> tuple[Path, ...]:
    """The files a configuration names as something other than the log (its ``[survey]
    file``), the configuration itself and the files ``given`` (``--config``, ``--survey``):
    none of them is ever a part of a folder's log."""
    named = raw.get("survey", {}).get("file") if isinstance(raw.get("survey"), dict) else None
    out = [p for p in (config_path, *given) if p is not None]
    if isinstance(named, str) and config_path is not None:
        out.append(config_path.parent / named)
    return tuple(out)


def find_survey(data_path: Path, config_path: Path | None, raw: dict,
                 peek: bool = True, *, confined: bool = True) -> Path | None:
    """The survey a well's configuration names, else its sidecar, else one stored in the
    data file. ``confined``: the configuration travelled with the data (a sidecar, a folder's
    well.toml), so the file it names must lie in its folder; one given on the command line
    (``--config``) may name a survey anywhere."""
    named = raw.get("survey", {}).get("file") if isinstance(raw.get("survey"), dict) else None
    if isinstance(named, str) and config_path is not None:
        named_path = config_path.parent / named
        if not confined:
            return named_path
        return require_inside(named_path, config_path.parent,
                              "survey file named by the configuration",
                              fix="give it with --survey (or the configuration with --config), "
                                  "or move it beside the configuration")
    for ext in SURVEY_EXT:
        if (candidate := _sidecar(data_path, ".survey" + ext)) is not None:
            return candidate
    if peek and (_h5_has(data_path, "survey") or _witsml_has(data_path, "trajectory")):
        return data_path
    return None


def find_string(data_path: Path, raw: dict, peek: bool = True) -> Path | None:
    """The WITSML tubular read as the string when the configuration has no sections:
    ``NAME.tubular.xml`` beside the data (or configuration), else the data file itself when
    it holds a ``<tubular>`` beside its log."""
    string = raw.get("string")
    if isinstance(string, dict) and "sections" in string:
        return None
    found = _sidecar(data_path, ".tubular.xml")
    if found is None and peek and _witsml_has(data_path, "tubular"):
        found = data_path
    return found


def _witsml_has(path: Path, kind: str) -> bool:
    """Whether a WITSML data file holds a ``kind`` object (e.g. a trajectory beside its
    log); False for any other file."""
    if path.suffix.lower() != ".xml" or not path.is_file() or path.stat().st_size == 0:
        return False
    return kind in witsml.object_kinds(path)


def _h5_has(path: Path, key: str) -> bool:
    if path.suffix.lower() not in HDF5_EXT or not path.is_file() or path.stat().st_size == 0:
        return False
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            return h5.get(key, getlink=True) is not None  # a link is not followed here
    except OSError as exc:
        raise InputError("not a readable HDF5 file (truncated or corrupt)", file=path,
                         fix="re-export or re-copy the file") from exc


def raw_config(config_path: Path | None) -> dict:
    """The configuration mapping of a TOML file or an HDF5 bundle's ``/config`` ({} if none)."""
    if config_path is None:
        return {}
    if config_path.suffix.lower() in HDF5_EXT:
        return _h5_config(config_path)
    return read_toml(config_path)


def _h5_config(path: Path) -> dict:
    """The ``/config`` of an HDF5 bundle as a raw TOML mapping."""
    import h5py

    where = f"{path}:/config"
    with h5py.File(path, "r") as h5:
        node = node_at(h5, "config", path)
        if isinstance(node, h5py.Dataset) or "toml" in node.attrs:
            text = node[()] if isinstance(node, h5py.Dataset) else node.attrs["toml"]
            try:
                text = text.decode() if isinstance(text, bytes) else str(text)
            except UnicodeDecodeError:
                raise ConfigError("not TOML text (not UTF-8)", file=where,
                                  fix="store the configuration as UTF-8 TOML text") from None
            return parse_toml(text, where)
        raw: dict = {}
        for group in [node] + [g for g in members(node, path).values()
                               if isinstance(g, h5py.Group)]:
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
