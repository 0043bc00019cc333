"""`drillfric simulate`: scenarios, noise, files and sidecars, one-line errors (exit 2)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric import torsional as T
from drillfric.config import config_from_dict, load_config
from drillfric.errors import ConfigError, ModelError
from drillfric.io.readers import open_source
from drillfric.io.writers import dumps_toml
from drillfric.sim import run as sim
from drillfric.sim import scenario, settings, well_b
from drillfric.wellpath import minimum_curvature

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

RPM = np.pi / 30.0

CONFIG = """
[rig]
top_drive_inertia_kg_m2 = 2900.0
[model]
cells = 120
[simulate]
mu_s = 0.6
mu_k = 0.3
rate_hz = 20.0
duration_s = 30.0
rpm = 50.0
[[string.sections]]
name = "dp"
od_m = 0.146529
id_m = 0.123024
[[string.sections]]
name = "collars"
od_m = 0.2032
id_m = 0.0714
length_m = 120.0
"""

SURVEY = "md_m,inc_deg,azi_deg\n0,0,0\n500,0,0\n1000,30,20\n2000,30,20\n"

SCENARIO = """
connection_s = 20.0
[defaults]
duration_s = 60.0
rpm = 40.0
[[stand]]
bit_depth_m = 1500.0
start = "creep"
[[stand]]
bit_depth_m = 1530.0
rpm = 60.0
"""


@pytest.fixture
def well(tmp_path) -> Path:
    """A config with a survey beside it, as users write them."""
    (tmp_path / "w.survey.csv").write_text(SURVEY)
    cfg = tmp_path / "w.toml"
    cfg.write_text('[survey]\nfile = "w.survey.csv"\n' + CONFIG)
    (tmp_path / "s.toml").write_text(SCENARIO)
    return cfg


def invoke(*args):
    return CliRunner().invoke(cli, ["--quiet", "simulate", *map(str, args)])


# ------------------------------------------------------------------------------ scenario

def test_creep_start_shape(tmp_path):
    """docs/theory.md §6.3 creep: 0 → 5 RPM in 5 s, hold 30 s, then ramp to the set-point."""
    stand = scenario.Stand(2000.0, duration_s=100.0, rpm=40.0, start="creep", idle_s=5.0)
    k = stand.knots()
    np.testing.assert_allclose(k[:6], [[0, 0], [5, 0], [10, 5], [40, 5], [50, 40], [105, 40]])
    assert k[-1, 0] == stand.total_s == 5 + 100 + 5 + 10


def test_scenario_file_defaults_and_overrides(well):
    cfg = load_config(well)
    scen = scenario.load_scenario(well.parent / "s.toml", scenario.base_stand(cfg))
    assert [s.bit_depth_m for s in scen.stands] == [1500.0, 1530.0]
    assert [s.rpm for s in scen.stands] == [40.0, 60.0]
    assert scen.stands[0].start == "creep" and scen.stands[1].start == "ramp"
    assert scen.connection_s == 20.0
    assert scen.total_s == pytest.approx(2 * (5 + 60 + 15) + 20)


@pytest.mark.parametrize("text, word", [
    ("[[stand]]\nrpm = 40.0\n", "bit_depth_m"),
    ("[[stand]]\nbit_depth_m = 1.0\nspeed = 3\n", "unknown key 'speed'"),
    ("[[stand]]\nbit_depth_m = 1000.0\nstart = 'jump'\n", "start"),
    ("[[stand]]\nbit_depth_m = 1000.0\nduration_s = 5.0\n", "start-up"),
    ("pause = 3\n[[stand]]\nbit_depth_m = 1000.0\n", "unknown key 'pause'"),
    ("[[stand]]\nbit_depth_m = 1000.0\nsetpoint_rpm = [[1, 2]]\n", "setpoint_rpm"),
    ("[[stand]]\nbit_depth_m = 1000.0\nbit_weakening_ratio = 0.5\n", "bit_weakening_ratio"),
    ("[[stand]]\nbit_depth_m = 1000.0\nbit_weakening_rpm = 0.0\n", "bit_weakening_rpm"),
    ("[[stand]]\nbit_depth_m = 1000.0\ntop_drive_inertia_kg_m2 = 0.0\n",
     "top_drive_inertia_kg_m2"),
])
def test_bad_scenarios_name_the_problem(tmp_path, text, word):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=word):
        scenario.load_scenario(path, scenario.Stand(float("nan")))


def test_explicit_setpoint_with_a_step():
    """A repeated knot time is a step; values between knots are linear."""
    t = np.array([0.0, 1.0, 1.0, 2.0])
    v = np.array([0.0, 1.0, 3.0, 3.0])
    out = sim.step_interp(np.array([0.5, 0.999, 1.0, 1.5, 5.0]), t, v)
    np.testing.assert_allclose(out, [0.5, 0.999, 3.0, 3.0, 3.0])


# ----------------------------------------------------------------------------- pipeline

@pytest.fixture(scope="module")
def two_stands():
    cfg = config_from_dict({"simulate": {"rate_hz": 20.0, "mu_s": 0.6, "mu_k": 0.3,
                                         "cells": 120}})
    path = minimum_curvature([0.0, 500.0, 1000.0, 2000.0], np.radians([0, 0, 30, 30]),
                             np.radians([0, 0, 20, 20]))
    scen = scenario.Scenario((scenario.Stand(1500.0, duration_s=60.0, rpm=40.0, start="creep"),
                         scenario.Stand(1530.0, duration_s=60.0, rpm=60.0)), 20.0)
    return cfg, path, scen, sim.simulate(cfg, path, scen)


def test_columns_time_base_and_connection(two_stands):
    cfg, _, scen, result = two_stands
    c = result.columns
    assert set(c) == {"time_s", "surface_rpm", "surface_torque_Nm", "hookload_N",
                      "bit_depth_m", "hole_depth_m", "bit_rpm", "string_torque_Nm"}
    dt = np.diff(c["time_s"])
    np.testing.assert_allclose(dt, 1 / 20.0, atol=1e-9)
    assert c["time_s"][-1] == pytest.approx(scen.total_s)
    s1, s2 = result.stands
    conn = (c["time_s"] > s1.t_end_s) & (c["time_s"] < s2.t_start_s)
    assert conn.sum() == 20 * 20 - 1
    assert np.all(c["surface_rpm"][conn] == 0) and np.all(c["surface_torque_Nm"][conn] == 0)
    assert np.all(c["hookload_N"][conn] == 0)
    assert np.all(np.diff(c["bit_depth_m"][conn]) > 0)
    np.testing.assert_allclose(c["hole_depth_m"] - c["bit_depth_m"], 5.0)


def test_a_gear_change_between_stands_changes_the_inertia_of_that_stand(two_stands):
    """Issue 34 item 2 (inertia per stand): the motor torque less the string's is
    I_TD·dω₀/dt with the stand's own inertia; the stand before keeps the rig's."""
    cfg, path, scen, result = two_stands
    geared = scenario.Scenario((scen.stands[0], replace(scen.stands[1],
                                                        top_drive_inertia_kg_m2=3 * 2900.0)),
                               scen.connection_s)
    other = sim.simulate(cfg, path, geared)
    t = result.columns["time_s"]
    first = t <= result.stands[0].t_end_s
    for key in ("surface_torque_Nm", "bit_rpm"):
        np.testing.assert_array_equal(other.columns[key][first], result.columns[key][first])
    second = t >= result.stands[1].t_start_s
    inertia_term = [np.std((r.columns["surface_torque_Nm"] - r.columns["string_torque_Nm"])
                           [second]) for r in (result, other)]
    assert inertia_term[1] > 1.5 * inertia_term[0]


def test_creep_hold_and_stick_slip_truth(two_stands):
    _, _, _, result = two_stands
    c, s1 = result.columns, result.stands[0]
    hold = (c["time_s"] > s1.t_rotation_start_s + 10) & (c["time_s"] < s1.creep_end_s)
    np.testing.assert_allclose(c["surface_rpm"][hold], 5.0, atol=0.2)
    assert s1.hookload_N > 0 and s1.T_N_Nm > 0
    assert s1.cells == pytest.approx(120, abs=6)
    truth = result.truth()
    assert truth["mu_s"] == 0.6 and truth["mu_k"] == 0.3
    json.dumps(truth)


@pytest.mark.parametrize("law", [{}, {"friction_law": "stribeck", "stribeck_speed_rad_s": 6.0}],
                         ids=["step", "stribeck"])
def test_cased_open_truth_torque_from_the_truth_file(law):
    """docs/simulator.md: a truth with its own friction factors above the casing shoe
    (mu_s_cased, mu_k_cased) and optionally the Stribeck law. Its steady rotating torque
    follows from the truth record alone (what a validation script reads, per zone):
    Σ_zones [μ_k T_zone + (μ_s − μ_k) T_zone·w(Ω)] + k_tΩ∫ρJ dx, T_zone = ∫F_c dx of the
    zone, w = exp(−(Ω/v_s)^δ) or 0 (step law above ω_c). 80 RPM, 1 %: the cased zone
    (44–48 %) and the Stribeck term (7 %, w = 0.25 at v_s = 6 rad/s) carry far more of the
    torque (checked), the O(k_tΔt) steady-state speed gradient is 0.1 % (measured within
    0.08 %); k_t = 1 1/s keeps the sliding stable against the Stribeck slope
    (200 < k_t∫ρJ dx = 400 N·m·s/rad)."""
    cfg = config_from_dict({
        "model": {"casing_shoe_md_m": 1000.0, "k_t_per_s": 1.0},
        "simulate": {"rate_hz": 10.0, "mu_s": 0.3, "mu_k": 0.2, "mu_s_cased": 0.45,
                     "mu_k_cased": 0.35, "cells": 300, "duration_s": 60.0, "rpm": 80.0,
                     **law}})
    path = minimum_curvature([0.0, 300.0, 900.0, 2000.0], np.radians([0, 0, 45, 45]),
                             np.zeros(4))
    result = sim.simulate(cfg, path, scenario.single_stand(cfg, 1500.0))
    truth = json.loads(json.dumps(result.truth()))
    cased, open_ = truth["zones"]
    assert (cased["zone"], cased["md_to_m"], open_["zone"]) == ("cased", 1000.0, "open")
    stand = truth["stands"][0]
    t_zone = {"cased": stand["T_N_cased_Nm"], "open": stand["T_N_Nm"]}
    omega = 80 * RPM
    w = 0.0
    if truth["friction_law"] == "stribeck":
        w = np.exp(-(omega / truth["stribeck_speed_rad_s"]) ** truth["stribeck_exponent"])
    friction = sum(z["mu_k"] * t_zone[z["zone"]] + (z["mu_s"] - z["mu_k"]) * w
                   * t_zone[z["zone"]] for z in truth["zones"])
    plant, _ = sim.plant_for(cfg, result.settings, path, scenario.Stand(1500.0))
    viscous = 1.0 * omega * float(np.sum(plant.grid.rho_j_kg_m * plant.grid.dx_model_m))
    kinetic = sum(z["mu_k"] * t_zone[z["zone"]] for z in truth["zones"])
    assert cased["mu_k"] * t_zone["cased"] > 0.1 * (friction + viscous)
    assert (friction - kinetic > 0.03 * (friction + viscous)) == bool(law)
    late = result.columns["time_s"] > 50.0
    torque = result.columns["surface_torque_Nm"][late].mean()
    assert torque == pytest.approx(friction + viscous, rel=0.01)


@pytest.mark.parametrize("simulate, word", [
    ({"mu_s_cased": 0.4}, "go together"),
    ({"mu_s_cased": 0.4, "mu_k_cased": 0.3}, "casing shoe"),
    ({"mu_s_cased": 0.2, "mu_k_cased": 0.3, "casing": True}, "larger than")])
def test_bad_cased_truth(simulate, word):
    model = {"casing_shoe_md_m": 800.0} if simulate.pop("casing", False) else {}
    cfg = config_from_dict({"model": model, "simulate": simulate})
    with pytest.raises((ConfigError, ModelError), match=word):
        settings.PlantSettings.from_config(cfg)


def test_noise_is_seeded_and_quantised():
    cols = {"surface_rpm": np.full(20000, 40.0), "surface_torque_Nm": np.full(20000, 1e4),
            "hookload_N": np.full(20000, 5e5)}
    a, b, c = (dict(cols) for _ in range(3))
    settings.Noise(0.5, 200.0, 0.0, 0.1, 10.0, seed=1).apply(a)
    settings.Noise(0.5, 200.0, 0.0, 0.1, 10.0, seed=1).apply(b)
    settings.Noise(0.5, 200.0, 0.0, 0.1, 10.0, seed=2).apply(c)
    np.testing.assert_array_equal(a["surface_rpm"], b["surface_rpm"])
    assert not np.array_equal(a["surface_rpm"], c["surface_rpm"])
    # standard error of a 20 000-sample sd is 0.5 %; quantisation adds step²/12
    assert np.std(a["surface_torque_Nm"]) == pytest.approx(np.hypot(200, 10 / 12**0.5),
                                                           rel=0.03)
    np.testing.assert_allclose(a["surface_torque_Nm"] / 10.0,
                               np.round(a["surface_torque_Nm"] / 10.0), atol=1e-9)


def test_bit_on_bottom_adds_bit_torque():
    """Coulomb bit (docs/simulator.md): steady torque gains T_bit = μ_bit·WOB·D/3."""
    p = well_b.well_b_plant(cells=200, k_t_per_s=0.5, mu_s=0.2, mu_k=0.2)
    cap = T.bit_torque_cap(0.3, 80e3, 0.2159)
    on = T.Plant(p.grid, p.fc_Nm_m, p.mu_s, p.mu_k, p.omega_c_rad_s, p.k_t_per_s,
                 bit_torque_cap_Nm=cap)
    drive = T.Drive("pi", np.array([0.0, 60 * RPM]), 10.0)
    off_rec, _ = T.run(p, drive, 80.0, 5.0)
    on_rec, _ = T.run(on, drive, 80.0, 5.0)
    gained = on_rec.motor_torque_Nm[-1] - off_rec.motor_torque_Nm[-1]
    assert gained == pytest.approx(cap, rel=0.01)


# ------------------------------------------------------------------------------ CLI

@pytest.mark.parametrize("ext", ["csv", "parquet", "h5"])
def test_cli_writes_data_and_sidecars_that_read_back(well, tmp_path, ext):
    out = tmp_path / "out" / f"sim.{ext}"
    result = invoke(well, "--out", out, "--duration", 20, "--bit-depth", 1500, "--rpm", 40,
                    "--mu-s", 0.5, "--mu-k", 0.3, "--rpm-noise", 0.5, "--seed", 3)
    assert result.exit_code == 0, result.output
    frame = pd.concat(list(open_source(out).chunks()), ignore_index=True)
    assert list(frame.columns)[:3] == ["time_s", "surface_rpm", "surface_torque_Nm"]
    assert len(frame) == 20 * 20 + 1
    cfg = load_config(out.with_suffix(".toml"))
    assert cfg.simulate.mu_s == 0.5 and cfg.survey.file == "sim.survey.csv"
    assert [s["name"] for s in cfg.sections] == ["dp", "collars"]
    survey = pd.read_csv(out.parent / "sim.survey.csv")
    assert list(survey.columns) == ["md_m", "inc_deg", "azi_deg"]
    assert survey["md_m"].iloc[-1] == 2000.0
    truth = json.loads((out.parent / "sim.truth.json").read_text())
    assert truth["mu_s"] == 0.5 and truth["stands"][0]["bit_depth_m"] == 1500.0
    if ext == "parquet":
        meta = pq.read_schema(out).metadata
        assert json.loads(meta[b"drillfric.truth"])["mu_k"] == 0.3
    if ext == "h5":
        with h5py.File(out) as h5:
            assert {"surface", "survey", "config"} <= set(h5)
            assert "mu_s = 0.5" in h5["config"][()].decode()


def test_cli_output_is_read_by_ingestion(well, tmp_path):
    """`drillfric run FILE` consumes the result: the well loader finds data and sidecars."""
    from drillfric.io.well import load_well

    out = tmp_path / "sim.csv"
    assert invoke(well, "--out", out, "--duration", 15, "--bit-depth", 1500).exit_code == 0
    data = load_well(out)
    assert data.survey is not None and data.survey.md_max_m == 2000.0
    for name in ("surface_rpm", "surface_torque_Nm", "hookload_N", "bit_depth_m", "bit_rpm"):
        assert name in data.surface.columns
    assert data.surface["surface_rpm"].iloc[-1] == pytest.approx(60.0, abs=30.0)


def test_cli_scenario_keeps_input_sidecars(well, tmp_path):
    """Writing NAME.csv beside its own NAME.toml/NAME.survey.csv (the demo) keeps them."""
    cfg = well.parent / "w.toml"
    before = cfg.read_text()
    result = invoke(cfg, "--out", well.parent / "w.csv", "--scenario", well.parent / "s.toml")
    assert result.exit_code == 0, result.output
    assert cfg.read_text() == before
    assert (well.parent / "w.survey.csv").read_text() == SURVEY
    assert len(pd.read_csv(well.parent / "w.csv")) > 1000


def _one_line_error(result):
    assert result.exit_code == 2, result.output
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in result.output
    return lines[0]


@pytest.mark.parametrize("args, word", [
    (["--duration", "0"], "duration_s"),
    (["--rate", "-5"], "rate_hz"),
    (["--mu-s", "0.3", "--mu-k", "0.5"], "μ_k"),
    (["--omega-c-rpm", "0"], "omega_c"),
    (["--bit-depth", "2500"], "deeper than the survey"),
])
def test_cli_bad_input_one_line_exit_2(well, tmp_path, args, word):
    line = _one_line_error(invoke(well, "--out", tmp_path / "x.csv", *args))
    assert word in line


def test_cli_zero_inertia_and_deep_stand(well, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(well.read_text().replace("2900.0", "0.0"))
    assert "top_drive_inertia" in _one_line_error(invoke(bad, "--out", tmp_path / "x.csv"))
    deep = tmp_path / "deep.toml"
    deep.write_text("[[stand]]\nbit_depth_m = 1500.0\n[[stand]]\nbit_depth_m = 2600.0\n")
    line = _one_line_error(invoke(well, "--out", tmp_path / "x.csv", "--scenario", deep))
    assert "stand 2" in line and "deeper than the survey" in line


def test_cli_rejects_unknown_output_type(well, tmp_path):
    assert ".xlsx" in _one_line_error(invoke(well, "--out", tmp_path / "x.xlsx"))


def test_toml_round_trip_of_effective_config(well, tmp_path):
    """The sidecar writer's TOML reads back to the same configuration (channels included)."""
    path = tmp_path / "c.toml"
    path.write_text(well.read_text() + '[channels]\nsurface_rpm = { column = "SRPM", '
                    'unit = "rpm" }\nhookload = "HKLD"\n')
    cfg = load_config(path)
    text = dumps_toml(cfg.to_dict())
    again = config_from_dict(__import__("tomllib").loads(text))
    assert again.values == cfg.values and again.sections == cfg.sections
    assert again.channels == cfg.channels == {"surface_rpm": {"column": "SRPM", "unit": "rpm"},
                                              "hookload": {"column": "HKLD"}}


def test_cli_bit_depth_overrides_configured_scenario(well, tmp_path):
    """--bit-depth without --scenario: one stand, even if [simulate] names a scenario."""
    cfg = tmp_path / "with_scenario.toml"
    cfg.write_text(well.read_text().replace("[simulate]\n", '[simulate]\nscenario = "s.toml"\n'))
    out = tmp_path / "one.csv"
    assert invoke(cfg, "--out", out, "--bit-depth", 1400, "--duration", 10).exit_code == 0
    truth = json.loads((tmp_path / "one.truth.json").read_text())
    assert [s["bit_depth_m"] for s in truth["stands"]] == [1400.0]
    assert invoke(cfg, "--out", out).exit_code == 0
    truth = json.loads((tmp_path / "one.truth.json").read_text())
    assert [s["bit_depth_m"] for s in truth["stands"]] == [1500.0, 1530.0]


def test_on_bottom_stand_records_wob_and_hole_depth():
    """A stand with WOB: T&D on-bottom load case, Coulomb bit, wob_N column, bit at bottom."""
    cfg = config_from_dict({"model": {"cells": 100}, "simulate": {"rate_hz": 10.0}})
    scen = scenario.Scenario((scenario.Stand(1200.0, duration_s=30.0, rpm=60.0, wob_N=50e3),), 0.0)
    bare = scenario.Stand(1200.0, duration_s=30.0, rpm=60.0)
    off = sim.simulate(cfg, None, scenario.Scenario((bare,), 0.0))
    on = sim.simulate(cfg, None, scen)
    c = on.columns
    assert "wob_N" in c and "wob_N" not in off.columns
    np.testing.assert_array_equal(c["hole_depth_m"], c["bit_depth_m"])
    assert on.stands[0].hookload_N < off.stands[0].hookload_N - 49e3


@pytest.mark.parametrize("ratio", [1.0, 3.0])
def test_truth_bit_torque_is_the_mean_the_bit_applied(tmp_path, ratio):
    """The truth's on-bottom bit torque (docs/simulator.md, Bit) is the time-mean of what the
    plant's bit applied after the start-up: steady sliding at 60 RPM with μ_s = μ_k and
    strong damping (k_t = 2 1/s; at 0.5 1/s this bit stays in stick-slip and its mean is 27 %
    above) makes it T_bit(ω) = T_k·(1 + (r − 1)·exp(−ω/ω_b)) — T_k for the Coulomb bit, 10 %
    above it for r = 3, ω_b = 20 RPM (within 1e-3, measured 3e-5; the mean includes the
    settling after the 10-s ramp). The stand's r, ω_b come from the scenario and go to the
    truth."""
    cfg = config_from_dict({"model": {"cells": 100, "k_t_per_s": 2.0},
                            "simulate": {"rate_hz": 10.0, "mu_s": 0.3, "mu_k": 0.3,
                                         "bit_mu": 0.3, "bit_weakening_rpm": 20.0}})
    path = tmp_path / "s.toml"
    path.write_text(f"[[stand]]\nbit_depth_m = 1200.0\nduration_s = 60.0\nrpm = 60.0\n"
                    f"wob_N = 80e3\nbit_weakening_ratio = {ratio}\n")
    scen = scenario.load_scenario(path, scenario.base_stand(cfg))
    truth = sim.simulate(cfg, None, scen).truth()["stands"][0]
    t_k = T.bit_torque_cap(0.3, 80e3, 0.2159)
    want = t_k * (1.0 + (ratio - 1.0) * np.exp(-60.0 / 20.0))
    assert truth["bit_torque_k_Nm"] == pytest.approx(t_k, rel=1e-12)
    assert truth["bit_weakening_ratio"] == ratio and truth["bit_weakening_rpm"] == 20.0
    assert truth["bit_torque_time_mean_Nm"] == pytest.approx(want, rel=1e-3)


def test_cli_without_survey_simulates_the_path_run_assumes(tmp_path):
    """No survey: the plant runs on the path `run` assumes (vertical with the nominal
    tortuosity, docs/torque_drag.md) — friction acts — and that path is written as the
    output's survey, so `run` on the output uses the true path. With tortuosity 0 the hole
    is exactly vertical (T_N = 0, docs/theory.md §2) and the warning says so."""
    cfg = tmp_path / "v.toml"
    cfg.write_text(CONFIG)
    result = CliRunner().invoke(cli, ["simulate", str(cfg), "--out", str(tmp_path / "v.csv"),
                                      "--duration", "15", "--bit-depth", "1500"])
    assert result.exit_code == 0, result.output
    assert "nominal tortuosity of 1°/30 m" in result.output
    truth = json.loads((tmp_path / "v.truth.json").read_text())
    assert truth["stands"][0]["T_N_Nm"] > 1e3
    survey = pd.read_csv(tmp_path / "v.survey.csv")
    assert survey["inc_deg"].max() == pytest.approx(1.59, abs=0.01)  # a 1°/30 m helix
    flat = tmp_path / "flat.toml"  # v.toml now has v.survey.csv beside it, which it would use
    flat.write_text("[survey]\ntortuosity_deg_30m = 0.0\n" + CONFIG)
    result = CliRunner().invoke(cli, ["simulate", str(flat), "--out", str(tmp_path / "w.csv"),
                                      "--duration", "15", "--bit-depth", "1500"])
    assert result.exit_code == 0, result.output
    assert "tortuosity of 0°/30 m" in result.output
    assert json.loads((tmp_path / "w.truth.json").read_text())["stands"][0]["T_N_Nm"] < 1.0


def test_simulate_config_uses_the_survey_beside_it(tmp_path):
    """Regression (issue 15): `simulate NAME.toml` ignored NAME.survey.csv beside it and
    simulated a vertical hole; it now finds the survey as `run` finds a well's."""
    (tmp_path / "w.survey.csv").write_text(SURVEY)
    (tmp_path / "w.toml").write_text(CONFIG)  # no [survey] file: the sidecar by name
    result = invoke(tmp_path / "w.toml", "--out", tmp_path / "out" / "sim.csv",
                    "--duration", 15, "--bit-depth", 1500)
    assert result.exit_code == 0, result.output
    survey = pd.read_csv(tmp_path / "out" / "sim.survey.csv")
    assert survey["inc_deg"].max() == 30.0 and survey["md_m"].iloc[-1] == 2000.0
    truth = json.loads((tmp_path / "out" / "sim.truth.json").read_text())
    path = minimum_curvature(np.array([0.0, 500.0, 1000.0, 2000.0]),
                             np.radians([0.0, 0.0, 30.0, 30.0]), np.radians([0.0, 0, 20, 20]))
    expected = sim.fc_profile(load_config(tmp_path / "w.toml"), path, 1500.0).T_N_Nm
    # the plant meshes the string on its own grid (simulate.cells): T_N agrees with the
    # configuration's torque and drag on this path to that discretisation (0.03 % here)
    assert truth["stands"][0]["T_N_Nm"] == pytest.approx(expected, rel=1e-3)


def test_simulate_sidecar_names_the_well_after_the_output(well, tmp_path):
    """Regression (issue 15): the sidecar config kept the input config's well name, so two
    outputs of one config claimed one well (and one result directory)."""
    well.write_text('[well]\nname = "A-12"\n' + well.read_text())
    out = tmp_path / "runs" / "A-12_high_mu.parquet"
    assert invoke(well, "--out", out, "--duration", 15, "--bit-depth", 1500).exit_code == 0
    assert load_config(out.with_suffix(".toml")).well.name == "A-12_high_mu"


def test_simulate_options_take_quantities(well, tmp_path):
    """--bit-depth "4921.26 ft" is 1499.999… m, "5000 ft" exactly 1524 m; "0.25 min" 15 s."""
    out = tmp_path / "q.csv"
    result = invoke(well, "--out", out, "--duration", "0.25 min", "--bit-depth", "5000 ft",
                    "--wob", "0 klbf")
    assert result.exit_code == 0, result.output
    truth = json.loads((tmp_path / "q.truth.json").read_text())
    assert truth["stands"][0]["bit_depth_m"] == 1524.0
    assert load_config(out.with_suffix(".toml")).simulate.duration_s == 15.0


def test_duration_with_a_scenario_says_what_it_did(well, tmp_path):
    """Issue 25 item 10: --duration with a scenario whose [defaults] set each stand's time
    changed nothing silently (1800 s asked, 1040 s made); now a warning says how long the
    record is and how to get one stand of that length."""
    result = CliRunner().invoke(cli, ["simulate", str(well), "--out", str(tmp_path / "d.csv"),
                                      "--scenario", str(well.parent / "s.toml"),
                                      "--duration", "1800"])
    assert result.exit_code == 0, result.output
    line = next(ln for ln in result.output.splitlines() if "--duration 1800 s" in ln)
    assert "the record lasts 180 s" in line and "0 of 2" in line and "--bit-depth" in line


def test_written_well_states_the_block_its_hook_load_carries(well, tmp_path):
    """The simulated hook load is the string alone (block 0) unless the configuration gives
    hookload.block_weight_N, which is then on the hook throughout and alone in the slips. The
    written NAME.toml states it, so `run` can weigh the string of a record without a
    connection (docs/theory.md §2.1: without a block weight friction factors are withheld)."""
    out = tmp_path / "bare" / "sim.csv"
    assert invoke(well, "--out", out, "--duration", 15, "--bit-depth", 1500).exit_code == 0
    assert load_config(out.with_suffix(".toml")).hookload.block_weight_N == 0.0
    bare = pd.read_csv(out)
    heavy_cfg = tmp_path / "heavy.toml"
    heavy_cfg.write_text(well.read_text() + "\n[hookload]\nblock_weight_N = 150000.0\n")
    (tmp_path / "heavy.survey.csv").write_text(SURVEY)
    out = tmp_path / "heavy" / "sim.csv"
    assert invoke(heavy_cfg, "--out", out, "--scenario", well.parent / "s.toml").exit_code == 0
    assert load_config(out.with_suffix(".toml")).hookload.block_weight_N == 150e3
    heavy = pd.read_csv(out)
    slips = heavy["string_torque_Nm"].eq(0) & heavy["bit_rpm"].eq(0)  # noise-free truth:
    assert slips.sum() > 100  # the connection between the two stands
    # 2 kN hook-load noise (the default): the slips read the block, the first stand block +
    # the same string as the bare record at the same depth
    assert heavy.loc[slips, "hookload_N"].median() == pytest.approx(150e3, abs=1e3)
    assert heavy["hookload_N"].iloc[:200].median() - bare["hookload_N"].iloc[:200].median() \
        == pytest.approx(150e3, abs=2e3)


def test_truth_power_bit_torque_of_a_stick_slipping_coulomb_bit_is_its_sliding_torque(
        tmp_path):
    """⟨τ_bit·ω_bit⟩/⟨ω_bit⟩ (docs/theory.md §2.3) of a Coulomb bit is T_k whatever the
    stick-slip: it slides at T_k and does no work while stuck (the bit does not turn
    backwards here). The plant of the test above at k_t = 0.5 1/s, sticky
    string (μ_s 0.6, μ_k 0.25), 40 RPM: the bit is stuck 12 % of the time."""
    cfg = config_from_dict({"model": {"cells": 100, "k_t_per_s": 0.5},
                            "simulate": {"rate_hz": 10.0, "mu_s": 0.6, "mu_k": 0.25,
                                         "bit_mu": 0.3}})
    path = tmp_path / "s.toml"
    path.write_text("[[stand]]\nbit_depth_m = 1200.0\nduration_s = 90.0\nrpm = 40.0\n"
                    "wob_N = 80e3\n")
    run = sim.simulate(cfg, None, scenario.load_scenario(path, scenario.base_stand(cfg)))
    truth = run.truth()["stands"][0]
    assert truth["bit_stuck_fraction"] > 0.1  # it sticks and slips (0.12)
    assert np.min(run.columns["bit_rpm"]) > -0.5  # and never turns backwards
    t_k = T.bit_torque_cap(0.3, 80e3, 0.2159)
    assert truth["bit_power_torque_Nm"] == pytest.approx(t_k, rel=1e-3)


# ------------------------------------------------------------------ friction schedule

def test_friction_pieces_follow_a_ramp_and_a_step():
    """A schedule becomes pieces of ≤ SCHEDULE_PIECE_S, each at the factor of its middle:
    a ramp 1 → 1.3 over 10 s is 5 pieces whose factors rise by 0.06, a repeated time a
    step at that very time, a constant part one piece."""
    stand = scenario.Stand(100.0, idle_s=5.0, mu_k_schedule=(
        (0.0, 1.0), (10.0, 1.3), (20.0, 1.3), (20.0, 1.0)))
    pieces = sim.friction_pieces(stand, 0.0, 40.0)
    ends = [e for e, _ in pieces]
    factors = [f for _, f in pieces]
    assert ends[:6] == pytest.approx([5.0, 7.0, 9.0, 11.0, 13.0, 15.0])
    assert factors[1:6] == pytest.approx([1.03, 1.09, 1.15, 1.21, 1.27])
    assert pieces[-2] == (pytest.approx(25.0), pytest.approx(1.3))
    assert pieces[-1] == (pytest.approx(40.0), pytest.approx(1.0))
    assert sim.friction_pieces(scenario.Stand(100.0), 0.0, 40.0) == [(40.0, 1.0)]


@pytest.mark.parametrize("value, word", [
    ([[0.0, 1.0], [10.0, 0.0]], "factors"), ([[0.0, 1.0], [10.0, 9.0]], "factors"),
    ([[5.0, 1.0], [10.0, 1.2]], "t = 0")])
def test_friction_schedule_is_validated(tmp_path, value, word):
    """Factors must be in (0, 8] and the series start at t = 0 (as setpoint_rpm)."""
    with pytest.raises(ConfigError, match=word):
        scenario._stand_from_dict({"bit_depth_m": 100.0, "mu_k_schedule": value}, {},
                                  "stand[1]", None)


def test_friction_schedule_raises_the_torque_and_records_the_truth():
    """Physics: friction up 30 % halfway through a steady rotation (μ_s = μ_k, 120 RPM: no
    stick-slip) raises the mean string torque by 30 % of its friction part (the viscous part
    stays), and the truth column follows the factor; without a schedule there is no truth
    column (constant friction is the truth file's μ_k)."""
    cfg = config_from_dict({"simulate": {"rate_hz": 10.0, "mu_s": 0.25, "mu_k": 0.25,
                                         "cells": 120, "rpm_noise": 0.0,
                                         "torque_noise_Nm": 0.0}})
    path = minimum_curvature([0.0, 500.0, 1000.0, 2000.0], np.radians([0, 0, 30, 30]),
                             np.radians([0, 0, 20, 20]))
    stand = scenario.Stand(1500.0, duration_s=80.0, rpm=120.0, idle_s=0.0, stop=False,
                           mu_k_schedule=((0.0, 1.0), (40.0, 1.0), (40.0, 1.3)))
    out = sim.simulate(cfg, path, scenario.Scenario((stand,), 0.0))
    t, torque = out.columns["time_s"], out.columns["string_torque_Nm"]
    truth = out.columns["mu_k_true"]
    assert np.all(truth[t < 39.9] == pytest.approx(0.25))
    assert np.all(truth[t > 40.1] == pytest.approx(0.325))
    before, after = torque[(t > 25) & (t < 39)].mean(), torque[(t > 65) & (t < 79)].mean()
    friction = out.stands[0].T_N_Nm * 0.25
    # steady sliding: the torque rise is 0.3·μ_k·T_N within the ringing's 2 % of it
    assert after - before == pytest.approx(0.3 * friction, rel=0.02)
    assert out.truth()["stands"][0]["mu_k_schedule"] == [
        [0.0, 0.25], [40.0, 0.25], [40.0, pytest.approx(0.325)]]
    plain = sim.simulate(cfg, path, scenario.Scenario((replace(stand, mu_k_schedule=None),),
                                                      0.0))
    assert "mu_k_true" not in plain.columns
