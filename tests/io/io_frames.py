"""Synthetic rig surface data for the ingestion tests (seeded, small)."""

from __future__ import annotations

import numpy as np
import pandas as pd


def surface_frame(rows: int = 500, rate_hz: float = 5.0, seed: int = 7) -> pd.DataFrame:
    """A plausible surface log in SI: 60 RPM rotation with noise, 8–12 kN·m torque."""
    rng = np.random.default_rng(seed)
    t = np.arange(rows) / rate_hz
    return pd.DataFrame({
        "time_s": t,
        "surface_rpm": 60.0 + rng.normal(0.0, 2.0, rows),
        "surface_torque_Nm": 10e3 + rng.normal(0.0, 500.0, rows),
        "hookload_N": 1.2e6 + rng.normal(0.0, 1e4, rows),
        "bit_depth_m": np.full(rows, 2500.0),
    })
