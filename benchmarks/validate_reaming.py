"""μ_k of reaming and back-reaming segments against the truth (issue 36 item 2; docs/validation.md).

Reaming and back-reaming stands are simulated on the demo well's string and path
(examples/demo): each stand turns in place for 20 s after a 10-s ramp, then moves along the
hole at 0.05–0.5 m/s (running in and pulling out) while it turns at 40–120 RPM, over at most
25 m, and stops. The plant splits each cell's Coulomb force between the torque and the drag
(docs/theory.md §3.3) with F_c of the rotating slack-off / pick-up case at the truth's μ_k
(docs/simulator.md, Reaming). Two truths, μ_k 0.18 and 0.35 (μ_s = 2 μ_k), neither the
configured T&D factor (0.25), so the estimator's fixed point on μ is exercised. Each record
is logged at 100, 10, 5 and 1 Hz and run through the whole pipeline (:func:`drillfric.run`);
every reaming / back-reaming segment's μ_k is graded:

- within: converged and within 5 % of the truth (10 % at 1 Hz);
- withheld: no μ_k, or a μ_k not converged (shown without an interval), with its reason;
- FALSE: converged and outside the tolerance.

Zero false claims is the line. The hook load of each estimated reaming segment is checked
against its model (the moving case at the fitted μ_k) as well.

Run: ``python benchmarks/validate_reaming.py [--quick] [--json FILE]`` (quick: one truth,
four stands, 10 and 1 Hz; the full sweep took ≈ 70 s with one numba thread). The
simulations use 1000 cells (Δx ≈ 2.3 m; the estimator's fit runs at Δx ≤ 5 m).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import validate_trust as trust  # noqa: E402

import drillfric  # noqa: E402

RATES = ("100 Hz", "10 Hz", "5 Hz", "1 Hz")
MU_K_TOL = {"100 Hz": 0.05, "10 Hz": 0.05, "5 Hz": 0.05, "1 Hz": 0.10}
TRUTHS = (0.18, 0.35)
#: (axial speed [m/s], RPM, bit depth at the start [m]) of the stands of each record.
STANDS = ((0.05, 40.0, 2100.0), (-0.05, 120.0, 2330.0), (0.1, 80.0, 2150.0),
          (-0.1, 40.0, 2380.0), (0.2, 120.0, 2200.0), (-0.2, 80.0, 2300.0),
          (0.5, 80.0, 2250.0), (-0.5, 120.0, 2400.0))
QUICK_STANDS = (STANDS[0], STANDS[5], STANDS[6], STANDS[3])
TRAVEL_M, MAX_MOTION_S = 25.0, 150.0
RAMP_S, DELAY_S = 10.0, 20.0


def stand(v: float, rpm: float, depth: float) -> dict:
    """A reaming stand: ramp, turn in place, move for min(25 m, 150 s) and stop."""
    motion = min(MAX_MOTION_S, TRAVEL_M / abs(v))
    return {"bit_depth_m": depth, "start": "ramp", "ramp_s": RAMP_S, "rpm": rpm,
            "duration_s": RAMP_S + DELAY_S + motion + 2.0, "axial_speed_m_s": v,
            "axial_delay_s": DELAY_S}


def grade(seg: dict | None, truth: float, rate: str) -> tuple[str, str, float | None]:
    """(status, reason, relative error) of one reaming segment (module docstring)."""
    if seg is None:
        return "withheld", "no reaming segment found", None
    mu = seg["mu_k"]
    if seg["status"] != "ok" or mu is None:
        return "withheld", (seg.get("message") or "")[:160], None
    err = mu / truth - 1.0
    if not seg["converged"]:
        flags = [f for f in seg["quality_flags"] if f != "pipe_moving"]
        return "withheld", "not converged: " + ", ".join(flags), err
    return ("within" if abs(err) <= MU_K_TOL[rate] else "FALSE"), "", err


def _moving_segment(segments: list[dict], t0: float, t1: float) -> dict | None:
    """The segment over most of the motion [t0, t1]: reaming / back-reaming, or whatever
    kind the run gave it (at 0.05 m/s, the gate ``ream_speed_m_s``, the motion may read as
    rotation in place: what the run then says is graded all the same)."""
    best, share = None, 0.0
    for g in segments:
        overlap = min(t1, g["t_end_s"]) - max(t0, g["t_start_s"])
        if overlap / (t1 - t0) > share:
            best, share = g, overlap / (t1 - t0)
    return best if share > 0.5 else None


def run_truth(mu_k: float, stands, rates, work: Path) -> list[dict]:
    name = f"ream-{mu_k:g}"
    folder = work / name
    folder.mkdir()
    spec = ({"mu_s": 2.0 * mu_k, "mu_k": mu_k}, {}, name)
    sim_cfg, est_cfg = trust._config(folder, name, spec, stand(*stands[0]))
    scenario = {"connection_s": 60.0, "stand": [stand(*s) for s in stands]}
    (folder / "stand.toml").write_text(trust.dumps_toml(scenario), encoding="utf-8")
    text = sim_cfg.read_text(encoding="utf-8")  # the sweep's cost: Δx ≈ 2.3 m (docstring)
    sim_cfg.write_text(text.replace("cells = 2000", "cells = 1000"), encoding="utf-8")
    t = time.perf_counter()
    sim = drillfric.simulate(sim_cfg)
    frame = pd.DataFrame(sim.columns)
    truth = sim.truth()["stands"]
    print(f"simulated μ_k = {mu_k}: {len(stands)} stands, {frame.shape[0]} rows in "
          f"{time.perf_counter() - t:.0f} s", flush=True)
    rows = []
    for rate in rates:
        t = time.perf_counter()
        summary = trust.run_logged(frame, rate, name, folder, est_cfg).summary
        spent = time.perf_counter() - t
        for s, (v, rpm, _) in zip(truth, stands, strict=True):
            seg = _moving_segment(summary["segments"], s["axial_start_s"], s["axial_end_s"])
            status, reason, err = grade(seg, mu_k, rate)
            hook = None
            if seg is not None and seg.get("hookload_N") and seg.get("hookload_model_N"):
                hook = seg["hookload_model_N"] / seg["hookload_N"] - 1.0
            row = {"mu_k_truth": mu_k, "axial_speed_m_s": v, "rpm": rpm, "rate": rate,
                   "kind": None if seg is None else seg["kind"],
                   "travel_m": s["travel_m"], "mu_k": None if seg is None else seg["mu_k"],
                   "error": err, "status": status, "reason": reason,
                   "hookload_error": hook, "run_s": spent}
            rows.append(row)
            print(_line(row), flush=True)
    return rows


def _line(r: dict) -> str:
    mu = "—" if r["mu_k"] is None else f"{r['mu_k']:.3f}"
    err = "—" if r["error"] is None else f"{100 * r['error']:+.1f} %"
    hook = "—" if r["hookload_error"] is None else f"{100 * r['hookload_error']:+.2f} %"
    return (f"| {r['mu_k_truth']} | {r['axial_speed_m_s']:+g} | {r['rpm']:g} | "
            f"{r['travel_m']:.0f} | {r['rate']} | {r['kind'] or '—'} | {mu} | {err} | {hook} "
            f"| {r['status']} | {r['reason'] or '—'} |")


def table(rows: list[dict]) -> str:
    """The summary line: records, within, withheld, false, worst error of a shown μ_k."""
    count = {s: sum(r["status"] == s for r in rows) for s in ("within", "withheld", "FALSE")}
    converged = [abs(r["error"]) for r in rows if r["status"] in ("within", "FALSE")]
    worst = f"{100 * max(converged):.1f} %" if converged else "—"
    return (f"{len(rows)} reaming records: within tolerance {count['within']}, withheld "
            f"with a reason {count['withheld']}, false {count['FALSE']}; worst error of a "
            f"converged μ_k {worst}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="one truth (μ_k 0.35), four stands, 10 and 1 Hz")
    parser.add_argument("--json", type=Path, help="write the rows to this file")
    args = parser.parse_args()
    truths = (0.35,) if args.quick else TRUTHS
    stands = QUICK_STANDS if args.quick else STANDS
    rates = ("10 Hz", "1 Hz") if args.quick else RATES
    print("| truth μ_k | v [m/s] | RPM | travel [m] | rate | segment | μ_k | error | hook "
          "load model − measured | status | reason |")
    print("|" + "---|" * 11)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for mu_k in truths:
            rows += run_truth(mu_k, stands, rates, Path(tmp))
    print("\n" + table(rows))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
