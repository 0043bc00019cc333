"""Relaxation cycles of a soft top drive (issue 22 item 5; docs/theory.md §6.4).

A PI drive with k_p at the pipe impedance ζ and an integral gain far too small to deliver the
break-away torque quickly: the string stalls while the top drive crawls below ω_c, winding it
up, then bursts free. The mean torque of such cycles is mostly static wind-up; μ_k from it
was reported converged and 21–29 % high (−15…+35 % on benchmarks/validate_soft_drive.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_batch import OMEGA_C, RPM, estimate, make_case, sample, schedule, well_string

from drillfric import torque_drag, torsional
from drillfric.config import load_config
from drillfric.drillstring import build_string
from drillfric.estimation import batch, relaxation
from drillfric.estimation.creep import smooth
from drillfric.estimation.verdict import Evidence, decide
from drillfric.io.survey import read_survey
from drillfric.result import Flag

DEMO = Path(__file__).resolve().parents[1] / "examples" / "demo"


def _impedance_Nms_rad(md_m: float) -> float:
    """ζ = J√(Gρ) of the top section [N·m·s/rad]."""
    s = well_string(md_m).sections[0]
    j = np.pi * (s.od_m ** 4 - s.id_m ** 4) / 32.0
    return float(j * np.sqrt(s.shear_modulus_Pa * s.steel_density_kg_m3))


@pytest.fixture(scope="module")
def relaxing():
    """k_p = ζ ≈ 500 N·m·s/rad, k_i = 100 N·m/rad, 40 RPM, μ_s 0.6, μ_k 0.25 at 2300 m, 200 s:
    the string stalls at ~5 RPM for ~14 s, winding up by ~4 kN·m, between bursts to ~130 RPM."""
    return make_case(0.6, 0.25, "normal", 200.0, 40.0, md_m=2300.0, cells=1000,
                     kp=_impedance_Nms_rad(2300.0), ki=100.0)


@pytest.mark.parametrize("rate_hz", [100.0, 1.0])
def test_soft_drive_relaxation_cycle_mu_k_not_false(relaxing, rate_hz):
    """Regression (issue 22 item 5): the drive replay let a relaxation cycle's μ_k through as
    converged. The fit now finds the stall (crawl below ω_c, torque winding up, a burst
    after it), flags it, and the verdict withholds μ_k as not converged, with the reason,
    even where the observer agrees and the rotation is long; no μ_s bound either."""
    string, fc, rec = relaxing
    res = estimate(string, fc, *sample(rec, rate_hz, seed=1))
    cycles = res.details.relaxation
    assert "relaxation_cycles" in res.flags and cycles is not None
    assert cycles.stalls >= 1 and cycles.stall_s >= relaxation.MIN_STALL_S
    assert 0.1 * OMEGA_C < cycles.crawl_rad_s < OMEGA_C < 40 * RPM < cycles.burst_rad_s
    assert any(m.startswith("relaxation cycles of a soft top drive") for m in res.messages)
    ev = Evidence(res.mu_k, tuple(res.flags), tuple(res.messages), 0.3, 0.5, None,
                  res.mu_k, True, (), 180.0, False)
    v = decide(ev)
    assert not v.converged and v.mu_s_lower_bound is None
    assert Flag.RELAXATION_CYCLES in v.flags


def test_ordinary_soft_torque_stick_slip_is_no_relaxation_cycle():
    """The soft-torque plant of issue 14 (k_p 900, k_i 2500: speed dips to ~0 between slips
    for a second or two) stick-slips without stalls: nothing is found, μ_k stays claimable —
    also with the crawl line at half the set-point (its dips below 30 RPM last ≤ 3 s)."""
    string, fc, rec = make_case(0.6, 0.25, "normal", 120.0, 60.0, md_m=2300.0, cells=1000,
                                kp=900.0, ki=2500.0)
    t, w, tau = sample(rec, 100.0, seed=0)
    tau_bar = smooth(tau, 0.01, 1.0)
    assert relaxation.find(t, w, tau_bar, OMEGA_C, float(np.mean(tau))) is None
    setpoint = float(np.mean(w[t > 30.0]))
    assert 0.5 * setpoint > OMEGA_C
    assert relaxation.find(t, w, tau_bar, OMEGA_C, float(np.mean(tau)), setpoint) is None


def _stall(t, crawl_rad_s, windup_Nm, start_s=40.0, end_s=80.0):
    w = np.where((t >= start_s) & (t < end_s), crawl_rad_s, 4.0)
    tau = np.where((t >= start_s) & (t < end_s), 15e3 + windup_Nm * (t - start_s)
                   / (end_s - start_s), 15e3)
    return w, tau


def test_relaxation_find_counts_only_stalls_that_wind_up_between_rotations():
    """A stall needs rotation before and after it, the top drive crawling (not at rest),
    the torque winding up by MIN_WINDUP of the mean, and MIN_STALL_S: a creep start-up from
    rest, a stop with the torque held, a flat crawl and a short dip are none."""
    t = np.arange(0.0, 120.0, 0.1)
    w, tau = _stall(t, 0.5, 15e3)
    assert relaxation.find(t, w, tau, 1.0, 16e3).stalls == 1
    w0, tau0 = _stall(t, 0.5, 15e3, start_s=0.0)  # a creep start-up
    assert relaxation.find(t, w0, tau0, 1.0, 16e3) is None
    w1, tau1 = _stall(t, 0.0, 15e3)  # stopped, the torque held
    assert relaxation.find(t, w1, tau1, 1.0, 16e3) is None
    w2, tau2 = _stall(t, 0.5, 1e3)  # crawling without winding up
    assert relaxation.find(t, w2, tau2, 1.0, 16e3) is None
    w3, tau3 = _stall(t, 0.5, 15e3, end_s=47.0)  # a 7-s dip
    assert relaxation.find(t, w3, tau3, 1.0, 16e3) is None
    w4, tau4 = _stall(t, 0.5, 15e3, end_s=130.0)  # stalled until the record ends
    assert relaxation.find(t, w4, tau4, 1.0, 16e3) is None


@pytest.fixture(scope="module")
def crawling_above_omega_c():
    """The sweep's plant (benchmarks/validate_soft_drive.py): the demo well's string at 2300 m
    (μ_s 0.6, μ_k 0.25), PI drive k_p = ζ, k_i = 300 N·m/rad, 40 RPM, 300 s. The string sticks
    for ~30 s of every ~43-s cycle while the top drive winds it up at 3–18 RPM — around
    ω_c = 9.5 RPM, never below it for 10 s — then bursts to ~190 RPM."""
    cfg = load_config(DEMO / "demo.toml")
    td = torque_drag.solve_config(cfg, read_survey(DEMO / "demo.survey.csv"), 2300.0)
    string = build_string(cfg.sections, 2300.0)
    top = string.sections[0]
    zeta = np.pi * (top.od_m ** 4 - top.id_m ** 4) / 32.0 * np.sqrt(
        top.shear_modulus_Pa * top.steel_density_kg_m3)
    grid = torsional.make_grid(string, 1000)
    plant = torsional.Plant(grid, td.fc_at(grid.x_m), 0.6, 0.25, cfg.omega_c_rad_s,
                            cfg.model.k_t_per_s, cfg.rig.top_drive_inertia_kg_m2)
    drive = torsional.Drive("pi", schedule("normal", 300.0, 40.0), 0.5, kp_Nms_rad=zeta,
                            ki_Nm_rad=300.0)
    rec, _ = torsional.run(plant, drive, 300.0, 100.0)
    return string, td.fc_at, rec, batch.BatchSettings.from_config(cfg)


@pytest.mark.parametrize("rate_hz", [100.0, 5.0, 1.0])
def test_soft_drive_ki300_crawl_above_omega_c_mu_k_not_false(crawling_above_omega_c, rate_hz):
    """Regression (issue 22 item 5, the sweep's k_p = ζ, k_i = 300 drive): its μ_k was
    reported converged and +5.8 / +32.4 / +16.6 / +8.4 % high (100 Hz / 5 Hz / 1 Hz / 1-s
    means) because the stall finder looked only for a crawl below ω_c, and this top drive
    winds the stuck string up at about ω_c. The crawl line is now the larger of ω_c and half
    the set-point (the rotation's mean speed): the stalls are found and μ_k is withheld."""
    string, fc, rec, settings = crawling_above_omega_c
    res = estimate(string, fc, *sample(rec, rate_hz, seed=1), settings=settings)
    cycles = res.details.relaxation
    assert cycles is not None and Flag.RELAXATION_CYCLES in res.flags
    assert cycles.stalls >= 4 and 20.0 < cycles.stall_s < 40.0
    assert settings.omega_c_rad_s < cycles.crawl_line_rad_s < 0.6 * 40 * RPM
    assert 0.3 * settings.omega_c_rad_s < cycles.crawl_rad_s < cycles.crawl_line_rad_s
    assert cycles.period_s is not None and 30.0 < cycles.period_s < 60.0
    ev = Evidence(res.mu_k, tuple(res.flags), tuple(res.messages), 0.3, 0.5, None,
                  res.mu_k, True, (), 240.0, False)
    assert not decide(ev).converged


def test_a_drive_fit_with_negative_gains_prints_no_gains():
    """Regression (the fourth newcomer, DSATS): "best PI speed control, k_p = -296 N·m·s/rad,
    k_i = -13.4 N·m/rad" — negative gains are no controller, and printing them reads as a
    finding. The note says no PI law fits."""
    from drillfric.estimation.drive import DriveModel

    text = DriveModel(-296.0, -13.4, 0.02).describe()
    assert "no PI speed control fits" in text and "-296" not in text
    assert "k_p = 900" in DriveModel(900.0, 2500.0, 0.01).describe()
