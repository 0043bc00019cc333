"""Real sensors on the second plant family: channel skew, top-drive inertia and EDR defects
(issue 34's sweeps on the lumped plant; docs/validation.md "Departures on the second plant
family").

validate_skew, validate_inertia and validate_edr run on drillfric's own simulator. This
sweep gives the same departures to the lumped plant of benchmarks/plants/lumped.py (3000 m,
μ_k 0.25; ``steady``: μ_s = μ_k; ``stick-slip``: μ_s/μ_k 2 with a creep break-over;
``steps``: μ_s = μ_k under set-point steps 0 → 60 → 90 → 50 → 70 RPM, which time a lag):

- ``lag L``: the torque logged L = −1, 0.5, 1, 2 s late (the configuration states no lag);
- ``inertia ×f``: the plant's top drive f = 0.4, 2.5 × the 2900 kg·m² configured, the motor
  torque logged (``rig.torque_kind = "motor"``);
- EDR defects of validate_edr (spikes ×10, drop-outs, held readings, duplicated and
  re-stamped rows, gaps),

logged at 100, 10, 5 and 1 Hz and as 1-s means, each run through :func:`drillfric.run` and
graded as validate_lumped grades (μ_k within 5 %, 10 % at 1 Hz and 1-s means, of the
effective truth μ_k·T_N,plant/T_N,drillfric or withheld; μ_s claims within 10 %, bounds
below; every resolved trace's 30-s windows by the window rule) plus: a stated lag within
±0.2 s of the truth and its ±; a stated inertia within ±25 % and its ±; stick-slip
statistics within ±0.05 / ±12 %.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/validate_lumped_departures.py [--quick]
[--json FILE]`` (``--quick``: 10 Hz and 1-s means).
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

import validate_lumped as VL  # noqa: E402
from validate_edr import DEFECTS  # noqa: E402
from validate_inertia import grade_inertia  # noqa: E402

import drillfric  # noqa: E402
from benchmarks.plants import lumped as L  # noqa: E402
from drillfric.io.writers import dumps_toml  # noqa: E402
from drillfric.sim import recorder  # noqa: E402

RATES = VL.RATES
CONFIGURED_I = 2900.0
LAG_TOL_S, STUCK_TOL, SEVERITY_TOL = 0.2, 0.05, 0.12
STEPS = ((0.0, 0.0), (5.0, 0.0), (15.0, 60.0), (100.0, 60.0), (103.0, 90.0), (160.0, 90.0),
         (163.0, 50.0), (230.0, 50.0), (233.0, 70.0), (300.0, 70.0), (305.0, 0.0),
         (315.0, 0.0))
#: name → (μ_s/μ_k, set-point knots or None for validate_lumped's creep stand).
STANDS = {"steady": (1.0, None), "stick-slip": (2.0, None), "steps": (1.0, STEPS)}
DEPARTURES = ([("lag", v) for v in (-1.0, 0.5, 1.0, 2.0)]
              + [("inertia", f) for f in (0.4, 2.5)]
              + [("edr", d) for d in DEFECTS if d != "clean"])


def simulate(stand: str, inertia_factor: float):
    """The 100-Hz record (noise as validate_lumped's), the case, its survey and string."""
    ratio, knots = STANDS[stand]
    case = VL.Case(3000.0, 0.25, ratio)
    if knots is None:
        rec, survey, string, _ = VL.simulate_case(case, CONFIGURED_I * inertia_factor)
        return rec.columns, case, survey, string
    survey, string = VL.well(case)
    drive = L.Drive(knots, CONFIGURED_I * inertia_factor, case.kp, case.ki)
    friction = L.Friction(case.mu_k * ratio, case.mu_k, omega_switch_rad_s=case.omega_sw)
    noise = L.Noise(rpm_sd=0.5, torque_sd_Nm=200.0, hookload_sd_N=2000.0, seed=case.seed)
    rec = L.simulate(string, drive, friction, knots[-1][0], rate_hz=100.0, noise=noise)
    return rec.columns, case, survey, string


def logged(cols: dict, rate: str, kind: str, value) -> pd.DataFrame:
    """The record as logged at ``rate`` with the departure applied."""
    cols = dict(cols)
    if kind == "lag":
        cols["surface_torque_Nm"] = recorder.lagged(np.asarray(cols["time_s"], float),
                                                    np.asarray(cols["surface_torque_Nm"],
                                                               float), value)
    if kind == "inertia":
        cols["surface_torque_Nm"] = cols["motor_torque_Nm"]
    frame = VL.logged(cols, rate)
    if kind == "edr":
        frame = DEFECTS[value](frame.reset_index(drop=True), np.random.default_rng(3))
    return frame.reset_index(drop=True)


def configure(folder: Path, case, survey, kind: str) -> Path:
    """drillfric's configuration of the plant; with an inertia departure the motor torque."""
    cfg = VL.write_config(folder, case, survey)
    if kind == "inertia":
        raw = tomllib.loads(cfg.read_text(encoding="utf-8"))
        raw["rig"]["torque_kind"] = "motor"
        cfg.write_text(dumps_toml(raw), encoding="utf-8")
    return cfg


def grade(result, case, rate: str, truth: dict, plant_cols: dict, kind: str, value) -> dict:
    """validate_lumped's score plus the departure's own verdicts; ``false`` if any number
    shown lies outside its tolerance."""
    row = VL.score(result, case, rate, truth, plant_cols)
    tol = 0.05 if rate in ("100 Hz", "10 Hz", "5 Hz") else 0.10
    false = []
    if row["mu_k_err"] is not None and abs(row["mu_k_err"]) > tol:
        false.append("μ_k")
    if row["mu_s_false"] or row["bounds_false"]:
        false.append("μ_s")
    for tr in row["traces"]:
        if tr.get("windows") and (tr["ok_share"] < 0.95 or tr["worst_outside_rpm"] > 10.0):
            false.append(f"trace #{tr['id']}")
        if tr["stuck"] is not None and tr["stuck_truth"] is not None and abs(
                tr["stuck"] - tr["stuck_truth"]) > STUCK_TOL:
            false.append(f"stuck #{tr['id']}")
        if tr["severity"] is not None and tr["severity_truth"] and abs(
                tr["severity"] / tr["severity_truth"] - 1.0) > SEVERITY_TOL:
            false.append(f"severity #{tr['id']}")
    skew = result.summary["inputs"]["channel_skew"]
    row["lag_found"], row["lag_pm"] = skew["lag_s"], skew["uncertainty_s"]
    if kind == "lag" and skew["lag_s"] is not None and not (
            abs(skew["lag_s"] - value) <= min(LAG_TOL_S, skew["uncertainty_s"] + 1e-9)):
        false.append("lag")
    if kind == "inertia":
        row.update(grade_inertia(result, CONFIGURED_I * value))
        if not row["inertia_ok"]:
            false.append("inertia")
    row.update(kind=kind, value=value, false=false)
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    rates = ("10 Hz", "1-s means") if args.quick else RATES
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for stand in STANDS:
            for kind, value in DEPARTURES:
                if kind == "lag" and stand == "steady" or kind == "edr" and stand == "steps":
                    continue
                cols, case, survey, string = simulate(
                    stand, value if kind == "inertia" else 1.0)
                folder = Path(tmp) / f"{stand}_{kind}_{value}"
                folder.mkdir()
                cfg = configure(folder, case, survey, kind)
                ratio = string.T_N_Nm / VL.drillfric_td(cfg, case.depth_m).T_N_Nm
                truth = {"mu_k_eff": case.mu_k * ratio,
                         "mu_s_eff": case.mu_k * case.ratio * ratio, "ratio": ratio}
                plant = {"time_s": cols["time_s"], "bit_rpm": cols["bit_rpm"]}
                for rate in rates:
                    data = folder / f"{rate.replace(' ', '_')}.parquet"
                    logged(cols, rate, kind, value).to_parquet(data, index=False)
                    t0 = time.perf_counter()
                    result = drillfric.run(drillfric.open_well(
                        data, config=cfg, survey=folder / "path.survey.csv"))
                    row = grade(result, case, rate, truth, plant, kind, value)
                    row.update(stand=stand, run_s=time.perf_counter() - t0)
                    rows.append(row)
                    print(_line(row), flush=True)
    print(f"\n{len(rows)} records, {sum(bool(r['false']) for r in rows)} with a false number")
    print("\n" + table(rows))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1, default=float), encoding="utf-8")


def table(rows: list[dict]) -> str:
    """One line per stand and departure over the rates."""
    out = ["| stand | departure | μ_k err (withheld) | lag stated | traces resolved "
           "(windows) | statistics printed | false |", "|---|---|---|---|---|---|---|"]
    keys = dict.fromkeys((r["stand"], r["kind"], r["value"]) for r in rows)
    for stand, kind, value in keys:
        group = [r for r in rows if (r["stand"], r["kind"], r["value"]) == (stand, kind,
                                                                             value)]
        errs = [r["mu_k_err"] for r in group if r["mu_k_err"] is not None]
        err = (f"{100 * min(errs):+.1f} … {100 * max(errs):+.1f} %" if errs else "—") + (
            f" ({len(group) - len(errs)})" if len(errs) < len(group) else "")
        lags = [f"{r['lag_found']:.2f}" for r in group if r["lag_found"] is not None]
        traces = [t for r in group for t in r["traces"] if t.get("windows")]
        windows = sum(t["windows"] for t in traces)
        stats = sum(t["stuck"] is not None for r in group for t in r["traces"])
        false = sum(bool(r["false"]) for r in group)
        label = f"{kind} {value:g} s" if kind == "lag" else (
            f"inertia ×{value:g}" if kind == "inertia" else f"EDR {value}")
        out.append(f"| {stand} | {label} | {err} | {', '.join(lags) or '—'} | "
                   f"{len(traces)} ({windows}) | {stats} | {false} |")
    return "\n".join(out)


def _line(r: dict) -> str:
    err = "—" if r["mu_k_err"] is None else f"{100 * r['mu_k_err']:+.1f} %"
    lag = "—" if r["lag_found"] is None else f"{r['lag_found']:.2f}±{r['lag_pm']:.2f}"
    return (f"{r['stand']:<10} {r['kind']:<7} {r['value']!s:<10} {r['rate']:<9} μ_k {err} "
            f"lag {lag} traces {sum(bool(t.get('windows')) for t in r['traces'])} "
            f"{'FALSE ' + ','.join(r['false']) if r['false'] else 'ok'} ({r['run_s']:.1f} s)")


if __name__ == "__main__":
    main()
