"""Issue #20 "Hostile files, round two": native readers that abort or segfault, a fleet one
file can stop, and ``--scheduler`` pointing at something that is not a Dask scheduler.

Every attack is built here, tiny, and goes through the CLI: exit code 2 (1 for a fleet
with good wells), one line naming the file and what happened, no traceback, no crash of
drillfric itself, within 30 s. Cases are named after the attack (lasio's practice).
"""

from __future__ import annotations

import shutil
import socket
import struct
import subprocess
import sys
import threading
import zipfile
from pathlib import Path

import pytest

from tests.test_fleet import fleet, make_wells, manifest

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[1]
_SHEET_NS = "http://schemas.openxmlformats.org/spreadsheetml/2006/main"
_REL_NS = "http://schemas.openxmlformats.org/package/2006/relationships"
_DOC_REL = "http://schemas.openxmlformats.org/officeDocument/2006/relationships"


# --------------------------------------------------------------------------- attacks
def xlsx_cell_at_xfd1048576(path: Path) -> Path:
    """A 1.5 KB workbook with cells at A1 and XFD1048576: calamine sizes the sheet as
    16384 × 1048576 cells (512 GiB) and aborts."""
    main = "application/vnd.openxmlformats-officedocument.spreadsheetml"
    parts = {
        "[Content_Types].xml":
            '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
            f'<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.'
            f'relationships+xml"/><Default Extension="xml" ContentType="application/xml"/>'
            f'<Override PartName="/xl/workbook.xml" ContentType="{main}.sheet.main+xml"/>'
            f'<Override PartName="/xl/worksheets/sheet1.xml" '
            f'ContentType="{main}.worksheet+xml"/></Types>',
        "_rels/.rels": f'<Relationships xmlns="{_REL_NS}"><Relationship Id="rId1" '
                       f'Type="{_DOC_REL}/officeDocument" Target="xl/workbook.xml"/>'
                       '</Relationships>',
        "xl/workbook.xml": f'<workbook xmlns="{_SHEET_NS}" xmlns:r="{_DOC_REL}"><sheets>'
                           '<sheet name="log" sheetId="1" r:id="rId1"/></sheets></workbook>',
        "xl/_rels/workbook.xml.rels":
            f'<Relationships xmlns="{_REL_NS}"><Relationship Id="rId1" '
            f'Type="{_DOC_REL}/worksheet" Target="worksheets/sheet1.xml"/></Relationships>',
        "xl/worksheets/sheet1.xml":
            f'<worksheet xmlns="{_SHEET_NS}"><sheetData><row r="1"><c r="A1"><v>1</v></c>'
            '</row><row r="1048576"><c r="XFD1048576"><v>2</v></c></row></sheetData>'
            '</worksheet>',
    }
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, text in parts.items():
            archive.writestr(name, text)
    return path


def dlis_zero_length_records(path: Path, records: int = 20_000) -> Path:
    """A 160 KB DLIS file: a storage unit label, then ``records`` visible records each
    holding one logical record segment of header only (explicitly formatted, no body) —
    dlisio segfaults on it."""
    label = b"   1V1.00RECORD 8192Default Storage Set".ljust(80)
    segment = struct.pack(">HBB", 4, 0x80, 0)
    record = struct.pack(">HBB", 4 + len(segment), 0xFF, 1) + segment
    path.write_bytes(label + record * records)
    return path


def _one_line(text: str) -> list[str]:
    lines = [ln for ln in text.splitlines() if ln.strip()]
    assert "Traceback" not in text and len(lines) == 1, text
    return lines


def _drillfric(*args, timeout: float = 60) -> subprocess.CompletedProcess:
    """drillfric in a fresh process (a crash of the reader would kill it, not pytest)."""
    return subprocess.run([sys.executable, "-m", "drillfric.cli.main", *map(str, args)],
                          cwd=REPO, capture_output=True, text=True, timeout=timeout)


# --------------------------------------------------------------------------- readers
@pytest.mark.parametrize("build, says", [
    (lambda p: xlsx_cell_at_xfd1048576(p / "bomb.xlsx"),
     "refused: worksheet xl/worksheets/sheet1.xml spans 1.72e+10 cells"),
    (lambda p: dlis_zero_length_records(p / "zero.dlis"),
     "the DLIS reader crashed (signal 11, SIGSEGV)"),
], ids=["xlsx_cell_at_XFD1048576", "dlis_20000_zero_length_records"])
@pytest.mark.parametrize("command", ["run", "inspect"])
def test_native_reader_crash_is_one_line_exit_2(tmp_path, build, says, command):
    path = build(tmp_path)
    out = tmp_path / "out"
    args = [command, path] + (["--out", out] if command == "run" else [])
    done = _drillfric(*args)  # a hang ends in its TimeoutExpired
    assert done.returncode == 2, (done.returncode, done.stderr)
    (line,) = _one_line(done.stderr)
    assert line.startswith(f"Error: {path}: {says}") and "fix:" in line, line
    assert not out.exists()


# --------------------------------------------------------------------------- fleet
@pytest.fixture(scope="module")
def hostile_fleet(tmp_path_factory) -> Path:
    """One good simulated well beside the xlsx bomb and the segfaulting DLIS file."""
    made = make_wells(tmp_path_factory.mktemp("made") / "wells", corrupt=False)
    folder = tmp_path_factory.mktemp("hostile") / "wells"
    folder.mkdir()
    for path in made.glob("w1.*"):
        shutil.copy(path, folder / path.name)
    shutil.copy(made.parent / "demo.survey.csv", folder.parent / "demo.survey.csv")
    xlsx_cell_at_xfd1048576(folder / "bomb.xlsx")
    dlis_zero_length_records(folder / "zero.dlis")
    return folder


def check_hostile_fleet(out: Path, output: str) -> None:
    """The good well is written; each hostile one failed alone with its one line."""
    entries = manifest(out)
    assert entries["w1"]["status"] == "ok" and (out / "w1" / "summary.json").is_file()
    assert entries["bomb"]["status"] == "failed" and entries["zero"]["status"] == "failed"
    assert "refused: worksheet xl/worksheets/sheet1.xml spans" in entries["bomb"]["message"]
    assert "the DLIS reader crashed (signal 11" in entries["zero"]["message"]
    errors = [ln for ln in output.splitlines() if ln.startswith("error:")]
    assert len(errors) == 2 and "Traceback" not in output
    assert (out / "fleet.html").is_file() and (out / "fleet_summary.parquet").is_file()


@pytest.mark.parametrize("workers", [1, 2])
def test_fleet_of_hostile_files_writes_the_good_well(hostile_fleet, tmp_path, workers):
    result = fleet(hostile_fleet, "--out", tmp_path / "out", "--workers", workers)
    assert result.exit_code == 1, result.output
    check_hostile_fleet(tmp_path / "out", result.output)


# --------------------------------------------------------------------------- --scheduler
class _Listener:
    """A TCP service on 127.0.0.1 that is not a Dask scheduler: it sends ``greeting``
    (garbage) on every connection, or nothing at all."""

    def __init__(self, greeting: bytes | None):
        self.greeting = greeting
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.address = f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"
        self.open: list[socket.socket] = []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.open.append(conn)
            if self.greeting is not None:
                conn.sendall(self.greeting)

    def close(self) -> None:
        self.sock.close()
        for conn in self.open:
            conn.close()


@pytest.mark.parametrize("greeting, says", [
    (b"HTTP/1.1 400 Bad Request\r\n\r\n", "does not answer as a Dask scheduler (its first "
                                          "bytes are not a Dask message)"),
    (None, "does not answer as a Dask scheduler (it sent nothing within"),
], ids=["scheduler_answers_garbage_first", "scheduler_is_silent"])
def test_scheduler_that_is_not_dask_is_one_line(hostile_fleet, tmp_path, greeting, says):
    listener = _Listener(greeting)
    try:
        result = fleet(hostile_fleet, "--out", tmp_path / "out", "--scheduler",
                       listener.address)  # bounded by drillfric's own greeting timeout
    finally:
        listener.close()
    assert result.exit_code == 2
    (line,) = _one_line(result.output)
    assert says in line and listener.address in line, line
    assert not (tmp_path / "out").exists()  # a fleet that failed first leaves no OUT


@pytest.mark.parametrize("address, says", [
    ("http://[::1", "not a scheduler address"),
    ("http://127.0.0.1:8786", "scheme 'http'"),
    ("tcp://127.0.0.1", "needs a host and a port"),
    ("tcp://127.0.0.1:99999", "not a scheduler address"),
    ("tcp://:8786", "needs a host and a port"),
    ("tcp://h:1/\x1b[2J", "needs a host and a port"),
], ids=["unclosed_ipv6_bracket", "http_scheme", "no_port", "port_out_of_range", "no_host",
        "path_with_terminal_escape"])
def test_malformed_scheduler_address_is_one_line(hostile_fleet, tmp_path, address, says):
    result = fleet(hostile_fleet, "--out", tmp_path / "out", "--scheduler", address)
    assert result.exit_code == 2
    (line,) = _one_line(result.output)
    assert says in line and "\x1b" not in line and "internal error" not in line, line
    assert not (tmp_path / "out").exists()


def test_existing_out_is_kept_when_the_scheduler_fails(hostile_fleet, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    result = fleet(hostile_fleet, "--out", out, "--scheduler", "tcp://127.0.0.1")
    assert result.exit_code == 2
    assert (out / "notes.txt").read_text() == "mine"
