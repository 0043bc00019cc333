"""`drillfric inspect` says what `drillfric run` will do (issue 35 items 5 and 7).

Inspect had called segments usable that run then skipped or failed: Volve F-4 "7 usable"
and run skipped all 8 ("only 7 samples"); F-9 "11 usable" and run failed 8 (the default
string's 230 m below its top section, the bit at 154 m). It now makes run's checks before
the estimation chain with run's own functions (drillfric.runner.preview). On each real log
(../shared/data/real, read in place; skipped when absent) the segments inspect calls usable
are those run estimates, and the others carry run's status and message. The DSATS log's
run (minutes) is compared in tests/test_real_dsats.py with the same helper.
"""

from __future__ import annotations

import json
import shutil

import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from tests.conftest import REPO


def inspect_json(*args) -> tuple[int, dict]:
    """Exit code and document of ``drillfric inspect --json ARGS``."""
    result = CliRunner().invoke(cli, ["inspect", "--json", *map(str, args)])
    return result.exit_code, json.loads(result.stdout)


def run_summary(out, *args) -> dict:
    """summary.json of ``drillfric run ARGS --out OUT`` (its one well)."""
    result = CliRunner().invoke(cli, ["-q", "run", *map(str, args), "--out", str(out),
                                      "--no-report"])
    assert result.exit_code in (0, 1), result.output
    (folder,) = [p for p in out.iterdir() if p.is_dir()]
    return json.loads((folder / "summary.json").read_text())


def assert_verdicts_agree(doc: dict, summary: dict) -> None:
    """inspect's segments are run's, those it calls usable are those run estimated, and
    each of the others names run's status and reason."""
    seen = [(g["id"], g["kind"], g["status"]) for g in doc["segments"]]
    ran = [(g["id"], g["kind"], g["status"]) for g in summary["segments"]]
    assert seen == ran
    for mine, theirs in zip(doc["segments"], summary["segments"], strict=True):
        if mine["status"] != "ok":
            assert mine["message"] == theirs["message"], mine["id"]


@pytest.fixture
def volve(real_data):
    return real_data / "volve_witsml"


def test_f9_segments_run_fails_are_failed_in_inspect(volve, tmp_path):
    """F-9 A without its string: the default string's sections below the top are 230 m
    long, the bit at 127–184 m — inspect fails those segments as run does, none usable."""
    code, doc = inspect_json(volve / "F-9_time_log_1.xml")
    summary = run_summary(tmp_path, volve / "F-9_time_log_1.xml")
    assert code == 0 and doc["run_refuses"] is None
    assert_verdicts_agree(doc, summary)
    failed = [g for g in doc["segments"] if g["status"] == "failed"]
    assert len(failed) == 10 and not [g for g in doc["segments"] if g["status"] == "ok"]
    assert all("string below the top section is 230.0 m long" in g["message"] for g in failed)
    # issue 35 (F-9's geometry): segment 1 turned the BHA above the rotary, at −18.6 m
    first = doc["segments"][0]
    assert first["status"] == "skipped" and "above the rotary table" in first["message"]


def test_f4_with_its_sidecars_skips_what_run_skips(volve, tmp_path):
    """F-4 with its trajectory and tubular beside it and max_gap_s above its 15-s spacing:
    eight rotation bursts of ≤ 1 min, each too few samples for the estimator — and in the
    slips (issue 35: top-drive make-up, not off-bottom rotation), in inspect as in run."""
    well = tmp_path / "well"
    well.mkdir()
    for source, name in (("F-4_time_log_1.xml", "F-4.xml"), ("F-4_trajectory.xml",
                         "F-4.survey.xml"), ("F-4_tubular_run3.xml", "F-4.tubular.xml")):
        shutil.copyfile(volve / source, well / name)
    (well / "F-4.toml").write_text("[segmentation]\nmax_gap_s = 60.0\n")
    code, doc = inspect_json(well / "F-4.xml")
    summary = run_summary(tmp_path / "out", well / "F-4.xml")
    assert code == 0 and len(doc["segments"]) == 8
    assert_verdicts_agree(doc, summary)
    assert {g["status"] for g in doc["segments"]} == {"skipped"}
    shown = CliRunner().invoke(cli, ["inspect", str(well / "F-4.xml")]).output
    assert "segments   8 rotating: 0 usable, 8 skipped" in shown
    assert "7 skipped like segment 1: rotation in the slips: its hook load 633 kN" in shown


def test_f4_without_max_gap_is_refused_by_both_over_one_gap_rule(volve, tmp_path):
    """Issue 35 item 7: without max_gap_s inspect printed "gaps 0 longer than 75 s" and
    run refused the log, "every sample would be a gap" (10 s). Both now use max_gap_s:
    inspect lists every spacing as a gap and ends with run's error."""
    log = volve / "F-4_time_log_1.xml"
    code, doc = inspect_json(log)
    ran = CliRunner().invoke(cli, ["-q", "run", str(log), "--out", str(tmp_path)])
    assert code == ran.exit_code == 2
    assert doc["max_gap_s"] == 10.0 and len(doc["gaps"]) == doc["rows"] - 1
    assert doc["run_refuses"] in ran.output and "every sample would be a gap" in ran.output
    shown = CliRunner().invoke(cli, ["inspect", str(log)]).output
    assert "gaps       9999 longer than max_gap_s = 10 s" in shown
    assert "none estimated: run refuses the log" in shown


@pytest.mark.slow
@pytest.mark.parametrize("bha_m", [None, 3000.0], ids=["documented", "bha_3000_m"])
def test_usrop_f5_windows_are_run_s(real_data, tmp_path, bha_m):
    """The depth log of F-5 (2828–3792 m) with examples/usrop_f5.toml: inspect's windows are
    those run back-calculates; with its 60-m BHA made 3000 m long, the windows above 3090 m
    fail in both for the string below the top section, run's other windows estimated."""
    config = (REPO / "examples" / "usrop_f5.toml").read_text()
    if bha_m is not None:
        config = config.replace("length_m = 60.0", f"length_m = {bha_m}")
    (tmp_path / "f5.toml").write_text(config)
    args = (real_data / "volve_usrop_f5" / "USROP_F-5_depth.csv", "--config",
            tmp_path / "f5.toml", "--survey", real_data / "volve_surveys" / "F-5_ACTUAL.txt")
    code, doc = inspect_json(*args)
    assert code == 0
    assert_verdicts_agree(doc, run_summary(tmp_path / "out", *args))
    failed = [g for g in doc["segments"] if g["status"] == "failed"]
    assert len(failed) == (0 if bha_m is None else 10)
    assert all("string below the top section" in g["message"] for g in failed)
