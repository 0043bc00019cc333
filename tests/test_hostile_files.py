"""Hostile files, round two (issue 20): reads outside the named file, hangs, raw terminal
escapes in drillfric's own lines, and messages that said something untrue.

Each case builds its files in a sandbox and runs the CLI through the checks of the first
corpus (:func:`tests.test_hostile_inputs._check`: exit code, no traceback, nothing written
outside ``--out``, one error line with the file and the fix, no secret and no escape
sequence printed), and in addition: no control character but newline in anything printed,
the secret in no file under ``--out``, and every command done within
:data:`SECONDS`. Cases are named after the attack or accident they reproduce.
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from tests.test_hostile_inputs import SECRET, Case, _check, _config

#: Longest a hostile case may take [s] (the corpus's bound for "bounded time").
SECONDS = 30.0
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


CASES = {name[5:]: fn for name, fn in sorted(globals().items()) if name.startswith("case_")}


def _strict_check(case: Case, root: Path, capsys) -> None:
    """:func:`_check`, then: no control characters printed, no secret in --out, in time."""
    started = time.monotonic()
    text = _check(case, root)
    took = time.monotonic() - started
    printed = capsys.readouterr()
    label = f"{case.args}: took {took:.1f} s: {text[-600:]!r}"
    assert took < SECONDS, label
    assert not _CONTROL.search(text + printed.out + printed.err), label
    out = root / "out"
    for path in out.rglob("*") if out.is_dir() else ():
        if path.is_file():
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

