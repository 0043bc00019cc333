"""Real wells, round two (issue 22 "Done when"): two sweeps of plants that depart from the
configuration the way real logs do, run through the whole pipeline (:func:`drillfric.run`).

**string** — the configured string's buoyed weight −40 … +40 % against the plant's (every
section's linear mass rescaled, :func:`drillfric.hookload.scaled_sections`), on the trust
sweep's step-law plant (demo string at 2300 m, μ_s 0.6, μ_k 0.25, creep start, 300 s at
60 RPM) with a travelling block of :data:`BLOCK_N` on the hook, with and without 60 s in
the slips before the stand (hook load = block weight, string still) or without them (then
also with ``hookload.block_weight_N`` configured), hook-load calibration off and on.

**axial** — rotation while the pipe moves at 0.05–0.5 m/s, running in (reaming) and pulling
out (back-reaming): the bit-depth / block-position channels move at that speed from the
start of rotation over at most one stand (:data:`STROKE_M`). The simulator has no axial
friction split, so the plant approximates it: the wall friction's tangential share at the
set-point speed, ω·r_c/√(v² + (ω·r_c)²) with r_c of each section (docs/theory.md §2 steps
3–4), weighted by each section's share of T_N, scales the plant's μ_s and μ_k for the whole
stand (the normal-force change from the axial drag is not modelled; the truth is the
wall's μ). The depth channel is ``bit_depth_m`` (with ``hole_depth_m``) at 100 Hz and 1 Hz,
``block_position_m`` alone at 5 Hz and 1-s means.

**mixed** — the string sweep's stand (no block) turning still, then moving at each speed
for at most 120 s, then still again (:func:`mixed_sweep`; the plant's torque is the
pure-rotation one: the stroke's rows are the ones to be withheld).

Each record at 100 Hz, 5 Hz, 1 Hz and 1-s means with the demo's noise (0.5 RPM, 300 N·m,
2 kN hook load). Scores (docs/validation.md):

- μ_k (every estimated segment and the well's) within 5 % (10 % at 1 Hz / 1-s means), or
  withheld with the reason (printed); a converged μ_k outside is FALSE;
- every μ_s claim within 10 %, every lower bound below the truth;
- on segments whose bit trace is reported as resolved, its RMS error against the truth no
  worse than the surface speed's (after the first 30 s).

Run: ``python benchmarks/validate_real_wells.py [--sweeps string,axial,mixed] [--rates ...]
[--weights -40,0,40] [--speeds 0.05,0.5]`` (about 15–20 minutes on one core for the default
grid).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import validate_trust as trust  # noqa: E402

import drillfric  # noqa: E402
from drillfric import hookload  # noqa: E402
from drillfric.config import load_config  # noqa: E402
from drillfric.io.survey import read_survey  # noqa: E402
from drillfric.io.writers import dumps_toml  # noqa: E402
from drillfric.torque_drag import solve_config  # noqa: E402
from drillfric.units import RPM_TO_RAD_S  # noqa: E402

MU_S, MU_K = 0.6, 0.25
RATES = ("100 Hz", "5 Hz", "1 Hz", "1-s means")
#: Travelling block, hook and top drive on the hook [N] (the simulator's hook load has none).
BLOCK_N = 300e3
SLIPS_S = 60.0
#: Configured string's buoyed weight against the plant's [%].
WEIGHTS = (-40, -25, -10, 0, 10, 25, 40)
#: Axial pipe speeds [m/s]; each run in (+) and pulled out (−).
SPEEDS = (0.05, 0.1, 0.2, 0.5)
STROKE_M = 28.0
AXIAL_RPM = 60.0
AXIAL_MOVE_S = 240.0
MIXED_DELAY_S = 120.0
MIXED_MOVE_S = 120.0


# --------------------------------------------------------------------------- scoring
def statuses(summary: dict, rate: str, truth_mu_k: float = MU_K) -> list[dict]:
    """Status of every estimated segment's μ_k and of the well's (validate_soft_drive's
    rule): converged within tolerance, withheld with the reason, or FALSE."""
    tol = trust.MU_K_TOL[rate]
    out = []
    rows = [(f"seg {g['id']} {g['kind']}", g) for g in summary["segments"]]
    rows.append(("well", {"mu_k": summary["mu_k"], "converged": summary["mu_k"] is not None,
                          "status": "ok", "quality_flags": [],
                          "message": summary.get("mu_k_reason") or "no converged segment"}))
    for name, g in rows:
        if g["status"] != "ok":
            out.append({"what": name, "status": "withheld", "mu_k": None,
                        "reason": (g["message"] or "")[:90]})
            continue
        mu = g["mu_k"]
        if mu is not None and g["converged"]:
            ok = abs(mu / truth_mu_k - 1.0) <= tol
            out.append({"what": name, "status": "ok" if ok else "FALSE", "mu_k": mu,
                        "reason": ", ".join(g["quality_flags"])})
        else:
            why = [f for f in g["quality_flags"] if f not in ("observer_starts_disagree",
                                                      "observer_deadlock_averted")]
            out.append({"what": name, "status": "withheld", "mu_k": mu,
                        "reason": ", ".join(why) or (g["message"] or "not converged")[:90]})
    return out


def claims(summary: dict, truth_mu_s: float = MU_S) -> dict:
    """μ_s claims and lower bounds of the estimated segments, the false ones apart."""
    segs = [g for g in summary["segments"] if g["status"] == "ok"]
    mu_s = [g["mu_s"] for g in segs if g["mu_s_identifiable"] and g["mu_s"] is not None]
    bounds = [g["mu_s_lower_bound"] for g in segs if g["mu_s_lower_bound"] is not None]
    return {"mu_s": mu_s, "mu_s_false": [m for m in mu_s if abs(m / truth_mu_s - 1) > 0.10],
            "bounds": bounds, "bounds_false": [b for b in bounds if b >= truth_mu_s]}


def bit_traces(result) -> list[dict]:
    """Per segment reported as resolved: RMS error of the bit trace and of the surface speed
    taken as the bit speed, against the truth (rows after the first 30 s)."""
    est, out = result.estimates, []
    for g in result.summary["segments"]:
        if g["status"] != "ok" or not g.get("bit_speed_resolved") or "bit_rpm" not in est:
            continue
        rows = est[(est["segment_id"] == g["id"]) & (est["start_id"] == -1)]
        rows = rows[rows["time_s"] >= g["t_start_s"] + 30.0]
        ok = rows["bit_rpm_est"].notna() & rows["bit_rpm"].notna()
        if not ok.any():
            continue
        e = (rows["bit_rpm_est"] - rows["bit_rpm"])[ok].to_numpy()
        p = (rows["surface_rpm"] - rows["bit_rpm"])[ok].to_numpy()
        out.append({"id": g["id"], "bit_rms": float(np.sqrt(np.mean(e ** 2))),
                    "surface_rms": float(np.sqrt(np.mean(p ** 2)))})
    return out


def run_record(frame: pd.DataFrame, rate: str, folder: Path, est_cfg: Path, label: str,
               truth_mu: tuple = (MU_S, MU_K), drop=()) -> dict:
    """Log ``frame`` at ``rate`` (without the ``drop`` channels), run it, score it, print it."""
    data = folder / (label.replace(" ", "_").replace("/", "_") + f"_{rate.replace(' ', '')}"
                     ".parquet")
    trust.record(frame, rate, label).drop(columns=list(drop)).to_parquet(data, index=False)
    t0 = time.perf_counter()
    well = drillfric.open_well(data, config=est_cfg, survey=folder / "path.survey.csv")
    result = drillfric.run(well)
    s = result.summary
    row = {"label": label, "rate": rate, "segments": statuses(s, rate, truth_mu[1]),
           **claims(s, truth_mu[0]), "bits": bit_traces(result), "hookload": s.get("hookload"),
           "warnings": s["warnings"], "run_s": time.perf_counter() - t0}
    row["bits_false"] = [b for b in row["bits"] if b["bit_rms"] > b["surface_rms"]]
    row["false"] = (sum(x["status"] == "FALSE" for x in row["segments"])
                    + len(row["mu_s_false"]) + len(row["bounds_false"]) + len(row["bits_false"]))
    print(_line(row), flush=True)
    return row


def _line(r: dict) -> str:
    segs = "; ".join(f"{x['what']}: " + (f"{x['mu_k']:.3f} ({100 * (x['mu_k'] / MU_K - 1):+.1f} %)"
                                         if x["mu_k"] is not None else "—")
                     + ("" if x["status"] == "ok" else f" {x['status']}"
                        + (f" [{x['reason']}]" if x["reason"] else ""))
                     for x in r["segments"])
    hook = r["hookload"] or {}
    ratio = hook.get("string_weight_ratio")
    verdict = (f"{hook.get('verdict')}" + (f" {ratio:.2f}" if ratio is not None else "")
               + (f" ×{hook['calibration_scale']:.3f}" if hook.get("calibration_scale")
                  else ""))
    mu_s = ", ".join(f"{m:.3f}" for m in r["mu_s"]) or "—"
    bounds = ", ".join(f"{b:.2f}" for b in r["bounds"]) or "—"
    bits = ", ".join(f"{b['bit_rms']:.1f}/{b['surface_rms']:.1f}" for b in r["bits"]) or "—"
    nfalse = r["false"]
    return (f"| {r['label']} | {r['rate']} | {verdict} | {segs} | {mu_s} | {bounds} | {bits} "
            f"| {f'{nfalse} FALSE' if nfalse else '✓'} "
            f"| {r['run_s']:.0f} |")


# --------------------------------------------------------------------------- string weight
def string_config(est_cfg: Path, percent: float, calibrate: bool, block_N: float | None,
                  name: str) -> Path:
    """The estimator's configuration with the string's buoyed weight × (1 + percent/100),
    calibration allowed or not, the block weight configured or not."""
    cfg = load_config(est_cfg)
    raw = cfg.to_dict()
    raw["string"] = {"sections": [{k: v for k, v in s.items() if v is not None} for s in
                                  hookload.scaled_sections(cfg.sections, 1 + percent / 100,
                                                           cfg.fluid.mud_density_kg_m3,
                                                           cfg.inner_mud_density_kg_m3)]}
    raw["hookload"] = dict(raw["hookload"], calibrate_string_weight=calibrate,
                           block_weight_N=block_N)
    raw.pop("simulate", None)
    out = est_cfg.parent / f"{name}.toml"
    out.write_text(dumps_toml(trust._clean(raw)), encoding="utf-8")
    return out


def weighed_log(frame: pd.DataFrame, slips: bool, seed: int = 22) -> pd.DataFrame:
    """The simulated stand with the block on the hook, behind ``SLIPS_S`` in the slips when
    ``slips`` (hook load = block weight + 2 kN noise, no rotation, string still)."""
    stand = frame.copy()
    stand["hookload_N"] += BLOCK_N
    if not slips:
        return stand
    t = np.arange(0.0, SLIPS_S, 0.01)
    first = stand.iloc[0]
    pre = pd.DataFrame({c: np.full(t.size, first[c]) for c in stand.columns})
    pre["time_s"] = t
    for c in ("surface_rpm", "surface_torque_Nm", "bit_rpm", "string_torque_Nm"):
        pre[c] = 0.0
    pre["hookload_N"] = BLOCK_N + np.random.default_rng(seed).normal(0.0, 2e3, t.size)
    stand["time_s"] += SLIPS_S
    return pd.concat([pre, stand], ignore_index=True)


def string_sweep(work: Path, rates, weights) -> list[dict]:
    folder = work / "string"
    folder.mkdir()
    sim_cfg, est_cfg = trust._config(folder, "step")
    frame = pd.DataFrame(drillfric.simulate(sim_cfg).columns)
    rows = []
    for evidence in ("slips", "no slips", "no slips, block_weight_N"):
        log = weighed_log(frame, evidence == "slips")
        block = BLOCK_N if evidence.endswith("block_weight_N") else None
        for percent in weights:
            for calibrate in (False, True):
                label = f"string {percent:+d} % {evidence} {'calibrate' if calibrate else 'check'}"
                cfg = string_config(est_cfg, percent, calibrate, block,
                                    f"w{percent}{evidence[:6]}{block}{calibrate}")
                for rate in rates:
                    rows.append(run_record(log, rate, folder, cfg, label) | {
                        "percent": percent, "evidence": evidence, "calibrate": calibrate})
    return rows


# --------------------------------------------------------------------------- axial motion
def tangential_share(est_cfg: Path, speed_m_s: float, rpm: float) -> float:
    """T_N-weighted share ω·r_c/√(v² + (ω·r_c)²) of the wall friction that acts
    tangentially when the pipe moves at ``speed_m_s`` turning at ``rpm`` (docs/theory.md §2
    steps 3–4), on the demo string at 2300 m."""
    cfg = load_config(est_cfg)
    td = solve_config(cfg, read_survey(est_cfg.parent / "path.survey.csv"), trust.DEPTH_M)
    rc = td.fc_Nm_m / np.where(td.normal_force_N_m > 0, td.normal_force_N_m, np.inf)
    omega_r = rpm * RPM_TO_RAD_S * rc
    share = omega_r / np.hypot(speed_m_s, omega_r)
    weight = td.fc_Nm_m * np.diff(td.md_m)
    return float(np.sum(share * weight) / np.sum(weight))


def moving_log(frame: pd.DataFrame, stand: dict, speed_m_s: float, delay_s: float = 0.0,
               move_s: float = np.inf) -> pd.DataFrame:
    """The stand with the pipe moving at ``speed_m_s`` (> 0 running in) from ``delay_s``
    after the start of rotation, for at most ``move_s`` and :data:`STROKE_M`; the hole
    bottom below the deepest bit position by the simulator's 5 m; the block position
    follows."""
    out = frame.copy()
    t = out["time_s"].to_numpy(float)
    t0 = float(t[np.argmax(out["surface_rpm"].to_numpy(float) > 2.0)]) + delay_s
    travel = np.clip((t - t0) * abs(speed_m_s), 0.0, min(STROKE_M, move_s * abs(speed_m_s)))
    start = stand["bit_depth_m"] - np.sign(speed_m_s) * STROKE_M / 2
    out["bit_depth_m"] = start + np.sign(speed_m_s) * travel
    out["hole_depth_m"] = stand["bit_depth_m"] + STROKE_M / 2 + 5.0
    out["block_position_m"] = 30.0 - (out["bit_depth_m"] - out["bit_depth_m"].iloc[0])
    return out


def block_config(est_cfg: Path, start_bit_depth_m: float) -> Path:
    """The estimator's configuration for a log with the block position only: the bit depth
    at the first sample given (``segmentation.start_bit_depth_m``)."""
    raw = load_config(est_cfg).to_dict()
    raw["segmentation"] = dict(raw["segmentation"], start_bit_depth_m=start_bit_depth_m)
    raw.pop("simulate", None)
    out = est_cfg.parent / "block.toml"
    out.write_text(dumps_toml(trust._clean(raw)), encoding="utf-8")
    return out


def axial_sweep(work: Path, rates, speeds) -> list[dict]:
    rows = []
    for speed in (s * way for s in speeds for way in (1, -1)):
        name = f"{'ream' if speed > 0 else 'backream'}-{abs(speed):g}"
        folder = work / name
        folder.mkdir()
        move_s = min(AXIAL_MOVE_S, STROKE_M / abs(speed))
        stand = {"bit_depth_m": trust.DEPTH_M, "start": "ramp", "ramp_s": 10.0,
                 "duration_s": move_s, "rpm": AXIAL_RPM}
        _, est_cfg = trust._config(folder, name, ({"mu_s": MU_S, "mu_k": MU_K}, {}, ""), stand)
        share = tangential_share(est_cfg, speed, AXIAL_RPM)
        spec = ({"mu_s": MU_S * share, "mu_k": MU_K * share}, {}, name)
        sim_cfg, est_cfg = trust._config(folder, name, spec, stand)
        frame = moving_log(pd.DataFrame(drillfric.simulate(sim_cfg).columns), stand, speed)
        print(f"  {name}: {move_s:.0f} s moving, tangential share {share:.3f} "
              f"(plant μ_k {MU_K * share:.3f})", flush=True)
        block_cfg = block_config(est_cfg, float(frame["bit_depth_m"].iloc[0]))
        for rate in rates:
            block_only = rate in ("5 Hz", "1-s means")
            drop = ("bit_depth_m", "hole_depth_m") if block_only else ("block_position_m",)
            label = f"{name} m/s ({'block position' if block_only else 'bit depth'})"
            rows.append(run_record(frame, rate, folder, block_cfg if block_only else est_cfg,
                                   label, drop=drop) | {"speed": speed, "share": share})
    return rows


def mixed_sweep(work: Path, rates, speeds) -> list[dict]:
    """The trust sweep's step-law stand (creep start, 300 s at 60 RPM) with the pipe moving
    at each speed from 120 s after the start of rotation for at most 120 s (one stand at
    most), then still again while it turns: segments before and after the stroke are
    estimated. The plant's torque is the pure-rotation one throughout (the simulator has no
    axial split: the stroke's own rows are the ones that must be withheld)."""
    folder = work / "mixed"
    folder.mkdir()
    sim_cfg, est_cfg = trust._config(folder, "step")
    frame = pd.DataFrame(drillfric.simulate(sim_cfg).columns)
    rows = []
    for speed in (s * way for s in speeds for way in (1, -1)):
        log = moving_log(frame, {"bit_depth_m": trust.DEPTH_M}, speed, MIXED_DELAY_S,
                         MIXED_MOVE_S)
        block_cfg = block_config(est_cfg, float(log["bit_depth_m"].iloc[0]))
        name = f"still-{'ream' if speed > 0 else 'backream'}-still {abs(speed):g}"
        for rate in rates:
            block_only = rate in ("5 Hz", "1-s means")
            drop = ("bit_depth_m", "hole_depth_m") if block_only else ("block_position_m",)
            label = f"{name} m/s ({'block position' if block_only else 'bit depth'})"
            rows.append(run_record(log, rate, folder, block_cfg if block_only else est_cfg,
                                   label, drop=drop) | {"speed": speed})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sweeps", default="string,axial,mixed")
    parser.add_argument("--rates", default=",".join(RATES))
    parser.add_argument("--weights", default=",".join(map(str, WEIGHTS)),
                        help="configured string weight against the plant's [%%]")
    parser.add_argument("--speeds", default=",".join(map(str, SPEEDS)), help="[m/s]")
    args = parser.parse_args()
    rates = tuple(args.rates.split(","))
    print(f"truth μ_s {MU_S}, μ_k {MU_K}; block {BLOCK_N / 1e3:g} kN\n")
    print("| record | rate | hook-load verdict | μ_k by segment and well | μ_s claims | "
          "bounds | bit RMS / surface RMS [RPM] | false | run [s] |")
    print("|" + "---|" * 9)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        if "string" in args.sweeps:
            rows += string_sweep(Path(tmp), rates, [int(w) for w in args.weights.split(",")])
        speeds = [float(v) for v in args.speeds.split(",")]
        if "axial" in args.sweeps:
            rows += axial_sweep(Path(tmp), rates, speeds)
        if "mixed" in args.sweeps:
            rows += mixed_sweep(Path(tmp), rates, speeds)
    segs = [x for r in rows for x in r["segments"]]
    count = {s: sum(x["status"] == s for x in segs) for s in ("ok", "withheld", "FALSE")}
    print(f"\n{len(rows)} records, {len(segs)} μ_k results: within tolerance {count['ok']}, "
          f"withheld with a reason {count['withheld']}, FALSE {count['FALSE']}; μ_s claims "
          f"{sum(len(r['mu_s']) for r in rows)} (false {sum(len(r['mu_s_false']) for r in rows)}"
          f"), bounds {sum(len(r['bounds']) for r in rows)} (at or above truth "
          f"{sum(len(r['bounds_false']) for r in rows)}), resolved bit traces "
          f"{sum(len(r['bits']) for r in rows)} (worse than the surface speed "
          f"{sum(len(r['bits_false']) for r in rows)})")


if __name__ == "__main__":
    main()
