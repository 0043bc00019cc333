"""`drillfric td` (docs/cli.md): JSON keys, profile/broomstick files, bad input → exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.config import load_config
from drillfric.io.survey import read_survey
from drillfric.torque_drag import solve_config

DOCUMENTED_KEYS = {"bit_depth_m", "friction_factor", "load_case", "surface_torque_Nm",
                  "hookload_N", "T_N_Nm"}
PROFILE_COLUMNS = ["md_m", "inc_deg", "azi_deg", "tension_N", "torque_Nm",
                   "normal_force_N_m", "fc_Nm_m"]


def invoke(*args):
    return CliRunner().invoke(cli, ["td", *map(str, args)])


@pytest.fixture
def well(tmp_path):
    """A build-and-hold well: config with [survey] file, survey CSV beside it."""
    survey = tmp_path / "w.survey.csv"
    pd.DataFrame({"md_m": [0.0, 500.0, 1500.0, 3000.0], "inc_deg": [0.0, 0.0, 50.0, 50.0],
                  "azi_deg": [0.0, 0.0, 45.0, 45.0]}).to_csv(survey, index=False)
    cfg = tmp_path / "w.toml"
    cfg.write_text('[survey]\nfile = "w.survey.csv"\n[fluid]\nmud_density_kg_m3 = 1250.0\n'
                   "[model]\nelement_length_m = 3.0\n")
    return cfg


def test_json_has_interface_keys_and_library_numbers(well):
    result = invoke(well, "--bit-depth", 2500, "--friction", 0.3, "--json")
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert DOCUMENTED_KEYS <= set(out)
    assert out["bit_depth_m"] == 2500.0 and out["friction_factor"] == 0.3
    assert out["load_case"] == "rotating_off_bottom"
    expected = solve_config(load_config(well), read_survey(well.parent / "w.survey.csv"),
                            2500.0, friction=0.3)
    assert out["surface_torque_Nm"] == pytest.approx(expected.surface_torque_Nm, rel=1e-12)
    assert out["hookload_N"] == pytest.approx(expected.hookload_N, rel=1e-12)
    assert out["T_N_Nm"] == pytest.approx(expected.T_N_Nm, rel=1e-12)


def test_default_bit_depth_is_end_of_survey_and_on_bottom_case(well):
    result = invoke(well, "--load-case", "rotating_on_bottom", "--wob", 1e5, "--bit-torque",
                    3e3, "--json")
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["bit_depth_m"] == 3000.0 and out["load_case"] == "rotating_on_bottom"
    assert out["wob_N"] == 1e5 and out["surface_torque_Nm"] > 3e3


def test_config_bit_depth_is_the_default_of_td_and_the_api(well):
    """Issue 35 (17): `drillfric td WELL.toml` ignored [well] bit_depth_m (used the survey's
    end); --bit-depth still wins."""
    well.write_text(well.read_text() + "[well]\nbit_depth_m = 2000.0\n")
    assert json.loads(invoke(well, "--json").stdout)["bit_depth_m"] == 2000.0
    assert json.loads(invoke(well, "--json", "--bit-depth", 2100).stdout)["bit_depth_m"] == 2100
    import drillfric

    demo = drillfric.open_well(Path(__file__).parents[1] / "examples/demo/demo.csv",
                               overrides={"well.bit_depth_m": 2000.0})
    assert drillfric.torque_and_drag(demo).bit_depth_m == 2000.0


def test_output_piped_into_a_reader_that_stops_early_is_no_internal_error(well):
    """`drillfric td … --json | head -1`: the reader closes the pipe first; drillfric stops
    with the shell's SIGPIPE code (141) and prints no error, not "internal error:
    BrokenPipeError"."""
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-m", "drillfric.cli.main", "td", str(well),
                             "--broomstick", "--json"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    proc.stdout.close()  # before drillfric writes a byte
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141, err
    assert "Error" not in err and "Traceback" not in err, err


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_profile_file_columns(well, tmp_path, suffix):
    out = tmp_path / f"profile{suffix}"
    result = invoke(well, "--bit-depth", 2000, "--out", out)
    assert result.exit_code == 0, result.output
    assert "hook load" in result.stdout
    table = pd.read_csv(out) if suffix == ".csv" else pd.read_parquet(out)
    assert list(table.columns) == PROFILE_COLUMNS
    assert table["md_m"].iloc[0] == 0.0 and table["md_m"].iloc[-1] == 2000.0
    assert np.all(np.diff(table["md_m"]) > 0)


def test_data_file_with_sidecars(well, tmp_path):
    """A well given as a data file finds NAME.toml and NAME.survey.csv (docs/ingestion.md)."""
    pd.DataFrame({"time_s": [0.0, 1.0], "surface_rpm": [60.0, 60.0],
                  "surface_torque_Nm": [1e4, 1e4]}).to_csv(tmp_path / "w.csv", index=False)
    by_data = invoke(tmp_path / "w.csv", "--bit-depth", 2500, "--json")
    by_config = invoke(well, "--bit-depth", 2500, "--json")
    assert by_data.exit_code == 0, by_data.output
    assert json.loads(by_data.stdout) == json.loads(by_config.stdout)


def test_section_friction_reported(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text("[model]\ncasing_shoe_md_m = 1000.0\nfriction_cased = 0.2\n"
                   "friction_open = 0.3\n")
    result = invoke(cfg, "--bit-depth", 1500, "--json")
    out = json.loads(result.stdout)
    assert out["friction_factor"] is None
    assert out["friction_by_section"] == {"casing_shoe_md_m": 1000.0, "cased": 0.2,
                                          "open_hole": 0.3}


@pytest.mark.parametrize("plot", [None, "b.svg"])
def test_broomstick_table_and_plot(well, tmp_path, plot):
    out = tmp_path / "b.csv"
    args = [well, "--broomstick", "--frictions", "0.1,0.3", "--depths", "1000:2500:500",
            "--out", out]
    if plot:
        args += ["--plot", tmp_path / plot]
    result = invoke(*args)
    assert result.exit_code == 0, result.output
    table = pd.read_csv(out)
    assert len(table) == 4 * 2 * 3
    assert set(table["load_case"]) == {"rotating_off_bottom", "pick_up", "slack_off"}
    picture = tmp_path / (plot or "b.png")
    assert picture.stat().st_size > 1000


def test_broomstick_json(well):
    result = invoke(well, "--broomstick", "--frictions", "0.2", "--depths", "800,1600",
                    "--wob", 5e4, "--json")
    assert result.exit_code == 0, result.output
    rows = json.loads(result.stdout)
    assert len(rows) == 2 * 4 and DOCUMENTED_KEYS <= set(rows[0])
    assert {r["load_case"] for r in rows} >= {"rotating_on_bottom"}  # added when WOB given


def _one_line_exit_2(result, needle):
    assert result.exit_code == 2, result.output
    lines = [ln for ln in result.stderr.splitlines() if not ln.startswith("warning:")]
    assert len(lines) == 1 and needle in lines[0], result.stderr
    assert "Traceback" not in result.output


def test_string_shorter_than_bha(well):
    _one_line_exit_2(invoke(well, "--bit-depth", 100), "the bit is at 100.0 m")


def test_bit_deeper_than_survey(well):
    _one_line_exit_2(invoke(well, "--bit-depth", 3500), "beyond the survey")


@pytest.mark.parametrize("entry,needle", [
    ("od_m = 0.0\nid_m = 0.0", "od_m"),
    ("od_m = 0.127\nid_m = -0.01", "id_m"),
    ("od_m = 0.127\nid_m = 0.13", "must be smaller than od_m"),
    ("od_m = 0.127\nid_m = 0.1\nlinear_mass_kg_m = -3.0", "linear_mass_kg_m"),
])
def test_bad_dimensions(tmp_path, entry, needle):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(f"[[string.sections]]\nname = 'dp'\n{entry}\n")
    _one_line_exit_2(invoke(cfg, "--bit-depth", 1000), needle)


def test_zero_length_bha_section(tmp_path):
    cfg = tmp_path / "bad.toml"
    cfg.write_text("[[string.sections]]\nod_m = 0.127\nid_m = 0.1\n"
                   "[[string.sections]]\nod_m = 0.17\nid_m = 0.07\nlength_m = 0.0\n")
    _one_line_exit_2(invoke(cfg, "--bit-depth", 1000), "length_m")


@pytest.mark.parametrize("text,needle", [
    ("[fluid]\nmud_density_kg_m3 = 8000.0\n", "mud_density_kg_m3"),
    ("[fluid]\nmud_density_kg_m3 = 1500.0\n[[string.sections]]\nod_m = 0.127\nid_m = 0.1\n"
     "steel_density_kg_m3 = 1400.0\n", "not lighter than the steel"),
])
def test_mud_heavier_than_steel(tmp_path, text, needle):
    cfg = tmp_path / "mud.toml"
    cfg.write_text(text)
    _one_line_exit_2(invoke(cfg, "--bit-depth", 1000), needle)


def test_other_bad_usage(well, tmp_path):
    _one_line_exit_2(invoke(tmp_path / "nothing.toml"), "not found")
    _one_line_exit_2(invoke(well, "--out", tmp_path / "p.xlsx"), "unsupported output type")
    _one_line_exit_2(invoke(well, "--broomstick", "--frictions", "a,b"), "--frictions")
    _one_line_exit_2(invoke(tmp_path / "w.toml", "--load-case", "rotating_pick_up"),
                     "axial speed and RPM")
    no_survey = tmp_path / "ns.toml"
    no_survey.write_text("")
    _one_line_exit_2(invoke(no_survey), "--bit-depth")


def test_no_survey_is_vertical_with_the_nominal_tortuosity(tmp_path):
    """Without a survey td takes the same assumed path as run (vertical, 1°/30 m), warns
    and lists it in "assumed"; tortuosity 0 is the exactly vertical hole (T_N = 0)."""
    cfg = tmp_path / "ns.toml"
    cfg.write_text("[fluid]\nmud_density_kg_m3 = 1200.0\n")
    result = invoke(cfg, "--bit-depth", 2000, "--json")
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert any("nominal tortuosity of 1.0°/30 m" in a for a in out["assumed"])
    assert "nominal tortuosity of 1.0°/30 m" in result.stderr
    assert out["T_N_Nm"] == pytest.approx(solve_config(load_config(cfg), None, 2000.0).T_N_Nm,
                                          rel=1e-12) and out["T_N_Nm"] > 0
    broom = invoke(cfg, "--broomstick", "--bit-depth", 2000, "--depths", "1000,2000",
                   "--json")
    assert broom.exit_code == 0, broom.output
    assert all(row["T_N_Nm"] > 0 for row in json.loads(broom.stdout))
    cfg.write_text("[survey]\ntortuosity_deg_30m = 0.0\n")
    flat = json.loads(invoke(cfg, "--bit-depth", 2000, "--json").stdout)
    assert flat["T_N_Nm"] == 0.0 and "vertical well: no survey found" in flat["assumed"]


DEMO = Path(__file__).resolve().parents[1] / "examples" / "demo"


def test_config_bit_depth_wins_over_the_logs_deepest_without_a_survey(tmp_path):
    """Issue 35: [well] bit_depth_m is td's bit depth for a log without survey too — the
    profile, and the broomstick, whose default was the log's deepest stand (2300 m)."""
    data = tmp_path / "w.csv"
    data.write_bytes((DEMO / "demo.csv").read_bytes())
    (tmp_path / "w.toml").write_text("[well]\nbit_depth_m = 2100.0\n")
    profile = invoke(data, "--json")
    assert profile.exit_code == 0, profile.output
    assert json.loads(profile.stdout)["bit_depth_m"] == 2100.0
    broom = invoke(data, "--broomstick", "--frictions", "0.2", "--json")
    assert broom.exit_code == 0, broom.output
    assert max(row["bit_depth_m"] for row in json.loads(broom.stdout)) == 2100.0


def test_broomstick_of_a_well_with_a_log_draws_measured_points(tmp_path):
    """`td --broomstick demo.csv`: the log is segmented, its 4 rotating stands are drawn
    on the plot, and the consistent demo string passes the weight check (the simulated
    hook load has no block: implied block weight ≈ 0)."""
    plot = tmp_path / "b.png"
    result = invoke(DEMO / "demo.csv", "--broomstick", "--depths", "1500:2300:100",
                    "--frictions", "0.2,0.3", "--plot", plot)
    assert result.exit_code == 0, result.output
    assert "measured: 4 rotating segments" in result.output
    assert "inconsistent" not in result.output
    assert plot.stat().st_size > 1000


def test_broomstick_warns_when_the_string_is_heavier_than_the_hook_load(tmp_path):
    """Drill pipe 1.6× too heavy: its modelled rotating hook load exceeds the measured one
    by far more than 5 %, and td says so (a warning, exit 0)."""
    text = (DEMO / "demo.toml").read_text().replace("linear_mass_kg_m = 41.41",
                                                    "linear_mass_kg_m = 66.0")
    heavy = tmp_path / "heavy.toml"
    heavy.write_text(text.replace('data = "demo.csv"', ""))
    result = invoke(DEMO / "demo.csv", "--broomstick", "--depths", "2000,2300",
                    "--frictions", "0.3", "--config", heavy, "--survey",
                    DEMO / "demo.survey.csv")
    assert result.exit_code == 0, result.output
    assert "string weight inconsistent with the hook load" in result.stderr
