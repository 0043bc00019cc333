"""Soft top drives and their relaxation cycles (issue 22 item 5; docs/validation.md).

A PI speed controller with k_p near the pipe impedance ζ absorbs the torsional waves, and an
integral gain too small to deliver the break-away torque quickly makes the string stick
while the top drive crawls at a few RPM, winding it up, until the integral breaks it free:
a burst to several hundred RPM, then stuck again — a relaxation cycle of minutes. The grid
sweeps k_p from 0.3ζ to 3ζ and k_i from far too small to normal on the demo well's string
at 2300 m (μ_s 0.6, μ_k 0.25, set-point 40 RPM, noise 0.5 RPM / 300 N·m, a plain ramp
start-up), each 600-s record logged at 100 Hz, 5 Hz, 1 Hz and as 1-s means, and run
through the whole pipeline (:func:`drillfric.run`). Every segment's μ_k is scored:

- converged: within 5 % of the truth at 100/5 Hz and 1-s means, 10 % at 1 Hz, else FALSE;
- withheld (not converged): its reason is printed (the segment's flags);
- the well's consensus μ_k (converged segments and pools of short ones) likewise.

Zero false claims is the line. Run: ``python benchmarks/validate_soft_drive.py
[--kp 0.3,1,3] [--ki 30,100,300,2500] [--rates '100 Hz,1 Hz']`` (≈ 10 minutes on one core
for the default grid).
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
from drillfric.drillstring import build_string  # noqa: E402

MU_S, MU_K = 0.6, 0.25
RPM = 40.0
RECORD_S = 600.0
RATES = ("100 Hz", "5 Hz", "1 Hz", "1-s means")
#: k_p as multiples of the top section's impedance ζ, k_i [N·m/rad] (A&S 2018: 100e3).
KP_ZETA = (0.3, 1.0, 3.0)
KI = (30.0, 100.0, 300.0, 2500.0)
STAND = {"bit_depth_m": trust.DEPTH_M, "start": "ramp", "ramp_s": 10.0,
         "duration_s": RECORD_S, "rpm": RPM}


def impedance_Nms_rad() -> float:
    """ζ = J√(Gρ) of the top section of the demo string at 2300 m [N·m·s/rad]."""
    cfg = load_config(trust.REPO / "examples" / "demo" / "demo.toml")
    top = build_string(cfg.sections, trust.DEPTH_M).sections[0]
    j = np.pi * (top.od_m ** 4 - top.id_m ** 4) / 32.0
    return float(j * np.sqrt(top.shear_modulus_Pa * top.steel_density_kg_m3))


def cycle_text(frame: pd.DataFrame) -> str:
    """Bursts of the truth's bit above 10 RPM and their mean period, for the table."""
    t = frame["time_s"].to_numpy(float)
    moving = (frame["bit_rpm"].to_numpy(float) > 10.0).astype(np.int8)
    starts = t[1:][np.diff(moving) == 1]
    if starts.size < 2:
        return f"{starts.size} burst(s)"
    return f"{starts.size} bursts / {np.median(np.diff(starts)):.0f} s"


def status(seg: dict, rate: str) -> tuple[str, str]:
    """(status, reason) of a segment's μ_k, or of the well's consensus, against the truth
    (module docstring)."""
    mu, tol = seg["mu_k"], trust.MU_K_TOL[rate]
    if mu is None:
        return "withheld", "no μ_k: " + (seg["message"] or "")[:80]
    if seg["converged"]:
        within = abs(mu / MU_K - 1.0) <= tol
        return ("converged" if within else "FALSE"), ", ".join(seg["quality_flags"])
    reasons = [f for f in seg["quality_flags"] if f not in ("observer_starts_disagree",
                                                    "observer_deadlock_averted")]
    return "withheld", ", ".join(reasons) or ", ".join(seg["quality_flags"])


def run_case(kp: float, ki: float, rates, work: Path, zeta: float) -> list[dict]:
    name = f"kp{kp:g}-ki{ki:g}"
    folder = work / name
    folder.mkdir()
    spec = ({"mu_s": MU_S, "mu_k": MU_K, "kp_Nms_rad": kp * zeta, "ki_Nm_rad": ki}, {}, name)
    sim_cfg, est_cfg = trust._config(folder, name, spec, STAND)
    frame = pd.DataFrame(drillfric.simulate(sim_cfg).columns)
    cycles = cycle_text(frame)
    rows = []
    for rate in rates:
        t0 = time.perf_counter()
        summary = trust.run_logged(frame, rate, name, folder, est_cfg).summary
        segs = [g for g in summary["segments"] if g["status"] == "ok"]
        pooled = [p["mu_k"] for p in summary["pooled"]]
        well_row = {"mu_k": summary["mu_k"], "converged": summary["mu_k"] is not None,
                    "quality_flags": ["well consensus" + (f" with {len(pooled)} pool(s)" if pooled
                                                  else "")],
                    "message": "no converged segment"}
        for g in (segs or [{"mu_k": None, "converged": False, "quality_flags": [], "message":
                            "no segment estimated"}]) + [well_row]:
            st, why = status(g, rate)
            row = {"kp": kp, "ki": ki, "rate": rate, "cycles": cycles, "mu_k": g["mu_k"],
                   "status": st, "reason": why, "s": time.perf_counter() - t0}
            rows.append(row)
            err = "—" if g["mu_k"] is None else f"{100 * (g['mu_k'] / MU_K - 1):+.1f} %"
            mu = "—" if g["mu_k"] is None else f"{g['mu_k']:.3f}"
            print(f"| {kp:g}ζ | {ki:g} | {cycles} | {rate} | {MU_K} | {mu} | {err} | {st} | "
                  f"{why or '—'} | {row['s']:.0f} |", flush=True)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kp", default=",".join(f"{k:g}" for k in KP_ZETA),
                        help="k_p as multiples of ζ")
    parser.add_argument("--ki", default=",".join(f"{k:g}" for k in KI), help="k_i [N·m/rad]")
    parser.add_argument("--rates", default=",".join(RATES))
    args = parser.parse_args()
    zeta = impedance_Nms_rad()
    print(f"ζ = {zeta:.0f} N·m·s/rad; truth μ_s {MU_S}, μ_k {MU_K}; set-point {RPM:g} RPM; "
          f"{RECORD_S:g}-s records\n")
    print("| k_p | k_i [N·m/rad] | truth bit cycles | rate | truth μ_k | μ_k | error | "
          "status | reason | run [s] |")
    print("|" + "---|" * 10)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for kp in (float(k) for k in args.kp.split(",")):
            for ki in (float(k) for k in args.ki.split(",")):
                rows += run_case(kp, ki, args.rates.split(","), Path(tmp), zeta)
    count = {s: sum(r["status"] == s for r in rows) for s in ("converged", "withheld", "FALSE")}
    print(f"\n{len(rows)} segments: converged within tolerance {count['converged']}, "
          f"withheld with a reason {count['withheld']}, false claims {count['FALSE']}")


if __name__ == "__main__":
    main()
