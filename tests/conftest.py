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


def documented_result_files() -> set[str]:
    """The files of ``OUT/NAME`` docs/outputs.md's table names (``state/`` as ``state``)."""
    text = (REPO / "docs" / "outputs.md").read_text(encoding="utf-8")
    table = text.split("## `drillfric run WELL")[1].split("###")[0]
    return {name.rstrip("/") for line in table.splitlines() if line.startswith("| `")
            for name in [line.split("`")[1]]}

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
#: A soft top drive (PI k_p 900 N·m·s/rad, k_i 2500 N·m/rad: the plant of issue 14) that
#: stick-slips at 30–50 RPM: the rotation stalls, so the log cuts into many segments of
#: every status (ok with a μ_s bound, skipped too short, reaming).
SOFT_SCENARIO = """connection_s = 40.0
[defaults]
duration_s = 120.0
rpm = 40.0
ramp_s = 10.0
[[stand]]
bit_depth_m = 2210.0
[[stand]]
bit_depth_m = 2240.0
rpm = 30.0
[[stand]]
bit_depth_m = 2270.0
rpm = 50.0
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


@pytest.fixture(scope="session")
def real_data() -> Path:
    """Path of ../shared/data/real, or skip when it is not there (a user's clone)."""
    if not REAL_DATA.is_dir():
        pytest.skip(f"real field data not available at {REAL_DATA}")
    return REAL_DATA


@pytest.fixture(scope="session")
def stands(tmp_path_factory):
    """A three-stand 100 Hz simulated well (CSV with sidecars) and its whole-file run, shared
    by the engine and live tests (one simulation and one run per session)."""
    from drillfric.io.well import open_well
    from drillfric.runner import run_well

    folder = tmp_path_factory.mktemp("stands")
    path = _simulated(folder, "three", DEMO / "demo.toml", SCENARIO, seed=5)
    whole = run_well(open_well(path))
    assert len(whole.segments) >= 4 and whole.counts["converged"] >= 2
    return path, whole


@pytest.fixture(scope="session")
def stick_slip(tmp_path_factory):
    """A three-stand 100 Hz well on a soft top drive that stick-slips (:data:`SOFT_SCENARIO`;
    CSV with sidecars) and its whole-file run: the second plant of the equivalence tests."""
    from drillfric.io.well import open_well
    from drillfric.runner import run_well

    folder = tmp_path_factory.mktemp("stick_slip")
    config = folder / "softdrive.toml"
    config.write_text((DEMO / "demo.toml").read_text().replace(
        "\n[simulate]\n", "\n[simulate]\nkp_Nms_rad = 900.0\nki_Nm_rad = 2500.0\n", 1))
    path = _simulated(folder, "soft", config, SOFT_SCENARIO, seed=7)
    whole = run_well(open_well(path))
    statuses = set(whole.segments["status"])
    assert len(whole.segments) >= 10 and {"ok", "skipped"} <= statuses
    assert whole.segments["mu_s_lower_bound"].notna().any()  # the stick-slip onset bound
    return path, whole


def _simulated(folder: Path, name: str, config: Path, scenario: str, seed: int) -> Path:
    """``folder/NAME.csv`` (with sidecars) simulated by `drillfric simulate` from ``config``
    and ``scenario`` (TOML text): 100 Hz, a 100-cell string, the demo survey."""
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    (folder / f"{name}.scenario.toml").write_text(scenario)
    done = CliRunner().invoke(cli, ["-q", "simulate", str(config), "--scenario",
                                    str(folder / f"{name}.scenario.toml"), "--out",
                                    str(folder / f"{name}.csv"), "--survey",
                                    str(DEMO / "demo.survey.csv"), "--cells", "100", "--rate",
                                    "100", "--seed", str(seed)])
    assert done.exit_code == 0, done.output
    return folder / f"{name}.csv"
