"""Per-segment estimation helpers (drillfric.estimate) that the end-to-end tests do not pin."""

from __future__ import annotations

import numpy as np

from drillfric.batch import BatchResult
from drillfric.drillstring import build_string
from drillfric.estimate import _creep_advice
from drillfric.observer import Measurements
from tests.synthetic import RPM, config


def test_creep_advice_is_the_wind_up_time():
    """Twist to break free under uniform friction = μ_s·T_N·L/(2GJ) (torque falls linearly
    from the top, THEORY §3, §6.3); at the creep speed that takes twist/ω seconds."""
    string = build_string(config().sections, 3000.0)
    pipe = string.sections[0]
    t = np.arange(0.0, 60.0, 0.1)
    speed = np.where((t > 5.0) & (t < 35.0), 5.0 * RPM, 0.0)
    meas = Measurements(0.0, 0.1, speed, np.zeros_like(t))
    refined = BatchResult(None, "mean_torque", None, False, None, "none", (), (), 0, (),
                          details={"creeps_found": [(10.0, 30.0)]})
    text = _creep_advice(string, 80e3, 0.3, refined, meas)
    expected = 2 * 0.3 * 80e3 * 3000.0 / (2 * pipe.shear_modulus_Pa * pipe.polar_moment_m4)
    assert f"about {expected / (5.0 * RPM):.0f} s" in text and "20 s at 5.0 RPM" in text
