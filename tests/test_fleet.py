"""`drillfric fleet` on local workers (issue 8): discovery, incremental manifest, fault
isolation, SIGTERM. Real components: wells come from `drillfric simulate`, runs go through
the CLI (in-process, or as a subprocess where a signal is sent)."""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.errors import InputError
from drillfric.fleet.discovery import WellSpec, discover
from drillfric.fleet.run import run_many

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[1]
#: Files of a complete well directory (docs/outputs.md).
WELL_FILES = ("summary.json", "estimates.parquet", "segments.parquet", "report.html")
#: Per-well friction truth of the synthetic wells (μ_s, μ_k).
TRUTH = {"w1": (0.5, 0.21), "w2": (0.5, 0.23), "w3": (0.5, 0.25)}


def make_wells(folder: Path, *, corrupt: bool = True) -> Path:
    """Three small simulated wells (60 s at 10 Hz, 50 cells: ~2-3 s to run each) and a
    corrupt CSV.

    The demo configuration without its scenario and well name, so each well is a single
    off-bottom stand named after its file.
    """
    folder.mkdir(parents=True, exist_ok=True)
    demo = REPO / "examples" / "demo"
    text = (demo / "demo.toml").read_text(encoding="utf-8")
    keep = [ln for ln in text.splitlines()
            if not ln.startswith(("scenario", "data =", 'name = "demo"'))]
    config = folder.parent / f"{folder.name}.sim.toml"
    config.write_text("\n".join(keep) + "\n", encoding="utf-8")
    shutil.copy(demo / "demo.survey.csv", folder.parent / "demo.survey.csv")
    runner = CliRunner()
    for i, (name, (mu_s, mu_k)) in enumerate(TRUTH.items()):
        result = runner.invoke(cli, [
            "-q", "simulate", str(config), "--out", str(folder / f"{name}.csv"),
            "--duration", "60", "--rate", "10", "--mu-s", str(mu_s), "--mu-k", str(mu_k),
            "--bit-depth", "1500", "--cells", "50", "--seed", str(i + 1)])
        assert result.exit_code == 0, result.output
    if corrupt:
        (folder / "bad.csv").write_bytes(b"time,rpm,torque\n1,2,3\ngarbage,\x00\x01,zz\n")
    return folder


def fleet(*args: str):
    """Run `drillfric fleet ARGS` in this process; returns the click result."""
    return CliRunner().invoke(cli, ["fleet", *map(str, args)])


def manifest(out: Path) -> dict:
    return json.loads((out / "manifest.json").read_text(encoding="utf-8"))["wells"]


def assert_complete(out: Path) -> None:
    """Every visible well directory of OUT is complete (no half-written well)."""
    for path in out.iterdir():
        if path.is_dir() and not path.name.startswith("."):
            missing = [f for f in WELL_FILES if not (path / f).is_file()]
            assert not missing, f"{path} lacks {missing}"


@pytest.fixture(scope="module")
def good_wells(tmp_path_factory) -> Path:
    """Three simulated wells and a manifest CSV listing them (relative paths)."""
    folder = make_wells(tmp_path_factory.mktemp("fleet") / "wells", corrupt=False)
    lines = ["well,data,config,survey"] + [f"{n},wells/{n}.csv,," for n in TRUTH]
    (folder.parent / "fleet.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    return folder


# --------------------------------------------------------------------------- discovery
def test_discover_directory_skips_sidecars_and_hidden_files(tmp_path):
    for name in ("a.csv", "a.toml", "a.survey.csv", "a.truth.json", "b.parquet",
                 ".hidden.csv", "notes.txt.bak"):
        (tmp_path / name).write_text("x")
    (tmp_path / "dirwell").mkdir()
    (tmp_path / "dirwell" / "well.toml").write_text("")
    (tmp_path / "empty_dir").mkdir()
    found = [s.data.name for s in discover(tmp_path)]
    assert found == ["a.csv", "b.parquet", "dirwell"]


def test_discover_manifest_resolves_relative_paths(tmp_path):
    (tmp_path / "m.json").write_text(json.dumps(
        [{"well": "A-1", "data": "d/a.csv", "config": "c.toml"}, {"data": "/abs/b.csv"}]))
    specs = discover(tmp_path / "m.json", config=tmp_path / "all.toml")
    assert specs == [WellSpec((tmp_path / "d/a.csv").resolve(), "A-1",
                              (tmp_path / "c.toml").resolve(), None),
                     WellSpec(Path("/abs/b.csv"), None, tmp_path / "all.toml", None)]


@pytest.mark.parametrize("content", ["well,config\nA,c.toml\n", "not,a\n\x00"])
def test_discover_bad_manifest_is_one_input_error(tmp_path, content):
    path = tmp_path / "m.csv"
    path.write_text(content)
    with pytest.raises(InputError, match="data"):
        discover(path)


def test_nothing_to_run_is_exit_2(tmp_path):
    result = fleet(tmp_path, "--out", tmp_path / "out")
    assert result.exit_code == 2
    assert "no wells found" in result.output
    assert fleet(tmp_path / "missing", "--out", tmp_path / "out").exit_code == 2


def test_all_wells_unreadable_is_exit_2(tmp_path):
    (tmp_path / "bad.csv").write_text("garbage\n\x00\n")
    result = fleet(tmp_path, "--out", tmp_path / "out", "--workers", "1")
    assert result.exit_code == 2
    assert "error: bad:" in result.output
    assert manifest(tmp_path / "out")["bad"]["status"] == "failed"


def test_wells_that_cannot_be_opened_fail_alone(tmp_path):
    """A missing well fails in the parent, unreadable ones in their workers (the parent
    never opens a data file); each fails alone."""
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x.csv").write_text("garbage\n")
    specs = [WellSpec(tmp_path / "missing.csv"), WellSpec(tmp_path / "a" / "x.csv"),
             WellSpec(tmp_path / "a" / "x.csv", "y")]
    result = run_many(specs, tmp_path / "out", workers=1)
    status = [(w.well, w.status) for w in result.wells]
    assert status == [("missing", "failed"), ("x", "failed"), ("y", "failed")]
    assert "file not found" in result.wells[0].message
    assert "time_s not found" in result.wells[1].message
    assert result.wells[0].attempts == 0  # found missing by the parent
    assert result.wells[2].attempts == 1 and "time_s not found" in result.wells[2].message
    assert len(manifest(tmp_path / "out")) == 3


# --------------------------------------------------------------------------- incremental
def test_incremental_skip_append_and_force(good_wells, tmp_path):
    """Second run skips everything and says so; appended data reprocesses only that well."""
    out = tmp_path / "out"
    source = good_wells.parent / "fleet.csv"
    first = fleet(source, "--out", out, "--workers", "1")
    assert first.exit_code == 0, first.output
    entries = manifest(out)
    assert {e["status"] for e in entries.values()} == {"ok"}
    for name, entry in entries.items():
        assert set(entry["inputs"]) == {"data", "config", "survey"}
        assert entry["drillfric_version"] and len(entry["config_sha256"]) == 64
        assert entry["task_s"] > 0 and Path(entry["outputs"]["dir"]) == out / name
    assert_complete(out)
    stamps = {n: (out / n / "summary.json").stat().st_mtime_ns for n in TRUTH}

    second = fleet(source, "--out", out, "--workers", "1")
    assert second.exit_code == 0
    assert "3 ok (0 processed, 3 unchanged; --force redoes them), 0 failed" in second.output
    assert stamps == {n: (out / n / "summary.json").stat().st_mtime_ns for n in TRUTH}

    data = good_wells / "w2.csv"
    frame = pd.read_csv(data)
    later = frame.assign(time_s=frame["time_s"] + frame["time_s"].iloc[-1] + 0.1)
    later.to_csv(data, mode="a", header=False, index=False)
    third = fleet(source, "--out", out, "--workers", "1")
    assert third.exit_code == 0
    assert "1 processed, 2 unchanged" in third.output
    after = {n: (out / n / "summary.json").stat().st_mtime_ns for n in TRUTH}
    assert [n for n in TRUTH if after[n] != stamps[n]] == ["w2"]
    summary = json.loads((out / "w2" / "summary.json").read_text())
    assert summary["inputs"]["rows"] == 2 * len(frame)

    rows = pd.read_parquet(out / "fleet_summary.parquet")
    assert set(rows["well"]) == set(TRUTH) and rows["segment_id"].notna().all()
    assert (rows.groupby("well").size() == [
        len(json.loads((out / n / "summary.json").read_text())["segments"])
        for n in sorted(TRUTH)]).all()

    doc = json.loads((out / "manifest.json").read_text())
    doc["wells"]["w3"]["drillfric_version"] = "0.0.0"  # as if an older drillfric ran it
    (out / "manifest.json").write_text(json.dumps(doc))
    upgraded = fleet(source, "--out", out, "--workers", "1")
    assert "1 processed, 2 unchanged" in upgraded.output
    assert manifest(out)["w3"]["drillfric_version"] != "0.0.0"

    forced = run_many([WellSpec(good_wells / "w1.csv")], out, workers=1, force=True)
    assert [w.status for w in forced.wells] == ["ok"]
    assert (out / "w1" / "summary.json").stat().st_mtime_ns != after["w1"]


# --------------------------------------------------------------------------- interruption
def test_sigterm_leaves_no_partial_well_and_rerun_completes(good_wells, tmp_path):
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "drillfric.cli.main", "-q", "fleet", str(good_wells),
           "--out", str(out), "--workers", "2"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 90
        while not any(".tmp-" in p.name for p in out.glob(".w*")):  # a well is being written
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.05)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "interrupted" in err
    assert_complete(out)
    done = [n for n, e in manifest(out).items() if e["status"] == "ok"]
    assert len(done) < len(TRUTH)

    rerun = fleet(good_wells, "--out", out, "--workers", "1")
    assert rerun.exit_code == 0, rerun.output
    assert f"{len(TRUTH) - len(done)} processed, {len(done)} unchanged" in rerun.output
    assert_complete(out)
    assert not [p.name for p in out.iterdir() if ".tmp-" in p.name or ".old-" in p.name]
    assert {n for n, e in manifest(out).items() if e["status"] == "ok"} == set(TRUTH)


def test_second_fleet_run_on_same_out_is_refused(good_wells, tmp_path):
    import fcntl

    out = tmp_path / "out"
    out.mkdir()
    with open(out / ".fleet.lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        result = fleet(good_wells, "--out", out)
    assert result.exit_code == 2
    assert "another fleet run" in result.output
    assert os.listdir(out) == [".fleet.lock"]


# --------------------------------------------------------------------------- stale results
def test_failed_well_marks_last_nights_results_stale_and_unchanged_wells_are_ok(good_wells,
                                                                               tmp_path):
    """Issue 25 item 7: after a well fails, OUT/NAME still held the previous night's
    summary.json and Parquet files with nothing marking them stale, and unchanged wells were
    shown as grey "skipped". Now the earlier results are marked (STALE.json, summary.json
    ``stale``, fleet_summary ``stale_result_dir``, fleet.html) and unchanged wells read "ok
    (unchanged)"; the next good run replaces the mark with fresh results."""
    shutil.copytree(good_wells.parent, tmp_path / "src")
    source, out = tmp_path / "src" / "fleet.csv", tmp_path / "out"
    assert fleet(source, "--out", out, "--workers", "1").exit_code == 0
    data = tmp_path / "src" / "wells" / "w2.csv"
    good = data.read_bytes()
    data.write_text("time_s,surface_rpm,surface_torque_Nm\n0,60,10\n1,60,10\n0.5,60,10\n")
    night = fleet(source, "--out", out, "--workers", "1")
    assert night.exit_code == 1
    assert "2 ok (0 processed, 2 unchanged), 1 failed" in night.output
    assert "1 failed well keeps an earlier run's results, marked stale" in night.output
    stale = json.loads((out / "w2" / "STALE.json").read_text())
    assert "time goes backwards" in stale["reason"] and stale["since_utc"]
    summary = json.loads((out / "w2" / "summary.json").read_text())
    assert summary["stale"]["reason"] == stale["reason"]
    assert "stale" not in json.loads((out / "w1" / "summary.json").read_text())
    rows = pd.read_parquet(out / "fleet_summary.parquet").drop_duplicates("well")
    marked = dict(zip(rows["well"], rows["stale_result_dir"], strict=True))
    assert Path(marked["w2"]) == out / "w2" and pd.isna(marked["w1"])
    html = (out / "fleet.html").read_text(encoding="utf-8")
    assert html.count(">ok (unchanged)</span>") == 2 and ">skipped<" not in html
    assert "2 ok (2 unchanged, results of an earlier run), 1 failed" in html
    assert "marked stale" in html and "stale report" in html
    data.write_bytes(good)
    assert fleet(source, "--out", out, "--workers", "1").exit_code == 0
    assert not (out / "w2" / "STALE.json").exists()
    assert "stale" not in json.loads((out / "w2" / "summary.json").read_text())


def test_linked_sidecars_get_a_fix_a_fleet_can_follow(tmp_path):
    """Issue 35: a well whose sidecars are symbolic links to files elsewhere failed with
    "fix: give the file with --config/--survey" — `fleet` has no --survey and its --config
    applies to every well. The fix now names a manifest's config/survey columns, and a
    manifest naming the linked files runs the well."""
    make_wells(tmp_path / "sim", corrupt=False)
    elsewhere, wells = tmp_path / "elsewhere", tmp_path / "wells"
    elsewhere.mkdir()
    wells.mkdir()
    shutil.copy(tmp_path / "sim" / "w1.csv", wells / "w1.csv")
    shutil.copy(tmp_path / "sim.sim.toml", elsewhere / "w1.toml")
    shutil.copy(tmp_path / "demo.survey.csv", elsewhere / "w1.survey.csv")
    (wells / "w1.toml").symlink_to(elsewhere / "w1.toml")
    (wells / "w1.survey.csv").symlink_to(elsewhere / "w1.survey.csv")
    result = fleet(wells, "--out", tmp_path / "out1", "--workers", "1")
    assert result.exit_code == 2
    assert "leads outside wells/" in result.output
    assert "config/survey columns of a `drillfric fleet` manifest" in result.output
    assert "--survey, or copy" not in result.output
    (tmp_path / "m.csv").write_text(
        "well,data,config,survey\n"
        f"w1,{wells / 'w1.csv'},{wells / 'w1.toml'},{wells / 'w1.survey.csv'}\n",
        encoding="utf-8")
    result = fleet(tmp_path / "m.csv", "--out", tmp_path / "out2", "--workers", "1")
    assert result.exit_code == 0, result.output
    assert manifest(tmp_path / "out2")["w1"]["status"] == "ok"


@pytest.mark.parametrize("outcome", ["all ok", "all unchanged", "partial", "some failed",
                                     "all failed", "nothing estimated"])
def test_fleet_last_line_names_manifest_or_folder_inconsistently(outcome):
    """Issue 35 (fourth newcomer): the fleet's last line named the folder when every well
    was unchanged and manifest.json otherwise. Every outcome now ends with the same path,
    OUT/manifest.json, after the same words in the same order."""
    from types import SimpleNamespace

    from drillfric.cli.fleet_cmd import _closing_line

    status = {"all ok": ["ok"] * 3, "all unchanged": ["skipped"] * 3,
              "partial": ["ok", "ok", "skipped"], "some failed": ["ok", "failed", "skipped"],
              "all failed": ["failed"] * 3, "nothing estimated": ["ok", "ok", "ok"]}[outcome]
    failing = 2 if outcome == "partial" else 0  # the first well's failed segments
    wells = [SimpleNamespace(status=s, stale_dir=None, failed_segments=failing * (i == 0))
             for i, s in enumerate(status)]
    result = SimpleNamespace(
        wells=wells, wall_s=2.0, manifest=Path("OUT/manifest.json"), out_root=Path("OUT"),
        count=lambda s: status.count(s), failed_segments=failing,
        nothing_estimated=("a", "b") if outcome == "nothing estimated" else ())
    line = _closing_line(result)
    assert re.fullmatch(r"fleet: 3 wells — \d ok \(\d processed, \d unchanged"
                        r"(; --force redoes them)?\)(, \d partial)?, \d failed(, [^—]+)? in "
                        r"2\.0 s — " + re.escape(str(Path("OUT/manifest.json"))), line), line
    # a well with failed segments is "partial", as fleet.html says, not counted ok
    assert ("2 ok (2 processed, 1 unchanged), 1 partial" in line) is (outcome == "partial")
    result.manifest = None  # not recorded: the same path all the same
    assert _closing_line(result) == line
