"""Unit conversion: drilling spellings against exact definitions (NIST SP 811 factors)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from drillfric.errors import InputError
from drillfric.units import conversion_factor, from_si, to_si

LBF = 4.4482216152605  # N, exact by definition of the avoirdupois pound and g_n
FT = 0.3048  # m, exact


@pytest.mark.parametrize("unit, kind, factor", [
    ("kN.m", "torque", 1000.0), ("kNm", "torque", 1000.0), ("kN-m", "torque", 1000.0),
    ("N.m", "torque", 1.0), ("ft.lbf", "torque", FT * LBF), ("ft-lbf", "torque", FT * LBF),
    ("klbf", "force", 1000 * LBF), ("kkgf", "force", 1000 * 9.80665), ("kN", "force", 1e3),
    ("g/cm3", "density", 1000.0), ("sg", "density", 1000.0),
    ("ppg", "density", 0.45359237 / 3.785411784e-3),
    ("rpm", "rpm", 1.0), ("RPM", "rpm", 1.0), ("c/s", "rpm", 60.0),
    ("rpm", "angular_velocity", 2 * np.pi / 60), ("ft", "length", FT), ("m", "length", 1.0),
    ("deg", "angle", np.pi / 180),
])
def test_drilling_spellings(unit, kind, factor):
    # exact definitions: only float round-off allowed
    assert conversion_factor(unit, kind) == pytest.approx(factor, rel=1e-12)


def test_wrong_kind_is_one_line():
    with pytest.raises(InputError, match="'klbf' is not a torque unit"):
        conversion_factor("klbf", "torque")


def test_unknown_unit():
    with pytest.raises(InputError, match="unknown unit 'furlongs/fortnight2'"):
        conversion_factor("furlongs/fortnight2", "length")


@given(st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=20),
       st.sampled_from([("kN.m", "torque"), ("ft.lbf", "torque"), ("klbf", "force"),
                        ("ppg", "density"), ("ft", "length"), ("rpm", "angular_velocity")]))
def test_round_trip(values, unit_kind):
    """to_si then from_si is the identity (to round-off)."""
    unit, kind = unit_kind
    back = from_si(to_si(values, unit, kind), unit, kind)
    np.testing.assert_allclose(back, values, rtol=1e-12, atol=1e-9)
