"""Mud motors declared and undeclared (issue 34 item 5): no false bit speed, stick-slip
statistic or MSE.

The demo well (examples/demo) is simulated with a positive displacement motor in its BHA,
k = 0.03, 0.1 and 0.3 rev/L at flows that turn it at 90–180 RPM without load, its speed
falling linearly with the bit torque (stall torque 5× the bit's: 20 % slower on bottom,
docs/theory.md eq. 2.4b). Three stands: off bottom with the pumps on, on bottom (60 kN WOB,
15 m/h) with the pumps on, off bottom with the pumps off. The 100-Hz record is logged at
100, 10, 5 and 1 Hz (spot values) and as 1-s means, and run with the motor declared
(``[bha] motor_rev_per_litre``) and undeclared. Graded:

* bit speed, 30-s windows of every trace shown: the window's mean within max(2 RPM, 5 %) of
  the truth's at the same rows, or the truth inside the window's mean band. The truth is
  the bit's (BHA + motor) — except for a trace that says it is the string's bottom speed
  (``bit_speed_reason``, the undeclared run with the pumps on), graded against the BHA's;
* stick-slip statistics against the BHA's truth (docs/bit_speed.md: stuck ±0.05,
  severity ±12 %);
* MSE against Teale's with the plant's bit power torque and the bit's true mean speed
  (the surface's where the segment says the MSE takes the string's speed): false when
  outside its stated 95 % half-width.

``false_as_bit`` and ``mse_false_as_bit`` count the windows and MSEs that would be false
were they read as the bit's whatever the segment's note says: the undeclared runs' numbers
before issue 34 item 5.

The second plant family (benchmarks/plants/lumped.py, §L6: its own motor law, independent
of drillfric) runs the same motors on one off-bottom rotation of its 3000-m well.

Run: ``python benchmarks/validate_motor.py [--quick] [--json OUT]`` (about 10 minutes;
--quick: k = 0.1 only).
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

from benchmarks import validate_lumped as VL  # noqa: E402
from benchmarks.plants import lumped as L  # noqa: E402
from drillfric.estimation.bit_torque import teale_mse_Pa  # noqa: E402
from drillfric.io.well import open_well  # noqa: E402
from drillfric.io.writers import dumps_toml  # noqa: E402
from drillfric.runner import run_well  # noqa: E402
from drillfric.sim import recorder  # noqa: E402
from drillfric.sim.run import simulate_config  # noqa: E402

DEMO = Path(__file__).resolve().parents[1] / "examples" / "demo"
#: (k [rev/L], flow [m³/s]): no-load motor speeds 90, 150 and 180 RPM.
MOTORS = ((0.03, 0.05), (0.1, 0.025), (0.3, 0.01))
RATES = ("100", "10", "5", "1", "1-s means")
WOB_N, ROP_M_H, BIT_MU, D_BIT = 60e3, 15.0, 0.3, 0.2159
#: Stall torque 5× the Coulomb bit's T_k = μ_bit·WOB·D_bit/3: the motor 20 % slower on bottom.
STALL_NM = 5.0 * BIT_MU * WOB_N * D_BIT / 3.0
WINDOW_S, STUCK_TOL, SEVERITY_TOL, OMEGA_C_RPM = 30.0, 0.05, 0.12, 60.0 / (2.0 * np.pi)
SCENARIO = """connection_s = 30.0
[defaults]
rpm = 60.0
duration_s = 150.0
[[stand]]
bit_depth_m = 2210.0
flow_m3_s = {q}
[[stand]]
bit_depth_m = 2240.0
flow_m3_s = {q}
wob_N = {wob}
rop_m_h = {rop}
[[stand]]
bit_depth_m = 2236.0
duration_s = 120.0
"""


def simulate(folder: Path, k: float, q: float) -> dict:
    """The 100-Hz record of the demo well with the motor (columns, truth)."""
    raw = tomllib.loads((DEMO / "demo.toml").read_text(encoding="utf-8"))
    raw["well"].pop("data", None)
    raw["well"]["bit_diameter_m"] = D_BIT
    (folder / "demo.survey.csv").write_bytes((DEMO / "demo.survey.csv").read_bytes())
    raw["simulate"] |= {"scenario": "motor.scenario.toml", "rate_hz": 100.0, "cells": 1000,
                        "motor_rev_per_litre": k, "motor_stall_torque_Nm": STALL_NM,
                        "bit_mu": BIT_MU, "bit_diameter_m": D_BIT}
    (folder / "motor.scenario.toml").write_text(SCENARIO.format(q=q, wob=WOB_N, rop=ROP_M_H))
    (folder / "sim.toml").write_text(dumps_toml(raw), encoding="utf-8")
    sim = simulate_config(folder / "sim.toml")
    return {"columns": sim.columns, "truth": sim.truth(), "config": raw}


def simulate_lumped(folder: Path, k: float, q: float) -> dict:
    """The second plant family (benchmarks/plants/lumped.py §L6) with the motor: one
    off-bottom rotation of 240 s at 60 RPM on the 3000-m well of validate_lumped.py,
    μ_s/μ_k = 0.4/0.25 (stick-slip), pumps on throughout."""
    case = VL.Case(3000.0, 0.25, 1.6, creep="ramp")
    survey, string = VL.well(case)
    knots = L.setpoint(60.0, 250.0)
    rec = L.simulate(string, L.Drive(knots, 2900.0, case.kp, case.ki),
                     L.Friction(0.4, 0.25, omega_switch_rad_s=VL.OMEGA_C), knots[-1][0],
                     rate_hz=100.0, noise=L.Noise(rpm_sd=0.5, torque_sd_Nm=200.0,
                                                  hookload_sd_N=2000.0, seed=1),
                     motor=L.Motor(k, q, STALL_NM))
    config = tomllib.loads(VL.write_config(folder, case, survey).read_text(encoding="utf-8"))
    return {"columns": rec.columns, "truth": {"stands": []}, "config": config}


def logged(cols: dict, rate: str) -> pd.DataFrame:
    """The 100-Hz record as logged at ``rate`` (spot values or 1-s block means)."""
    cols = {k: np.asarray(v, float) for k, v in cols.items()}
    if rate.endswith("means"):
        return pd.DataFrame(recorder.block_means(cols, 1.0, minmax=False))
    step = int(round(100.0 / float(rate)))
    return pd.DataFrame({k: v[::step] for k, v in cols.items()})


def run(folder: Path, sim: dict, rate: str, declared: bool, k: float):
    """drillfric's run of one logged record, the motor declared or not."""
    name = f"r{rate.split('-')[0]}{'m' if 'means' in rate else ''}_{'d' if declared else 'u'}"
    data = logged(sim["columns"], rate)
    truth_only = ("bha_rpm", "string_torque_Nm", "motor_torque_Nm")
    data = data.drop(columns=[c for c in truth_only if c in data])
    if not data["wob_N"].any():
        data = data.drop(columns="wob_N")
    data.to_csv(folder / f"{name}.csv", index=False)
    cfg = {t: v for t, v in sim["config"].items() if t not in ("simulate", "well")}
    cfg["hookload"] = {"block_weight_N": 0.0}
    cfg["well"] = {"bit_diameter_m": D_BIT}
    if declared:
        cfg["bha"] = {"motor_rev_per_litre": k}
    if rate.endswith("means"):
        cfg["rig"] = dict(cfg["rig"], sample_averaging_s=1.0)
    (folder / f"{name}.toml").write_text(dumps_toml(cfg), encoding="utf-8")
    return run_well(open_well(folder / f"{name}.csv"))


def windows(rows: pd.DataFrame, t: np.ndarray, truth: np.ndarray) -> list[dict]:
    """30-s windows of one shown trace: estimate, truth, band and whether right."""
    rows = rows[rows["bit_rpm_est"].notna()]
    if rows.empty:
        return []
    te = rows["time_s"].to_numpy(float)
    out = []
    for a in np.arange(te[0], te[-1], WINDOW_S):
        m = (te >= a) & (te < a + WINDOW_S)
        if m.sum() < 3:
            continue
        est = float(rows["bit_rpm_est"].to_numpy(float)[m].mean())
        tr = float(np.interp(te[m], t, truth).mean())  # at the rows shown
        lo = float(np.nanmean(rows["bit_rpm_est_min"].to_numpy(float)[m]))
        hi = float(np.nanmean(rows["bit_rpm_est_max"].to_numpy(float)[m]))
        ok = abs(est - tr) <= max(2.0, 0.05 * abs(tr)) or lo <= tr <= hi
        out.append({"est": est, "truth": tr, "low": lo, "high": hi, "ok": bool(ok)})
    return out


def stats_truth(t: np.ndarray, bha: np.ndarray, a: float, b: float) -> tuple[float, float]:
    """Stuck share and severity of the BHA's true speed after the start-up (the reported
    statistics' definitions, docs/bit_speed.md)."""
    m = (t >= a + min(30.0, 0.3 * (b - a))) & (t <= b)
    x = bha[m]
    p1, p99 = np.percentile(x, (1.0, 99.0))
    return float(np.mean(np.abs(x) <= OMEGA_C_RPM)), float((p99 - p1) / (2.0 * np.mean(x)))


def grade(result, sim: dict) -> dict:
    """Windows, statistics and MSE of one run against the truth (module docstring)."""
    cols, stands = sim["columns"], sim["truth"]["stands"]
    t, bit, bha = cols["time_s"], cols["bit_rpm"], cols["bha_rpm"]
    out = {"windows": 0, "false_windows": 0, "stats": 0, "false_stats": 0, "mse": 0,
           "false_mse": 0, "notes": 0, "false_as_bit": 0, "worst_error_rpm": 0.0,
           "mse_false_as_bit": 0, "worst_mse_error": 0.0}
    for g in result.summary["segments"]:
        if g["status"] != "ok":
            continue
        claims_bha = bool(g.get("bit_speed_reason") and "string's bottom speed"
                          in g["bit_speed_reason"])
        out["notes"] += claims_bha
        if g.get("bit_speed_resolved"):
            rows = result.estimates[(result.estimates["segment_id"] == g["id"])
                                    & (result.estimates["start_id"] == -1)]
            w = windows(rows, t, bha if claims_bha else bit)
            out["windows"] += len(w)
            out["false_windows"] += sum(not x["ok"] for x in w)
            out["worst_error_rpm"] = max([out["worst_error_rpm"]]
                                         + [abs(x["est"] - x["truth"]) for x in w])
            # the same trace read as the bit's without the note (before issue 34 item 5)
            out["false_as_bit"] += sum(not x["ok"] for x in windows(rows, t, bit))
        _grade_stats(out, g, t, bha)
        _grade_mse(out, g, stands, t, bit, cols)
    return out


def _grade_stats(out: dict, g: dict, t, bha) -> None:
    if g.get("stuck_fraction") is None and g.get("stick_slip_severity") is None:
        return
    stuck, severity = stats_truth(t, bha, g["t_start_s"], g["t_end_s"])
    out["stats"] += 1
    bad = (g.get("stuck_fraction") is not None
           and abs(g["stuck_fraction"] - stuck) > STUCK_TOL) or \
        (g.get("stick_slip_severity") is not None
         and abs(g["stick_slip_severity"] / severity - 1.0) > SEVERITY_TOL)
    out["false_stats"] += bool(bad)


def _grade_mse(out: dict, g: dict, stands: list, t, bit, cols) -> None:
    if g.get("mse_Pa") is None:
        return
    stand = min(stands, key=lambda s: abs(s["bit_depth_m"] - g["bit_depth_m"]))
    m = (t >= g["t_start_s"]) & (t <= g["t_end_s"]) & (cols["surface_rpm"] > 2.0)
    says_surface = "mse_Pa takes the string's speed" in (g.get("message") or "")
    at = lambda rpm: teale_mse_Pa(g["wob_N"], stand["bit_power_torque_Nm"],  # noqa: E731
                                  float(np.mean(rpm)), g["rop_m_h"], D_BIT)
    truth, of_bit = at(cols["surface_rpm"][m] if says_surface else bit[m]), at(bit[m])
    out["mse"] += 1
    out["false_mse"] += abs(g["mse_Pa"] - truth) > g["mse_uncertainty_Pa"]
    out["worst_mse_error"] = max(out["worst_mse_error"], abs(g["mse_Pa"] / truth - 1.0))
    # read as the bit's MSE whatever the note says (before issue 34 item 5)
    out["mse_false_as_bit"] += abs(g["mse_Pa"] - of_bit) > g["mse_uncertainty_Pa"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="k = 0.1 rev/L only")
    parser.add_argument("--json", type=Path, help="write the rows as JSON")
    args = parser.parse_args()
    rows, started = [], time.time()
    with tempfile.TemporaryDirectory() as tmp:
        for plant, make in (("simulator", simulate), ("lumped", simulate_lumped)):
            for k, q in MOTORS[1:2] if args.quick else MOTORS:
                folder = Path(tmp) / f"{plant}_k{k:g}"
                folder.mkdir()
                sim = make(folder, k, q)
                for rate in RATES:
                    for declared in (True, False):
                        result = run(folder, sim, rate, declared, k)
                        row = {"plant": plant, "k_rev_per_litre": k, "flow_m3_s": q,
                               "rate": rate, "declared": declared} | grade(result, sim)
                        rows.append(row)
                        print(json.dumps(row), flush=True)
    totals = {key: sum(r[key] for r in rows) for key in
              ("windows", "false_windows", "stats", "false_stats", "mse", "false_mse",
               "false_as_bit", "mse_false_as_bit")}
    print(json.dumps({"totals": totals, "runs": len(rows),
                      "wall_s": round(time.time() - started)}))
    if args.json:
        args.json.write_text(json.dumps({"rows": rows, "totals": totals}, indent=1))


if __name__ == "__main__":
    main()
