"""Relaxation cycles of a soft top drive (issue 22 item 5; docs/theory.md §6.4).

A PI drive with k_p at the pipe impedance ζ and an integral gain far too small to deliver the
break-away torque quickly: the string stalls while the top drive crawls below ω_c, winding it
up, then bursts free. The mean torque of such cycles is mostly static wind-up; μ_k from it
was reported converged and 21–29 % high (−15…+35 % on benchmarks/validate_soft_drive.py).
"""

from __future__ import annotations

import numpy as np
import pytest
from test_batch import OMEGA_C, RPM, estimate, make_case, sample, well_string

from drillfric.estimation import relaxation
from drillfric.estimation.creep import smooth
from drillfric.estimation.verdict import Evidence, decide
from drillfric.result import Flag


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
    for a second or two) stick-slips without stalls: nothing is found, μ_k stays claimable."""
    string, fc, rec = make_case(0.6, 0.25, "normal", 120.0, 60.0, md_m=2300.0, cells=1000,
                                kp=900.0, ki=2500.0)
    t, w, tau = sample(rec, 100.0, seed=0)
    assert relaxation.find(t, w, smooth(tau, 0.01, 1.0), OMEGA_C, float(np.mean(tau))) is None


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
