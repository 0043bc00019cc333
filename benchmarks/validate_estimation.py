"""Validation table of the friction estimators (issue 5 acceptance; docs/validation.md).

Truths × start-up (creep or not) × logging rate × estimator → estimates and errors.
Plants differ from the estimators: truths on 1.6 cells per metre (4000 at 2500 m) against
500 cells for μ_k and ≈ MD/500 for creep fits, a two-section BHA, noise 0.5 RPM and 200 N·m.
A truth coarser than the creep fit's grid is itself grid-biased in its creep build-up (a
1500-cell truth at 2500 m gave halves 0.521 / 0.592 for one μ_s = 0.6: not one friction
factor on the model's grid), so the truths are finer than every estimator grid.
Estimators: the full chain (`estimate_segment`: observer from
4 starts spanning μ_s 0.2–0.9, μ_k 0.05–0.4 → batch → seeded observer), and the observer
alone with the paper's printed laws (backstepping gains, eqs. 42–43) from the same starts.

Run: ``python benchmarks/validate_estimation.py`` (its table is in docs/validation.md)
(about 5–10 minutes on one core).
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from drillfric import torque_drag, torsional  # noqa: E402
from drillfric.drillstring import build_string  # noqa: E402
from drillfric.estimation.chain import SegmentData, build_observer, estimate_segment  # noqa: E402
from drillfric.estimation.observer import Measurements, ObserverState, observe  # noqa: E402
from drillfric.estimation.settings import ChainSettings  # noqa: E402
from tests.synthetic import RPM, build_and_hold, config, noisy  # noqa: E402

STARTS = [[0.2, 0.05], [0.5, 0.2], [0.9, 0.4], [0.9, 0.1]]
#: (name, μ_s, μ_k, bit depth [m], path, rpm)
TRUTHS = [
    ("paper 5.1", 0.6, 0.187, 2500.0, build_and_hold(1500.0, 60.0, 2500.0), 60.0),
    ("shallow", 0.35, 0.25, 1600.0, build_and_hold(600.0, 40.0, 1600.0), 80.0),
    ("deep", 0.5, 0.3, 3200.0, build_and_hold(1200.0, 55.0, 3200.0), 50.0),
    ("sticky", 0.8, 0.3, 2000.0, build_and_hold(800.0, 45.0, 2000.0), 40.0),
]
RATES = (100.0, 5.0, 1.0)
DURATION_S = 240.0
#: Truth grid [cells/m]: finer than the creep fit's doubled MD/1000 grid (docs/validation.md).
TRUTH_CELLS_PER_M = 1.6


def record(mu_s, mu_k, depth, path, rpm, creep, cfg):
    string = build_string(cfg.sections, depth)
    td = torque_drag.solve(path, string, load_case="rotating_off_bottom", mud_out_kg_m3=1200.0)
    grid = torsional.make_grid(string, max(1500, int(TRUTH_CELLS_PER_M * depth)))
    plant = torsional.Plant(grid, td.fc_at(grid.x_m), mu_s, mu_k, 1.0, 0.1, 2900.0)
    t = np.arange(0.0, DURATION_S + 1.0, 0.05)
    knots = ([0, 5, 35, 45, DURATION_S + 1], [0, 5, 5, rpm, rpm]) if creep else \
        ([0, 10, DURATION_S + 1], [0, rpm, rpm])
    drive = torsional.Drive("pi", np.interp(t, *knots) * RPM, 0.05)
    rec, _ = torsional.run(plant, drive, DURATION_S, 100.0)
    return rec


def paper_observer(cfg_paper, data: SegmentData, path):
    """The observer alone with the printed laws and backstepping gains."""
    settings = replace(ChainSettings.from_config(cfg_paper), cells=500)
    string = settings.td.string(data.bit_depth_m)
    td = settings.td.solve(path, data.bit_depth_m)
    obs = build_observer(settings, string, td)
    meas = Measurements.from_samples(data.time_s, data.surface_rpm * RPM,
                                     data.surface_torque_Nm)
    out, _ = observe(obs, meas, ObserverState.from_starts(obs, STARTS))
    late = out.time_s > out.time_s[-1] - 60.0
    return out.mu_k[late].mean(axis=0), out.mu_s[late].mean(axis=0)


def main() -> None:
    cfg = config(observer={"starts": STARTS})
    settings = ChainSettings.from_config(cfg)
    cfg_paper = config(gains="backstepping", observer={"law": "paper"})
    print("| truth | μ_s/μ_k | start-up | rate | μ_k chain (err) | μ_k observer starts "
          "(worst err) | μ_s chain | μ_s bound | bit RMS err [RPM] | severity | paper laws "
          "μ_k (worst err) | paper μ_s range | time [s] |")
    print("|" + "---|" * 13)
    for name, mu_s, mu_k, depth, path, rpm in TRUTHS:
        for creep in (True, False):
            rec = record(mu_s, mu_k, depth, path, rpm, creep, cfg)
            w, q = noisy(rec, seed=int(depth))
            for rate in RATES:
                k = int(round(100.0 / rate))
                data = SegmentData(rec.time_s[::k], w[::k] / RPM, q[::k], depth,
                                   bit_rpm=rec.bit_rad_s[::k] / RPM)
                t0 = time.perf_counter()
                est = estimate_segment(settings, path, data)
                wall = time.perf_counter() - t0
                tail = est.first.time_s > est.first.time_s[-1] - 60.0
                obs_k = est.first.mu_k[tail].mean(axis=0)
                pk, ps = paper_observer(cfg_paper, data, path)
                err = lambda v, truth=mu_k: 100.0 * (v / truth - 1.0)  # noqa: E731
                mu_s_txt = "—" if est.mu_s is None else \
                    f"{est.mu_s:.3f} ({100 * (est.mu_s / mu_s - 1):+.1f} %)"
                bound = "—" if est.mu_s_lower_bound is None else f"{est.mu_s_lower_bound:.2f}"
                print(f"| {name} | {mu_s}/{mu_k} | {'creep' if creep else 'ramp'} | {rate:g} Hz"
                      f" | {est.mu_k:.4f} ({err(est.mu_k):+.1f} %) | "
                      f"{obs_k.min():.3f}–{obs_k.max():.3f} "
                      f"({max(abs(err(obs_k.min())), abs(err(obs_k.max()))):.0f} %) | "
                      f"{mu_s_txt} | {bound} | {est.bit_rms_error_rpm:.1f} | "
                      f"{est.stick_slip_severity:.2f} | {pk.min():.3f}–{pk.max():.3f} "
                      f"({max(abs(err(pk.min())), abs(err(pk.max()))):.0f} %) | "
                      f"{ps.min():.2f}–{ps.max():.2f} | {wall:.1f} |", flush=True)


if __name__ == "__main__":
    main()
