"""Viscous damping: heavy and light mud (issue 34 item 3; docs/validation.md "Viscous
damping").

drillfric's simulator (the demo well, a stand at 2300 m, μ_k 0.25) runs with a true viscous
damping rate k_t of 0.3, 1 and 3× the 0.1 1/s the estimator is configured with, on two
plants — ``steady`` (μ_s = μ_k: no stick-slip) and ``step`` (μ_s 0.6: stick-slip at low
speed) — and two stands: ``set-points`` (60, 120 and 90 RPM, 120 s each: the viscous slope
is identifiable where the rotation is steady) and ``one set-point`` (120 RPM: it is not),
logged at 100, 10, 5 and 1 Hz and as 1-s means. The channels are stated in step (the demo's
``[channels] lag_s = 0``). The second plant family (benchmarks/plants/lumped.py: a lumped
string at 3000 m, μ_s = μ_k, its own mass-proportional drag κ·I_i) runs the same stands
with κ = 0.3, 1 and 3× the configured k_t, graded against its effective truths
(μ_k·T_N,plant/T_N,drillfric and κ·J_plant/J_drillfric). Every record runs through the
whole pipeline (:func:`drillfric.run`) and is graded:

- a segment's identified k_t (``k_t_identified_per_s``) within ±30 % of the truth, or "not
  identified" (a stated value outside is false);
- the well's μ_k: its stated ± (``mu_k_uncertainty``, which carries the damping where it is
  not identified) covering 0.25, or without a ± within its tolerance (5 % at ≤ 0.2 s, 10 %
  at coarser logging), or withheld; the table also counts those within the tolerance.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/validate_damping.py [--quick] [--json FILE]``
(``--quick``: 10 Hz and 1-s means).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from validate_lumped import logged  # noqa: E402
from validate_skew import record  # noqa: E402
from validate_trust import PLANTS, _config  # noqa: E402

import drillfric  # noqa: E402
from drillfric.estimation.batch.settings import mu_k_tolerance  # noqa: E402
from drillfric.io.writers import dumps_toml  # noqa: E402

RATES = ("100 Hz", "10 Hz", "5 Hz", "1 Hz", "1-s means")
#: The estimator's configured damping (the demo's) [1/s] and the plants' multiples of it.
CONFIGURED, FACTORS = 0.1, (0.3, 1.0, 3.0)
MU_K, K_T_TOL = 0.25, 0.30
STANDS = {
    "set-points": {"bit_depth_m": 2300.0, "start": "ramp", "duration_s": 380.0,
                   "setpoint_rpm": [[0, 0], [3, 0], [13, 60], [130, 60], [135, 120],
                                    [250, 120], [255, 90], [380, 90]]},
    "one set-point": {"bit_depth_m": 2300.0, "start": "ramp", "duration_s": 300.0,
                      "rpm": 120.0},
}


def simulate(plant: str, stand: str, factor: float, folder: Path) -> tuple[pd.DataFrame, Path]:
    """The 100-Hz simulation with the plant's damping ``factor``× the configured, and the
    estimator's configuration (k_t as configured)."""
    folder.mkdir(parents=True)
    sim, model, notes = PLANTS[plant]
    sim = {k: v for k, v in sim.items() if k != "rpm"}
    sim_cfg, est_cfg = _config(folder, plant, (sim, model, notes), STANDS[stand])
    raw = tomllib.loads(sim_cfg.read_text(encoding="utf-8"))
    raw["model"]["k_t_per_s"] = factor * CONFIGURED
    sim_cfg.write_text(dumps_toml(raw), encoding="utf-8")
    return pd.DataFrame(drillfric.simulate(sim_cfg).columns), est_cfg


def lumped(stand: str, factor: float, folder: Path) -> tuple[dict, Path, dict]:
    """The second plant family (benchmarks/plants/lumped.py, 3000 m, μ_s = μ_k = 0.25:
    steady) with the viscous drag rate κ = ``factor``× the configured k_t, on the stand's
    set-points: its 100-Hz columns, drillfric's configuration and the effective truths
    (μ_k·T_N,plant/T_N,drillfric; κ·J_plant/J_drillfric, the plant's string inertia
    holding its tool joints)."""
    import validate_lumped as VL

    from benchmarks.plants import lumped as L
    from drillfric.config import load_config
    from drillfric.drillstring import build_string

    folder.mkdir(parents=True)
    case = VL.Case(3000.0, MU_K, 1.0)
    survey, string = VL.well(case)
    spec = STANDS[stand]
    knots = tuple((float(a), float(b)) for a, b in spec["setpoint_rpm"]) + (
        (spec["duration_s"] + 5.0, 0.0), (spec["duration_s"] + 15.0, 0.0)) \
        if "setpoint_rpm" in spec else L.setpoint(spec["rpm"], spec["duration_s"])
    rec = L.simulate(string, L.Drive(knots, 2900.0, case.kp, case.ki),
                     L.Friction(MU_K, MU_K, omega_switch_rad_s=VL.OMEGA_C,
                                viscous_rate_per_s=factor * CONFIGURED),
                     knots[-1][0], rate_hz=100.0,
                     noise=L.Noise(rpm_sd=0.5, torque_sd_Nm=200.0, hookload_sd_N=2000.0,
                                   seed=1))
    cfg = VL.write_config(folder, case, survey)
    td = VL.drillfric_td(cfg, case.depth_m)
    inertia_df = build_string(load_config(cfg).sections, case.depth_m).polar_mass_moment_kg_m2
    truth = {"mu_k": MU_K * string.T_N_Nm / td.T_N_Nm,
             "k_t": factor * CONFIGURED * float(np.sum(string.inertia_kg_m2)) / inertia_df}
    return rec.columns, cfg, truth


def grade(result, rate: str, factor: float, truth: dict | None = None) -> dict:
    """The record's identified k_t and μ_k against the truth (``truth``: the lumped
    family's effective ``mu_k`` and ``k_t``)."""
    s = result.summary
    segs = [g for g in s["segments"] if g["status"] == "ok"]
    stated = [g["k_t_identified_per_s"] for g in segs
              if g.get("k_t_identified_per_s") is not None]
    truth = truth or {"mu_k": MU_K, "k_t": factor * CONFIGURED}
    k_t_ok = all(abs(v / truth["k_t"] - 1.0) <= K_T_TOL for v in stated)
    interval = 0.01 if rate == "100 Hz" else (1.0 if rate in ("1 Hz", "1-s means") else 0.2)
    tol = mu_k_tolerance(interval)
    mu_k, u = s["mu_k"], s.get("mu_k_uncertainty")
    within = mu_k is None or abs(mu_k / truth["mu_k"] - 1.0) <= tol
    covered = None if mu_k is None or u is None else abs(mu_k - truth["mu_k"]) <= u
    # a μ_k is false outside its stated ± (which carries the damping not identified), or
    # outside the tolerance where it states none
    mu_ok = covered if covered is not None else within
    return {"k_t_stated": stated, "k_t_truth": truth["k_t"], "mu_k_truth": truth["mu_k"],
            "k_t_ok": k_t_ok, "mu_k": mu_k, "mu_k_u": u,
            "mu_k_within": within, "covered": covered, "false": not (k_t_ok and mu_ok)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    rates = ("10 Hz", "1-s means") if args.quick else RATES
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for plant in ("steady", "step"):
            for stand in STANDS:
                for factor in FACTORS:
                    folder = Path(tmp) / f"{plant}_{stand.replace(' ', '_')}_{factor}"
                    frame, est_cfg = simulate(plant, stand, factor, folder)
                    for rate in rates:
                        data = folder / f"{rate.replace(' ', '_')}.parquet"
                        record(frame, rate, 0.0).to_parquet(data, index=False)
                        t0 = time.perf_counter()
                        result = drillfric.run(drillfric.open_well(
                            data, config=est_cfg, survey=folder / "path.survey.csv"))
                        row = {"plant": plant, "stand": stand, "rate": rate,
                               "factor": factor, **grade(result, rate, factor),
                               "run_s": time.perf_counter() - t0}
                        rows.append(row)
                        print(_line(row), flush=True)
        for stand in STANDS:
            for factor in FACTORS:
                folder = Path(tmp) / f"lumped_{stand.replace(' ', '_')}_{factor}"
                cols, cfg, truth = lumped(stand, factor, folder)
                for rate in rates:
                    data = folder / f"{rate.replace(' ', '_')}.parquet"
                    logged(cols, rate).to_parquet(data, index=False)
                    t0 = time.perf_counter()
                    result = drillfric.run(drillfric.open_well(
                        data, config=cfg, survey=folder / "path.survey.csv"))
                    row = {"plant": "lumped", "stand": stand, "rate": rate, "factor": factor,
                           **grade(result, rate, factor, truth),
                           "run_s": time.perf_counter() - t0}
                    rows.append(row)
                    print(_line(row), flush=True)
    print(f"\n{len(rows)} records, {sum(r['false'] for r in rows)} with a false number")
    print("\n" + table(rows))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1, default=float), encoding="utf-8")


def table(rows: list[dict]) -> str:
    """The docs/validation.md table: one line per plant, stand and damping over the rates."""
    out = ["| plant | stand | k_t (truth) | k_t identified (rates) | μ_k (truth) | "
           "within tolerance | ± covers | false |", "|---|---|---|---|---|---|---|---|"]
    keys = dict.fromkeys((r["plant"], r["stand"], r["factor"]) for r in rows)
    for plant, stand, factor in keys:
        group = [r for r in rows if (r["plant"], r["stand"], r["factor"]) == (plant, stand,
                                                                              factor)]
        ks = [v for r in group for v in r["k_t_stated"]]
        ident = (f"{min(ks):.3f}–{max(ks):.3f} ({sum(bool(r['k_t_stated']) for r in group)} "
                 f"of {len(group)})" if ks else f"not identified (0 of {len(group)})")
        mus = [r["mu_k"] for r in group if r["mu_k"] is not None]
        mu = (f"{min(mus):.3f}–{max(mus):.3f}" if mus else "—") + (
            f", {len(group) - len(mus)} withheld" if len(mus) < len(group) else "")
        cov = [r["covered"] for r in group if r["covered"] is not None]
        within = sum(r["mu_k"] is not None and r["mu_k_within"] for r in group)
        truth = f"{group[0]['k_t_truth']:.3f}"
        mu += f" ({group[0]['mu_k_truth']:.3f})"
        out.append(f"| {plant} | {stand} | {truth} | {ident} | {mu} | "
                   f"{within} of {len(mus)} | {sum(cov)} of {len(cov)} | "
                   f"{sum(r['false'] for r in group)} |")
    return "\n".join(out)


def _line(r: dict) -> str:
    mu = "—" if r["mu_k"] is None else f"{r['mu_k']:.4f} ± {r['mu_k_u'] or 0:.4f}"
    ks = ", ".join(f"{v:.3f}" for v in r["k_t_stated"]) or "not identified"
    return (f"{r['plant']:<7} {r['stand']:<14} k_t {r['k_t_truth']:.3f} "
            f"{r['rate']:<9} → k_t {ks}; μ_k {mu} {'FALSE' if r['false'] else 'ok'} "
            f"({r['run_s']:.1f} s)")


if __name__ == "__main__":
    main()
