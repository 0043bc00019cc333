"""`drillfric fleet --scheduler` against a real Dask cluster (issue 8): a `dask scheduler`
and two `dask worker` processes (each under a nanny, which restarts a killed worker) on
127.0.0.1. Every subprocess is torn down by the fixture; every wait has a timeout."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from tests.test_fleet import TRUTH, assert_complete, fleet, make_wells, manifest

DASK = Path(sys.executable).with_name("dask")
pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not DASK.is_file(), reason="dask CLI not installed")]


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=15)


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    """Address of a scheduler with two single-threaded workers (nanny-supervised)."""
    from distributed import Client

    logs = tmp_path_factory.mktemp("dask")
    address = f"tcp://127.0.0.1:{_free_port()}"
    procs = []

    def start(*args: str, name: str) -> None:
        log = open(logs / f"{name}.log", "w")  # noqa: SIM115 — closed with the process
        procs.append((subprocess.Popen([str(DASK), *args], stdout=log, stderr=log,
                                       cwd=logs), log))

    try:
        start("scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1],
              "--no-dashboard", name="scheduler")
        for i in range(2):
            start("worker", address, "--nworkers", "1", "--nthreads", "1", "--nanny",
                  "--host", "127.0.0.1", "--no-dashboard", "--name", f"w{i}",
                  name=f"worker{i}")
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(2, timeout=90)
            client.run(lambda: __import__("drillfric.runner.time_log") and None)  # warm imports
        yield address
    finally:
        for proc, log in reversed(procs):
            _stop(proc)
            log.close()


@pytest.fixture(scope="module")
def wells(tmp_path_factory) -> Path:
    return make_wells(tmp_path_factory.mktemp("fleet_dask") / "wells")


def _estimates(out: Path) -> dict:
    """(well, segment) → (μ_s, μ_k, μ_s lower bound) from the well summaries."""
    table = {}
    for name in TRUTH:
        summary = json.loads((out / name / "summary.json").read_text(encoding="utf-8"))
        for seg in summary["segments"]:
            table[name, seg["id"]] = (seg["mu_s"], seg["mu_k"], seg["mu_s_lower_bound"])
    return table


def _check_fleet(out: Path, output: str) -> None:
    """3 wells ok, the corrupt one failed with its message; manifest and summary complete."""
    entries = manifest(out)
    assert set(entries) == {*TRUTH, "bad"}
    assert {n for n, e in entries.items() if e["status"] == "ok"} == set(TRUTH)
    assert entries["bad"]["status"] == "failed"
    assert "bad.csv" in entries["bad"]["message"] and "not a text file" in entries["bad"]["message"]
    assert f"error: bad: {entries['bad']['message']}" in output
    for name in TRUTH:  # the corrupt well fails when opened, before any worker
        assert {"inputs", "config_sha256", "drillfric_version", "started_utc", "task_s",
                "worker", "attempts"} <= set(entries[name])
    assert_complete(out)
    html = (out / "fleet.html").read_text(encoding="utf-8")
    assert all(name in html for name in (*TRUTH, "bad"))
    rows = pd.read_parquet(out / "fleet_summary.parquet")
    assert set(rows["well"]) == {*TRUTH, "bad"}
    assert rows.loc[rows["well"] == "bad", "well_status"].tolist() == ["failed"]


def test_scheduler_fleet_matches_local_fleet(scheduler, wells, tmp_path):
    remote = fleet(wells, "--out", tmp_path / "dask", "--scheduler", scheduler)
    assert remote.exit_code == 1, remote.output
    _check_fleet(tmp_path / "dask", remote.output)
    workers = {e["worker"] for e in manifest(tmp_path / "dask").values() if "worker" in e}
    assert all(str(os.getpid()) not in w for w in workers)  # ran on the cluster

    local = fleet(wells, "--out", tmp_path / "local", "--workers", "2")
    assert local.exit_code == 1, local.output
    _check_fleet(tmp_path / "local", local.output)
    # Same code, same inputs, deterministic pipeline: bit-identical estimates.
    assert _estimates(tmp_path / "dask") == _estimates(tmp_path / "local")


def test_unreachable_scheduler_is_exit_2(wells, tmp_path, monkeypatch):
    monkeypatch.setattr("drillfric.fleet.run.CONNECT_TIMEOUT_S", 2)
    result = fleet(wells, "--out", tmp_path / "out", "--scheduler",
                   f"tcp://127.0.0.1:{_free_port()}")
    assert result.exit_code == 2
    assert "cannot reach the Dask scheduler" in result.output


def test_killed_worker_loses_no_well(scheduler, wells, tmp_path):
    """SIGKILL the worker processing a well: Dask reschedules it, every well completes."""
    from distributed import Client

    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "drillfric.cli.main", "-q", "fleet", str(wells), "--out",
           str(out), "--scheduler", scheduler]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    killed = None
    try:
        with Client(scheduler, timeout="30s") as client:
            deadline = time.monotonic() + 90
            while killed is None and proc.poll() is None and time.monotonic() < deadline:
                busy = [(w, str(k)) for w, keys in client.processing().items()
                        for k in keys if "drillfric-well-w" in str(k)]
                if busy:
                    pid = client.run(os.getpid, workers=[busy[0][0]])[busy[0][0]]
                    os.kill(pid, signal.SIGKILL)
                    killed = (busy[0][1].split("-")[2], pid)
                time.sleep(0.05)
            _, err = proc.communicate(timeout=150)
            client.wait_for_workers(2, timeout=90)  # the nanny restarted it
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert killed is not None, "no worker was seen processing a well"
    assert proc.returncode == 1, err
    entries = manifest(out)
    assert {n for n, e in entries.items() if e["status"] == "ok"} == set(TRUTH)
    well, pid = killed
    assert not entries[well]["worker"].endswith(f":{pid}")  # finished by another process
    assert_complete(out)


def test_hostile_files_on_a_cluster_fail_alone(scheduler, tmp_path_factory, tmp_path):
    """Issue #20: the xlsx bomb and the segfaulting DLIS file are opened on the workers (in
    a contained reader child): no worker dies, the good well is written."""
    from tests.test_hostile_round_two import (
        check_hostile_fleet,
        dlis_zero_length_records,
        xlsx_cell_at_xfd1048576,
    )

    folder = tmp_path / "wells"
    made = make_wells(tmp_path_factory.mktemp("made") / "wells", corrupt=False)
    folder.mkdir()
    for path in made.glob("w1.*"):
        (folder / path.name).write_bytes(path.read_bytes())
    (tmp_path / "demo.survey.csv").write_bytes((made.parent / "demo.survey.csv").read_bytes())
    xlsx_cell_at_xfd1048576(folder / "bomb.xlsx")
    dlis_zero_length_records(folder / "zero.dlis")
    result = fleet(folder, "--out", tmp_path / "out", "--scheduler", scheduler)
    assert result.exit_code == 1, result.output
    check_hostile_fleet(tmp_path / "out", result.output)
    assert all(e.get("attempts") == 1 for e in manifest(tmp_path / "out").values())
