"""Bad input through the CLI: one line naming the file, the problem and the fix; exit 2 and
nothing half-written — or, for a run that can go on, a clear warning (docs/ingestion.md)."""

from __future__ import annotations

import json
import shutil

import lasio
import numpy as np
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from tests.conftest import REPO

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

DEMO = REPO / "examples" / "demo"


def _invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def _one_line_error(result, name: str) -> str:
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and name in lines[0], result.output
    return lines[0]


# ------------------------------------------------------------------ nothing half-written
def test_unreadable_input_leaves_no_output_directory(tmp_path):
    """Time going backwards is found while streaming, after OUT would have been created:
    OUT (and its missing parents) must not be left behind empty."""
    bad = tmp_path / "w.csv"
    bad.write_text("time_s,surface_rpm,surface_torque_Nm\n0,60,10\n2,60,10\n1,60,10\n")
    result = _invoke("run", bad, "--out", tmp_path / "new" / "out")
    assert "time goes backwards" in _one_line_error(result, "w.csv")
    assert not (tmp_path / "new").exists()


def test_unreadable_input_keeps_an_existing_output_directory(tmp_path):
    """An OUT that existed before the run stays, untouched (and empty)."""
    bad = tmp_path / "w.csv"
    bad.write_text("time_s,surface_rpm,surface_torque_Nm\n")
    (tmp_path / "out").mkdir()
    _one_line_error(_invoke("run", bad, "--out", tmp_path / "out"), "w.csv")
    assert list((tmp_path / "out").iterdir()) == []


def test_unreadable_wells_on_workers_leave_no_output_directory(tmp_path):
    """`run A B --workers 2`: both unreadable (found on the workers), no OUT appears."""
    for name in ("a", "b"):
        (tmp_path / f"{name}.csv").write_text(
            "time_s,surface_rpm,surface_torque_Nm\n0,60,10\n2,60,10\n1,60,10\n")
    result = _invoke("run", tmp_path / "a.csv", tmp_path / "b.csv", "--workers", 2,
                     "--out", tmp_path / "out")
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert "a.csv" in result.output and "b.csv" in result.output
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", [["simulate"], ["td", "--bit-depth", "1000"]])
def test_simulate_and_td_with_a_bad_config_write_nothing(tmp_path, command):
    (tmp_path / "bad.toml").write_text("[fluid]\nmud_densty = 1200.0\n")
    result = _invoke(command[0], tmp_path / "bad.toml", *command[1:],
                     "--out", tmp_path / "new" / "x.csv")
    assert "unknown key 'fluid.mud_densty'" in _one_line_error(result, "bad.toml")
    assert not (tmp_path / "new").exists()


# ------------------------------------------------------------------ depth-indexed LAS
def _las(path, *, time_curve: bool):
    las = lasio.LASFile()
    las.append_curve("DEPT", np.arange(2000.0, 2010.0, 0.5), unit="M")
    if time_curve:
        las.append_curve("ETIM", np.arange(20.0), unit="S")
    las.append_curve("SRPM", np.full(20, 60.0), unit="RPM")
    las.append_curve("STOR", np.full(20, 12.0), unit="KN.M")
    las.write(str(path), version=2.0)
    return path


def test_depth_indexed_las_gives_a_friction_log(tmp_path):
    """A depth-indexed LAS log without a time curve was refused; it is now read as a
    friction log by depth (tests/test_friction_log.py checks the numbers)."""
    path = _las(tmp_path / "depth.las", time_curve=False)
    shown = _invoke("inspect", path)
    assert shown.exit_code == 0 and "depth-indexed log" in shown.output, shown.output
    result = _invoke("run", path, "--out", tmp_path / "out")
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "out" / "depth" / "summary.json").read_text())
    assert summary["index"] == "depth" and summary["segments"][0]["method"] == "td_backcalc"


def test_depth_indexed_las_with_a_time_curve_uses_it(tmp_path):
    path = _las(tmp_path / "depth.las", time_curve=True)
    result = _invoke("inspect", path, "--json")
    assert result.exit_code == 0, result.output
    doc = json.loads(result.output)
    assert doc["channels"]["time_s"]["column"] == "ETIM"
    assert doc["rows"] == 20 and doc["rate_hz"] == pytest.approx(1.0)


# ------------------------------------------------------------------ --rate above the data's
def _idle_log(path, rate_hz: float, seconds: float = 60.0):
    t = np.arange(0.0, seconds, 1.0 / rate_hz)
    lines = ["time_s,surface_rpm,surface_torque_Nm"] + [f"{v:g},0,0" for v in t]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_rate_above_the_data_rate_warns_and_uses_the_data_rate(tmp_path):
    log = _idle_log(tmp_path / "w.csv", rate_hz=1.0)
    result = CliRunner().invoke(
        cli, ["run", str(log), "--out", str(tmp_path / "o"), "--rate", "5"])
    assert result.exit_code == 0, result.output
    warning = [ln for ln in result.stderr.splitlines() if "5 Hz" in ln]
    assert len(warning) == 1 and "above the data's logging rate (1 Hz)" in warning[0]
    assert "not upsampled" in warning[0]
    summary = json.loads((tmp_path / "o" / "w" / "summary.json").read_text())
    assert any("not upsampled" in w for w in summary["warnings"])
    assert summary["inputs"]["requested_rate_hz"] == 5.0
    assert summary["inputs"]["resampled_rate_hz"] is None  # the data's own rate
    assert "not upsampled" in (tmp_path / "o" / "w" / "report.html").read_text()


def test_rate_below_the_data_rate_is_used_silently(tmp_path):
    log = _idle_log(tmp_path / "w.csv", rate_hz=10.0)
    result = CliRunner().invoke(
        cli, ["run", str(log), "--out", str(tmp_path / "o"), "--rate", "5"])
    assert result.exit_code == 0, result.output
    assert "upsampled" not in result.stderr
    summary = json.loads((tmp_path / "o" / "w" / "summary.json").read_text())
    # the idle log warns that nothing rotates — but nothing about the rate
    assert not [w for w in summary["warnings"] if "rate" in w]
    assert summary["inputs"]["resampled_rate_hz"] == 5.0


# ------------------------------------------------------------------ torque in the wrong unit
def _demo_with_torque(tmp_path, header: str, scale: float):
    """The demo well with its torque column renamed to ``header`` and values × ``scale``."""
    lines = (DEMO / "demo.csv").read_text().splitlines()
    columns = lines[0].split(",")
    k = columns.index("surface_torque_Nm")
    columns[k] = header
    rows = []
    for line in lines[1:]:
        fields = line.split(",")
        fields[k] = f"{float(fields[k]) * scale:.8g}"
        rows.append(",".join(fields))
    (tmp_path / "w.csv").write_text("\n".join([",".join(columns)] + rows) + "\n")
    shutil.copy(DEMO / "demo.toml", tmp_path / "w.toml")
    shutil.copy(DEMO / "demo.survey.csv", tmp_path / "demo.survey.csv")
    return tmp_path / "w.csv"


def _failed_segments(tmp_path, result):
    assert result.exit_code == 1, result.output  # segments failed, the run completed
    summary = json.loads((tmp_path / "o" / "demo" / "summary.json").read_text())
    rotating = [s for s in summary["segments"] if s["message"] != "" or s["status"] != "ok"]
    failed = [s for s in summary["segments"] if s["status"] == "failed"]
    assert len(failed) == 4 and failed == rotating  # every stand of the demo
    assert summary["mu_k"] is None  # never a made-up value
    return failed


def test_torque_in_kNm_labelled_Nm_fails_its_segments(tmp_path):
    """Values in kN·m under a header that says N·m: 1000 times below any friction."""
    well = _demo_with_torque(tmp_path, "STOR [N.m]", 1e-3)
    failed = _failed_segments(tmp_path, _invoke("run", well, "--out", tmp_path / "o"))
    for seg in failed:
        msg = seg["message"]
        assert "surface torque 1/" in msg and "of the bottom of the torque-and-drag range" in msg
        assert f"at {seg['bit_depth_m']:.0f} m" in msg and "for μ 0.02–1.5" in msg
        assert "if the log is in kN.m, correct the unit in the file" in msg


def test_torque_in_Nm_read_as_default_kNm_fails_its_segments(tmp_path):
    """A torque column without a unit is read in kN·m (the documented default): a log in
    N·m then reads 1000 times too high, and the fix is a [channels] unit."""
    well = _demo_with_torque(tmp_path, "TORQUE", 1.0)
    failed = _failed_segments(tmp_path, _invoke("run", well, "--out", tmp_path / "o"))
    for seg in failed:
        assert "x the top of the torque-and-drag range" in seg["message"]
        assert "read as kN.m (default)" in seg["message"]
        assert 'set [channels] surface_torque = { unit = "N.m" }' in seg["message"]


# ------------------------------------------------------------------ issue 25 item 10
def test_text_line_at_data_row_3_is_named_as_row_3(tmp_path):
    """A logger's note among the samples was reported as "cannot read '0' at data row 1"."""
    bad = tmp_path / "w.csv"
    bad.write_text("time_s,surface_rpm,surface_torque_Nm\n0,60,10\n0.5,60,10\n"
                   "logger restarted\n1.0,60,10\n1.5,60,10\n")
    line = _one_line_error(_invoke("run", bad, "--out", tmp_path / "o"), "w.csv")
    assert "cannot read 'logger restarted' at data row 3" in line
    assert "'0'" not in line and not (tmp_path / "o").exists()


def test_unknown_column_names_of_a_data_log_are_listed(tmp_path):
    """A file of numbers under unknown names is recognisably a data log: its header is
    listed; a text file named by mistake still is not quoted."""
    log = tmp_path / "w.csv"
    log.write_text("Zeit,Drehzahl,Moment\n" + "".join(f"{0.5 * i},{60 + i},{10 + i}\n"
                                                     for i in range(20)))
    line = _one_line_error(_invoke("inspect", log), "w.csv")
    assert "columns found: Zeit, Drehzahl, Moment" in line
    secrets = tmp_path / "s.csv"
    secrets.write_text("API_KEY=hunter2\nTOKEN=abc\n")
    line = _one_line_error(_invoke("inspect", secrets), "s.csv")
    assert "hunter2" not in line and "not shown" in line
    # A regression: two numeric columns under a key=value header read as a "log" and
    # quoted the secret (tests/test_hostile_inputs.py secret_named_as_the_data_file).
    keyed = tmp_path / "k.csv"
    keyed.write_text("API_KEY=hunter2,OTHER=1,X\n" + "1,2,3\n" * 20)
    line = _one_line_error(_invoke("inspect", keyed), "k.csv")
    assert "hunter2" not in line and "not shown" in line


@pytest.mark.parametrize("unit, says", [
    ("kNmx", "unknown unit 'kNmx' for surface_torque_Nm: no torque unit is spelled so"),
    ("kg", "unit 'kg' of surface_torque_Nm is not a torque unit (it measures [mass])"),
])
def test_bad_unit_in_channels_says_what_is_wrong_and_lists_accepted_units(tmp_path, unit,
                                                                          says):
    """A bad [channels] unit was answered with "state it in [channels]" — where it was."""
    shutil.copy(DEMO / "demo.csv", tmp_path / "w.csv")
    (tmp_path / "w.toml").write_text(f'[channels]\nsurface_torque = {{ unit = "{unit}" }}\n')
    line = _one_line_error(_invoke("inspect", tmp_path / "w.csv"), "w.csv")
    assert says in line and "kn.m, ft.lbf, kft.lbf" in line
    assert "state it in [channels]" not in line


def test_inspect_refuses_what_run_refuses_slow_witsml(tmp_path):
    """A WITSML log sampled every 30 s passed inspect, then run refused it over
    segmentation.max_gap_s: inspect now shows the log and ends with run's error (exit 2)."""
    quirk = REPO / "tests" / "fixtures" / "vendor_quirks" / \
        "witsml_time_log_after_depth_log_mnemonic_order_unitless_index_cps.xml"
    slow = tmp_path / "slow.xml"
    slow.write_text(quirk.read_text().replace("21:23:01.000Z", "21:23:30.000Z")
                    .replace("21:23:02.000Z", "21:24:00.000Z"))
    ran = _invoke("run", slow, "--out", tmp_path / "o")
    inspected = _invoke("inspect", slow)
    assert ran.exit_code == inspected.exit_code == 2
    refusal = ran.output.strip().splitlines()[-1]
    assert "segmentation.max_gap_s" in refusal and inspected.output.strip().endswith(refusal)
    as_json = _invoke("inspect", slow, "--json")
    assert as_json.exit_code == 2 and "segmentation.max_gap_s" in as_json.output
