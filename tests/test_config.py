"""Configuration schema: validation, precedence, and the generated reference doc."""

from __future__ import annotations

from fractions import Fraction

import pytest

from drillfric.config import SCHEMA, SECTION_KEYS, config_from_dict, load_config, schema_markdown
from drillfric.errors import ConfigError
from tests.conftest import REPO


def test_docs_configuration_matches_schema():
    """docs/configuration.md is generated from SCHEMA and must not drift (datasette practice)."""
    doc = (REPO / "docs" / "configuration.md").read_text(encoding="utf-8")
    assert doc == schema_markdown(), "run: python -m drillfric.config > docs/configuration.md"


def test_every_key_documented():
    for keys in list(SCHEMA.values()) + [SECTION_KEYS]:
        for key in keys:
            assert key.help.strip(), key.name


def test_defaults_and_assumptions_reported():
    cfg = load_config()
    assert cfg.model.cells == 500
    assert cfg.omega_c_rad_s == 1.0
    assert any("drill string" in a for a in cfg.assumed)


def test_interface_example_loads(tmp_path):
    """A full example configuration (every table of docs/configuration.md) loads unchanged."""
    text = '''
[well]
name = "A-12"
[fluid]
mud_density_kg_m3 = 1200.0
[rig]
top_drive_inertia_kg_m2 = 2900.0
torque_kind = "motor"
[model]
omega_c_rad_s = 1.0
k_t_per_s = 0.1
[[string.sections]]
name = "5 7/8in DP"
od_m = 0.146529
id_m = 0.123024
tool_joint_od_m = 0.1778
linear_mass_kg_m = 41.41
shear_modulus_Pa = 61.0e9
[[string.sections]]
name = "8in collars"
od_m = 0.2096
id_m = 0.0714
length_m = 56.7
[channels]
surface_rpm = { column = "SRPM", unit = "rpm" }
surface_torque = { column = "STOR", unit = "kN.m" }
bit_depth = { column = "BITDEP", unit = "m" }
'''
    path = tmp_path / "a12.toml"
    path.write_text(text)
    cfg = load_config(path)
    assert cfg.well.name == "A-12"
    assert len(cfg.sections) == 2 and cfg.sections[1]["length_m"] == 56.7
    assert cfg.channels["surface_torque"] == {"column": "STOR", "unit": "kN.m"}
    assert not any("drill string" in a for a in cfg.assumed)


@pytest.mark.parametrize("raw, words", [
    ({"model": {"cellz": 3}}, "unknown key 'model.cellz'"),
    ({"modle": {}}, "unknown table or key 'modle'"),
    ({"model": {"cells": "many"}}, "must be an integer"),
    ({"model": {"k_t_per_s": -1.0}}, "outside"),
    ({"rig": {"torque_kind": "vfd"}}, "must be one of"),
    ({"rig": {"top_drive_inertia_kg_m2": 0.0}}, "outside"),
    ({"fluid": {"mud_density_kg_m3": 9000.0}}, "outside"),
    ({"string": {"sections": [{"od_m": 0.1, "id_m": 0.2}]}}, "must be smaller than od_m"),
    ({"string": {"sections": [{"od_m": 0.2, "id_m": 0.1}, {"od_m": 0.2, "id_m": 0.1}]}},
     "needs length_m"),
    ({"channels": {"rpmm": "X"}}, "unknown channel 'rpmm'"),
    ({"model": {"omega_c_rad_s": 1.0, "omega_c_rpm": 10.0}}, "not both"),
    ({"observer": {"starts": [[0.3]]}}, "observer.starts[1]"),
    ({"observer": {"starts": [[0.3, "x"]]}}, "observer.starts[1]"),
    ({"observer": {"starts": [[0.2, 0.6]]}}, "0 ≤ μ_k ≤ μ_s"),
    # regression (issue 21): mu_max below the starts failed every segment with "observer
    # starts must be pairs (μ_s, μ_k) with 0 ≤ μ_k ≤ μ_s" instead of naming mu_max
    ({"observer": {"mu_max": 0.15}}, "observer.mu_max = 0.15 is below the observer starts"),
    ({"observer": {"poles_per_s": ["a", "b"]}}, "two positive numbers"),
    ({"segmentation": {"rotating_rpm": 1.0, "rotating_stop_rpm": 5.0}}, "rotating_stop_rpm"),
    ({"survey": {"tortuosity_deg_30m": -0.5}}, "outside [0, 10]"),
])
def test_bad_config_one_line(raw, words):
    with pytest.raises(ConfigError) as info:
        config_from_dict(raw, file="w.toml")
    message = str(info.value)
    assert words in message and "w.toml" in message and "\n" not in message


def test_precedence_command_line_over_file_over_default(tmp_path):
    path = tmp_path / "w.toml"
    path.write_text("[model]\ncells = 800\nk_t_per_s = 0.2\n")
    cfg = load_config(path, overrides={"model.cells": 1000, "model.k_t_per_s": None})
    assert cfg.model.cells == 1000  # command line wins
    assert cfg.model.k_t_per_s == 0.2  # file over default
    assert cfg.rig.top_drive_inertia_kg_m2 == 2900.0  # default


def test_integer_accepted_for_float(tmp_path):
    cfg = config_from_dict({"fluid": {"mud_density_kg_m3": 1100}})
    assert isinstance(cfg.fluid.mud_density_kg_m3, float)


def test_no_survey_tortuosity_default_and_note():
    """Without a survey the hole is vertical with a nominal 1°/30 m tortuosity (DLS in
    rad/m inside, docs/torque_drag.md), and the note says so; 0 restores the plain vertical
    note."""
    cfg = load_config()
    assert cfg.survey.tortuosity_deg_30m == 1.0
    assert cfg.tortuosity_rad_m == pytest.approx(3.141592653589793 / 180.0 / 30.0, rel=1e-15)
    assert "nominal tortuosity of 1.0°/30 m" in cfg.no_survey_note
    assert "0.25°/30 m" in config_from_dict(
        {"survey": {"tortuosity_deg_30m": 0.25}}).no_survey_note
    zero = config_from_dict({"survey": {"tortuosity_deg_30m": 0}})
    assert zero.tortuosity_rad_m == 0.0 and zero.no_survey_note == "vertical well: no survey found"


def _keys_with_units():
    return [(table, key) for table, keys in [*SCHEMA.items(), ("string.sections", SECTION_KEYS)]
            for key in keys if key.unit and key.type in (float, int)]


@pytest.mark.parametrize("table, key", _keys_with_units(), ids=lambda v: getattr(v, "name", v))
def test_every_key_with_a_unit_takes_a_quantity(table, key):
    """A key's unit label converts (docs/configuration.md: any key with a unit takes a number
    with a unit): one of its own unit is 1 exactly."""
    from drillfric.units import LABEL_UNITS, quantity_value

    assert key.unit in LABEL_UNITS, f"add {key.unit!r} to drillfric.units.LABEL_UNITS"
    assert quantity_value(f"1 {LABEL_UNITS[key.unit][0]}", key.unit) == 1.0


def test_field_units_in_a_config_file(tmp_path):
    path = tmp_path / "w.toml"
    path.write_text('[fluid]\nmud_density_kg_m3 = "1.2 sg"\n[well]\nbit_depth_m = "7500 ft"\n'
                    '[[string.sections]]\nod_m = "5 in"\nid_m = "4.276 in"\n'
                    'linear_mass_kg_m = "19.5 lb/ft"\n')
    cfg = load_config(path)
    assert cfg.fluid.mud_density_kg_m3 == 1200.0 and cfg.well.bit_depth_m == 2286.0
    assert cfg.sections[0]["od_m"] == 0.127
    assert cfg.sections[0]["id_m"] == float(Fraction("4.276") * Fraction("0.0254"))


@pytest.mark.parametrize("value, words", [
    ('"5 in"', "key 'fluid.mud_density_kg_m3' = '5 in' is a length, not a density (kg/m³)"),
    ('"100 ppg"', "key 'fluid.mud_density_kg_m3' = 1.198e+04 ('100 ppg') is outside [0, 7849]"),
    ('"1200"', "key 'fluid.mud_density_kg_m3' = '1200' has no unit"),
])
def test_bad_quantity_in_a_config_is_one_line_naming_key_and_file(tmp_path, value, words):
    path = tmp_path / "w.toml"
    path.write_text(f"[fluid]\nmud_density_kg_m3 = {value}\n")
    with pytest.raises(ConfigError) as err:
        load_config(path)
    assert words in err.value.message and str(path) in err.value.message
    assert "\n" not in err.value.message


def test_unit_system_key():
    assert config_from_dict({}).well.units == "si"
    assert config_from_dict({"well": {"units": "field"}}).well.units == "field"
    with pytest.raises(ConfigError, match="must be one of 'si', 'field'"):
        config_from_dict({"well": {"units": "imperial"}})
