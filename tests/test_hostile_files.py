"""Hostile files, round two (issue 20): reads outside the named file, hangs, raw terminal
escapes in drillfric's own lines, and messages that said something untrue.

Each case builds its files in a sandbox and runs the CLI through the checks of the first
corpus (:func:`tests.test_hostile_inputs._check`: exit code, no traceback, nothing written
outside ``--out``, one error line with the file and the fix, no secret and no escape
sequence printed), and in addition: no control character but newline in anything printed,
the secret in no file under ``--out``, and no command hung
(:data:`tests.test_hostile_inputs.HANG_S`; how long a case takes is timed by no test). Cases
are named after the attack or accident they reproduce.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import h5py
import numpy as np
import pytest

from tests.test_hostile_inputs import ESC, SECRET, Case, _check, _config, _log

#: Any control character but newline (ESC, BEL, CR, DEL …) in a printed line.
_CONTROL = re.compile(r"[\x00-\x09\x0b-\x1f\x7f]")


def _secret(root: Path) -> Path:
    """A local file a crafted input should never read: the secret, repeated."""
    path = root / "secrets.env"
    path.write_text((SECRET + "\n") * 200, encoding="utf-8")
    return path


def _h5_log(path: Path, rows: int = 400, **datasets) -> Path:
    """A group /surface of 1-D datasets (time, speed, torque) plus ``datasets`` (name →
    a callable making the dataset in the group), and a config beside it."""
    with h5py.File(path, "w") as h5:
        group = h5.create_group("surface")
        columns = {"time_s": np.arange(rows) * 0.1, "surface_rpm": np.full(rows, 60.0),
                   "surface_torque_Nm": np.full(rows, 8000.0)}
        for name, values in columns.items():
            if name in datasets:
                datasets[name](group, name)
            else:
                group[name] = values
    _config(path.with_suffix(".toml"))
    return path


# --------------------------------------------------------------------------- HDF5: outside
def case_h5_external_storage_reads_a_local_secret(root):
    """A dataset whose raw data are "stored" in /etc/passwd or a secret file: inspect printed
    min/median/max of the secret's bytes and run put them into tracks.parquet."""
    secret = _secret(root)
    rows = secret.stat().st_size // 8

    def external(group, name):
        group.create_dataset(name, shape=(rows,), dtype="f8",
                             external=[(str(secret), 0, h5py.h5f.UNLIMITED)])

    path = _h5_log(root / "w.h5", rows=rows, time_s=external)
    says = ("'/surface/time_s'", "external storage", "fix")
    return [Case(["inspect", path], (2,), says), Case(["run", path, "--out", "out"], (2,), says)]


def case_h5_external_link_to_a_file_outside_the_folder(root):
    (root / "elsewhere").mkdir()
    other = _h5_log(root / "elsewhere" / "other.h5")
    path = root / "w.h5"
    with h5py.File(path, "w") as h5:
        h5["surface"] = h5py.ExternalLink(str(other), "/surface")
    _config(path.with_suffix(".toml"))
    return [Case(["inspect", path], (2,), ("'/surface'", "another file")),
            Case(["run", path, "--out", "out"], (2,), ("another file",))]


def case_h5_external_link_for_one_column(root):
    other = _h5_log(root / "other.h5")

    def link(group, name):
        group[name] = h5py.ExternalLink(str(other), f"/surface/{name}")

    path = _h5_log(root / "w.h5", surface_torque_Nm=link)
    return [Case(["inspect", path], (2,), ("'/surface/surface_torque_Nm'", "another file"))]


def case_h5_soft_link_leading_to_an_external_link(root):
    other = _h5_log(root / "other.h5")
    path = root / "w.h5"
    with h5py.File(path, "w") as h5:
        h5["hidden"] = h5py.ExternalLink(str(other), "/surface")
        h5["surface"] = h5py.SoftLink("/hidden")
    _config(path.with_suffix(".toml"))
    return [Case(["inspect", path], (2,), ("'/hidden'", "another file"))]


def case_h5_soft_link_loop_is_one_line(root):
    path = root / "w.h5"
    with h5py.File(path, "w") as h5:
        h5["surface"] = h5py.SoftLink("/loop")
        h5["loop"] = h5py.SoftLink("/surface")
    _config(path.with_suffix(".toml"))
    return [Case(["inspect", path], (2,), ("loop",))]


def case_h5_virtual_dataset_mapping_another_file(root):
    other = _h5_log(root / "other.h5")
    layout = h5py.VirtualLayout(shape=(400,), dtype="f8")
    layout[:] = h5py.VirtualSource(str(other), "/surface/surface_rpm", shape=(400,))
    path = _h5_log(root / "w.h5",
                   surface_rpm=lambda group, name: group.create_virtual_dataset(name, layout))
    return [Case(["inspect", path], (2,), ("'/surface/surface_rpm'", "virtual dataset"))]


def case_h5_bundle_config_as_external_link(root):
    """A bundle's /config linked to another file's: read without a word before."""
    other = root / "other.h5"
    with h5py.File(other, "w") as h5:
        h5["config"] = "[segmentation]\nmin_segment_s = 60.0\n"
    path = _h5_log(root / "w.h5")
    path.with_suffix(".toml").unlink()
    with h5py.File(path, "a") as h5:
        h5["config"] = h5py.ExternalLink(str(other), "/config")
    return [Case(["run", path, "--out", "out"], (2,), ("'/config'", "another file"))]


# --------------------------------------------------------------------------- HDF5: size
def case_h5_chunked_datasets_declaring_1e12_rows(root):
    """A 4 kB file of chunked datasets declaring 10¹² rows (no chunk written) ran for ever,
    reading fill values."""
    def huge(group, name):
        group.create_dataset(name, shape=(10**12,), dtype="f8", chunks=(1000,))

    path = _h5_log(root / "w.h5", time_s=huge, surface_rpm=huge, surface_torque_Nm=huge)
    says = ("declares 8e+12 bytes", "1e+12 rows", "2000×")
    return [Case(["inspect", path], (2,), says), Case(["run", path, "--out", "out"], (2,), says)]


def case_h5_gzip_compressed_constant_log_still_reads(root):
    """The packing limit must not refuse a real compressed log (constant columns pack
    hundreds of times)."""
    rows = 200_000

    def packed(group, name):
        group.create_dataset(name, data=np.full(rows, 60.0), compression="gzip",
                             compression_opts=9, shuffle=True)

    path = _h5_log(root / "w.h5", rows=rows, surface_rpm=packed)
    return [Case(["inspect", path], (0,), ("surface_rpm",))]


# --------------------------------------------------------------------------- bounded time
def _las(path: Path, curves: list[str], rows: int = 3, extra: str = "") -> Path:
    """A LAS 2.0 file with a TIME index and ``curves`` (each 60.0 in every row)."""
    header = ["~Version", "VERS. 2.0 :", "WRAP. NO :", "~Well", "NULL. -999.25 :", extra,
              "~Curve", "TIME.s : time"] + [f"{c} : curve" for c in curves] + ["~ASCII"]
    data = [" ".join([str(r)] + ["60.0"] * len(curves)) for r in range(rows)]
    path.write_text("\n".join(header + data) + "\n", encoding="utf-8")
    return path


def case_las_declaring_20000_curves(root):
    """lasio's header parse is quadratic in the curve count: 20 000 curves took > 120 s."""
    path = _las(root / "w.las", [f"C{k}.m" for k in range(20_000)])
    return [Case(["inspect", path], (2,), ("holds 20,001 items", "1,000"))]


def case_las_header_line_longer_than_the_line_limit(root):
    path = _las(root / "w.las", ["RPM.rpm"], extra="DESC. " + "x" * (1 << 21) + " :")
    return [Case(["inspect", path], (2,), ("header line is longer",))]


def case_parquet_declaring_1e8_rows_of_one_run(root):
    """Run-length-encoded nulls: 10⁸ rows in half a megabyte were read for ten seconds
    (10¹² rows would be read for ever)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows = 5_000_000
    table = pa.table({c: pa.nulls(rows, pa.float64())
                      for c in ("time_s", "surface_rpm", "surface_torque_Nm")})
    pq.write_table(table, root / "w.parquet", row_group_size=rows)
    return [Case(["inspect", root / "w.parquet"], (2,), ("declares 5e+06 rows",
                                                          "100 rows per byte"))]


def case_survey_parquet_declaring_a_million_stations(root):
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({c: pa.nulls(1_000_000, pa.float64()) for c in ("md", "inc", "azi")}),
                   root / "s.parquet")
    _config(_log(root / "w.csv").with_suffix(".toml"), '[survey]\nfile = "s.parquet"\n')
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("s.parquet", "1e+06 stations"))]


# --------------------------------------------------------------------------- escapes
BEL = "\x07"


def case_escape_in_column_name_in_the_fix_hint(root):
    """The fix hint of a missing channel quoted a column name raw (ESC, BEL)."""
    path = root / "w.csv"
    path.write_text(f"time_s,surface_rpm,torque{ESC}{BEL}\n" + "1,60,3\n" * 50,
                    encoding="utf-8")
    return [Case(["inspect", path], (2,), ("surface_torque_Nm not found", "torque?[2J?"))]


def case_escape_in_column_that_turns_backwards(root):
    """logcheck's "turns backwards" message and its fix quoted the column name raw."""
    path = _log(root / "w.csv", rpm=-60.0,
                columns=("time_s", f"RPM{ESC}{BEL}", "surface_torque_Nm"))
    _config(path.with_suffix(".toml"),
            '[channels]\nsurface_rpm = { column = "RPM\\u001b[2J\\u0007", unit = "rpm" }\n')
    return [Case(["run", path, "--out", "out"], (2,), ("turns backwards", "RPM?[2J?"))]


def case_las_warning_quotes_an_escape_sequence(root):
    """lasio's own logged warning printed a curve mnemonic raw (an OSC title sequence)."""
    path = _las(root / "w.las", ["SURFACE_RPM.rpm", "SURFACE_TORQUE.N.m"])
    text = path.read_text(encoding="utf-8").replace(
        "~ASCII", f"GHOST{ESC}]0;pwned{BEL}.m : defined, no data\n~ASCII")
    path.write_text(text, encoding="utf-8")
    return [Case(["inspect", path], (0, 2), ("LAS reader", "GHOST?[2J]0;PWNED?"))]


def case_escape_in_unit_of_a_units_row(root):
    path = root / "w.csv"
    path.write_text(f"time_s,surface_rpm,surface_torque\ns,rpm,kN{ESC}m\n" + "1,60,3\n" * 50,
                    encoding="utf-8")
    return [Case(["inspect", path], (2,), ("kN?[2Jm",))]


def case_infinite_values_give_no_library_warning(root):
    """±inf in a log printed pandas/numpy RuntimeWarnings with library paths; an infinite
    sample is now a null value (counted by inspect)."""
    path = _log(root / "w.csv")
    text = path.read_text(encoding="utf-8").splitlines()
    text[100] = "9.9,inf,-inf"
    text[101] = "10.0,-inf,inf"
    path.write_text("\n".join(text) + "\n", encoding="utf-8")
    return [Case(["inspect", path], (0,), ("2 (0.5%)",)),
            Case(["run", path, "--out", "out"], (0,), ("1 segment (",))]


# --------------------------------------------------------------------------- true messages
def case_fifo_as_the_data_file(root):
    """A FIFO named as data blocked for ever (open waits for a writer)."""
    os.mkfifo(root / "w.csv")
    return [Case(["inspect", root / "w.csv"], (2,), ("not a regular file",))]


def case_fifo_as_the_config_sidecar(root):
    _log(root / "w.csv")
    os.mkfifo(root / "w.toml")
    return [Case(["run", root / "w.csv", "--out", "out"], (2,), ("w.toml",
                                                                  "not a regular file"))]


def case_device_as_the_survey(root):
    """--survey /dev/zero said "survey file not found"."""
    _config(_log(root / "w.csv").with_suffix(".toml"))
    return [Case(["run", "w.csv", "--survey", "/dev/zero", "--out", "out"], (2,),
                 ("/dev/zero", "survey file is not a regular file")),
            Case(["inspect", "w.csv", "--config", "/dev/null"], (2,),
                 ("config file is not a regular file",))]


def case_parquet_with_a_nested_time_column(root):
    """A valid Parquet whose time column is a list per row was "truncated or corrupt"."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({"time_s": pa.array([[0.0, 1.0]] * 50, pa.list_(pa.float64())),
                             "surface_rpm": [60.0] * 50, "surface_torque_Nm": [8.0] * 50}),
                   root / "w.parquet")
    return [Case(["inspect", root / "w.parquet"], (2,), ("unsupported column type",
                                                          "'time_s'", "list<"))]


def _with_bit_depth(path: Path, value: str) -> Path:
    lines = path.read_text(encoding="utf-8").splitlines()
    path.write_text("\n".join([lines[0] + ",bit_depth_m"] + [f"{ln},{value}" for ln in lines[1:]])
                    + "\n", encoding="utf-8")
    _config(path.with_suffix(".toml"))
    return path


def case_huge_bit_depth_in_the_summary_line(root):
    """A huge bit depth was printed as a 31-digit number in the run's summary line."""
    path = _with_bit_depth(_log(root / "w.csv"), "1e30")
    return [Case(["run", path, "--out", "out"], (0,), ("bit 1e+30–1e+30 m",))]


def case_bit_depth_1e308_is_no_value(root):
    """A 1e308 bit depth was printed as a 309-digit number and overflowed into infinities in
    tracks.parquet (float32); beyond float32's range a sample is no value."""
    path = _with_bit_depth(_log(root / "w.csv"), "1e308")
    return [Case(["inspect", path], (0,), ("400 (100.0%)",)),
            Case(["run", path, "--out", "out"], (0,), ("bit 2500–2500 m",))]


CASES = {name[5:]: fn for name, fn in sorted(globals().items()) if name.startswith("case_")}


def _strict_check(case: Case, root: Path, capsys) -> None:
    """:func:`_check`, then: no control characters printed, no secret in --out."""
    text = _check(case, root)
    printed = capsys.readouterr()
    label = f"{case.args}: {text[-600:]!r}"
    assert not _CONTROL.search(text + printed.out + printed.err), label
    out = root / "out"
    for path in out.rglob("*") if out.is_dir() else ():
        if path.is_file() and not path.is_symlink():  # a link a case planted: not ours
            assert SECRET.encode() not in path.read_bytes(), f"secret in {path}: {label}"


@pytest.mark.parametrize("name", sorted(CASES))
def test_hostile_file(name, tmp_path, capsys):
    root = tmp_path / "sandbox"
    root.mkdir()
    for case in CASES[name](root):
        _strict_check(case, root, capsys)


def test_printed_text_is_checked_for_control_characters():
    """The strict check's pattern catches what the cases guard against (and not newlines)."""
    assert _CONTROL.search("x\x1b[2J") and _CONTROL.search("\x07") and _CONTROL.search("\r")
    assert not _CONTROL.search("line one\nline two — ü")

