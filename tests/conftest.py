"""Shared test configuration: deterministic, headless, strict floating point."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
os.environ.setdefault("MPLBACKEND", "Agg")

REPO = Path(__file__).resolve().parents[1]
#: Real field data, read in place; tests using it skip when the folder is absent.
REAL_DATA = REPO.parent / "shared" / "data" / "real"
DEMO = REPO / "examples" / "demo"
#: Three stands (100 s of rotation each, so they converge) with 40-s connections.
SCENARIO = """connection_s = 40.0
[defaults]
duration_s = 100.0
rpm = 50.0
ramp_s = 10.0
[[stand]]
bit_depth_m = 2210.0
start = "creep"
[[stand]]
bit_depth_m = 2240.0
rpm = 40.0
[[stand]]
bit_depth_m = 2270.0
rpm = 60.0
"""


@pytest.fixture(autouse=True)
def _strict_numpy():
    """Floating-point problems (not gradual underflow) are errors in tests (py-pde practice)."""
    old = np.seterr(all="raise", under="ignore")
    yield
    np.seterr(**old)


@pytest.fixture(autouse=True, scope="session")
def _kernels_compiled():
    """Compile the kernels once before any test (what `drillfric run` does on a first run),
    so that no CLI test sees the first-run lines; tests/test_first_run.py checks those with a
    cache of its own."""
    from drillfric.runner import warmup

    if warmup.needed():
        warmup.warm_up()


@pytest.fixture
def real_data() -> Path:
    """Path of ../shared/data/real, or skip when it is not there (a user's clone)."""
    if not REAL_DATA.is_dir():
        pytest.skip(f"real field data not available at {REAL_DATA}")
    return REAL_DATA


@pytest.fixture(scope="session")
def stands(tmp_path_factory):
    """A three-stand 100 Hz simulated well (CSV with sidecars) and its whole-file run, shared
    by the engine and live tests (one simulation and one run per session)."""
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    from drillfric.io.well import open_well
    from drillfric.runner import run_well

    folder = tmp_path_factory.mktemp("stands")
    (folder / "three.scenario.toml").write_text(SCENARIO)
    done = CliRunner().invoke(cli, ["-q", "simulate", str(DEMO / "demo.toml"), "--scenario",
                                    str(folder / "three.scenario.toml"), "--out",
                                    str(folder / "three.csv"), "--cells", "100", "--rate",
                                    "100", "--seed", "5"])
    assert done.exit_code == 0, done.output
    whole = run_well(open_well(folder / "three.csv"))
    assert len(whole.segments) >= 4 and whole.counts["converged"] >= 2
    return folder / "three.csv", whole
