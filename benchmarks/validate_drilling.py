"""Drilling records: the bit torque on bottom and the friction log from short off-bottom
rotations (issue 22 item 1; docs/validation.md).

Each record is the demo well's string and path (examples/demo) drilling five stands from
2150 m, 28 m apart: per stand an on-bottom stand (150 s at 60 RPM against a Coulomb bit
T_bit = μ_bit·WOB·D_bit/3, D_bit 0.2159 m, ROP 20 m/h), a 30-s connection-side stop, then
the off-bottom rotation before the connection (5 m off bottom, ``--rotations`` seconds of
set-point including the 10-s ramp), a 30-s connection. Truth μ_s 0.6, μ_k 0.25; noise
0.5 RPM / 300 N·m. The grid sweeps the off-bottom rotation (20–60 s) against three bit
laws (WOB 5, 12, 20 t with μ_bit 0.3, 0.6, 0.15), each logged at 100 Hz, 5 Hz, 1 Hz and
as 1-s means and run through the whole pipeline (:func:`drillfric.run`). A law
``WOB:μ_bit:r:ω_b`` makes the bit rate-weakening (docs/simulator.md, Bit:
T_bit(ω) = T_k·(1 + (r − 1)·exp(−|ω|/ω_b)), T_k = μ_bit·WOB·D_bit/3, ω_b in RPM). The
truth of each on-bottom segment is the bit's mean power over its mean speed over its stand
after the start-up, ⟨τ_bit·ω_bit⟩/⟨ω_bit⟩ (the truth file's ``bit_power_torque_Nm``;
docs/theory.md §2.3: the torque Teale's MSE and μ_bit describe; with stick-slip on a
rate-weakening bit it is not T_k, and not the time-mean ``bit_torque_time_mean_Nm``, which holds the
stuck bit's reaction torque). Scored:

- every off-bottom μ_k claimed (converged segments, pools = the friction log entries, the
  well's consensus): within 5 % (10 % at 1 Hz / 1-s means) or FALSE;
- every on-bottom segment: T_bit within 20 % of the plant's or its stated 95 % half-width
  covering the truth, else FALSE; null with its reason (``missing`` when a friction-log
  entry lies within reach yet no T_bit came);
- μ_bit and MSE likewise against the plant's (MSE truth: Teale with the plant's T_bit at the
  segment's mean speed and ROP).

Zero false claims is the line. Run: ``python benchmarks/validate_drilling.py [--rotations
20,30,45,60] [--laws 5:0.3,12:0.6,20:0.15,12:0.3:2:10] [--rates '100 Hz,1 Hz']`` (the
default grid, Coulomb bits only, 48 records, took ≈ 3 minutes on one shared core with warm
kernels, 27 Nov 2026).
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

import validate_trust as trust  # noqa: E402

import drillfric  # noqa: E402
from drillfric.estimation.bit_torque import teale_mse_Pa  # noqa: E402
from drillfric.io.writers import dumps_toml  # noqa: E402

MU_S, MU_K = 0.6, 0.25
RPM = 60.0
D_BIT_M = 0.2159
ROP_M_H = 20.0
ON_BOTTOM_S = 150.0
FIRST_M, STAND_M, STANDS = 2150.0, 28.0, 5
ROTATIONS_S = (20.0, 30.0, 45.0, 60.0)
#: Bit laws: WOB [t] : μ_bit (Coulomb bits; ``--laws`` may add r : ω_b [RPM]).
LAWS = ((5.0, 0.3), (12.0, 0.6), (20.0, 0.15))
RATES = ("100 Hz", "5 Hz", "1 Hz", "1-s means")
T_BIT_TOL = 0.20
G = 9.81


def scenario(rotation_s: float, wob_N: float) -> dict:
    """The stands of one drilling record (module docstring)."""
    stands, depth = [], FIRST_M
    for _ in range(STANDS):
        stands.append({"bit_depth_m": depth, "wob_N": wob_N, "rop_m_h": ROP_M_H,
                       "duration_s": ON_BOTTOM_S})
        drilled = depth + ROP_M_H / 3600.0 * ON_BOTTOM_S
        stands.append({"bit_depth_m": drilled - 5.0, "duration_s": rotation_s})
        depth += STAND_M
    return {"connection_s": 30.0, "defaults": {"rpm": RPM, "ramp_s": 10.0},
            "stand": stands}


def configs(folder: Path, name: str, rotation_s: float, wob_N: float, bit_mu: float,
            ratio: float = 1.0, weakening_rpm: float = 10.0) -> tuple[Path, Path]:
    spec = ({"mu_s": MU_S, "mu_k": MU_K, "bit_mu": bit_mu, "bit_diameter_m": D_BIT_M,
             "rpm_noise": 0.5, "torque_noise_Nm": 300.0, "bit_weakening_ratio": ratio,
             "bit_weakening_rpm": weakening_rpm}, {}, name)
    sim_cfg, est_cfg = trust._config(folder, name, spec, {"bit_depth_m": FIRST_M})
    (folder / "stand.toml").write_text(dumps_toml(scenario(rotation_s, wob_N)),
                                       encoding="utf-8")
    raw = tomllib.loads(est_cfg.read_text(encoding="utf-8"))
    raw["well"]["bit_diameter_m"] = D_BIT_M
    est_cfg.write_text(dumps_toml(raw), encoding="utf-8")
    return sim_cfg, est_cfg


def mu_status(mu: float | None, rate: str) -> str:
    if mu is None:
        return "withheld"
    return "ok" if abs(mu / MU_K - 1.0) <= trust.MU_K_TOL[rate] else "FALSE"


def covered(value, half_width, truth, tol) -> str:
    """ok when within ``tol`` of the truth or the half-width covers it, else FALSE."""
    if value is None:
        return "withheld"
    near = abs(value / truth - 1.0) <= tol
    return "ok" if near or abs(value - truth) <= (half_width or 0.0) else "FALSE"


def stand_truth(stands, t_s: float) -> float:
    """The bit torque [N·m] of the on-bottom stand holding time ``t_s``: its mean power over
    its mean speed, ⟨τ_bit·ω_bit⟩/⟨ω_bit⟩ (docs/theory.md §2.3; the torque MSE describes)."""
    for s in stands:
        if s.wob_N > 0 and s.t_start_s <= t_s <= s.t_end_s:
            return s.bit_power_torque_Nm
    raise ValueError(f"no on-bottom stand at {t_s:g} s")


def score(summary: dict, rate: str, stands, wob_N: float) -> dict:
    """Counts of one record's claims (module docstring); ``stands`` the simulation's truth."""
    log = summary["off_bottom_friction_log"]
    out = {"log": [(len(e["segment_ids"]), e["mu_k"]) for e in log],
           "log_status": [mu_status(e["mu_k"], rate) for e in log],
           "log_u": [e["mu_k_uncertainty"] for e in log],
           "well": mu_status(summary["mu_k"], rate), "well_mu_k": summary["mu_k"],
           "well_u": summary["mu_k_uncertainty"],
           "t_bit": [], "reasons": set()}
    for g in summary["segments"]:
        if g["kind"] != "on_bottom_rotating" or g["status"] != "ok":
            continue
        t_bit_true = stand_truth(stands, 0.5 * (g["t_start_s"] + g["t_end_s"]))
        bit_mu = 3.0 * t_bit_true / (wob_N * D_BIT_M)
        st = covered(g["bit_torque_Nm"], g["bit_torque_uncertainty_Nm"], t_bit_true,
                     T_BIT_TOL)
        if st == "withheld":
            out["reasons"].add((g["bit_torque_reason"] or "")[:70])
            st = "missing" if log else "withheld"
        mu_st = covered(g["mu_bit"], g["mu_bit_uncertainty"], bit_mu, T_BIT_TOL)
        mse_st = "withheld"
        if g["mse_Pa"] is not None:
            truth = teale_mse_Pa(wob_N, t_bit_true, g["surface_rpm_mean"], g["rop_m_h"],
                                 D_BIT_M)
            mse_st = covered(g["mse_Pa"], g["mse_uncertainty_Pa"], truth, T_BIT_TOL)
        out["t_bit"].append((g["bit_torque_Nm"], g["bit_torque_uncertainty_Nm"], st,
                             mu_st, mse_st, t_bit_true))
    return out


def run_case(rotation_s: float, law: tuple, rates, work: Path) -> list[dict]:
    wob_t, bit_mu, ratio, weakening_rpm = (*law, 1.0, 10.0)[:4]
    name = f"rot{rotation_s:g}-wob{wob_t:g}-mubit{bit_mu:g}-r{ratio:g}-{weakening_rpm:g}rpm"
    folder = work / name
    folder.mkdir()
    wob_N = wob_t * 1000.0 * G
    t_k = bit_mu * wob_N * D_BIT_M / 3.0
    sim_cfg, est_cfg = configs(folder, name, rotation_s, wob_N, bit_mu, ratio, weakening_rpm)
    simulation = drillfric.simulate(sim_cfg)
    stands = simulation.stands
    on_bottom = [s for s in stands if s.wob_N > 0]
    t_bit_true = float(np.mean([s.bit_power_torque_Nm for s in on_bottom]))
    stuck = float(np.mean([s.bit_stuck_fraction for s in on_bottom]))
    frame = pd.DataFrame(simulation.columns)
    rows = []
    for rate in rates:
        t0 = time.perf_counter()
        s = score(trust.run_logged(frame, rate, name, folder, est_cfg).summary, rate, stands,
                  wob_N)
        s |= {"rotation_s": rotation_s, "wob_t": wob_t, "bit_mu": bit_mu, "rate": rate,
              "ratio": ratio, "weakening_rpm": weakening_rpm, "t_k": t_k, "stuck": stuck,
              "s": time.perf_counter() - t0, "t_bit_true": t_bit_true}
        rows.append(s)
        print(line(s, t_bit_true), flush=True)
    return rows


def line(s: dict, t_bit_true: float) -> str:
    log = "; ".join(f"{n} st {mu:.3f} {st}" for (n, mu), st in zip(s["log"], s["log_status"],
                                                                     strict=True)) or "—"
    well = "—" if s["well_mu_k"] is None else f"{s['well_mu_k']:.3f} {s['well']}"
    bits = ", ".join("—" if t is None else f"{t / 1e3:.2f}±{u / 1e3:.2f} "
                     f"({true / 1e3:.2f}) {st}" for t, u, st, _, _, true in s["t_bit"])
    mu_mse = ", ".join(f"{m}/{e}" for _, _, _, m, e, _ in s["t_bit"])
    why = "; ".join(sorted(s["reasons"])) or "—"
    law = f"{s['wob_t']:g} t, {s['bit_mu']:g}"
    if s["ratio"] != 1.0:
        law += f", r {s['ratio']:g}/{s['weakening_rpm']:g} RPM"
    return (f"| {s['rotation_s']:g} | {law} | {s['rate']} | {log} | {well} | "
            f"{s['t_k'] / 1e3:.2f} | {t_bit_true / 1e3:.2f} (stuck {100 * s['stuck']:.0f} %) | "
            f"{bits} | {mu_mse} | {why} | {s['s']:.0f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rotations", default=",".join(f"{r:g}" for r in ROTATIONS_S),
                        help="off-bottom rotation per stand [s]")
    parser.add_argument("--laws", default=",".join(f"{w:g}:{m:g}" for w, m in LAWS),
                        help="bit laws WOB[t]:μ_bit, or WOB[t]:μ_bit:r:ω_b[RPM] for a "
                        "rate-weakening bit")
    parser.add_argument("--rates", default=",".join(RATES))
    parser.add_argument("--json", type=Path, help="also write the records to FILE")
    args = parser.parse_args()
    print(f"truth μ_s {MU_S}, μ_k {MU_K}; {STANDS} stands from {FIRST_M:g} m, {RPM:g} RPM, "
          f"{ON_BOTTOM_S:g} s on bottom per stand\n")
    print("| off-bottom rotation [s] | bit law | rate | friction log (stands, μ_k) | well "
          "μ_k | T_k [kN·m] | true T_bit ⟨τω⟩/⟨ω⟩ [kN·m] | T_bit ± 95 % (truth) [kN·m] per "
          "on-bottom segment | μ_bit/MSE | why withheld | run [s] |")
    print("|" + "---|" * 11)
    rows = []
    laws = [tuple(float(x) for x in law.split(":")) for law in args.laws.split(",")]
    if any(len(law) not in (2, 4) for law in laws):
        parser.error("a bit law is WOB:μ_bit or WOB:μ_bit:r:ω_b")
    with tempfile.TemporaryDirectory() as tmp:
        for rotation in (float(r) for r in args.rotations.split(",")):
            for law in laws:
                rows += run_case(rotation, law, args.rates.split(","), Path(tmp))
    summarise(rows)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1, default=_plain))


def _plain(value):
    """JSON for what the records hold beside plain values (sets of reasons, numpy floats)."""
    return sorted(value) if isinstance(value, set) else float(value)


def summarise(rows: list[dict]) -> None:
    """The totals under the table."""
    claims = [st for r in rows for st in r["log_status"] + [r["well"]]]
    bits = [t[2:] for r in rows for t in r["t_bit"]]
    count = {k: sum(b[0] == k for b in bits) for k in ("ok", "withheld", "missing", "FALSE")}
    derived = [st for b in bits for st in b[1:]]
    print(f"\n{len(rows)} records; friction-log and well μ_k: {claims.count('ok')} within "
          f"tolerance, {claims.count('FALSE')} false, {claims.count('withheld')} withheld; "
          f"{len(bits)} on-bottom segments: T_bit {count}; μ_bit/MSE: "
          f"{derived.count('ok')} ok, {derived.count('FALSE')} false")
    for key in sorted({(r["wob_t"], r["bit_mu"], r["ratio"], r["rate"]) for r in rows}):
        mine = [r for r in rows if (r["wob_t"], r["bit_mu"], r["ratio"], r["rate"]) == key]
        states = [t[2] for r in mine for t in r["t_bit"]]
        errors = [abs(t[0] / t[5] - 1.0) for r in mine for t in r["t_bit"] if t[0] is not None]
        logs = [mu for r in mine for _, mu in r["log"]]
        print(f"{key[0]:g} t, μ_bit {key[1]:g}, r {key[2]:g}, {key[3]}: T_bit "
              f"{states.count('ok')} ok / {states.count('withheld')} withheld / "
              f"{states.count('missing')} missing / {states.count('FALSE')} FALSE, median "
              f"error {100 * np.median(errors) if errors else float('nan'):.0f} %; friction "
              f"log μ_k {', '.join(f'{m:.3f}' for m in logs) or '—'}")
    for rotation in sorted({r["rotation_s"] for r in rows}):
        mine = [r for r in rows if r["rotation_s"] == rotation]
        sizes = sorted({n for r in mine for n, _ in r["log"]})
        errors = [abs(t[0] / t[5] - 1.0) for r in mine for t in r["t_bit"]
                  if t[0] is not None]
        print(f"rotation {rotation:g} s: {sum(bool(r['log']) for r in mine)}/{len(mine)} "
              f"records with a friction log (stands per entry {sizes or '—'}); T_bit "
              f"reported {len(errors)}, median error "
              f"{100 * np.median(errors) if errors else float('nan'):.0f} %, max "
              f"{100 * max(errors) if errors else float('nan'):.0f} %")


if __name__ == "__main__":
    main()
