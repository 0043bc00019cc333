"""Fixtures of the ingestion tests."""

from __future__ import annotations

import pandas as pd
import pytest
from io_frames import surface_frame


@pytest.fixture
def frame() -> pd.DataFrame:
    return surface_frame()
