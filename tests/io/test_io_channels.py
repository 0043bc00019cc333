"""Channel recognition and unit conversion (drillfric.io.channels)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from drillfric.errors import InputError
from drillfric.io.channels import BY_KEY, CHANNELS, factor, map_channels, split_unit

# Conversion factors are exact by definition of the units (NIST SP 811): 1 lbf =
# 4.4482216152605 N, 1 ft = 0.3048 m, 1 kgf = 9.80665 N, 1 psi = 6894.757293168 Pa.
LBF_N = 4.4482216152605
FT_M = 0.3048


@pytest.mark.parametrize("unit, key, expected", [
    ("kN.m", "surface_torque", 1e3), ("kNm", "surface_torque", 1e3),
    ("ft.lbf", "surface_torque", FT_M * LBF_N), ("N.m", "surface_torque", 1.0),
    ("klbf", "hookload", 1e3 * LBF_N), ("kkgf", "hookload", 9806.65), ("kN", "wob", 1e3),
    ("ft", "bit_depth", FT_M), ("m", "bit_depth", 1.0), ("rpm", "surface_rpm", 1.0),
    ("c/s", "surface_rpm", 60.0), ("psi", "standpipe_pressure", 6894.757293168),
    ("kPa", "standpipe_pressure", 1e3), ("L/min", "flow_in", 1e-3 / 60.0),
    ("gpm", "flow_in", 3.785411784e-3 / 60.0), ("spm", "pump_rate", 1.0),
    ("%", "flow_out", 1.0), ("ms", "time", 1e-3), ("kft.lbf", "surface_torque",
    1e3 * FT_M * LBF_N), ("daN", "hookload", 10.0), ("tonf", "hookload", 9806.65),
    ("bar", "standpipe_pressure", 1e5), ("h", "time", 3600.0),
])
def test_factor_drilling_spellings(unit, key, expected):
    # Tolerance: floating-point round-off of pint's definitions only.
    assert factor(unit, BY_KEY[key]) == pytest.approx(expected, rel=1e-12)


def test_wrong_kind_of_unit_is_an_input_error():
    with pytest.raises(InputError, match="not a torque unit"):
        factor("klbf", BY_KEY["surface_torque"], file="x.csv")


def test_unknown_unit_names_the_channel():
    with pytest.raises(InputError, match="unknown unit 'blorps' for surface_torque_Nm"):
        factor("blorps", BY_KEY["surface_torque"])


@given(st.floats(-1e6, 1e6, allow_nan=False), st.sampled_from(
    [("kN.m", "surface_torque"), ("ft.lbf", "surface_torque"), ("klbf", "hookload"),
     ("ft", "bit_depth"), ("psi", "standpipe_pressure")]))
def test_unit_round_trip(value, pair):
    # Converting to SI and back with the inverse factor restores the value (round-off only).
    unit, key = pair
    f = factor(unit, BY_KEY[key])
    assert value * f / f == pytest.approx(value, rel=1e-12, abs=1e-9)


@pytest.mark.parametrize("header, expected", [
    ("TORQUE [kN.m]", ("TORQUE", "kN.m")), ("Torque (ft.lbf)", ("Torque", "ft.lbf")),
    ("SRPM", ("SRPM", None)), ("Time (s)", ("Time", "s")),
])
def test_split_unit(header, expected):
    assert split_unit(header) == expected


def test_mnemonics_and_header_units():
    cols = ["Time (s)", "Top Drive Speed", "TORQUE [kN.m]", "HKLD", "DBTM"]
    m = map_channels(cols, {}, {})
    assert m["time"].column == "Time (s)" and m["time"].unit == "s"
    assert m["surface_rpm"].column == "Top Drive Speed" and m["surface_rpm"].source == "default"
    assert (m["surface_torque"].unit, m["surface_torque"].source) == ("kN.m", "header")
    assert m["surface_torque"].factor == 1e3
    assert m["hookload"].column == "HKLD" and m["bit_depth"].column == "DBTM"


def test_trailing_unit_word_as_in_usrop_headers():
    m = map_channels(["TIME", "Average Rotary Speed rpm", "Average Surface Torque kN.m",
                      "Average Hookload kkgf"], {}, {})
    assert m["surface_torque"].unit == "kN.m" and m["hookload"].unit == "kkgf"


def test_canonical_names_take_the_unit_of_their_suffix():
    m = map_channels(["time_s", "surface_rpm", "surface_torque_Nm", "bit_depth_m", "bit_rpm"],
                     {}, {})
    assert m["surface_torque"].source == "name suffix" and m["surface_torque"].factor == 1.0
    assert m["bit_rpm"].column == "bit_rpm" and m["bit_depth"].unit == "m"


def test_earlier_mnemonic_wins_and_canonical_beats_mnemonic():
    m = map_channels(["TIME", "RPM", "TORQUE", "HKLA", "HKLD"], {}, {})
    assert m["hookload"].column == "HKLD"
    m = map_channels(["TIME", "time_s", "RPM", "TORQUE"], {}, {})
    assert m["time"].column == "time_s"


def test_two_equal_candidates_are_an_error():
    with pytest.raises(InputError, match="both look like surface_rpm"):
        map_channels(["TIME", "RPM [rpm]", "RPM (c/s)", "TORQUE"], {}, {})


def test_units_row_units_and_config_overrides():
    units = {"TQ": "kN.m", ("source", "TQ"): "units row"}
    m = map_channels(["TIME", "SPEED", "TQ"], units,
                     {"surface_rpm": {"column": "SPEED", "unit": "rpm"}})
    assert (m["surface_torque"].unit, m["surface_torque"].source) == ("kN.m", "units row")
    assert (m["surface_rpm"].column, m["surface_rpm"].source) == ("SPEED", "config")


def test_extra_mnemonics_from_config():
    m = map_channels(["TIME", "ROTSPD", "TORQUE"], {},
                     {"surface_rpm": {"mnemonics": ["ROTSPD"]}})
    assert m["surface_rpm"].column == "ROTSPD"


def test_config_unit_disagreeing_with_header_is_inconsistent():
    with pytest.raises(InputError, match="inconsistent unit .* says 'kN.m' but .* 'ft.lbf'"):
        map_channels(["TIME", "RPM", "TORQUE [kN.m]"], {},
                     {"surface_torque": {"unit": "ft.lbf"}})


def test_missing_required_channel_lists_columns_and_the_mapping_line():
    with pytest.raises(InputError) as info:
        map_channels(["TIME", "RPM", "TRQ_X", "DEPTH"], {}, {}, file="a.csv")
    msg = str(info.value)
    assert "surface_torque_Nm not found" in msg and "TIME, RPM, TRQ_X, DEPTH" in msg
    assert '[channels] surface_torque = { column = "' in msg and "\n" not in msg


def test_headerless_missing_channel_suggests_an_index():
    with pytest.raises(InputError, match=r"\[channels\] time = \{ column = 0"):
        map_channels([str(i) for i in range(4)], {}, {})


def test_index_out_of_range():
    with pytest.raises(InputError, match="column 7 does not exist"):
        map_channels(["0", "1"], {}, {"time": {"column": 7}})


def test_every_channel_has_a_known_default_and_suffix_unit():
    from drillfric.io.channels import SUFFIX_UNITS

    for ch in CHANNELS:
        assert factor(ch.default_unit, ch) > 0
        assert factor(SUFFIX_UNITS[ch.key], ch) == pytest.approx(1.0)


def test_docs_mnemonic_table_matches_the_code():
    from pathlib import Path

    from drillfric.io.channels import mnemonics_markdown

    doc = (Path(__file__).resolve().parents[2] / "docs" / "ingestion.md").read_text()
    block = doc.split("<!-- mnemonics:start -->\n")[1].split("\n<!-- mnemonics:end -->")[0]
    assert block == mnemonics_markdown(), "regenerate the table in docs/ingestion.md"
