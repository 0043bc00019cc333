"""Hostile and broken inputs through the CLI: a regression corpus (docs/security.md).

Every case builds its files in a sandbox, runs a drillfric command and must hold, whatever
the outcome (issue 12): no traceback, no code executed (a payload would create
``sandbox/PWNED``), nothing written or deleted outside ``--out``, no temporary entries left
in ``--out``, no silent "exit 0 with nothing done", an error is one line naming the file or
path and the fix, and no file content (secrets, terminal escapes) in what is printed.
Cases are named after what they reproduce (lasio's practice).
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

PAYLOAD = b"cos\nsystem\n(S'touch PWNED'\ntR."  # protocol-0 pickle that runs a shell command
SECRET = "API_KEY=sk-live-0123456789"
ESC = "\x1b[2J"


@dataclass
class Case:
    """args: the command (paths relative to the sandbox; OUT is the sandbox's out/); exit:
    allowed exit codes; says: text the output must contain; cwd: run from there."""

    args: list
    exit: tuple
    says: tuple = ()
    cwd: str = "."
    absent: tuple = field(default_factory=tuple)  # paths (absolute) that must not appear


# --------------------------------------------------------------------------- builders
def _log(path: Path, *, seconds=40.0, rate=10.0, rpm=60.0, torque=8000.0, t0=0.0,
         columns=("time_s", "surface_rpm", "surface_torque_Nm")) -> Path:
    """A small rotating log (its one segment is shorter than min_segment_s: skipped, fast)."""
    t = t0 + np.arange(0.0, seconds, 1.0 / rate)
    rot = (t - t0 > 5.0) & (t - t0 < seconds - 5.0)
    frame = pd.DataFrame({"time_s": t, "surface_rpm": np.where(rot, rpm, 0.0),
                          "surface_torque_Nm": np.where(rot, torque, 0.0)})
    frame.columns = list(columns)
    path.parent.mkdir(parents=True, exist_ok=True)
    frame.to_csv(path, index=False)
    return path


def _config(path: Path, text: str = "") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("[segmentation]\nmin_segment_s = 60.0\n" + text, encoding="utf-8")
    return path


def _h5_table(path: Path) -> Path:
    pytest.importorskip("tables")
    t = np.arange(0.0, 40.0, 0.1)
    pd.DataFrame({"time_s": t, "surface_rpm": 60.0, "surface_torque_Nm": 8000.0}).to_hdf(
        path, key="surface", format="table", index=False)
    _config(path.with_suffix(".toml"))
    return path


def case_h5_pickled_column_names_run_no_code(root):
    """PyTables unpickles a table's column-name attribute: a crafted one ran commands."""
    path = _h5_table(root / "w.h5")
    with h5py.File(path, "a") as h5:
        h5["surface/table"].attrs["values_block_0_kind"] = np.bytes_(PAYLOAD)
    return [Case(["inspect", path], (2,), ("pickle",)),
            Case(["run", path, "--out", "out"], (2,), ("pickle",))]


def case_h5_attribute_ending_in_dot_is_never_unpickled(root):
    """Any string attribute ending in "." is unpickled by PyTables when read."""
    path = _h5_table(root / "w.h5")
    with h5py.File(path, "a") as h5:
        h5["surface"].attrs["note"] = np.bytes_(PAYLOAD)
        h5["surface/table"].attrs["TITLE"] = np.bytes_(PAYLOAD)
    return [Case(["run", path, "--out", "out"], (0,))]


def case_h5_fixed_frame_with_object_column_is_refused(root):
    """pandas 'fixed' frames store object columns as pickles (one per value)."""
    pytest.importorskip("tables")
    path = root / "w.h5"
    pd.DataFrame({"time_s": [0.0, 1.0], "surface_rpm": [1.0, 2.0],
                  "surface_torque_Nm": [1.0, 2.0], "note": ["a", "b"]}).to_hdf(
        path, key="surface", format="fixed")
    return [Case(["inspect", path], (2,), ("pickle",))]


def case_h5_binary_pickle_in_column_names_is_refused(root):
    path = _h5_table(root / "w.h5")
    with h5py.File(path, "a") as h5:
        h5["surface/table"].attrs["values_block_0_kind"] = np.bytes_(b"\x80\x04\x95" + PAYLOAD)
    return [Case(["run", path, "--out", "out"], (2,), ("pickle",))]


def case_h5_config_attributes_with_pickle_text_are_data(root):
    """A bundle's /config attributes are read as values (a pickle text is just bad text)."""
    path = _h5_table(root / "w.h5")
    path.with_suffix(".toml").unlink()
    with h5py.File(path, "a") as h5:
        h5.create_group("config").attrs["rig.torque_kind"] = np.bytes_(PAYLOAD)
    return [Case(["run", path, "--out", "out"], (2,), ("torque_kind",))]


def case_h5_truncated_is_one_line(root):
    path = _h5_table(root / "w.h5")
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 3])
    return [Case(["run", path, "--out", "out"], (2,), ("truncated or corrupt",))]


def case_h5_not_hdf5_at_all(root):
    path = root / "w.h5"
    path.write_bytes(os.urandom(4096))
    return [Case(["inspect", path], (2,), ("HDF5",))]


def case_h5_escape_sequences_in_group_names_are_not_echoed(root):
    path = root / "w.h5"
    with h5py.File(path, "w") as h5:
        h5.create_group(f"a{ESC}")
        h5.create_group(f"b{ESC}")
    return [Case(["inspect", path], (2,), ("no '/surface' table",))]


def case_config_name_dot_gives_no_directory(root):
    """name = "." made the run replace --out itself."""
    _config(root / "victim" / "keep.toml")
    _config(_log(root / "w.csv").with_suffix(".toml"), '[well]\nname = "."\n')
    return [Case(["run", "w.csv", "--out", "victim"], (2,), ("usable directory name",))]


def case_config_name_traversal_stays_inside_out(root):
    """name = "../../victim" deleted a directory two levels up."""
    _config(root / "victim" / "keep.toml")
    _config(_log(root / "wells" / "w.csv").with_suffix(".toml"),
            '[well]\nname = "../victim"\n')
    return [Case(["run", "wells/w.csv", "--out", "out"], (0,), cwd=".")]


def case_config_name_absolute_path_stays_inside_out(root):
    target = root.parent / f"{root.name}-abs"
    _config(_log(root / "w.csv").with_suffix(".toml"), f'[well]\nname = "{target}"\n')
    return [Case(["run", "w.csv", "--out", "out"], (0,), absent=(target,))]


def case_config_name_with_nul_and_escapes(root):
    _config(_log(root / "w.csv").with_suffix(".toml"), '[well]\nname = "A\\u0000B\\u001b[2J"\n')
    return [Case(["run", "w.csv", "--out", "out"], (0,))]


def case_config_name_too_long_is_cut_with_a_hash(root):
    _config(_log(root / "w.csv").with_suffix(".toml"), f'[well]\nname = "{"W" * 5000}"\n')
    return [Case(["run", "w.csv", "--out", "out"], (0,))]


def case_run_dot_from_inside_a_well_folder_with_out_dotdot(root):
    """`drillfric run . --out ..` inside well folder A: OUT/A is the input folder itself."""
    folder = root / "A"
    _log(folder / "surface.csv")
    _config(folder / "well.toml", '[well]\ndata = "surface.csv"\n')
    return [Case(["run", ".", "--out", ".."], (2,), ("not written by drillfric",), cwd="A")]


def case_unmarked_directory_at_out_name_is_not_replaced(root):
    _config(_log(root / "w.csv").with_suffix(".toml"))
    (root / "out" / "w").mkdir(parents=True)
    (root / "out" / "w" / "precious.txt").write_text("mine")
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("not written by drillfric",))]


def case_symlink_at_out_name_is_not_followed(root):
    _config(_log(root / "w.csv").with_suffix(".toml"))
    (root / "elsewhere").mkdir()
    (root / "elsewhere" / "precious.txt").write_text("mine")
    (root / "out").mkdir()
    (root / "out" / "w").symlink_to(root / "elsewhere")
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("not written by drillfric",))]


def case_manifest_rows_sharing_a_stem_both_fail(root):
    """Two manifest rows whose files share a stem wrote one directory, both "ok"; then
    they stopped the whole fleet. Both fail now, naming each other; the other wells run."""
    for d in ("a", "b", "c"):
        _config(_log(root / d / ("y.csv" if d == "c" else "x.csv")).with_suffix(".toml"))
    (root / "wells.csv").write_text("data\na/x.csv\nb/x.csv\nc/y.csv\n")
    return [Case(["fleet", "wells.csv", "--out", "out", "--workers", "1"], (1,),
                 ("would both write",))]


def case_manifest_well_column_names_the_output(root):
    for d in ("a", "b"):
        _config(_log(root / d / "x.csv").with_suffix(".toml"))
    (root / "wells.csv").write_text("well,data\nAlpha,a/x.csv\nBeta,b/x.csv\n")
    return [Case(["fleet", "wells.csv", "--out", "out", "--workers", "1"], (1,),
                 ("2 processed",))]


def case_manifest_well_name_traversal_stays_inside_out(root):
    _config(_log(root / "a" / "x.csv").with_suffix(".toml"))
    (root / "wells.csv").write_text("well,data\n../../escaped,a/x.csv\n")
    return [Case(["fleet", "wells.csv", "--out", "out", "--workers", "1"], (1,),
                 absent=(root.parent / "escaped",))]


def case_two_wells_with_one_name_are_refused(root):
    for d in ("a", "b"):
        _config(_log(root / d / "x.csv").with_suffix(".toml"))
    return [Case(["run", "a/x.csv", "b/x.csv", "--out", "out"], (2,), ("would both write",))]


def case_names_differing_only_in_case_are_refused(root):
    _config(_log(root / "a" / "Well.csv").with_suffix(".toml"))
    _config(_log(root / "b" / "WELL.csv").with_suffix(".toml"))
    return [Case(["run", "a/Well.csv", "b/WELL.csv", "--out", "out"], (2,),
                 ("would both write",))]


def case_stale_temporary_of_a_killed_run_is_removed(root):
    """A `.NAME.tmp-PID` of a killed run stayed even after a successful re-run."""
    _config(_log(root / "w.csv").with_suffix(".toml"))
    from drillfric.io.results import _HOST, MARKER

    stale = root / "out" / f".w.tmp-99999999-{_HOST}-dead"
    stale.mkdir(parents=True)
    (stale / MARKER).write_text("{}")
    return [Case(["run", "w.csv", "--out", "out"], (0,), absent=(stale,))]


def case_foreign_hidden_directory_in_out_is_left_alone(root):
    """drillfric removes only temporary directories it marked as its own."""
    _config(_log(root / "w.csv").with_suffix(".toml"))
    keep = root / "out" / ".w.tmp-99999999-x-notours"
    keep.mkdir(parents=True)
    (keep / "data.txt").write_text("someone else's")
    return [Case(["run", "w.csv", "--out", "out"], (0,))]


def case_out_is_a_file(root):
    _config(_log(root / "w.csv").with_suffix(".toml"))
    (root / "out").write_text("a file")
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("file stands where",))]


def case_out_under_a_file(root):
    _config(_log(root / "w.csv").with_suffix(".toml"))
    (root / "blocker").write_text("a file")
    return [Case(["run", "w.csv", "--out", "blocker/out"], (2,), ("file stands where",))]


def case_out_name_too_long(root):
    _config(_log(root / "w.csv").with_suffix(".toml"))
    return [Case(["run", "w.csv", "--out", "o" * 300], (2,), ("too long",))]


def case_csv_huge_line_is_refused_quickly(root):
    """A 64 MiB line made reading quadratic (a 1 GiB line ran > 15 min)."""
    path = root / "w.csv"
    with open(path, "wb") as fh:
        fh.write(b"time_s,surface_rpm,surface_torque_Nm\n0,1,2\n1,2,")
        fh.write(b"9" * (3 << 20))
        fh.write(b"\n")
    return [Case(["run", path, "--out", "out"], (2,), ("longer than",))]


def case_csv_first_line_longer_than_the_limit(root):
    path = root / "w.csv"
    path.write_bytes(b"x," * (1 << 20) + b"\n")
    return [Case(["inspect", path], (2,), ("longer than",))]


def case_csv_utf16_with_bom_is_read(root):
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"))
    path.write_bytes(path.read_text().encode("utf-16"))
    return [Case(["run", path, "--out", "out"], (0,))]


def case_csv_binary_garbage_is_not_a_text_file(root):
    path = root / "w.csv"
    path.write_bytes(b"\x7fELF\x02\x01\x01" + os.urandom(8192))
    return [Case(["run", path, "--out", "out"], (2,), ("not a text file",))]


def case_csv_escapes_in_header_are_not_echoed(root):
    path = root / "w.csv"
    path.write_text(f"time_s,x{ESC},surface_rpm\n" + "1,2,3\n" * 500, encoding="utf-8")
    return [Case(["inspect", path], (2,), ("surface_torque_Nm not found",))]


def case_secret_named_as_the_data_file_is_not_quoted(root):
    path = root / "w.csv"
    path.write_text(f"{SECRET},OTHER=1\n1,2\n", encoding="utf-8")
    return [Case(["inspect", path], (2,), ("not shown",))]


def case_survey_csv_holding_a_secret_is_not_quoted(root):
    (root / "secrets.csv").write_text(f"{SECRET},B\n1,2\n")
    _config(_log(root / "w.csv").with_suffix(".toml"), '[survey]\nfile = "secrets.csv"\n')
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("secrets.csv", "not shown"))]


def case_survey_pointing_at_a_secret_does_not_leak_it(root):
    """A [survey] file pointing at an unrelated file printed its first line."""
    (root / "secrets.env").write_text(f"{SECRET}\nOTHER=1\n")
    _config(_log(root / "w.csv").with_suffix(".toml"), '[survey]\nfile = "secrets.env"\n')
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("secrets.env",))]


def case_survey_secret_stays_out_of_fleet_files(root):
    (root / "a").mkdir()
    (root / "a" / "secrets.env").write_text(f"{SECRET}\n")
    _config(_log(root / "a" / "w.csv").with_suffix(".toml"), '[survey]\nfile = "secrets.env"\n')
    (root / "wells.csv").write_text("data\na/w.csv\n")
    return [Case(["fleet", "wells.csv", "--out", "out", "--workers", "1"], (2,),
                 ("secrets.env",))]


def case_parquet_truncated(root):
    path = root / "w.parquet"
    pd.DataFrame({"time_s": np.arange(100.0), "surface_rpm": 1.0,
                  "surface_torque_Nm": 1.0}).to_parquet(path)
    path.write_bytes(path.read_bytes()[:200])
    return [Case(["run", path, "--out", "out"], (2,), ("truncated or corrupt",))]


def case_las_garbage(root):
    path = root / "w.las"
    path.write_text(f"~V\nnot a las {ESC}\n~A\n1 2 3\n")
    return [Case(["inspect", path], (2,), ("LAS",))]


def case_xml_billion_laughs_is_refused(root):
    path = root / "w.xml"
    ents = "".join(f'<!ENTITY l{i} "&l{i - 1};&l{i - 1};&l{i - 1};&l{i - 1};">'
                   for i in range(1, 10))
    path.write_text(f'<?xml version="1.0"?><!DOCTYPE logs [<!ENTITY l0 "ha">{ents}]>'
                    "<logs>&l9;</logs>")
    return [Case(["inspect", path], (2,), ("w.xml",))]


def case_xml_external_entity_is_refused(root):
    (root / "secret.txt").write_text(SECRET)
    path = root / "w.xml"
    path.write_text(f'<?xml version="1.0"?><!DOCTYPE logs [<!ENTITY x SYSTEM '
                    f'"file://{root / "secret.txt"}">]><logs>&x;</logs>')
    return [Case(["inspect", path], (2,), ("w.xml",))]


def case_constant_time_column(root):
    path = root / "w.csv"
    path.write_text("time_s,surface_rpm,surface_torque_Nm\n" + "5,60,8000\n" * 200)
    return [Case(["run", path, "--out", "out"], (2,), ("one value",))]


def case_time_in_ms_labelled_s(root):
    """Time in ms read as s: every sample a gap, exit 0 with "0 segments" before."""
    path = _log(root / "w.csv", seconds=120.0)
    frame = pd.read_csv(path)
    frame["time_s"] *= 1000.0
    frame.to_csv(path, index=False)
    return [Case(["run", path, "--out", "out"], (2,), ('unit = "ms"',))]


def case_negated_rpm(root):
    path = _log(root / "w.csv", rpm=-60.0)
    return [Case(["run", path, "--out", "out"], (2,), ("scale = -1",))]


def case_all_nan_torque(root):
    path = _log(root / "w.csv")
    frame = pd.read_csv(path)
    frame["surface_torque_Nm"] = np.nan
    frame.to_csv(path, index=False)
    return [Case(["run", path, "--out", "out"], (2,), ("holds no numbers",))]


def case_rotating_rpm_nan_in_config(root):
    _config(_log(root / "w.csv").with_suffix(".toml"), "rotating_rpm = nan\n")
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("finite",))]


def case_top_drive_inertia_1e300(root):
    """An absurd I_TD gave an "ok" μ_k of 0.01."""
    _config(_log(root / "w.csv").with_suffix(".toml"),
            "[rig]\ntop_drive_inertia_kg_m2 = 1e300\n")
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("outside",))]


def case_inf_in_observer_starts(root):
    _config(_log(root / "w.csv").with_suffix(".toml"), "[observer]\nstarts = [[inf, 0.2]]\n")
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("observer.starts",))]


def case_no_rotation_at_all_is_not_silent(root):
    path = _log(root / "w.csv", rpm=0.0)
    return [Case(["run", path, "--out", "out"], (0,), ("no rotating segment",))]


def case_message_numbers_carry_at_most_four_digits(root):
    _config(_log(root / "w.csv").with_suffix(".toml"),
            "[fluid]\nmud_density_kg_m3 = 123456.789012\n")
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("1.235e+05",))]


def case_config_not_text(root):
    _log(root / "w.csv").with_suffix(".toml").write_bytes(b"\xff\xfe\x00" + os.urandom(64))
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("w.toml",))]


def case_unknown_channel_scale_key(root):
    _config(_log(root / "w.csv").with_suffix(".toml"),
            '[channels]\nsurface_rpm = { column = "surface_rpm", scale = 0 }\n')
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("scale",))]


def case_channel_scale_of_1e300(root):
    """Regression (issue 30, eighth attack): a scale of 1e300 was taken, every value
    overflowed, a RuntimeWarning leaked and the error printed a 300-digit number."""
    _config(_log(root / "w.csv").with_suffix(".toml"),
            '[channels]\nsurface_torque = { column = "surface_torque_Nm", scale = 1e300 }\n')
    return [Case(["run", "w.csv", "--out", "out"], (2,), ("scale", "1e-06–1e+06"))]


CASES = {name[5:]: fn for name, fn in sorted(globals().items()) if name.startswith("case_")}


# --------------------------------------------------------------------------- the checks
def _tree(root: Path, out: Path) -> dict:
    """Every path under ``root`` but ``out`` with its content digest (files) or kind."""
    seen = {}
    for path in sorted(root.rglob("*")):
        if path == out or out in path.parents:
            continue
        seen[str(path.relative_to(root))] = (path.read_bytes() if path.is_file() and not
                                             path.is_symlink() else "link" if
                                             path.is_symlink() else "dir")
    return seen


#: A command still running after this long [s] is taken as hung (a guard against a hang,
#: not a speed target: how long a case takes is no test's business, benchmarks/ time them).
HANG_S = 300


@contextmanager
def hang_guard(seconds: float = HANG_S):
    """Raise TimeoutError in this (main) thread after ``seconds`` [s] of one command."""
    def _hung(signum, frame):
        raise TimeoutError(f"still running after {seconds:.0f} s: hung")
    previous = signal.signal(signal.SIGALRM, _hung)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _check(case: Case, root: Path) -> str:
    out = root / "out"
    cwd = root / case.cwd
    outside = root.parent / f"{root.name}-outside"
    before = _tree(root, out), sorted(p.name for p in root.parent.iterdir())
    old = Path.cwd()
    os.chdir(cwd)
    try:
        with hang_guard():
            result = CliRunner().invoke(cli, [str(a) for a in case.args])
    finally:
        os.chdir(old)
    text = result.output
    label = f"{case.args} → {result.exit_code}: {text[-800:]}"
    assert result.exit_code in case.exit, label
    assert "Traceback" not in text and result.exception is None or isinstance(
        result.exception, SystemExit), label
    assert not (root / "PWNED").exists() and not (cwd / "PWNED").exists(), "code ran: " + label
    assert SECRET not in text and ESC not in text, "file content echoed: " + label
    for piece in case.says:
        assert piece in text, label
    after = _tree(root, out), sorted(p.name for p in root.parent.iterdir())
    assert after == before, "written or deleted outside --out: " + label
    assert not outside.exists()
    for path in case.absent:
        assert not Path(path).exists(), f"{path} exists: {label}"
    if out.is_dir():
        left = [p.name for p in out.rglob("*") if ".tmp-" in p.name and "notours" not in p.name
                or ".old-" in p.name]
        assert not left, f"temporary entries left: {left}: {label}"
        for record in ("manifest.json",):
            if (out / record).is_file() and not (out / record).is_symlink():
                assert SECRET not in (out / record).read_text(), label
        for page in out.rglob("*.html"):  # a link a case planted is not drillfric's page
            assert page.is_symlink() or not page.is_file() or \
                SECRET not in page.read_text(encoding="utf-8"), label
    if result.exit_code == 2:
        errors = [ln for ln in text.splitlines() if ln.startswith("Error:")]
        assert len(errors) == 1 and "fix" in errors[0], label
    if result.exit_code == 0 and case.args[0] == "run":
        summaries = list(out.glob("*/summary.json"))
        assert summaries, "exit 0 but no result: " + label
        summary = json.loads(summaries[0].read_text())
        assert summary["segments"] or summary["warnings"], "silent empty result: " + label
    return text


@pytest.mark.parametrize("name", sorted(CASES))
def test_hostile_input(name, tmp_path):
    root = tmp_path / "sandbox"
    root.mkdir()
    for case in CASES[name](root):
        _check(case, root)


def test_corpus_is_large_enough():
    assert len(CASES) >= 40


# --------------------------------------------------------------------------- processes
def _drillfric(*args, cwd, env=None, **kw) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "drillfric.cli.main", *map(str, args)],
                            cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=(env or os.environ) | {"MPLBACKEND": "Agg"}, **kw)


@pytest.mark.slow
@pytest.mark.parametrize("signum, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_signal_during_run_leaves_nothing_and_exits_128_plus_signal(tmp_path, signum, code):
    """SIGTERM/SIGINT during `run` left `.NAME.tmp-PID` behind, even after a re-run."""
    from tests.conftest import REPO

    out = tmp_path / "out"
    # a test run in the background of a non-interactive shell inherits SIGINT ignored, and
    # Python then leaves it ignored: the child gets the default, as a terminal would give it
    proc = _drillfric("run", REPO / "examples" / "demo" / "demo.csv", "--out", out,
                      cwd=tmp_path,
                      preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not list(out.glob(".demo.tmp-*")):
        time.sleep(0.05)
    time.sleep(2.0)  # inside the estimation
    proc.send_signal(signum)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == code, stderr
    assert "Traceback" not in stderr and "interrupted" in stderr
    assert not out.exists() or not list(out.iterdir()), list(out.iterdir())


def _unshare_ok(folder: Path) -> bool:
    """Whether a tmpfs can be mounted in a user namespace here (unprivileged)."""
    folder.mkdir()
    probe = subprocess.run(["unshare", "-rm", "sh", "-c", f"mount -t tmpfs tmpfs {folder}"],
                           capture_output=True)
    return probe.returncode == 0


@pytest.mark.parametrize("mount, says", [("ro", "read-only"), ("size=48k", "no space left")])
def test_full_or_read_only_disk_is_one_line_and_nothing_partial(tmp_path, mount, says):
    """Out of disk: exit 0, a printed report path that did not exist and a
    report.html.tmp inside the result. Now one line, exit 2, nothing in the final place.
    (A tmpfs mounted in a user namespace; skipped where namespaces are not allowed.)"""
    if shutil.which("unshare") is None or not _unshare_ok(tmp_path / "probe"):
        pytest.skip("no user/mount namespaces here: cannot mount a small tmpfs")
    from tests.conftest import REPO

    disk = tmp_path / "disk"
    disk.mkdir()
    run = (f"mount -t tmpfs -o {mount} tmpfs {disk} && exec {sys.executable} -m "
           f"drillfric.cli.main run {REPO / 'examples' / 'demo' / 'demo.csv'} --out {disk}/out")
    done = subprocess.run(["unshare", "-rm", "sh", "-c", run], capture_output=True, text=True,
                          env=os.environ | {"MPLBACKEND": "Agg"}, timeout=600)
    assert done.returncode == 2, done.stderr
    lines = [ln for ln in done.stderr.splitlines() if ln.startswith("Error:")]
    assert len(lines) == 1 and says in lines[0] and "fix" in lines[0], done.stderr
    assert "report:" not in done.stdout and "Traceback" not in done.stderr


def test_concurrent_writers_of_one_well_leave_one_complete_result(tmp_path):
    """The write-and-rename under concurrent writers raised ENOTEMPTY and left stray
    .old/.tmp directories (a stress test)."""
    import threading

    from drillfric.io.results import MARKER, ResultDirectory

    out = tmp_path / "out"
    errors = []

    def writer(k: int) -> None:
        try:
            for _ in range(20):
                with ResultDirectory(out, "w", "w") as tmp:
                    (tmp / "summary.json").write_text(json.dumps({"writer": k}))
        except Exception as exc:  # noqa: BLE001 — collected and asserted below
            errors.append(exc)

    threads = [threading.Thread(target=writer, args=(k,)) for k in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert sorted(p.name for p in out.iterdir()) == ["w"]
    assert {p.name for p in (out / "w").iterdir()} == {"summary.json", MARKER}


def test_no_code_path_unpickles_evaluates_or_opens_hdf5_with_pytables():
    """The mechanism, not the cases: no pickle, eval or exec, no pandas/PyTables HDF5 reader
    anywhere in the library or the CLI (docs/security.md)."""
    import re

    from tests.conftest import REPO

    banned = re.compile(r"\bimport pickle\b|\bpickle\.loads?\(|(?<![\w.])eval\(|(?<![\w.])exec\("
                        r"|read_hdf\(|HDFStore\(|^\s*import tables\b|^\s*from tables\b", re.M)
    found = [f"{p.relative_to(REPO)}: {m.group(0)}"
             for folder in ("drillfric", "cli") for p in (REPO / folder).rglob("*.py")
             for m in banned.finditer(p.read_text(encoding="utf-8"))]
    assert not found, found
