"""Which wells a fleet holds: a folder of wells, or a manifest (docs/fleet.md).

:func:`discover` names the wells of a folder (each data file with its sidecars, each
sub-folder with ``well.toml`` or the numbered parts of a WITSML log) or of a ``.csv``/``.json``
manifest (columns ``well, data, config, survey, string``) as :class:`WellSpec` — cheaply: no data
file is opened here (a name stored inside one is resolved by the worker that runs the well,
docs/security.md), so no input can stop, crash or stall a night before it starts.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, replace
from pathlib import Path

from drillfric.errors import InputError
from drillfric.io import witsml
from drillfric.io.atomic import OUT_FILES
from drillfric.io.text import printable

_DATA_EXT = (".parquet", ".pq", ".csv", ".txt", ".h5", ".hdf5", ".las", ".xml", ".dlis",
             ".xlsx")
_SIDECAR_TAGS = (".survey", ".truth", ".tubular")
#: WITSML objects that are not surface data (read beside a log, never a well of their own).
_NOT_WELLS = frozenset({"trajectory", "tubular", "bhaRun"})
_MANIFEST_COLUMNS = ("well", "data", "config", "survey", "string")


@dataclass(frozen=True)
class WellSpec:
    """A well to process: a data file, an HDF5 bundle or a well directory (docs/ingestion.md,
    docs/fleet.md).

    Attributes
    ----------
    data : Path
        What ``drillfric run`` accepts as WELL.
    name : str or None
        Output name (OUT/NAME); None: the configuration's ``well.name``, else the stem.
    config, survey : Path or None
        Overrides of the sidecars (``--config``, manifest columns).
    string : Path or None
        The WITSML tubular read as the string (``--string``, manifest column ``string``),
        instead of a ``NAME.tubular.xml`` sidecar.
    """

    data: Path
    name: str | None = None
    config: Path | None = None
    survey: Path | None = None
    string: Path | None = None


def discover(source, *, config=None) -> list[WellSpec]:
    """The wells of a directory or of a manifest file (CSV or JSON).

    A directory holds data files with their sidecars (``NAME.toml``, ``NAME.survey.csv``,
    ``NAME.truth.json`` are not wells) and well directories (holding ``well.toml``).
    A manifest has columns/keys ``well, data, config, survey, string`` (``data`` required; relative
    paths are relative to the manifest). ``config`` (``--config``) applies to every well
    that does not name its own.

    Raises
    ------
    InputError
        Missing source, unreadable manifest, or no well found.
    """
    source = Path(source)
    if not source.exists():
        raise InputError("not found", file=source, fix="give a directory of wells or a "
                         "manifest (.csv/.json with columns well, data, config, survey, string)")
    if source.is_dir():
        specs = _discover_dir(source)
    else:
        specs = _read_manifest(source)
    if not specs:
        raise InputError("no wells found", file=source,
                         fix=f"put data files ({', '.join(_DATA_EXT)}) or well directories "
                             "(with well.toml) there")
    if config is not None:
        specs = [s if s.config is not None else replace(s, config=Path(config)) for s in specs]
    return specs


def _discover_dir(folder: Path) -> list[WellSpec]:
    """Wells of a folder; the numbered parts of one WITSML log (``NAME_1.xml``,
    ``NAME_2.xml`` …, or a sub-folder of ``00001.xml`` …) are one well."""
    specs, logs = [], set()
    for path in sorted(folder.iterdir()):
        if path.name.startswith("."):
            continue
        split = witsml.split_log(path)
        if split is not None and split[0] in logs:
            continue
        if path.is_dir():
            if (path / "well.toml").is_file() or split is not None:
                specs.append(WellSpec(path))
        elif _is_data_file(path):
            specs.append(WellSpec(path))
        logs |= {split[0]} if split is not None else set()
    return specs


def _is_data_file(path: Path) -> bool:
    """A data file of a well: a data extension, not a sidecar, not a WITSML object that
    only accompanies a log (a file that does not parse is kept: it fails as its well)."""
    if path.suffix.lower() not in _DATA_EXT or path.stem.endswith(_SIDECAR_TAGS) or \
            path.name.casefold() in OUT_FILES:  # a fleet's own output (--out = the wells)
        return False
    if path.suffix.lower() != ".xml":
        return True
    try:
        return witsml.object_kind(path) not in _NOT_WELLS
    except InputError:
        return True


def _read_manifest(path: Path) -> list[WellSpec]:
    suffix = path.suffix.lower()
    try:
        if suffix == ".csv":
            with open(path, newline="", encoding="utf-8-sig") as fh:
                rows = list(csv.DictReader(fh))
        elif suffix == ".json":
            rows = json.loads(path.read_text(encoding="utf-8-sig"),
                              object_pairs_hook=_no_repeated_keys)
            rows = rows.get("wells", rows) if isinstance(rows, dict) else rows
        else:
            raise InputError("a fleet manifest must be .csv or .json", file=path,
                             fix="give a directory of wells or a .csv/.json manifest")
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, csv.Error) as exc:
        raise InputError(f"unreadable manifest ({exc})", file=path,
                         fix="write a CSV/JSON list with columns well, data, config, "
                             "survey") from None
    except RecursionError:  # json: [[[[…]]]] a hundred thousand deep
        raise InputError("unreadable manifest (nested too deep)", file=path,
                         fix="write a CSV/JSON list with columns well, data, config, "
                             "survey") from None
    if not isinstance(rows, list) or any(not isinstance(r, dict)
                                         or not str(r.get("data") or "").strip()
                                         for r in rows):
        raise InputError("every manifest entry needs a 'data' path", file=path,
                         fix=f"use columns {', '.join(_MANIFEST_COLUMNS)} (data required)")

    for i, row in enumerate(rows, start=1):
        _check_entry(row, i, path)

    def where(value) -> Path | None:
        value = str(value or "").strip()  # a cell of blanks is an empty cell
        if "\x00" in value:  # no path holds NUL: the OS refuses it
            raise InputError("a manifest path holds a NUL character", file=path,
                             fix="write each path as plain text")
        return None if not value else (path.parent / value).resolve()

    return [WellSpec(where(r["data"]), _name(r.get("well")), where(r.get("config")),
                     where(r.get("survey")), where(r.get("string"))) for r in rows]


def _check_entry(row: dict, i: int, path: Path) -> None:
    """A manifest entry holds only the columns drillfric reads, each a text (a well's name
    may be a number): a declared ``type`` or a well name given as a list was ignored in
    silence — the well ran as its file stem, as whatever its data are (issue 30, tenth
    attack)."""
    unknown = [str(k) for k, v in row.items() if k not in _MANIFEST_COLUMNS and k is not None
               and not (k == "" and not v)]  # a trailing comma's empty column
    if unknown or None in row:  # None: a CSV row with more fields than the header
        what = (f"column '{printable(unknown[0])}'" if unknown
                else "more fields than the header has columns")
        raise InputError(f"manifest entry {i} has {what}, which drillfric does not read (a "
                         "well's kind and settings come from its data and configuration)",
                         file=path, fix=f"keep only the columns {', '.join(_MANIFEST_COLUMNS)}"
                                        "; set anything else in the well's configuration")
    for key in _MANIFEST_COLUMNS:
        value = row.get(key)
        number = key == "well" and isinstance(value, int | float) and not isinstance(value, bool)
        if value is not None and not isinstance(value, str) and not number:
            raise InputError(f"manifest entry {i}: {key} is a {type(value).__name__}, not a "
                             "text", file=path, fix=f'write {key} as a text, e.g. "{key}": '
                             + ('"A-1"' if key == "well" else '"wells/a.csv"'))


def _name(value) -> str | None:
    """A manifest's well name (a number as written), None when not given (a cell of
    blanks too)."""
    if value is None or not str(value).strip():
        return None
    return value.strip() if isinstance(value, str) else format(value, "g")


def _no_repeated_keys(pairs: list) -> dict:
    """A JSON object, refusing a key written twice (the last had been used silently)."""
    keys = [k for k, _ in pairs]
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise json.JSONDecodeError(f"key '{twice[0]}' written twice in one entry", "", 0)
    return dict(pairs)
