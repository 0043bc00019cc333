"""Directional-survey readers: CSV (any delimiter), Parquet and the fixed-width Volve text.

A survey is a table of stations: measured depth, inclination and azimuth, optionally with
the operator's own TVD, north/east offsets and dogleg severity. :func:`read_survey_table`
returns it in the canonical columns of docs/ingestion.md (``md_m, inc_deg, azi_deg`` plus
``tvd_m, north_m, east_m, dls_deg_30m`` when the file has them), validated, in file order;
:func:`read_survey` turns it into a :class:`~drillfric.wellpath.WellPath` by minimum
curvature (docs/theory.md §1). The sidecar a pipeline writes and reads is ``NAME.survey.csv``
with the columns ``md_m,inc_deg,azi_deg`` (:func:`write_survey`).

Recognised layouts
------------------
- A header row of column names: ``MD``/``Measured Depth``/``DEPTH``, ``INC``/``Incl``/
  ``Inclination``, ``AZI``/``Azim``/``Azimuth``, ``TVD``/``TVDKB``, ``Y_Offset_NS``/``NS``/
  ``North``, ``X_Offset_EW``/``EW``/``East``, ``DLS``; units either in the name
  (``MD (ft)``, ``MD [m]``, ``md_ft``, ``inc_deg``) or in a units row under the header
  (``m RKB``, ``deg``, ``deg/30m``). Without a unit, depths are metres and angles degrees.
- Delimiters ``,`` ``;`` tab ``|`` or runs of spaces (fixed width); ``;``/tab files may use a
  decimal comma. LF, CRLF and old-Mac CR-only line endings.
- Parquet with the same column names.
- A WITSML 1.4.1 ``<trajectory>`` (``.xml``): its stations' md, incl, azi (and tvd, dispNs,
  dispEw, dls) in the units of their ``uom`` (:func:`drillfric.io.witsml_objects.trajectory_table`).
"""

from __future__ import annotations

import csv
import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.files import require_file
from drillfric.io.grouping import ungroup
from drillfric.io.text import listing, printable
from drillfric.units import conversion_factor
from drillfric.wellpath import WellPath, minimum_curvature

#: Columns of the survey sidecar ``NAME.survey.csv`` (docs/ingestion.md).
SIDECAR_COLUMNS = ("md_m", "inc_deg", "azi_deg")

#: Canonical column -> accepted names, lower-cased with everything but letters and digits
#: removed (so ``X_Offset_EW``, ``x-offset ew`` and ``XOFFSETEW`` are the same name).
_ALIASES: dict[str, frozenset[str]] = {
    "md": frozenset({"md", "measureddepth", "mdepth", "depth", "dept", "dmea", "mdrkb", "mdkb"}),
    "inc": frozenset({"inc", "incl", "inclination", "dev", "devi", "deviation"}),
    "azi": frozenset({"azi", "azim", "azimuth", "az", "azm", "hazi", "azit", "azimuthtrue",
                      "trueazimuth"}),
    "tvd": frozenset({"tvd", "tvdkb", "tvdrkb", "tvdrt", "tvddf", "trueverticaldepth"}),
    "north": frozenset({"north", "ns", "nsoffset", "yoffsetns", "northoffset", "localns"}),
    "east": frozenset({"east", "ew", "ewoffset", "xoffsetew", "eastoffset", "localew"}),
    "dls": frozenset({"dls", "doglegseverity"}),
}
_KIND = {"md": "length", "inc": "angle", "azi": "angle", "tvd": "length", "north": "length",
         "east": "length", "dls": "dls"}
_OUT = {"md": "md_m", "inc": "inc_deg", "azi": "azi_deg", "tvd": "tvd_m", "north": "north_m",
        "east": "east_m", "dls": "dls_deg_30m"}
_DEFAULT_UNIT = {"length": "m", "angle": "deg", "dls": "deg/30m"}
_REQUIRED = ("md", "inc", "azi")
_NULLS = (-999.25, -9999.0, -999.0)
_TEXT_EXT = {".csv", ".txt", ".tsv", ".dat", ".prn", ".asc"}
_PARQUET_EXT = {".parquet", ".pq"}
#: Largest survey file read [bytes]: surveys are read whole; a station every metre of a
#: 30 km well is about 2 MB of text.
MAX_SURVEY_BYTES = 64 << 20
#: Most stations a Parquet survey may declare (a station every metre of a 100 km well).
MAX_STATIONS = 100_000
_FIX_NAMES = "name the columns MD, INC, AZI (or md_m, inc_deg, azi_deg)"


def read_survey_table(path) -> pd.DataFrame:
    """Read a survey file into canonical columns, validated, in file order.

    Parameters
    ----------
    path : str or Path
        CSV/text (``.csv .txt .tsv .dat .prn .asc``), Parquet (``.parquet .pq``) or WITSML
        trajectory (``.xml``) file.

    Returns
    -------
    pandas.DataFrame
        Columns ``md_m`` [m], ``inc_deg`` [°], ``azi_deg`` [°], and ``tvd_m``, ``north_m``,
        ``east_m`` [m], ``dls_deg_30m`` [°/30 m] when the file has them.

    Raises
    ------
    InputError
        Missing, empty or unreadable file; unknown extension; missing columns (the message
        lists the columns found); unknown units; missing values; depths not strictly
        increasing; inclination outside 0–180° or azimuth outside 0–360°.
    """
    path = Path(path)
    require_file(path, "survey file", fix="check the path (or the [survey] file key of the "
                                          "config)")
    _check_size(path)
    ext = path.suffix.lower()
    if ext in _PARQUET_EXT:
        names, units, data = _parquet_columns(path)
    elif ext in _TEXT_EXT:
        names, units, data = _text_columns(path)
    elif ext == ".xml":
        from drillfric.io.witsml_objects import trajectory_table

        return _validate(trajectory_table(path), path)
    else:
        raise InputError(f"unknown survey file extension '{path.suffix}'", file=path,
                         fix="give a .csv, .txt, .parquet or WITSML .xml survey")
    return _validate(_canonical(names, units, data, path), path)


def _check_size(path: Path) -> None:
    """Refuse a survey file larger than :data:`MAX_SURVEY_BYTES` (read whole) or, for Parquet,
    declaring more than :data:`MAX_STATIONS` rows (before reading its data)."""
    size = path.stat().st_size
    if size > MAX_SURVEY_BYTES:
        raise InputError(f"survey file of {size / 2**20:.4g} MiB: more than the "
                         f"{MAX_SURVEY_BYTES / 2**20:.4g} MiB a survey may have", file=path,
                         fix="check that the file is the survey (MD, inclination, azimuth)")
    if path.suffix.lower() in _PARQUET_EXT:
        import pyarrow as pa
        import pyarrow.parquet as pq

        try:
            rows = pq.ParquetFile(path).metadata.num_rows
        except (pa.ArrowException, OSError) as exc:
            raise InputError(f"cannot read Parquet survey ({type(exc).__name__})", file=path,
                             fix="re-export the survey as Parquet or CSV") from exc
        if rows > MAX_STATIONS:
            raise InputError(f"survey file declares {rows:.4g} stations: more than "
                             f"{MAX_STATIONS:,}", file=path,
                             fix="check that the file is the survey (MD, inclination, "
                                 "azimuth)")


def read_survey(path, *, tie_in=None) -> WellPath:
    """Read a survey file and compute its well path by minimum curvature (docs/theory.md §1).

    Parameters
    ----------
    path : str or Path
        Survey file (see :func:`read_survey_table`).
    tie_in : tuple of float, optional
        (tvd, north, east) [m] of the first station. Default: the file's own TVD and
        offsets at the first station when it lists a TVD there (operator surveys such as
        Volve start below the rotary table at the operator's tie-in point; offsets the file
        lacks are 0), else a vertical hole above the first station, i.e. (md₀, 0, 0).

    Returns
    -------
    WellPath
    """
    return wellpath_from_table(read_survey_table(path), tie_in=tie_in)


def wellpath_from_table(table: pd.DataFrame, *, tie_in=None) -> WellPath:
    """Well path of a canonical survey table (see :func:`read_survey` for ``tie_in``)."""
    if tie_in is None:
        tie_in = _file_tie_in(table)
    return minimum_curvature(table["md_m"].to_numpy(float),
                             np.radians(table["inc_deg"].to_numpy(float)),
                             np.radians(table["azi_deg"].to_numpy(float)), tie_in=tie_in)


def _file_tie_in(table: pd.DataFrame) -> tuple[float, float, float] | None:
    """(tvd, north, east) the file lists at its first station; missing offsets are 0."""
    first = table.iloc[0]
    tvd, north, east = (float(first.get(c, np.nan)) for c in ("tvd_m", "north_m", "east_m"))
    if not np.isfinite(tvd):
        return None
    return tvd, north if np.isfinite(north) else 0.0, east if np.isfinite(east) else 0.0


def survey_table_from_frame(frame: pd.DataFrame, *, file=None) -> pd.DataFrame:
    """Canonical, validated survey table from an in-memory frame (e.g. an HDF5 ``/survey``).

    Column names are recognised as in a file header (units in the name allowed).
    """
    names = [str(c) for c in frame.columns]
    data = [frame[c].to_numpy() for c in frame.columns]
    return _validate(_canonical(names, [None] * len(names), data, file), file)


def write_survey(path, well_path: WellPath) -> None:
    """Write the stations of ``well_path`` as a ``md_m,inc_deg,azi_deg`` CSV sidecar."""
    pd.DataFrame({"md_m": well_path.md_m, "inc_deg": np.degrees(well_path.inc_rad),
                  "azi_deg": np.degrees(well_path.azi_rad)}).to_csv(
        path, index=False, float_format="%.10g")


# --------------------------------------------------------------------------------- parsing

def _parquet_columns(path: Path):
    try:
        frame = pd.read_parquet(path)
    except Exception as exc:  # pyarrow raises several types for corrupt files
        raise InputError(f"cannot read Parquet survey ({type(exc).__name__})", file=path,
                         fix="re-export the survey as Parquet or CSV") from exc
    return [str(c) for c in frame.columns], [None] * frame.shape[1], \
        [frame[c].to_numpy() for c in frame.columns]


def _text_columns(path: Path):
    """Header names, units row (or Nones) and raw string columns of a text survey."""
    raw = path.read_bytes()
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    lines = [ln for ln in text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
             if ln.strip()]
    if not lines:
        raise InputError("survey file is empty", file=path,
                         fix="export the survey with a header row MD, INC, AZI and its stations")
    delim = _delimiter(lines[0])
    header = _split(lines[0], delim)
    if all(_is_number(f) for f in header):
        raise InputError("survey file has no header row", file=path,
                         fix=f"add a header row; {_FIX_NAMES}")
    units: list[str | None] = [None] * len(header)
    body = lines[1:]
    if body and not all(_is_number(f) or not f.strip() for f in _split(body[0], delim)):
        units = _units_row(lines[0], body[0], delim, len(header))
        body = body[1:]
    rows = [_split(ln, delim) for ln in body]
    cols = []
    for j in range(len(header)):
        cols.append(np.array([r[j] if j < len(r) else "" for r in rows], dtype=object))
    return header, units, cols


def _delimiter(line: str) -> str | None:
    """The delimiter of a header line (outside double quotes: ``"MD, m";"Inc, deg"`` is
    delimited by ``;``); ``None`` means runs of whitespace (fixed width)."""
    bare = re.sub(r'"[^"]*"', "", line)
    counts = {d: bare.count(d) for d in (",", ";", "\t", "|")}
    best = max(counts, key=counts.get)
    return best if counts[best] else None


def _split(line: str, delim: str | None) -> list[str]:
    """The fields of a line; a field in double quotes may hold the delimiter (RFC 4180:
    ``"MD, m"`` had been split in two, every later name moved one column right of its
    data — issue 30, twelfth attack F3, as in the log reader)."""
    if delim is None:
        return line.split()
    try:
        fields = next(csv.reader([line], delimiter=delim, skipinitialspace=True), [""])
    except csv.Error:  # a field beyond the csv module's limit
        fields = line.split(delim)
    return [f.strip().strip('"').strip("'") for f in fields]


def _units_row(header_line: str, units_line: str, delim: str | None, n: int) -> list:
    """Units under the header; fixed-width units (``m RKB``) are cut at the header columns."""
    if delim is not None:
        units = _split(units_line, delim)
    else:
        starts = [m.start() for m in re.finditer(r"\S+", header_line)]
        ends = starts[1:] + [None]
        units = [units_line[a:b].strip() for a, b in zip(starts, ends, strict=True)]
    units = (units + [""] * n)[:n]
    return [u or None for u in units]


def _is_number(text: str) -> bool:
    try:
        float(text.replace(",", "."))
    except ValueError:
        return False
    return True


def _name_and_unit(name: str) -> tuple[str | None, str | None]:
    """Canonical key and unit embedded in a column name (``MD (ft)``, ``md_ft``, ``TVD``)."""
    m = re.fullmatch(r"\s*(.*?)\s*[\[({]\s*(.*?)\s*[\])}]\s*", name)
    if m:
        return _key(m.group(1)), m.group(2)
    key = _key(name)
    if key is not None:
        return key, None
    m = re.fullmatch(r"\s*(.*?)\s*(?:,|\s/)\s*(\S+)\s*", name)  # "MD, m", "MD / ft"
    if m and _key(m.group(1)) is not None:
        return _key(m.group(1)), m.group(2)
    parts = name.strip().split("_")
    for i in range(len(parts) - 1, 0, -1):
        key = _key("_".join(parts[:i]))
        if key is not None:
            return key, "/".join(parts[i:]) if len(parts) - i > 1 else parts[i]
    return None, None


def _key(name: str) -> str | None:
    flat = re.sub(r"[^a-z0-9]", "", name.lower())
    return next((k for k, names in _ALIASES.items() if flat in names), None)


# ----------------------------------------------------------------------------- conversion

def _canonical(names, units, data, file) -> pd.DataFrame:
    found: dict[str, tuple[int, str | None]] = {}
    for j, name in enumerate(names):
        key, unit = _name_and_unit(name)
        if key is not None and key not in found:
            found[key] = (j, units[j] or unit)
    missing = [k for k in _REQUIRED if k not in found]
    if missing:
        shown = listing(names, recognised=bool(found))
        raise InputError(f"survey has no {'/'.join(_OUT[k] for k in missing)} column "
                         f"(columns found: {shown})", file=file, fix=_FIX_NAMES)
    out = {}
    for key in _OUT:
        if key in found:
            j, unit = found[key]
            values = _numbers(data[j], names[j], file)
            out[_OUT[key]] = values * _factor(unit, _KIND[key], names[j], file)
    return pd.DataFrame(out)


def _numbers(column, name: str, file) -> np.ndarray:
    """Floats of a column; empty cells and the nulls -999.25/-9999/-999 become NaN."""
    text = pd.Series(column, dtype=object).astype(str).str.strip().map(ungroup)  # 2 210,5
    text = text.str.replace(",", ".", regex=False)
    blank = text.isin(["", "nan", "NaN", "None", "<NA>"])
    values = pd.to_numeric(text.mask(blank), errors="coerce").to_numpy(float, copy=True)
    bad = np.isnan(values) & ~blank.to_numpy()
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(f"column '{printable(name)}' has a non-numeric value "
                         f"'{printable(text[k], 20)}' at station {k + 1}", file=file,
                         fix="remove the text from the survey stations")
    values[np.isin(values, _NULLS)] = np.nan
    return values


def _factor(unit: str | None, kind: str, name: str, file) -> float:
    """Factor to m (lengths), degrees (angles) or °/30 m (DLS) from the unit spelling."""
    unit = (unit or _DEFAULT_UNIT[kind]).strip()
    try:
        if kind == "length":
            return conversion_factor(unit.split()[0], "length")
        if kind == "angle":
            return float(np.degrees(conversion_factor(unit, "angle")))
        m = re.fullmatch(r"\s*([^/]+?)\s*/\s*([0-9.]*)\s*([A-Za-z]+)\s*", unit.replace("°", "deg"))
        if m is None:
            raise InputError(f"unknown unit '{printable(unit, 20)}'")
        per = float(m.group(2) or 1.0) * conversion_factor(m.group(3), "length")
        return float(np.degrees(conversion_factor(m.group(1), "angle"))) * 30.0 / per
    except InputError as exc:
        raise InputError(f"column '{printable(name)}': {exc.problem}", file=file,
                         fix=exc.fix if " reads as " in exc.problem else
                         "use m or ft for depths, deg or rad for angles, deg/30m or "
                         "deg/100ft for DLS") from exc


class SurveyWarning(UserWarning):
    """Something in a survey file drillfric read past (a station written twice)."""


def _validate(table: pd.DataFrame, file) -> pd.DataFrame:
    """``table`` checked, a station repeating the one before exactly dropped (warned)."""
    if len(table) == 0:
        raise InputError("survey has no stations", file=file,
                         fix="export the survey with its stations under the header")
    if len(table) < 2:
        raise InputError("survey has a single station", file=file,
                         fix="give at least two stations (surface and bit depth)")
    for col in SIDECAR_COLUMNS:
        nan = np.isnan(table[col].to_numpy())
        if nan.any():
            k = int(np.argmax(nan))
            raise InputError(f"survey station {k + 1} has no {col} value", file=file,
                             fix="fill or remove the incomplete station")
    table = _repeats_dropped(table, file)
    md = table["md_m"].to_numpy()
    step = np.diff(md)
    if np.any(step <= 0):
        k = int(np.argmax(step <= 0)) + 1
        raise InputError(f"survey depths not increasing at station {k + 1} "
                         f"(MD {md[k - 1]:g} m then {md[k]:g} m)", file=file,
                         fix="sort the survey by MD and remove duplicate stations")
    _check_range(table["inc_deg"].to_numpy(), 180.0, "inclination", file)
    _check_range(table["azi_deg"].to_numpy(), 360.0, "azimuth", file)
    return table


def _repeats_dropped(table: pd.DataFrame, file) -> pd.DataFrame:
    """``table`` without the stations that repeat the one before exactly (a tie-in station
    written twice: one warning naming the file and the MD); a station at the MD of the one
    before with other values is an InputError naming the MD (which is the station cannot
    be told)."""
    md = table["md_m"].to_numpy(float)
    twice = np.flatnonzero(np.diff(md) == 0) + 1
    if not twice.size:
        return table
    values = table.to_numpy(dtype=float, na_value=np.nan)
    for k in twice:
        if not np.array_equal(values[k - 1], values[k], equal_nan=True):
            shown = [f"{table['inc_deg'].iat[i]:g}° / {table['azi_deg'].iat[i]:g}°"
                     for i in (k - 1, k)]
            other = "" if shown[0] != shown[1] else " (other columns differ)"
            raise InputError(f"survey stations {k} and {k + 1} are both at MD {md[k]:g} m "
                             f"with different values (inclination / azimuth {shown[0]} and "
                             f"{shown[1]}{other}): which is the station cannot be told",
                             file=file, fix=f"keep one station at MD {md[k]:g} m (the tie-in "
                                            "or the measured one) and remove the other")
    first = f"MD {md[twice[0]]:g} m"
    text = (f"survey station {twice[0] + 1} repeats station {twice[0]} exactly ({first})"
            if twice.size == 1 else f"{twice.size} survey stations repeat the station before "
                                    f"exactly (the first at {first})")
    warnings.warn_explicit(f"{file}: {text}: dropped (a tie-in station written twice)",
                           SurveyWarning, __file__, 0, module=__name__, registry={})
    return table.drop(index=table.index[twice]).reset_index(drop=True)


def check_doglegs(path: WellPath, limit_deg_30m: float, file) -> None:
    """Refuse a path whose dog-leg severity between two stations exceeds
    ``limit_deg_30m`` [°/30 m] (``survey.max_dogleg_deg_30m``): a bend no rotating drill
    string follows, most often a typo (one station's inclination 5 for 50). The friction
    factors scale with the side force such a bend invents (docs/theory.md §2).

    Raises
    ------
    InputError
        Naming the station and its severity.
    """
    dls = np.degrees(path.dls_rad_m) * 30.0
    if not dls.size or float(np.max(dls)) <= limit_deg_30m:
        return
    k = int(np.argmax(dls))
    md = path.md_m
    raise InputError(f"survey stations {k + 1}–{k + 2} (MD {md[k]:g}–{md[k + 1]:g} m) bend "
                     f"the path {dls[k]:.0f}°/30 m, beyond survey.max_dogleg_deg_30m = "
                     f"{limit_deg_30m:g}°/30 m: a typo in a station?", file=file,
                     fix="check those stations' inclination and azimuth, or raise [survey] "
                         "max_dogleg_deg_30m for a short-radius well")


def _check_range(values: np.ndarray, top: float, what: str, file) -> None:
    bad = (values < 0.0) | (values > top)
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(f"{what} {values[k]:g}° at station {k + 1} is outside 0–{top:g}°",
                         file=file, fix=f"check the {what} column and its unit (degrees "
                                        "unless the header says rad)")
