"""Stuck fraction and stick-slip severity in SEVERE off-bottom stick-slip (issue 22).

Each plant is one off-bottom stand of the demo well's string (examples/demo; its 50° hold
extended to the plant's depth) started by a 10-s ramp, 240 s of rotation at a low set-point
with sticky friction, simulated at 100 Hz on a 2000-cell truth with the demo's noise
(validate_trust's ``_config``; the estimator's config states the plant's block weight 0).
The record is logged at 100 Hz, 10 Hz and 5 Hz (spot values) and run through the whole
pipeline (:func:`drillfric.open_well`, :func:`drillfric.run`). Each off-bottom segment's
reported ``stuck_fraction`` and ``stick_slip_severity`` is scored against the truth's
bit speed (the simulated ``bit_rpm`` at 100 Hz) with the same definitions on the same
rows — the segment after its start-up, min(30 s, 30 % of the segment)
(``diagnostics.settled_mask``): stuck = share of |ω_bit| ≤ ω_c, severity =
(ω_99 − ω_1)/(2·ω_mean). Tolerance (docs/bit_speed.md): stuck ±0.05, severity ±12 %.
A value withheld (null) is not scored as false. The reported bit trace of each record is
scored too (validate_trust's measure): its RMS error against the truth after the first
30 s, beside the surface speed's as bit speed; a resolved trace worse than that is the
issue's false claim.

Run: ``nice python benchmarks/validate_severity.py [--plants a,b] [--rates '100 Hz,5 Hz']``
(default 5 plants × 3 rates: about 10–15 minutes on one shared core with warm kernels).
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
from drillfric.config import load_config  # noqa: E402
from drillfric.estimation.diagnostics import STARTUP_S  # noqa: E402
from drillfric.units import RPM_TO_RAD_S  # noqa: E402

RATES = ("100 Hz", "10 Hz", "5 Hz")
STUCK_TOL = 0.05
SEVERITY_TOL = 0.12
DURATION_S = 240.0
#: name → (μ_s, μ_k, bit depth [m], set-point [RPM]).
PLANTS = {
    "s2000-40": (0.8, 0.25, 2000.0, 40.0),
    "s2000-33": (0.8, 0.3, 2000.0, 33.0),
    "s2500-36": (0.8, 0.25, 2500.0, 36.0),
    "s2500-33": (0.8, 0.3, 2500.0, 33.0),
    "s3000-36": (0.8, 0.3, 3000.0, 36.0),
}


def configs(folder: Path, name: str) -> tuple[Path, Path]:
    """Simulation and estimation configs of a plant (the survey's hold extended)."""
    mu_s, mu_k, depth, rpm = PLANTS[name]
    spec = ({"mu_s": mu_s, "mu_k": mu_k, "rpm_noise": 0.5, "torque_noise_Nm": 300.0}, {},
            name)
    stand = {"bit_depth_m": depth, "start": "ramp", "ramp_s": 10.0,
             "duration_s": DURATION_S, "rpm": rpm}
    sim_cfg, est_cfg = trust._config(folder, name, spec, stand)
    survey = folder / "path.survey.csv"
    lines = survey.read_text(encoding="utf-8").rstrip("\n").splitlines()
    md, inc, azi = (float(v) for v in lines[-1].split(","))
    extra = [f"{m:g},{inc:g},{azi:g}" for m in np.arange(md + 30.0, depth + 61.0, 30.0)]
    survey.write_text("\n".join(lines + extra) + "\n", encoding="utf-8")
    return sim_cfg, est_cfg


def truth(frame: pd.DataFrame, seg: dict, omega_c_rad_s: float) -> tuple[float, float]:
    """Stuck share and severity of the true bit speed on the segment's rows from
    ``stick_slip_from_s`` (else after its start-up) to ``stick_slip_to_s``: the reported
    statistics' definitions."""
    t = frame["time_s"].to_numpy(float)
    t0, t1 = seg["t_start_s"], seg["t_end_s"]
    start = seg.get("stick_slip_from_s") or t0 + min(STARTUP_S, 0.3 * (t1 - t0))
    end = seg.get("stick_slip_to_s") or t1
    bit = frame["bit_rpm"].to_numpy(float)[(t >= start) & (t <= end)] * RPM_TO_RAD_S
    stuck = float(np.mean(np.abs(bit) <= omega_c_rad_s))
    lo, hi = np.percentile(bit, (1.0, 99.0))
    return stuck, float((hi - lo) / (2.0 * abs(np.mean(bit))))


def score(summary: dict, frame: pd.DataFrame, omega_c: float, name: str,
          rate: str) -> list[dict]:
    rows = []
    for seg in summary["segments"]:
        if seg["kind"] != "off_bottom_rotating" or seg["status"] != "ok":
            continue
        stuck_true, sev_true = truth(frame, seg, omega_c)
        stuck, sev = seg.get("stuck_fraction"), seg.get("stick_slip_severity")
        row = {"plant": name, "rate": rate, "segment": seg["id"], "stuck_true": stuck_true,
               "severity_true": sev_true, "stuck": stuck, "severity": sev,
               "reason": seg.get("bit_speed_reason") or "",
               "stats_reason": next((m for m in (seg.get("message") or "").split("; ")
                                     if m.startswith("severe stick-slip")), "")}
        row["stuck_err"] = None if stuck is None else stuck - stuck_true
        row["severity_err"] = None if sev is None else sev / sev_true - 1.0
        row["ok"] = ((row["stuck_err"] is None or abs(row["stuck_err"]) <= STUCK_TOL)
                     and (row["severity_err"] is None
                          or abs(row["severity_err"]) <= SEVERITY_TOL))
        rows.append(row)
    return rows


def _fmt(v, spec: str) -> str:
    return "—" if v is None else format(v, spec)


def line(r: dict) -> str:
    verdict = "ok" if r["ok"] else "FALSE"
    if r["stuck"] is None and r["severity"] is None:
        verdict = "withheld"
    sev_err = "—" if r["severity_err"] is None else f"{100.0 * r['severity_err']:+.1f} %"
    trace = r["trace"]
    rms = ("not resolved" if not trace["bit_resolved"] else
           f"{trace['bit_rms_rpm']:.1f} vs {trace['surface_rms_rpm']:.1f}")
    return (f"| {r['plant']} | {r['rate']} | {r['stuck_true']:.3f} / {r['severity_true']:.2f} "
            f"| {_fmt(r['stuck'], '.3f')} / {_fmt(r['severity'], '.2f')} | "
            f"{_fmt(r['stuck_err'], '+.3f')} / {sev_err} | {verdict} | {rms} |")


def run_plant(name: str, rates, work: Path) -> list[dict]:
    folder = work / name
    folder.mkdir()
    sim_cfg, est_cfg = configs(folder, name)
    frame = pd.DataFrame(drillfric.simulate(sim_cfg).columns)
    omega_c = load_config(est_cfg).omega_c_rad_s
    rows = []
    for rate in rates:
        t0 = time.perf_counter()
        result = trust.run_logged(frame, rate, name, folder, est_cfg)
        trace = trust._bit(result, [g for g in result.summary["segments"]
                                    if g["status"] == "ok"])
        for r in score(result.summary, frame, omega_c, name, rate):
            r |= {"trace": trace}
            print(line(r) + f" {time.perf_counter() - t0:.0f} s", flush=True)
            if r["stats_reason"] and rate == rates[0]:
                print("    ", r["stats_reason"], flush=True)
            rows.append(r)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plants", default=",".join(PLANTS))
    parser.add_argument("--rates", default=",".join(RATES))
    args = parser.parse_args()
    print("| plant (μ_s/μ_k, depth, RPM) | rate | truth stuck / severity | reported | error "
          "(stuck / severity) | within ±0.05 / ±12 %? | bit trace RMS vs surface-as-bit "
          "[RPM] |")
    print("|" + "---|" * 7)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.plants.split(","):
            rows += run_plant(name, args.rates.split(","), Path(tmp))
    shown = [r for r in rows if r["stuck"] is not None]
    traces = [r["trace"] for r in rows if r["trace"]["bit_resolved"]]
    worse = sum(t["bit_rms_rpm"] > t["surface_rms_rpm"] for t in traces)
    print(f"\n{len(rows)} segments: {len(shown)} with statistics reported, "
          f"{sum(not r['ok'] for r in rows)} outside the tolerance, "
          f"{len(rows) - len(shown)} withheld; bit traces reported as resolved {len(traces)}, "
          f"worse than the surface speed {worse}, RMS "
          f"{min((t['bit_rms_rpm'] for t in traces), default=float('nan')):.1f}–"
          f"{max((t['bit_rms_rpm'] for t in traces), default=float('nan')):.1f} RPM")


if __name__ == "__main__":
    main()
