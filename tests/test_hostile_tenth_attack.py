"""Regression tests of the tenth hostile-input attack (issue 30): units a file states wrongly
or twice. Each test is named after what the attack did."""

from __future__ import annotations

import pytest

from drillfric.errors import InputError
from drillfric.io.channels import BY_KEY, factor, map_channels
from drillfric.units import conversion_factor


def test_speed_logged_in_hz_counts_revolutions():
    """``RPM (Hz)`` was read as rad/s (pint's Hz = 1/s = 1 rad/s): a 200-RPM well read
    28–32 RPM with no warning, and a low speed was advised to be 'rad/s'. A rotary speed
    in a unit that names no angle counts cycles: 1 Hz = 60 RPM."""
    speed = BY_KEY["surface_rpm"]
    assert factor("Hz", speed) == factor("1/s", speed) == factor("cps", speed) == 60.0
    assert factor("rad/s", speed) == pytest.approx(30.0 / 3.141592653589793)
    assert conversion_factor("Hz", "rpm") == 60.0


def test_usft_is_the_us_survey_foot_not_a_micro_foot():
    """``BIT DEPTH (usft)`` was read as micro-survey-feet (3e-7 m): every segment failed as
    'the bit is at 0.0 m', the survey as bending 3 000 000°/30 m."""
    assert conversion_factor("usft", "length") == pytest.approx(0.3048006, rel=1e-6)
    assert factor("USFT", BY_KEY["bit_depth"]) == pytest.approx(0.3048006, rel=1e-6)


@pytest.mark.parametrize("columns, units", [
    (["TIME", "RPM", "TORQUE [kN.m]"], {"TORQUE [kN.m]": "kft.lbf"}),       # header vs row
    (["time_s", "surface_rpm", "surface_torque_Nm"], {"surface_torque_Nm": "ft.lbf"}),
])
def test_a_column_stated_in_two_units_is_refused(columns, units):
    """A header saying kN·m over a units row saying kft·lbf (μ_k 0.204 for 0.28), or a
    canonical ``surface_torque_Nm`` over metadata saying ft·lbf (0.379): one unit was taken
    silently. Two different units stated for one column are refused, naming both; the
    configuration settles it."""
    with pytest.raises(InputError, match="states two units for surface_torque_Nm"):
        map_channels(columns, units, {}, file="w.csv")
    stated = list(units.values())[0]
    mapped = map_channels(columns, units, {"surface_torque": {"unit": stated}}, file="w.csv")
    assert mapped


def test_a_column_stated_twice_in_one_unit_is_read():
    columns = ["TIME", "RPM", "TORQUE [kN.m]"]
    assert map_channels(columns, {"TORQUE [kN.m]": "kNm"}, {}, file="w.csv")
