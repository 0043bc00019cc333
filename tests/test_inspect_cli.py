"""`drillfric inspect`: the table, --json keys of docs/cli.md, and one-line errors (exit 2)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
GOOD = "TIME,SRPM,STOR [kN.m],HKLD [klbf]\n0,60,10,100\n0.2,61,11,101\n0.4,62,-999.25,102\n"


def _inspect(*args):
    return CliRunner().invoke(cli, ["inspect", *map(str, args)])


@pytest.fixture
def good(tmp_path) -> Path:
    (tmp_path / "w.csv").write_text(GOOD)
    return tmp_path / "w.csv"


def test_table(good):
    result = _inspect(good)
    assert result.exit_code == 0, result.output
    out = result.output
    for text in ("surface_torque_Nm", "STOR [kN.m]", "kN.m", "1 (33.3%)", "rows       3",
                 "5 Hz nominal", "survey     none", "segments   0 rotating: 0 usable",
                 "assumed    a vertical well with a nominal tortuosity of 1.0°/30 m"):
        assert text in out


def test_table_in_engineering_units(tmp_path):
    """Issue 35: forces in kN, torques in kN·m, pressures in bar — not 2.549e+05 N."""
    (tmp_path / "w.csv").write_text("TIME,SRPM,STOR [kN.m],HKLD [klbf],SPP [psi]\n"
                                    "0,60,10,100,3000\n0.2,61,11,101,3100\n")
    out = _inspect(tmp_path / "w.csv").output
    shown = {ln.split()[0]: ln.split()[-6:] for ln in out.splitlines() if ln.strip()}
    assert shown["hookload_N"] == ["kN", "0", "(0.0%)", "444.8", "447", "449.3"]
    assert shown["surface_torque_Nm"] == ["kN·m", "0", "(0.0%)", "10", "10.5", "11"]
    assert shown["standpipe_pressure_Pa"] == ["bar", "0", "(0.0%)", "206.8", "210.3", "213.7"]
    assert "e+0" not in out


def test_json_keys(good):
    result = _inspect(good, "--json")
    doc = json.loads(result.output)
    assert {"channels", "rows", "t_start_s", "t_end_s", "rate_hz", "gaps", "survey"} <= set(doc)
    assert doc["channels"]["surface_rpm"]["column"] == "SRPM"
    assert doc["channels"]["surface_torque_Nm"]["unit"] == "kN.m"
    assert doc["channels"]["hookload_N"]["max"] == pytest.approx(102 * 4448.2216152605)
    assert (doc["rows"], doc["t_start_s"], doc["gaps"], doc["survey"]) == (3, 0.0, [], None)
    assert doc["t_end_s"] == pytest.approx(0.4) and doc["rate_hz"] == pytest.approx(5.0)
    # 0.4 s of rotation is shorter than segmentation.min_rotation_s (2 s): speed noise,
    # not a segment.
    assert doc["segments"] == []


def test_json_survey_summary(good, tmp_path):
    (tmp_path / "w.survey.csv").write_text("md_m,inc_deg,azi_deg\n0,0,0\n800,10,0\n1200,20,0\n")
    doc = json.loads(_inspect(good, "--json").output)
    assert doc["survey"]["stations"] == 3 and doc["survey"]["md_max_m"] == 1200.0
    assert not any("tortuosity" in note for note in doc["assumed"])  # a survey is real


RIG_HEADER = ("# Rig: Example 7   Well: A-12\n# Exported 2024-05-01 12:00, depth ref. RKB\n"
              "#\n\n")


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"], ids=["LF", "CRLF", "CR"])
def test_csv_comment_lines_are_skipped(tmp_path, newline):
    """A rig header block of # lines (and a blank line) above the header, comments between
    the header and the units row and among the data: all skipped, the units row kept."""
    text = (RIG_HEADER + "TIME;SRPM;STOR;Pump #1\n# units below\ns;rpm;kN.m;spm\n"
            "0,0;60;10,5;80\n# bit change\n0,5;61;11;80\n   # note, 3 fields; 1; 2\n"
            "1,0;62;12;81\n")
    path = tmp_path / "w.csv"
    path.write_bytes(text.replace("\n", newline).encode())
    (tmp_path / "w.toml").write_text('[channels]\npump_rate = { column = "Pump #1" }\n')
    result = _inspect(path, "--json")
    assert result.exit_code == 0, result.output
    doc = json.loads(result.output)
    torque = doc["channels"]["surface_torque_Nm"]
    assert (torque["column"], torque["unit"]) == ("STOR", "kN.m")
    assert doc["channels"]["pump_rate_spm"]["column"] == "Pump #1"  # '#' inside a line stays
    assert (doc["rows"], doc["t_end_s"]) == (3, 1.0)
    assert (torque["min"], torque["max"]) == (10.5e3, 12e3)


def test_csv_of_comments_only_is_one_line(tmp_path):
    (tmp_path / "w.csv").write_text(RIG_HEADER)
    result = _inspect(tmp_path / "w.csv")
    assert result.exit_code == 2 and "only blank or # comment lines" in result.output
    assert len(result.output.strip().splitlines()) == 1


def test_dsats_acceptance(real_data):
    path = real_data / "dsats_1hz" / "SampleData1.csv"
    result = _inspect(path, "--config", EXAMPLES / "dsats_1hz.toml")
    assert result.exit_code == 0, result.output
    lines = {ln.split()[0]: ln for ln in result.output.splitlines() if ln.strip()}
    assert "ft.lbf" in lines["surface_torque_Nm"] and "kN·m" in lines["surface_torque_Nm"]
    assert "klbf" in lines["hookload_N"] and "1458 (2.9%)" in lines["hookload_N"]
    assert "254.9" in lines["hookload_N"] and "23.27" in lines["standpipe_pressure_Pa"]
    assert "1 Hz nominal" in lines["rate"] and "0.31–1.69 s" in lines["rate"]
    doc = json.loads(_inspect(path, "--config", EXAMPLES / "dsats_1hz.toml", "--json").output)
    assert doc["channels"]["surface_torque_Nm"]["null_count"] == 1458


# ------------------------------------------------------------------ bad input → exit 2
def _bad_cases(tmp_path):
    """(name, path, extra args, text expected in the one-line message)."""
    cases = []
    (tmp_path / "empty.csv").write_text("")
    cases.append(("empty", "empty.csv", [], "file is empty"))
    cases.append(("missing", "nope.csv", [], "file not found"))
    (tmp_path / "w.ods").write_text("x")
    cases.append(("extension", "w.ods", [], "unknown file extension '.ods'"))
    (tmp_path / "w.xlsx").write_text("x")
    cases.append(("not a workbook", "w.xlsx", [], "not a readable Excel workbook"))
    (tmp_path / "notorque.csv").write_text("TIME,RPM,HOOK\n0,1,2\n1,1,2\n")
    cases.append(("channel", "notorque.csv", [], "[channels] surface_torque = { column = "))
    (tmp_path / "unit.csv").write_text("TIME,RPM,TORQUE [blorps]\n0,1,2\n1,1,2\n")
    cases.append(("unknown unit", "unit.csv", [], "unknown unit 'blorps'"))
    (tmp_path / "kind.csv").write_text("TIME,RPM,TORQUE [klbf]\n0,1,2\n1,1,2\n")
    cases.append(("wrong-kind unit", "kind.csv", [], "is not a torque unit"))
    (tmp_path / "incons.csv").write_text("TIME,RPM,TORQUE [kN.m]\n0,1,2\n1,1,2\n")
    (tmp_path / "incons.toml").write_text('[channels]\nsurface_torque = { unit = "ft.lbf" }\n')
    cases.append(("inconsistent unit", "incons.csv", [], "inconsistent unit"))
    (tmp_path / "back.csv").write_text("TIME,RPM,TORQUE\n0,1,2\n1,1,2\n0.5,1,2\n")
    cases.append(("backwards", "back.csv", [], "time goes backwards at data row 3"))
    frame = pd.DataFrame({"time_s": [0.0, 1.0], "surface_rpm": [1.0, 1.0],
                          "surface_torque_Nm": [1.0, 1.0]})
    pq.write_table(pa.Table.from_pandas(frame), tmp_path / "t.parquet")
    data = (tmp_path / "t.parquet").read_bytes()
    (tmp_path / "t.parquet").write_bytes(data[:-20])
    cases.append(("truncated parquet", "t.parquet", [], "truncated or corrupt"))
    frame.to_hdf(tmp_path / "t.h5", key="surface", format="table")
    data = (tmp_path / "t.h5").read_bytes()
    (tmp_path / "t.h5").write_bytes(data[: len(data) // 3])
    cases.append(("truncated hdf5", "t.h5", [], "truncated or corrupt"))
    with h5py.File(tmp_path / "nosurf.h5", "w") as h5:
        h5["a"], h5["b"] = [1.0], [2.0]
    cases.append(("hdf5 without /surface", "nosurf.h5", [], "no '/surface' table"))
    (tmp_path / "ok.csv").write_text(GOOD)
    (tmp_path / "badkey.toml").write_text("[fluid]\nmud_densty = 1.0\n")
    cases.append(("unknown config key", "ok.csv", ["--config", tmp_path / "badkey.toml"],
                  "unknown key 'fluid.mud_densty'"))
    (tmp_path / "badtype.toml").write_text('[fluid]\nmud_density_kg_m3 = "heavy"\n')
    cases.append(("config key type", "ok.csv", ["--config", tmp_path / "badtype.toml"],
                  "must be a number"))
    (tmp_path / "chan.toml").write_text('[channels]\ntorque = { column = "STOR" }\n')
    cases.append(("unknown channel key", "ok.csv", ["--config", tmp_path / "chan.toml"],
                  "unknown channel 'torque'"))
    cases.append(("missing config", "ok.csv", ["--config", tmp_path / "none.toml"],
                  "config file not found"))
    return cases


def test_every_bad_input_is_one_line_exit_2(tmp_path):
    for name, file, extra, expected in _bad_cases(tmp_path):
        result = _inspect(tmp_path / file, *extra)
        message = result.output.strip()
        assert result.exit_code == 2, (name, result.output)
        assert "Traceback" not in result.output and len(message.splitlines()) == 1, name
        assert expected in message, (name, message)
        named = str(tmp_path / file) if "--config" not in extra else str(extra[1])
        assert named in message or "command line" in message, (name, message)


def test_bad_survey_through_inspect(good, tmp_path):
    (tmp_path / "s.csv").write_text("md_m,inc_deg,azi_deg\n0,0,0\n500,200,0\n")
    result = _inspect(good, "--survey", tmp_path / "s.csv")
    assert result.exit_code == 2 and "s.csv" in result.output
    assert len(result.output.strip().splitlines()) == 1


def test_inspect_lists_the_gaps_run_ends_segments_at(tmp_path):
    """Issue 35 item 7: inspect listed the spacings longer than max(max_gap_s, 5 periods)
    — none for Volve F-4 at 15 s ("0 longer than 75 s") — while run cut at max_gap_s. On a
    0.4 Hz log an 11-s hole is no gap under the old floor (12.5 s) but ends a rotation in
    run: inspect now lists exactly the gaps at which run's segments end."""
    t = np.arange(0.0, 200.0, 2.5)
    t[t >= 100.5] += 8.5  # one spacing of 11 s: 100 → 111 s
    rpm = np.where((t >= 80.0) & (t <= 131.0), 60.0, 0.0)
    pd.DataFrame({"TIME": t, "SRPM": rpm, "STOR [kN.m]": rpm / 6.0}).to_csv(
        tmp_path / "w.csv", index=False)
    doc = json.loads(_inspect(tmp_path / "w.csv", "--json").output)
    assert doc["gaps"] == [[100.0, 111.0]] and doc["max_gap_s"] == 10.0
    assert "gaps       1 longer than max_gap_s = 10 s" in _inspect(tmp_path / "w.csv").output
    ran = CliRunner().invoke(cli, ["-q", "run", str(tmp_path / "w.csv"), "--out",
                                   str(tmp_path / "o"), "--no-report"])
    summary = json.loads((tmp_path / "o" / "w" / "summary.json").read_text())
    ends = [(s["t_start_s"], s["t_end_s"]) for s in summary["segments"]]
    assert ran.exit_code == 0, ran.output
    assert ends == [(80.0, 100.0), (111.0, 131.0)]


def test_inspect_gives_run_s_verdict_before_the_estimation(tmp_path):
    """Issue 35 item 5 without the field data: a 40-s rotation at 2.5-s logging (too few
    samples) and a 100-s one with the bit at 150 m, above the default string's 230 m of
    HWDP and collars. inspect skips the first and fails the second with run's messages."""
    t = np.arange(0.0, 300.0, 2.5)
    rpm = np.where(((t >= 20) & (t <= 60)) | ((t >= 120) & (t <= 220)), 80.0, 0.0)
    pd.DataFrame({"TIME": t, "SRPM": rpm, "STOR [kN.m]": rpm / 8.0,
                  "BITDEP [m]": 150.0, "DEPTH [m]": 900.0}).to_csv(tmp_path / "w.csv",
                                                                   index=False)
    doc = json.loads(_inspect(tmp_path / "w.csv", "--json").output)
    ran = CliRunner().invoke(cli, ["-q", "run", str(tmp_path / "w.csv"), "--out",
                                   str(tmp_path / "o"), "--no-report"])
    summary = json.loads((tmp_path / "o" / "w" / "summary.json").read_text())
    verdicts = [(g["status"], g["message"]) for g in doc["segments"]]
    assert ran.exit_code == 1
    assert verdicts == [(g["status"], g["message"]) for g in summary["segments"]]
    assert [v[0] for v in verdicts] == ["skipped", "failed"]
    assert verdicts[0][1].startswith("only ") and "bit is at 150.0 m" in verdicts[1][1]
    shown = _inspect(tmp_path / "w.csv").output
    assert "segments   2 rotating: 0 usable, 1 skipped, 1 failed" in shown


def test_inspect_notes_the_bit_depth_run_assumes(tmp_path):
    """A log without a bit depth: run estimates its segments at the default bit depth and
    says so in summary.json ``assumed``; inspect checks them there and says so too."""
    from drillfric.runner.checks import DEFAULT_BIT_DEPTH_M

    t = np.arange(0.0, 200.0)
    rpm = np.where((t > 20) & (t < 150), 80.0, 0.0)
    pd.DataFrame({"TIME": t, "SRPM": rpm, "STOR [kN.m]": rpm / 8.0}).to_csv(
        tmp_path / "w.csv", index=False)
    doc = json.loads(_inspect(tmp_path / "w.csv", "--json").output)
    assert [g["bit_depth_m"] for g in doc["segments"]] == [DEFAULT_BIT_DEPTH_M]
    assert "bit depth 2500 m: neither the log nor a survey gives one" in doc["assumed"]


def test_inspect_wob_threshold_stays_si_in_field_mode():
    """Issue 35 (fourth newcomer, F-5 in ft): inspect's assumed line "rows that log WOB ≤ 10
    kN" stayed SI in field units, as did the skip reasons' m/s and m; in field units every
    inspect line gives its quantities in field units (klbf, ft/s, ft), in SI unchanged."""
    from drillfric.cli.inspect_cmd import _assumed_lines, _reasons

    note = ("on bottom in 731 of 18548 rows that log WOB ≤ 10 kN (segmentation.wob_on_bottom_N)"
            " while the hole advanced (ROP > 0)")
    [line] = _assumed_lines([note], "field")
    assert "WOB ≤ 2.25 klbf (segmentation.wob_on_bottom_N)" in line and " kN" not in line
    assert _assumed_lines([note], "si") == [f"assumed    {note}"]
    skipped = [{"id": 7, "status": "skipped", "message": "reaming at an unsteady speed: the "
                "pipe moves at +0.05 to +0.15 m/s; the bit depth jumps by 0.1 m; hook load "
                "633 kN at the block's level (585 kN)"}]
    [line] = _reasons(skipped, "field")
    assert "+0.164 to +0.492 ft/s" in line and "0.328 ft" in line and "142 klbf" in line
    assert not re.search(r"\d (m|kN|m/s)\b", line), line
    assert _reasons(skipped, "si")[0].endswith(skipped[0]["message"])


def _hooked_log(tmp_path, hookload_kN: float) -> Path:
    """A 1-Hz log rotating off bottom at 80 RPM for 130 s with the bit at 2000 m (hole at
    2100 m), the hook load ``hookload_kN`` and a configured block weight of 300 kN."""
    t = np.arange(0.0, 200.0)
    rpm = np.where((t > 20) & (t < 150), 80.0, 0.0)
    pd.DataFrame({"TIME": t, "SRPM": rpm, "STOR [kN.m]": rpm / 8.0, "HKLD [kN]": hookload_kN,
                  "BITDEP [m]": 2000.0, "DMEA [m]": 2100.0}).to_csv(tmp_path / "w.csv",
                                                                      index=False)
    (tmp_path / "w.toml").write_text("[hookload]\nblock_weight_N = 300000.0\n")
    return tmp_path / "w.csv"


def test_inspect_says_run_withholds_by_the_hookload_check(tmp_path):
    """Issue 35 (fourth newcomer): inspect said "30 usable" on DSATS and run then withheld
    all 30 μ_k by the hook-load check (the assumed default string weighs far more than the
    hook load measures). inspect applies run's check (hookload.judge on the soft-string
    model's off-bottom hook load) and says so in one line."""
    from drillfric import hookload
    from drillfric.io.well import open_well
    from drillfric.torque_drag import TDSettings

    path = _hooked_log(tmp_path, 400.0)
    well = open_well(path)
    td = TDSettings.from_config(well.config)
    model = hookload.modelled_string_weight_N(td, td.path_to(None, 2000.0), 2000.0)
    doc = json.loads(_inspect(path, "--json").output)
    check = doc["string_check"]
    assert check["string_weight_ratio"] == pytest.approx(100e3 / model, rel=1e-6)
    assert check["withheld_segments"] == [1] and check["verdict"] == "contradicted"
    out = _inspect(path).output
    line = next(ln for ln in out.splitlines() if ln.startswith("string "))
    assert f"measures {100e3 / model:.2f}× the modelled weight of the string (assumed " \
           "default): run will withhold the friction factors of 1 of 1 segments" in line
    assert "configure [[string]]" in line


def test_inspect_is_silent_when_the_hookload_weighs_the_string(tmp_path):
    """The hook load less the block is the model's off-bottom hook load: no line."""
    from drillfric import hookload
    from drillfric.io.well import open_well
    from drillfric.torque_drag import TDSettings

    well = open_well(_hooked_log(tmp_path, 400.0))
    td = TDSettings.from_config(well.config)
    model = hookload.modelled_string_weight_N(td, td.path_to(None, 2000.0), 2000.0)
    path = _hooked_log(tmp_path, 300.0 + model / 1e3)
    doc = json.loads(_inspect(path, "--json").output)
    assert doc["string_check"]["withheld_segments"] == []
    assert doc["string_check"]["string_weight_ratio"] == pytest.approx(1.0, rel=1e-6)
    assert "\nstring " not in _inspect(path).output


def test_dsats_inspect_says_run_withholds_by_the_hookload_check(real_data):
    """Issue 35 (fourth newcomer) on the real DSATS file, read in place: the 30 usable
    segments are all withheld by run's hook-load check (the assumed default string against
    the hook load), and inspect says so."""
    path = real_data / "dsats_1hz" / "SampleData1.csv"
    out = _inspect(path, "--config", EXAMPLES / "dsats_1hz.toml").output
    line = next(ln for ln in out.splitlines() if ln.startswith("string "))
    assert "the modelled weight of the string (assumed default): run will withhold the " \
           "friction factors of 30 of 30 segments" in line
