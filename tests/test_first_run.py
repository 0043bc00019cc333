"""The first run after an install (issue 25, point 8): it says what it compiles, compiles
ahead of the run in two processes, and leaves the run nothing to compile; the compiled code
lives in one per-user cache directory, never beside the inputs or in --out."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from drillfric.kernels.cache import cache_dir

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[1]
DEMO = REPO / "examples" / "demo" / "demo.csv"

#: Counts the kernel compilations a run of the demo still makes after the warm-up.
_COUNT_MISSES = """
import drillfric
from drillfric.kernels import observer, plant
from drillfric import torque_drag
drillfric.run(drillfric.open_well({demo!r}))
misses = 0
for module in (observer, plant, torque_drag):
    for name in dir(module):
        stats = getattr(getattr(module, name), "stats", None)
        if stats is not None:
            misses += sum(stats.cache_misses.values())
print("misses", misses)
"""


def _env(cache: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    return env | {"NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(REPO)}


@pytest.mark.slow
def test_first_run_says_it_compiles_and_leaves_the_run_nothing_to_compile(tmp_path):
    cache, out = tmp_path / "cache", tmp_path / "out"
    cmd = [sys.executable, "-m", "drillfric.cli.main", "run", str(DEMO), "--out", str(out),
           "--no-report"]
    first = subprocess.run(cmd, env=_env(cache), capture_output=True, text=True, cwd=tmp_path,
                           timeout=600)
    assert first.returncode == 0, first.stderr
    lines = first.stderr.splitlines()
    assert lines[0].startswith("first run of this installation: compiling the numerical "
                               f"kernels once (15–60 s, longer on a busy machine; kept in {cache})")
    assert lines[1].startswith("kernels compiled in ")
    assert list(cache.glob("drillfric-run-*.ready"))  # the stamp
    assert not list(out.rglob("*.nb*")) and not list(DEMO.parent.glob("*.nb*"))
    # The run after the warm-up compiles nothing: every kernel loads from the cache.
    count = subprocess.run([sys.executable, "-c", _COUNT_MISSES.format(demo=str(DEMO))],
                           env=_env(cache), capture_output=True, text=True, cwd=tmp_path,
                           timeout=600)
    assert count.returncode == 0, count.stderr
    assert count.stdout.split()[-2:] == ["misses", "0"]
    again = subprocess.run(cmd, env=_env(cache), capture_output=True, text=True, cwd=tmp_path,
                           timeout=600)
    assert again.returncode == 0 and "compiling" not in again.stderr


def test_cache_directory_is_per_user(monkeypatch, tmp_path):
    """$NUMBA_CACHE_DIR wins; else the platform's per-user cache (XDG on Linux)."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "given"))
    assert cache_dir() == tmp_path / "given"
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    if sys.platform.startswith("linux"):
        monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
        assert cache_dir() == tmp_path / "xdg" / "drillfric" / "numba"
        monkeypatch.delenv("XDG_CACHE_HOME")
        assert cache_dir() == Path.home() / ".cache" / "drillfric" / "numba"
