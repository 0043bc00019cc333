"""Writing a well to disk (docs/ingestion.md "Well layouts: a well on disk"): surface table,
sidecars, truth.

:func:`write_well` writes ``NAME.{parquet,csv,h5,hdf5}`` (format by extension) with the
canonical columns, and beside it ``NAME.toml`` (a configuration that
:func:`drillfric.config.load_config` accepts, naming the survey), ``NAME.survey.csv``
(``md_m, inc_deg, azi_deg``) and ``NAME.truth.json`` (ground truth of a simulation). The
truth is also stored inside the data file where the format allows: Parquet schema metadata
key ``drillfric.truth``, HDF5 attribute ``truth`` on ``/surface`` (HDF5 files, written with
h5py as groups of 1-D datasets, also get the ``/survey`` group and the configuration as TOML
text in ``/config``). CSV files are plain
(no comment lines), so every reader takes them.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.io.atomic import refuse_link, replacing, write_text_replacing
from drillfric.wellpath import WellPath

FORMATS = {".parquet": "parquet", ".csv": "csv", ".h5": "hdf5", ".hdf5": "hdf5"}
TRUTH_KEY = "drillfric.truth"


def data_format(path: str | Path) -> str:
    """Format of an output file from its extension (raises InputError if unsupported)."""
    fmt = FORMATS.get(Path(path).suffix.lower())
    if fmt is None:
        raise InputError(f"cannot write '{Path(path).suffix}' files", file=path,
                         fix="use .parquet, .csv, .h5 or .hdf5")
    return fmt


def sidecar_paths(path: str | Path) -> dict[str, Path]:
    """``{"config", "survey", "truth"}`` paths beside a data file ``NAME.ext``."""
    path = Path(path)
    stem = path.with_suffix("")
    return {"config": path.with_suffix(".toml"),
            "survey": stem.with_name(stem.name + ".survey.csv"),
            "truth": stem.with_name(stem.name + ".truth.json")}


def write_table(path: str | Path, frame: pd.DataFrame, truth: dict | None = None, *,
                survey: WellPath | None = None, config_toml: str | None = None) -> Path:
    """Write a surface table by extension, with the truth as metadata where possible."""
    path = Path(path)
    fmt = data_format(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    truth_text = None if truth is None else json.dumps(truth, default=_plain)
    if fmt == "csv":
        frame.to_csv(path, index=False, float_format="%.8g")
    elif fmt == "parquet":
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pandas(frame, preserve_index=False)
        if truth_text is not None:
            meta = dict(table.schema.metadata or {})
            meta[TRUTH_KEY.encode()] = truth_text.encode()
            table = table.replace_schema_metadata(meta)
        pq.write_table(table, path, compression="zstd")
    else:
        _write_hdf5(path, frame, truth_text, survey, config_toml)
    return path


def _write_hdf5(path: Path, frame, truth_text, survey, config_toml) -> None:
    """HDF5 bundle through h5py: ``/surface`` and ``/survey`` groups of 1-D datasets (one per
    column, the shape :mod:`drillfric.io.hdf5` reads), the truth as a JSON text attribute of
    ``/surface`` and the configuration as a TOML text dataset ``/config``."""
    import h5py

    if path.exists():
        path.unlink()
    with h5py.File(path, "w", track_order=True) as h5:
        _h5_group(h5, "surface", frame)
        if truth_text is not None:
            h5["surface"].attrs["truth"] = truth_text
        if survey is not None:
            _h5_group(h5, "survey", survey_frame(survey))
        if config_toml is not None:
            h5.create_dataset("config", data=config_toml)


def _h5_group(h5, name: str, frame: pd.DataFrame) -> None:
    group = h5.create_group(name, track_order=True)
    for column in frame.columns:
        group.create_dataset(str(column), data=frame[column].to_numpy(), compression="gzip",
                             compression_opts=5)


def survey_frame(path: WellPath) -> pd.DataFrame:
    """Survey stations as ``md_m, inc_deg, azi_deg``."""
    return pd.DataFrame({"md_m": path.md_m, "inc_deg": np.degrees(path.inc_rad),
                         "azi_deg": np.degrees(path.azi_rad)})


def write_well(path: str | Path, frame: pd.DataFrame, *, config: dict, survey: WellPath,
               truth: dict | None = None, keep: tuple[Path, ...] = ()) -> dict[str, Path]:
    """Write the data file and its sidecars; return what was written.

    Parameters
    ----------
    path : str or Path
        Data file ``NAME.{parquet,csv,h5,hdf5}``.
    frame : DataFrame
        Canonical surface columns.
    config : dict
        Effective configuration as plain data (``Config.to_dict()``); ``[survey] file`` is
        set to the survey sidecar and ``[well] name`` to NAME (the well is named after the
        file written, whatever the input configuration called it).
    survey : WellPath
    truth : dict, optional
        Ground truth (NAME.truth.json and file metadata).
    keep : tuple of Path
        Files that must not be overwritten (e.g. the input configuration when it is also
        the sidecar: the demo's ``demo.toml``); a sidecar at one of them is skipped.
    """
    path = Path(path)
    side = sidecar_paths(path)
    config = _sidecar_config(config, path, side["survey"])
    toml_text = dumps_toml(config)
    kept = {Path(k).resolve() for k in keep}
    for target in (path, *side.values()):  # before anything is written: no half a set
        if target.resolve() not in kept:
            refuse_link(target)
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp:  # every file whole or not at all, never through a link
        write_table(tmp, frame, truth, survey=survey, config_toml=toml_text)
    written = {"data": path}
    if side["config"].resolve() not in kept:
        write_text_replacing(side["config"], toml_text)
        written["config"] = side["config"]
    if side["survey"].resolve() not in kept:
        with replacing(side["survey"]) as tmp:
            survey_frame(survey).to_csv(tmp, index=False, float_format="%.10g")
        written["survey"] = side["survey"]
    if truth is not None:
        write_text_replacing(side["truth"], json.dumps(truth, indent=2, default=_plain) + "\n")
        written["truth"] = side["truth"]
    return written


def _sidecar_config(config: dict, data: Path, survey: Path) -> dict:
    out = {k: (dict(v) if isinstance(v, dict) else v) for k, v in config.items()}
    out.setdefault("well", {})
    out["well"]["name"] = data.stem
    out["well"]["data"] = data.name
    out["survey"] = {"file": survey.name}
    if "simulate" in out:
        out["simulate"].pop("scenario", None)
    return out


# ------------------------------------------------------------------------------- TOML

def dumps_toml(data: dict) -> str:
    """Serialise a configuration mapping to TOML (tables, arrays of tables, scalars, lists).

    ``None`` values are left out (absent keys take their defaults when read back).

    Examples
    --------
    >>> print(dumps_toml({"well": {"name": "A"}, "string": {"sections": [{"od_m": 0.1}]}}))
    [well]
    name = "A"
    <BLANKLINE>
    [[string.sections]]
    od_m = 0.1
    <BLANKLINE>
    """
    lines: list[str] = []
    scalars = {k: v for k, v in data.items() if not isinstance(v, dict) and v is not None}
    lines += [f"{_key(k)} = {_value(v)}" for k, v in scalars.items()]
    for table, body in data.items():
        if isinstance(body, dict):
            _table(lines, table, body)
    return "\n".join(lines).lstrip("\n") + "\n"


def _table(lines: list[str], name: str, body: dict) -> None:
    plain = {k: v for k, v in body.items()
             if v is not None and not isinstance(v, dict) and not _is_table_list(v)}
    nested = {k: v for k, v in body.items() if isinstance(v, dict)}
    arrays = {k: v for k, v in body.items() if _is_table_list(v)}
    if plain or not (nested or arrays):
        lines += ["", f"[{name}]"] if lines else [f"[{name}]"]
        lines += [f"{_key(k)} = {_value(v)}" for k, v in plain.items()]
    for key, sub in nested.items():
        lines += ["", f"[{name}.{_key(key)}]"]
        lines += [f"{_key(k)} = {_value(v)}" for k, v in sub.items() if v is not None]
    for key, items in arrays.items():
        for item in items:
            lines += ["", f"[[{name}.{_key(key)}]]"]
            lines += [f"{_key(k)} = {_value(v)}" for k, v in item.items() if v is not None]


def _is_table_list(value) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def _key(key: str) -> str:
    bare = key.replace("_", "").replace("-", "").isalnum() and key.isascii()
    return key if bare else json.dumps(key)


def _value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        value = float(value)
        if not math.isfinite(value):
            raise ValueError(f"cannot write {value} to TOML")
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()
                                if v is not None) + " }"
    if isinstance(value, Path):
        return json.dumps(str(value))
    raise TypeError(f"cannot write {type(value).__name__} to TOML")


def _plain(obj):
    """JSON fallback for NumPy scalars/arrays and paths."""
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
