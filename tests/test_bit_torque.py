"""The bit torque on bottom from the off-bottom friction nearby, and the friction log of a
drilling record (issue 22 item 1; docs/theory.md §2.3)."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from drillfric.estimation.bit_torque import assess, mu_bit, teale_mse_Pa
from drillfric.estimation.consensus import mean_half_width, pool_short_segments
from drillfric.result import Flag, SegmentRecord
from drillfric.torsional import bit_torque_cap
from drillfric.vocabulary import Kind, Method, Status

REPO = __import__("pathlib").Path(__file__).resolve().parents[1]


def _off(i, depth, mu_k, T_N, duration=50.0, converged=False, interval=0.01):
    flags = () if converged else (Flag.TOO_SHORT_TO_CONVERGE,)
    return SegmentRecord(id=i, kind=Kind.OFF_BOTTOM, status=Status.OK, mu_k=mu_k,
                         bit_depth_m=depth, duration_s=duration, converged=converged,
                         method=Method.BATCH, quality_flags=flags, T_N_Nm=T_N,
                         sample_interval_s=interval)


def _on(i, depth, torque, per_mu=45e3, fixed=300.0, sem=50.0, wob=100e3, rop=20.0, rpm=60.0):
    return SegmentRecord(id=i, kind=Kind.ON_BOTTOM, status=Status.OK, mu_k=0.3,
                         bit_depth_m=depth, duration_s=150.0, converged=True,
                         method=Method.BATCH, surface_torque_turning_Nm=torque,
                         torque_per_mu_Nm=per_mu, torque_fixed_Nm=fixed,
                         surface_torque_sem_Nm=sem, wob_N=wob, rop_m_h=rop,
                         surface_rpm_mean=rpm, T_N_Nm=0.9 * per_mu)


def _drilling_pieces(mu=(0.250, 0.246, 0.238, 0.245, 0.244)):
    """Five 50-s off-bottom rotations 28 m apart, T_N growing 2 % per stand (the demo well
    at 2150–2260 m), μ_k scattered by ~2 % as the batch fit's short pieces are at 1 Hz
    (true 0.25; docs/validation.md)."""
    return [_off(2 * k + 2, 2146.0 + 28.0 * k, m, 52.2e3 * (1 + 0.021 * k))
            for k, m in enumerate(mu)]


def test_short_rotations_a_stand_apart_pool_into_a_friction_log():
    """Regression (issue 22): pooling stopped at 5 m of depth while stands are ~28 m apart,
    so a drilling log's 40–70 s off-bottom rotations gave no μ_k at all. Pieces within 10 %
    of the string's friction torque pool; their mean's 95 % half-width (2.2 % here) is within
    the 5 % tolerance."""
    records, pools = pool_short_segments(_drilling_pieces())
    assert len(pools) == 1 and pools[0]["segment_ids"] == [2, 4, 6, 8, 10]
    assert pools[0]["mu_k"] == pytest.approx(0.2446, abs=1e-3)
    assert (pools[0]["md_from_m"], pools[0]["md_to_m"]) == (2146.0, 2258.0)
    assert all(Flag.POOLED in r.quality_flags for r in records)


def test_pool_of_few_pieces_states_students_t_half_width():
    """Regression: the half-width of a pool's mean was 1.96·sd/√n, which understates it for
    3–5 pieces (their sd is itself uncertain). Five pieces scattering by 5 % (sd 0.0126) have
    t₀.₉₇₅,₄·sd/√5 = 6.3 % > 5 %: not pooled (1.96 said 4.5 %); three pieces logged at 1 Hz
    pool when t₀.₉₇₅,₂·sd/√3 is within their 10 %, and the friction log states that 10 %."""
    assert pool_short_segments(_drilling_pieces((0.262, 0.246, 0.227, 0.245, 0.243)))[1] == []
    three = [_off(2 * k + 2, 2146.0 + 28.0 * k, m, 52.2e3 * (1 + 0.021 * k), interval=1.0)
             for k, m in enumerate((0.259, 0.266, 0.251))]
    records, pools = pool_short_segments(three)
    [entry] = assess(records, pools, None)[1]
    half = mean_half_width(np.array([0.259, 0.266, 0.251]))
    assert half == pytest.approx(4.303 * 0.0075 / np.sqrt(3), rel=1e-3)
    assert entry["mu_k_uncertainty"] == pytest.approx(0.10 * entry["mu_k"])
    assert entry["mu_k_uncertainty"] > half


def test_pieces_too_far_apart_in_friction_torque_or_too_scattered_do_not_pool():
    far = [_off(1, 1500.0, 0.25, 30e3), _off(2, 2300.0, 0.25, 50e3)]
    scattered = _drilling_pieces((0.20, 0.30, 0.22, 0.28, 0.25))
    for records in (far, scattered):
        assert pool_short_segments(records)[1] == []


def test_bit_torque_is_the_on_bottom_torque_minus_the_model_off_bottom_torque():
    """T_bit = T_on − (μ_k·torque_per_mu + fixed); its 95 % half-width from μ_k's (the
    pool's tolerance, 5 % at 100 Hz) and the torque's standard error; μ_bit and Teale's MSE
    from it, inverting the simulator's bit law."""
    pieces = _drilling_pieces()
    t_bit = bit_torque_cap(0.3, 100e3, 0.2159)
    mu = 0.2446
    on = _on(1, 2150.0, t_bit + mu * 45e3 + 300.0)
    records, pools = pool_short_segments(pieces + [on])
    records, log = assess(records, pools, 0.2159)
    got = records[-1]
    assert got.bit_torque_Nm == pytest.approx(t_bit, rel=1e-3)
    u_mu = 0.05 * mu
    assert got.bit_torque_mu_k_uncertainty == pytest.approx(u_mu, rel=1e-3)
    assert got.bit_torque_uncertainty_Nm == pytest.approx(np.hypot(u_mu * 45e3, 1.96 * 50.0),
                                                          rel=1e-3)
    assert got.bit_torque_evidence == (2, 4, 6, 8, 10)
    assert got.mu_bit == pytest.approx(0.3, rel=1e-3)
    assert got.mu_bit_uncertainty == pytest.approx(
        mu_bit(got.bit_torque_uncertainty_Nm, 100e3, 0.2159))
    assert got.mse_Pa == pytest.approx(teale_mse_Pa(100e3, t_bit, 60.0, 20.0, 0.2159), rel=1e-3)
    assert got.bit_torque_reason is None
    assert len(log) == 1 and log[0]["segment_ids"] == [2, 4, 6, 8, 10]


def test_on_bottom_segment_without_off_bottom_rotation_nearby_says_so():
    """Drilling 400 m below the last off-bottom rotation (far beyond 10 % of the friction
    torque): no number, the reason instead."""
    pieces = _drilling_pieces()
    on = _on(1, 2660.0, 15e3)
    records, _ = assess(*pool_short_segments(pieces + [on]), 0.2159)
    got = records[-1]
    assert got.bit_torque_Nm is None and got.mu_bit is None and got.mse_Pa is None
    assert got.bit_torque_reason.startswith("no off-bottom μ_k within reach")


def test_without_bit_diameter_or_rop_the_bit_torque_stands_alone():
    pieces = _drilling_pieces()
    records, _ = assess(*pool_short_segments(pieces + [_on(1, 2150.0, 14e3)]), None)
    assert records[-1].bit_torque_Nm is not None and records[-1].mu_bit is None
    assert "well.bit_diameter_m" in records[-1].bit_torque_reason
    records, _ = assess(*pool_short_segments(pieces + [_on(1, 2150.0, 14e3, rop=None)]),
                        0.2159)
    assert records[-1].mu_bit is not None and records[-1].mse_Pa is None
    assert "rate of penetration" in records[-1].bit_torque_reason


def test_on_bottom_torque_below_the_model_is_withheld_not_negative():
    pieces = _drilling_pieces()
    records, _ = assess(*pool_short_segments(pieces + [_on(1, 2150.0, 8e3)]), 0.2159)
    assert records[-1].bit_torque_Nm is None
    assert "below the modelled off-bottom torque" in records[-1].bit_torque_reason


# ------------------------------------------------------------------ end to end
def _drilling_well(tmp_path, rotation_s: float):
    """The demo string and path drilling three stands (on bottom 120 s, 10 t, μ_bit 0.5,
    ROP 20 m/h; then ``rotation_s`` off bottom), 60 RPM, logged at 10 Hz with noise."""
    from drillfric.io.writers import dumps_toml

    demo = REPO / "examples" / "demo"
    raw = tomllib.loads((demo / "demo.toml").read_text(encoding="utf-8"))
    (tmp_path / "demo.survey.csv").write_bytes((demo / "demo.survey.csv").read_bytes())
    raw["well"] = {"name": "drilling", "bit_diameter_m": 0.2159}
    raw["simulate"].update(scenario="stands.toml", mu_s=0.6, mu_k=0.25, bit_mu=0.5,
                           bit_diameter_m=0.2159, rate_hz=10.0, cells=1000, seed=3)
    stands, depth = [], 2180.0
    for _ in range(3):
        stands.append({"bit_depth_m": depth, "wob_N": 98.1e3, "rop_m_h": 20.0,
                       "duration_s": 120.0})
        stands.append({"bit_depth_m": depth + 20.0 * 120 / 3600 - 5.0,
                       "duration_s": rotation_s})
        depth += 28.0
    (tmp_path / "stands.toml").write_text(dumps_toml(
        {"connection_s": 30.0, "defaults": {"rpm": 60.0}, "stand": stands}), encoding="utf-8")
    (tmp_path / "drilling.toml").write_text(dumps_toml(raw), encoding="utf-8")
    return tmp_path / "drilling.toml"


def test_drilling_only_log_gives_a_friction_factor_per_few_stands(tmp_path):
    """Regression (issue 22 item 1): a drilling log, its off-bottom rotations all under the
    90 s one segment needs, gave no μ_k and left the bit torque inside an apparent μ. Now
    the three 60-s rotations a stand apart pool into one friction-log entry (within 5 %)
    and every on-bottom segment reports T_bit within 20 % of the plant's or within its
    stated half-width."""
    import drillfric

    config = _drilling_well(tmp_path, 60.0)
    data = tmp_path / "drilling.parquet"
    drillfric.simulate(config, out=data)
    summary = drillfric.run(drillfric.open_well(data)).summary
    log = summary["off_bottom_friction_log"]
    assert len(log) == 1 and len(log[0]["segment_ids"]) == 3
    assert log[0]["mu_k"] == pytest.approx(0.25, rel=0.05)
    assert summary["mu_k"] == pytest.approx(0.25, rel=0.05)
    truth = bit_torque_cap(0.5, 98.1e3, 0.2159)
    on = [g for g in summary["segments"] if g["kind"] == "on_bottom_rotating"
          and g["status"] == "ok"]
    assert len(on) == 3
    for g in on:
        err = abs(g["bit_torque_Nm"] - truth)
        assert err <= max(0.2 * truth, g["bit_torque_uncertainty_Nm"]), g
        assert g["mu_bit"] == pytest.approx(0.5, abs=max(0.1, g["mu_bit_uncertainty"]))
        assert g["mse_Pa"] > 0 and g["rop_m_h"] == pytest.approx(20.0, rel=0.05)
