"""Top-drive inertia (issue 34 item 2, docs/theory.md §5.4): identified with its ± where the
accelerations explain the torque, contradicted beyond ±25 %, immaterial where its correction is
small, else not identified with why."""

import numpy as np
import pytest

from drillfric.estimation import inertia
from tests.conftest import REPO

T = np.arange(0.0, 120.0, 0.01)


def _top_drive(true_kg_m2, seed=1, string_noise_Nm=0.0):
    """Broadband speed changes and the motor torque of a top drive of ``true_kg_m2`` over a
    string whose torque the model knows up to ``string_noise_Nm`` of misfit."""
    rng = np.random.default_rng(seed)
    steps = np.cumsum(rng.normal(0.0, 1.0, T.size // 500 + 1)).repeat(500)[:T.size]
    kernel = np.exp(-np.arange(0, 1.0, 0.01) / 0.2)
    w = 6.0 + np.convolve(steps, kernel / kernel.sum(), mode="same")
    string = 8e3 + 300.0 * np.sin(2 * np.pi * T / 5.0)
    motor = string + true_kg_m2 * np.gradient(w, T)
    model = string + string_noise_Nm * np.sin(2 * np.pi * T / 4.3 + 1.0)
    return w, motor, model


@pytest.mark.parametrize("factor", [0.4, 1.0, 2.5])
def test_broadband_speed_changes_identify_the_inertia_within_its_tolerance(factor):
    w, motor, model = _top_drive(2900.0 * factor)
    rig = inertia.assess(T, w, motor, model, 2900.0)
    assert rig.identified_kg_m2 is not None
    assert abs(rig.identified_kg_m2 / (2900.0 * factor) - 1) <= 0.25
    assert abs(rig.identified_kg_m2 - 2900.0 * factor) <= rig.uncertainty_kg_m2 + 1e-9
    assert rig.source == ("confirmed" if factor == 1.0 else "contradicted")
    assert (rig.reason is None) == (factor == 1.0)


def test_a_gear_change_is_said_with_the_identified_value():
    w, motor, model = _top_drive(2.0 * 2900.0)
    rig = inertia.assess(T, w, motor, model, 2900.0)
    assert rig.source == "contradicted" and "against the configured 2900" in rig.reason


def test_a_model_misfit_beyond_the_accelerations_is_not_identified():
    """The misfit explains the torque's changes more than the accelerations do: no number,
    and the trace that rests on the inertia is withheld."""
    w, motor, model = _top_drive(2900.0, string_noise_Nm=2e4)
    rig = inertia.assess(T, w, motor, model, 2900.0)
    assert rig.identified_kg_m2 is None and rig.source == "not identified"
    assert rig.share >= inertia.MATERIAL_SHARE and "not identified" in rig.reason


def test_a_steady_top_drive_leaves_the_inertia_immaterial():
    w = 6.0 + 0.001 * np.sin(T)
    motor = 8e3 + 2e3 * np.sin(2 * np.pi * T / 5.0)
    rig = inertia.assess(T, w, motor, 8e3 + 0.0 * T, 2900.0)
    assert rig.source == "immaterial" and rig.reason is None and rig.share < 0.01


def test_a_string_torque_does_not_use_the_inertia():
    w, motor, model = _top_drive(5000.0)
    rig = inertia.assess(T, w, motor, model, 2900.0, torque_kind="string")
    assert rig.source == "not used" and rig.reason is None and rig.share is None


def test_a_short_segment_says_nothing():
    t = T[:300]
    rig = inertia.assess(t, 6.0 + np.sin(t), 8e3 + np.cos(t), 8e3 + 0 * t, 2900.0)
    assert rig.source == "immaterial" and rig.identified_kg_m2 is None


@pytest.mark.slow
def test_a_gear_change_between_stands_withholds_the_trace_that_rests_on_it(tmp_path):
    """End to end (issue 34 item 2): the configured 2900 kg·m², a stiff-drive stick-slip
    stand at that inertia and a stand of set-point steps after a gear change to 2.5×. The
    first stand's trace does not rest on the inertia (share < 0.2) and is shown; the second
    one's does and the data do not identify it: trace and statistics withheld with the flag;
    μ_k stands in both."""
    import tomllib
    from pathlib import Path

    import drillfric
    from drillfric.io.writers import dumps_toml

    demo = Path(__file__).resolve().parents[1] / "examples" / "demo"
    steps = [[0, 0], [3, 0], [3, 60], [80, 60], [80, 90], [140, 90], [140, 50], [200, 50]]
    (tmp_path / "stands.toml").write_text(dumps_toml({"stand": [
        {"bit_depth_m": 2300.0, "duration_s": 200.0, "start": "creep", "creep_hold_s": 60.0},
        {"bit_depth_m": 2330.0, "duration_s": 200.0, "setpoint_rpm": steps,
         "top_drive_inertia_kg_m2": 2.5 * 2900.0}]}), encoding="utf-8")
    cfg = tomllib.loads((demo / "demo.toml").read_text(encoding="utf-8"))
    cfg["simulate"].update(scenario="stands.toml", rate_hz=10.0, cells=1000, mu_s=0.6,
                           mu_k=0.25)
    cfg["survey"] = {"file": str(demo / "demo.survey.csv")}
    (tmp_path / "sim.toml").write_text(dumps_toml(cfg), encoding="utf-8")
    data = tmp_path / "well.parquet"
    drillfric.simulate(tmp_path / "sim.toml", out=data)
    result = drillfric.run(drillfric.open_well(data))
    segs = [g for g in result.summary["segments"] if g["status"] == "ok"]
    assert len(segs) == 2
    stiff, geared = segs
    assert stiff["top_drive_inertia_source"] == "immaterial" and stiff["bit_speed_resolved"]
    assert geared["top_drive_inertia_source"] == "not identified"
    assert "top_drive_inertia_unconfirmed" in geared["quality_flags"]
    assert not geared["bit_speed_resolved"] and geared["stick_slip_severity"] is None
    assert "top-drive inertia not identified" in geared["message"]
    for seg in segs:
        assert seg["mu_k"] == pytest.approx(0.25, rel=0.05)


# ------------------------------------- the stick-slip onset bound and an unknown gear
def test_a_swing_made_by_the_inertia_subtracted_is_no_stick_slip():
    """A motor torque's swing that rests on the top-drive inertia taken off it: with the
    inertia 0.4–2.5× the configured (a gear change) it ranges from ~0 to beyond the 0.1
    stick-slip line, so it is no evidence of stick-slip; a string torque's has one value."""
    from drillfric.estimation.batch import harness
    from drillfric.estimation.batch.settings import GEAR_RANGE, STICK_SLIP_FLUCTUATION

    t = np.arange(0.0, 200.0, 0.1)
    inertia_part = 1.5e3 * np.sin(2 * np.pi * t / 5.0)  # I·dω/dt taken off [N·m]
    string = 1e4 + 0.1 * inertia_part  # what remains once the inertia is taken off
    still = np.zeros_like(t)
    data = harness.FitData(t=t, dt=0.1, drive=still, motor=still, creep_drive=still,
                           w_bar=still, tau=string, tau_bar=string, speed=still,
                           inertia_bar=inertia_part)
    used = np.arange(t.size)
    low, high = harness.fluctuation_range(data, used, GEAR_RANGE)
    assert low < STICK_SLIP_FLUCTUATION < high
    flat = harness.FitData(**{**data.__dict__, "inertia_bar": None})
    value = harness.fluctuation(string)
    assert harness.fluctuation_range(flat, used, GEAR_RANGE) == (value, value)


@pytest.mark.slow
def test_a_heavier_gear_under_set_point_steps_gives_no_false_mu_s_bound(tmp_path):
    """The second plant family (benchmarks/plants/lumped.py, 3000 m, μ_s = μ_k: no
    stick-slip) under set-point steps 0 → 60 → 90 → 50 → 70 RPM with a top drive of 2.5×
    the configured 2900 kg·m², its motor torque logged at 10 Hz: the inertia subtracted
    left a swing of 0.13 of the mean, read as stick-slip, and the onset scan bounded μ_s
    ≥ 0.19 over a true (effective) 0.157 — a false number (issue 34's sweeps on the second
    family). No bound is given now, with the reason; μ_k stays within 5 %."""
    import sys

    sys.path.insert(0, str(REPO / "benchmarks"))
    import validate_lumped as VL
    import validate_lumped_departures as D

    import drillfric

    cols, case, survey, string = D.simulate("steps", 2.5)
    cfg = D.configure(tmp_path, case, survey, "inertia")
    truth = case.mu_k * string.T_N_Nm / VL.drillfric_td(cfg, case.depth_m).T_N_Nm
    data = tmp_path / "log.parquet"
    D.logged(cols, "10 Hz", "inertia", 2.5).to_parquet(data, index=False)
    result = drillfric.run(drillfric.open_well(data, config=cfg,
                                               survey=tmp_path / "path.survey.csv"))
    segs = [g for g in result.summary["segments"] if g["status"] == "ok"]
    assert segs and all(g["mu_s_lower_bound"] is None for g in segs)
    assert any("no μ_s bound from the stick-slip onset" in g["message"] for g in segs)
    assert result.summary["mu_k"] == pytest.approx(truth, rel=0.05)
