"""The built wheel installs into a clean virtual environment and its CLI runs from outside.

The clean environment gets the wheel only; third-party dependencies come from this test
environment's site-packages through a .pth path (which does not activate the editable
install's finder), so the check is of our packaging — ``cli/`` and ``templates/``
installed inside the ``drillfric`` namespace — without re-downloading numba and friends.
"""

from __future__ import annotations

import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

from tests.conftest import REPO

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow


def _run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw)


def test_wheel_installs_and_runs_outside_repo(tmp_path: Path):
    dist = tmp_path / "dist"
    _run([sys.executable, "-m", "pip", "wheel", str(REPO), "--no-deps", "--no-build-isolation",
          "-w", str(dist)])
    wheel = next(dist.glob("drillfric-*.whl"))
    env = tmp_path / "env"
    venv.create(env, with_pip=False)
    py = env / "bin" / "python"
    site = Path(_run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]
                     ).stdout.strip())
    (site / "deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    _run([sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps", str(wheel)])
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    where = _run([str(py), "-c", "import drillfric, drillfric.cli, drillfric.templates; "
                  "print(drillfric.__file__)"], cwd=outside).stdout
    assert str(env) in where, f"imported from outside the clean env: {where}"
    out = _run([str(env / "bin" / "drillfric"), "--help"], cwd=outside).stdout
    assert "simulate" in out and "fleet" in out
    # every module of the source tree is in the wheel (a regression: drillfric.estimation.batch
    # was left out of pyproject's package list, and `drillfric run` failed after `pip install .`)
    names = sorted(".".join(("drillfric", *p.relative_to(REPO / "drillfric").with_suffix("").parts))
                   .removesuffix(".__init__") for p in (REPO / "drillfric").rglob("*.py"))
    _run([str(py), "-c", f"import importlib\nfor m in {names!r}: importlib.import_module(m)"],
         cwd=outside)
    # the live page's template and script are package data (templates/live.*)
    _run([str(py), "-c", "from drillfric.live.page import page; assert b'bk-live' in page()[0]"],
         cwd=outside)
    bare = subprocess.run([str(py), "-c", "import cli"], cwd=outside, capture_output=True)
    assert bare.returncode != 0, "a bare top-level package 'cli' must not be installed"
    # from the repository root the source tree's drillfric/ shadows the installed one: its
    # cli/ and templates/ must still be found (a regression: No module named
    # 'drillfric.templates'), and the report code with them
    _run([str(py), "-c", "import drillfric.cli.main, drillfric.templates, drillfric.report; "
          "from drillfric.report import write_well_report"], cwd=REPO)


def test_source_checkout_exposes_only_cli_and_templates():
    """A regression: the checkout appended the repository root to ``drillfric.__path__``,
    so ``drillfric.tests``, ``drillfric.benchmarks`` and ``drillfric.docs`` imported."""
    code = ("import importlib, drillfric, drillfric.cli.main, drillfric.templates\n"
            "for name in ('tests', 'benchmarks', 'docs', 'examples'):\n"
            "    try:\n"
            "        importlib.import_module('drillfric.' + name)\n"
            "        print('exposed', name)\n"
            "    except ImportError:\n"
            "        pass\n"
            "print(drillfric.__path__, drillfric.cli.__path__)")
    out = _run([sys.executable, "-c", code], cwd=REPO).stdout
    assert "exposed" not in out, out
    assert str(REPO / "cli") in out and f"['{REPO / 'drillfric'}']" in out


#: Imports every drillfric module with ``fcntl`` missing (as on Windows), then takes both
#: kinds of lock through their fallbacks.
_WITHOUT_FCNTL = """
import importlib, sys, tempfile
from pathlib import Path
sys.modules["fcntl"] = None
files = [("drillfric", p.relative_to("drillfric")) for p in Path("drillfric").rglob("*.py")]
files += [("drillfric.cli", p.relative_to("cli")) for p in Path("cli").rglob("*.py")]
names = sorted(".".join([package, *p.with_suffix("").parts]).removesuffix(".__init__")
               for package, p in files)
for name in names:
    importlib.import_module(name)
from drillfric.io.locks import Busy, lock_directory, lock_file
folder = Path(tempfile.mkdtemp())
with lock_directory(folder), lock_file(folder / ".fleet.lock"):
    try:
        with lock_file(folder / ".fleet.lock"):
            raise SystemExit("a held lock file was taken twice")
    except Busy:
        pass
print(len(names))
"""


def test_every_module_imports_without_fcntl():
    """Issue #21 item 5: ``import fcntl`` at module top made drillfric fail to import on
    Windows; the locks fall back to lock files there."""
    done = subprocess.run([sys.executable, "-c", _WITHOUT_FCNTL], cwd=REPO, text=True,
                          capture_output=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    assert int(done.stdout.split()[-1]) > 60  # every module, cli and report included
