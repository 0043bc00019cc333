"""Units the user's way (issue 15): field-unit configurations, quantity options, ``--units``.

The reference for every conversion is the exact definition of the unit (NIST SP 811:
1 in = 0.0254 m, 1 lb = 0.45359237 kg, 1 gal = 231 in³, g_n = 9.80665 m/s²), evaluated in
rational arithmetic (``fractions.Fraction``) and rounded once to a float: the SI twin of a
field-unit configuration, written as a person would, must give bit-for-bit the same
numbers.
"""

from __future__ import annotations

import json
import shutil
from fractions import Fraction

import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.config import load_config
from drillfric.io.well import open_well
from drillfric.io.writers import dumps_toml
from drillfric.runner import run_well
from tests.conftest import REPO

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

DEMO = REPO / "examples" / "demo"
IN = Fraction("0.0254")
FT = 12 * IN
LB = Fraction("0.45359237")
GAL = 231 * IN ** 3
LBF = LB * Fraction("9.80665")
PSI = LBF / IN ** 2

#: (table, key, field-unit text, exact SI value): the demo's string and mud in field units.
FIELD = [
    ("fluid", "mud_density_kg_m3", "10.5 ppg", Fraction("10.5") * LB / GAL),
    ("rig", "top_drive_inertia_kg_m2", "68800 lb*ft**2", 68800 * LB * FT ** 2),
    ("segmentation", "on_bottom_m", "1.5 ft", Fraction("1.5") * FT),
    ("segmentation", "wob_on_bottom_N", "2 klbf", 2000 * LBF),
]
SECTIONS = [
    {"name": "DP", "od_m": ("5 3/4 in", Fraction(23, 4) * IN),
     "id_m": ("4.84 in", Fraction("4.84") * IN), "tool_joint_od_m": ("7 in", 7 * IN),
     "linear_mass_kg_m": ("27.8 lb/ft", Fraction("27.8") * LB / FT),
     "shear_modulus_Pa": ("8.847e6 psi", 8847000 * PSI)},
    {"name": "HWDP", "od_m": ("5 in", 5 * IN), "id_m": ("3 in", 3 * IN),
     "length_m": ("361 ft", 361 * FT), "tool_joint_od_m": ("6½ in", Fraction(13, 2) * IN),
     "linear_mass_kg_m": ("50 lb/ft", 50 * LB / FT)},
    {"name": "DC", "od_m": ("8 in", 8 * IN), "id_m": ("2 13/16 in", Fraction(45, 16) * IN),
     "length_m": ("394 ft", 394 * FT)},
]


def _configs(folder):
    """The field-unit configuration and its SI twin (values: the exact SI, rounded once)."""
    field, si = {}, {}
    for table, key, text, exact in FIELD:
        field.setdefault(table, {})[key] = text
        si.setdefault(table, {})[key] = float(exact)
    for target, pick in ((field, 0), (si, 1)):
        target["survey"] = {"file": str(DEMO / "demo.survey.csv")}
        target["string"] = {"sections": [
            {k: (v if k == "name" else v[pick] if pick == 0 else float(v[1]))
             for k, v in s.items()} for s in SECTIONS]}
    (folder / "field.toml").write_text(dumps_toml(field))
    (folder / "si.toml").write_text(dumps_toml(si))
    return folder / "field.toml", folder / "si.toml"


def test_field_config_reads_the_exact_si_values(tmp_path):
    field, si = (load_config(p) for p in _configs(tmp_path))
    assert field.values == si.values and field.sections == si.sections


@pytest.fixture(scope="module")
def twin_runs(tmp_path_factory):
    """The demo's first stand (a creep start-up, 0–230 s) run with each configuration."""
    folder = tmp_path_factory.mktemp("twins")
    frame = pd.read_csv(DEMO / "demo.csv")
    frame[frame["time_s"] < 230.0].to_csv(folder / "stand.csv", index=False)
    out = {}
    for config in _configs(folder):
        well = open_well(folder / "stand.csv", config=config, name=config.stem)
        out[config.stem] = run_well(well, folder / "out").out_dir
    return out


def test_field_unit_config_gives_bit_for_bit_the_results_of_its_si_twin(twin_runs):
    for table in ("segments.parquet", "estimates.parquet", "profiles.parquet"):
        field = pd.read_parquet(twin_runs["field"] / table)
        si = pd.read_parquet(twin_runs["si"] / table)
        assert len(si) > 0
        pd.testing.assert_frame_equal(field, si, check_exact=True)
    summary = json.loads((twin_runs["si"] / "summary.json").read_text())
    assert summary["counts"]["estimated"] == 1  # the stand was estimated, not skipped


def test_config_value_of_the_wrong_dimension_is_one_line_naming_key_file_and_quantity(tmp_path):
    path = tmp_path / "w.toml"
    path.write_text('[fluid]\nmud_density_kg_m3 = "5 in"\n')
    result = CliRunner().invoke(cli, ["td", str(path), "--bit-depth", "1000"])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and str(path) in lines[0]
    assert "key 'fluid.mud_density_kg_m3' = '5 in' is a length, not a density (kg/m³)" \
        in lines[0]


def _td_json(*args) -> dict:
    result = CliRunner().invoke(cli, ["td", str(DEMO / "demo.toml"), "--json", *args])
    assert result.exit_code == 0, result.output
    return json.loads(result.output)


def test_td_options_take_quantities():
    """7500 ft = 2286 m and 30 klbf, 3 kft·lbf exactly in N and N·m: the same profile."""
    on = ["--load-case", "rotating_on_bottom"]
    field = _td_json("--bit-depth", "7500 ft", "--wob", "30 klbf", "--bit-torque",
                     "3 kft.lbf", *on)
    si = _td_json("--bit-depth", "2286", "--wob", repr(float(30000 * LBF)), "--bit-torque",
                  repr(float(3000 * FT * LBF)), *on)
    assert field == si


def test_bad_quantity_option_names_the_option():
    result = CliRunner().invoke(cli, ["td", str(DEMO / "demo.toml"), "--bit-depth", "7 kg"])
    assert result.exit_code == 2 and "--bit-depth" in result.output
    assert "'7 kg' is a mass, not a length (m)" in result.output


def test_td_prints_field_units_and_json_stays_si():
    result = CliRunner().invoke(cli, ["td", str(DEMO / "demo.toml"), "--bit-depth", "2286",
                                      "--units", "field"])
    assert result.exit_code == 0, result.output
    assert "7500.0 ft" in result.output and "klbf" in result.output
    assert "kft·lbf" in result.output
    si = _td_json("--bit-depth", "2286", "--units", "field")
    assert si["bit_depth_m"] == 2286.0


def test_units_key_of_the_config_sets_the_printed_units(tmp_path):
    path = tmp_path / "w.toml"
    path.write_text(DEMO.joinpath("demo.toml").read_text().replace(
        'name = "demo"', 'name = "demo"\nunits = "field"').replace(
        'file = "demo.survey.csv"', f'file = "{DEMO / "demo.survey.csv"}"'))
    result = CliRunner().invoke(cli, ["td", str(path)])
    assert result.exit_code == 0, result.output
    assert " ft " in result.output and "klbf" in result.output
    result = CliRunner().invoke(cli, ["td", str(path), "--units", "si"])
    assert " m " in result.output and " kN " in result.output


def test_inspect_shows_channels_in_field_units():
    result = CliRunner().invoke(cli, ["inspect", str(DEMO / "demo.csv"), "--units", "field"])
    assert result.exit_code == 0, result.output
    line = next(ln for ln in result.output.splitlines() if ln.startswith("bit_depth_m"))
    assert " ft " in line and "7251" in line  # 2210 m = 7250.7 ft


def test_inspect_states_what_was_assumed_in_field_units(tmp_path):
    """Issue 35: the assumed string, mud and tortuosity in ft, ppg and °/100 ft as well."""
    shutil.copy(DEMO / "demo.csv", tmp_path / "w.csv")  # no config, no survey: defaults
    result = CliRunner().invoke(cli, ["inspect", str(tmp_path / "w.csv"), "--units", "field"])
    assert result.exit_code == 0, result.output
    assumed = [ln for ln in result.output.splitlines() if ln.startswith("assumed")]
    assert any("361 ft 5in HWDP + 394 ft 8in collars" in ln for ln in assumed), assumed
    assert any("mud density 10.0 ppg" in ln for ln in assumed), assumed
    assert any("1.02°/100 ft" in ln for ln in assumed), assumed
    assert not any(unit in ln for ln in assumed for unit in (" m ", "kg/m³", "°/30 m"))
