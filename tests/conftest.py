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
    from drillfric.estimation import warmup

    if warmup.needed():
        warmup.warm_up()


@pytest.fixture
def real_data() -> Path:
    """Path of ../shared/data/real, or skip when it is not there (a user's clone)."""
    if not REAL_DATA.is_dir():
        pytest.skip(f"real field data not available at {REAL_DATA}")
    return REAL_DATA
