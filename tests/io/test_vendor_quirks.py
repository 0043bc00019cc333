"""Vendor quirks of real exports, kept as small files on disk (tests/fixtures/vendor_quirks/).

lasio's practice: each file is a few hundred bytes to a few KB, named after the quirk it
reproduces, and read through the public reader (:func:`drillfric.io.readers.open_source`)
and the channel mapping, as a user's file would be. The DLIS file was written once with
dliswriter (a depth frame listed first and longer than the surface frame, which carries an
array channel); the others are hand-written text.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drillfric.io.channels import map_channels
from drillfric.io.readers import open_source

QUIRKS = Path(__file__).resolve().parents[1] / "fixtures" / "vendor_quirks"


def _read(name: str):
    source = open_source(QUIRKS / name)
    return source, pd.concat(list(source.chunks(2)), ignore_index=True)


def test_witsml_time_log_after_depth_log_mnemonic_order_unitless_index_cps():
    source, frame = _read(
        "witsml_time_log_after_depth_log_mnemonic_order_unitless_index_cps.xml")
    # The time log is read, not the longer depth log listed first.
    assert source.depth_index is None and source.rows == 3
    # Columns in mnemonicList order, not logCurveInfo order.
    assert source.columns == ["TIME", "TORQUE", "SURF_RPM", "HKLD"]
    assert "TIME" not in source.units  # "unitless" is no unit
    assert frame["TIME"].iloc[0] == "2008-10-03T21:23:00.000Z"  # absolute time kept as text
    # The log's null (-999.25) and HKLD's own null (-1) are missing values.
    assert np.isnan(frame["TORQUE"].iloc[1]) and np.isnan(frame["HKLD"].iloc[1])
    assert frame["TORQUE"].iloc[2] == 11.5 and frame["SURF_RPM"].tolist() == [1.0, 1.5, 2.0]
    mapping = map_channels(source.columns, source.units, {})
    # c/s is revolutions per second: 60 rpm exactly; kN.m is 1000 N·m exactly.
    assert mapping["surface_rpm"].factor == pytest.approx(60.0, rel=1e-15)
    assert mapping["surface_torque"].factor == pytest.approx(1e3, rel=1e-15)


def test_witsml131_column_index_without_mnemonic_list():
    source, frame = _read("witsml131_column_index_without_mnemonic_list.xml")
    assert source.columns == ["TIME", "RPM", "TQ"]
    assert frame["TQ"].tolist() == [5000, 6000, 7000] and frame["RPM"].tolist() == [60, 61, 62]


def test_las_time_index_crlf_null_unit_with_dot():
    source, frame = _read("las_time_index_crlf_null_unit_with_dot.las")
    assert source.depth_index is None and source.columns == ["TIME", "SRPM", "STOR", "HKLD"]
    assert source.units["STOR"] == "KN.M"  # the unit runs to the first space, dots included
    assert np.isnan(frame["STOR"].iloc[1]) and np.isnan(frame["SRPM"].iloc[3])
    assert frame["TIME"].tolist() == [0.0, 0.5, 1.0, 1.5, 2.0]
    mapping = map_channels(source.columns, source.units, {})
    assert mapping["surface_torque"].factor == pytest.approx(1e3, rel=1e-12)  # KN.M, any case


def test_las_depth_index_in_feet():
    source, frame = _read("las_depth_index_in_feet.las")
    assert source.depth_index == "DEPT [F]"
    assert frame["DEPT"].tolist() == [8200.0, 8200.5, 8201.0]


def test_dlis_depth_frame_first_surface_frame_with_array_channel():
    source, frame = _read("dlis_depth_frame_first_surface_frame_with_array_channel.dlis")
    # The surface frame wins over the longer depth frame listed first; the array is left out.
    assert source.columns == ["TIME", "SRPM", "STOR", "HKLD"] and source.rows == 20
    assert source.depth_index is None
    assert source.units["HKLD"] == "klbf"
    np.testing.assert_array_equal(frame["SRPM"].to_numpy(), 60.0 + np.arange(20))


def test_csv_decimal_comma_thousands_dot():
    """Regression (issue 30, eighth attack): a ';'-separated export with decimal commas
    ("0,05") writes its integers with a thousands dot ("17.240", "791.504"); the dot was
    read as a decimal point, so every value ≥ 1000 shrank 1000× (hook load 791.504 N, bit
    depth 2.21 m) and the run blamed the string's length."""
    _, frame = _read("csv_decimal_comma_thousands_dot.csv")
    assert frame["TIME [s]"].tolist() == [0.0, 0.05, 0.1]
    assert frame["TORQUE [N.m]"].tolist() == [-200.0, 17240.0, 950.5]
    assert frame["HKLD [N]"].tolist() == [791504.0, 794686.0, 1002300.25]
    assert frame["BIT DEPTH [m]"].tolist() == [2210.0, 2210.0, 2210.5]
