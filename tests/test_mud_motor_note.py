"""A bit speed shown while the pumps ran says it is the string's bottom speed (issue 34
item 5, until mud motors are modelled): with a motor in the BHA the bit turns faster by the
motor's speed (≈ k·flow), so a trace taken for the bit's would be a false number."""

from __future__ import annotations

import shutil

import numpy as np
import pandas as pd
import pytest

from drillfric.config import config_from_dict
from drillfric.runner.segment_output import MOTOR_NOTE, pumped


@pytest.mark.parametrize("flow_m3_s, expected", [(0.03, True), (0.0005, False), (None, False)])
def test_pumped_needs_most_turning_rows_with_the_pumps_on(flow_m3_s, expected):
    cfg = config_from_dict({})  # pumps on above 0.002 m³/s
    rows = pd.DataFrame({"surface_rpm": np.r_[np.zeros(10), np.full(90, 60.0)]})
    if flow_m3_s is not None:
        rows["flow_in_m3_s"] = np.r_[np.zeros(10), np.full(90, flow_m3_s)]
    assert pumped(rows, cfg) is expected


@pytest.mark.slow
def test_traces_shown_with_the_pumps_on_say_so_once_for_the_well(stands, tmp_path):
    from drillfric.io.well import open_well
    from drillfric.runner import run_well

    path, whole = stands
    for sidecar in path.parent.glob(f"{path.stem}.*"):
        shutil.copy(sidecar, tmp_path / sidecar.name)
    data = pd.read_csv(path)
    data["flow_in_m3_s"] = 0.03  # 1800 L/min: pumps on throughout
    data.to_csv(tmp_path / path.name, index=False)
    result = run_well(open_well(tmp_path / path.name))
    shown = result.segments[result.segments["bit_speed_resolved"].fillna(False).astype(bool)]
    assert len(shown) >= 1
    assert all(MOTOR_NOTE in m for m in shown["message"])
    notes = [w for w in result.summary["warnings"] if MOTOR_NOTE in w]
    assert len(notes) == 1
    # without the flow the same run says nothing of a motor
    assert not any(MOTOR_NOTE in (m or "") for m in whole.segments["message"])
