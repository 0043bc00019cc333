"""μ_k's interval carries the viscous damping it assumes (issue 34 item 3, docs/theory.md §6.4
"The damping assumed")."""

from __future__ import annotations

import re

import numpy as np
import pytest

from drillfric.estimation.chain import SegmentData, estimate_segment
from drillfric.estimation.settings import ChainSettings
from tests.synthetic import build_and_hold, config, noisy, simulate

RPM = np.pi / 30.0


@pytest.mark.slow
def test_heavy_mud_three_times_the_damping_is_inside_mu_k_interval():
    """Heavy mud: the plant's viscous damping is 3× the configured k_t (steady rotation at
    120 RPM, 2000 m, μ_k 0.25, 10 Hz). The extra damping is read as friction — μ_k ≈ 10 %
    high, twice the validated 5 % tolerance, which had excluded the truth — so the stated
    95 % half-width carries (f − 1)·k_t·J·ω̄/T_N with f = 3 (model.k_t_uncertainty_factor)
    in quadrature with the tolerance, and holds the truth. With f = 1 (k_t trusted) the
    interval is the tolerance alone and misses it: the term is what covers."""
    path = build_and_hold(800.0, 45.0, 2000.0)
    case = simulate(path, 2000.0, 0.25, 0.25, 120.0, 150.0, cells=400, rate_hz=10.0,
                    cfg=config(cells=200, k_t_per_s=0.3))
    w, q = noisy(case.record)
    data = SegmentData(case.record.time_s, w / RPM, q, 2000.0)
    for factor, covers in ((3.0, True), (1.0, False)):
        est = estimate_segment(ChainSettings.from_config(
            config(cells=200, k_t_uncertainty_factor=factor)), path, data)
        note = next(m for m in est.messages if "(95 %" in m)
        half = float(re.search(r"± ([0-9.]+) \(95 %", note).group(1))
        assert est.converged and est.mu_k > 0.25 * 1.05  # the damping read as friction
        assert (abs(est.mu_k - 0.25) <= half) is covers, (factor, est.mu_k, half, note)
    assert est.mu_k_damping == 0.0  # f = 1: no term
