"""Feasibility probe: the bit's speed on bottom with a bit boundary (issue 36 item 1).

Today every on-bottom bit-speed trace is withheld (docs/bit_speed.md, "On bottom"): the
seeded ensemble runs with a free bit and an *apparent* μ_k that holds the bit torque as
string friction. This probe asks whether the same ensemble with a Coulomb bit at the far
end (the observer kernel's ``bit_cap_rel``, :attr:`drillfric.torsional.Plant.bit_torque_cap_Nm`)
draws a trace that passes the window rule of docs/bit_speed.md ("Window by window"):

- a 30-s window is right when its trace mean is within max(2 RPM, 5 %) of the true bit's,
  or the truth's mean lies inside the band (the window means of the members' min and max);
  otherwise it is FALSE, and how far outside the band it lies is its "outside" error;
- "shown" windows are those the pipeline's own kinematic window check would not withhold
  (:func:`drillfric.estimation.chain._windows`, with the start-up withheld where μ_s was
  not identified); a trace is "kept" where the whole-segment kinematic check passes (or
  flags the phase approximate) and at most half its windows are withheld, as off bottom;
- the trace's RMS error after the start-up against the surface speed's taken as the bit's.

Records: :mod:`validate_drilling`'s drilling records (demo string and path, five stands
from 2150 m, 150 s on bottom at 60 RPM, 30-s off-bottom rotations; truth μ_s 0.6, μ_k
0.25), Coulomb bits WOB:μ_bit 5:0.3, 12:0.6, 20:0.15 and the rate-weakening 12:0.3:2:10
(r = 2, ω_b = 10 RPM), logged at 100 Hz, 5 Hz, 1 Hz and as 1-s means. Each record runs
through :func:`drillfric.run` (for the segments and the well-level T_bit of each on-bottom
segment, summary.json ``bit_torque_Nm``, its 95 % half-width and the friction-log μ_k it
used), then every on-bottom segment is re-estimated with
:func:`drillfric.estimation.chain.estimate_segment` (today's trace, free bit, apparent μ)
and its final ensemble re-run with a bit cap:

- ``free``: today's trace (cap 0, the segment's apparent μ_s seed and μ_k);
- ``true``: cap = the true bit's T_k (Coulomb), friction μ_s, μ_k the truth's;
- ``est``: cap = drillfric's T_bit, μ_k = the friction-log μ_k that T_bit rests on, μ_s =
  that μ_k plus the segment's apparent static excess (μ_s seed − μ_k: the bit cap is the
  same static and kinetic, so the string's excess is what the apparent fit saw);
- ``est±``: three caps T_bit − u, T_bit, T_bit + u (u its 95 % half-width) × the five μ_s
  members: one ensemble of 15 members, band over all of them;
- rate-weakening record only: ``T_k``, ``r·T_k`` (the law's bounds, truth μ),
  ``T_k..r·T_k``: both as one ensemble of 10 members, and ``T_k±30 %``: caps 0.7, 1 and
  1.3 × T_k as one ensemble of 15 (what members over T_bit ± its half-width would be where
  T_bit is right; drillfric's 95 % half-width was 14–67 % of T_bit on the Coulomb-and-r = 2
  records with T_bit ≥ 2 kN·m).

With ``--mu-s 0.25`` the string has no static excess (μ_s = μ_k): whatever stick-slip
there is, the bit drives it.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/probe_on_bottom_trace.py [--laws 12:0.6]
[--rates '100 Hz,5 Hz'] [--mu-s 0.25] [--rotation 60] [--json FILE]`` (the four laws at
100 and 5 Hz, 40 on-bottom segments, took 5 min 20 s on one shared core, 8 Dec 2026;
docs/bit_speed.md "On bottom: feasibility" has the results).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import validate_drilling as vd  # noqa: E402
import validate_trust as trust  # noqa: E402

import drillfric  # noqa: E402
from drillfric.estimation import bit_trace, chain, skew  # noqa: E402
from drillfric.estimation.bit_trace import window_grid  # noqa: E402
from drillfric.estimation.diagnostics import settled_mask  # noqa: E402
from drillfric.estimation.observer import ObserverRecord, ensemble_bit_speed  # noqa: E402
from drillfric.estimation.segment_data import SegmentData  # noqa: E402
from drillfric.estimation.settings import ChainSettings  # noqa: E402
from drillfric.units import RPM_TO_RAD_S  # noqa: E402
from drillfric.vocabulary import Kind  # noqa: E402

LAWS = ("5:0.3", "12:0.6", "20:0.15", "12:0.3:2:10")
ROTATION_S = 30.0
TOL_RPM, TOL_SHARE = 2.0, 0.05


def concat(records: list[ObserverRecord]) -> ObserverRecord:
    """One ensemble of the members of several records (same times)."""
    if len(records) == 1:
        return records[0]
    fields = ("mu_s", "mu_k", "surface_rad_s_est", "bit_rad_s_est", "bha_rad_s_est",
              "residual_rad_s", "surface_torque_est_Nm")
    return ObserverRecord(records[0].time_s,
                          *(np.concatenate([getattr(r, f) for r in records], axis=1)
                            for f in fields),
                          deadlock_events=np.concatenate([r.deadlock_events for r in records]))


def capped_trace(settings, models, caps_Nm, mu_s: float, mu_k: float, out_rate: float):
    """The final ensemble (5 members over μ_s ± 15 %) with each Coulomb bit cap of
    ``caps_Nm``, all as one ensemble: (time [s], weighted bit speed, band low, high) [rad/s]."""
    observer = models.observer
    records = []
    for cap in caps_Nm:
        obs = replace(observer, plant=replace(observer.plant, bit_torque_cap_Nm=float(cap)))
        records.append(chain._final_pass(settings, obs, models.meas, mu_s, mu_k, adapt=False,
                                         output_rate_hz=out_rate))
    final = concat(records)
    bit = ensemble_bit_speed(final, chain._memory_s(observer, models.meas),
                             settings.speed_noise_rad_s)
    return final.time_s, bit.rad_s, bit.low_rad_s, bit.high_rad_s


def grade(time_s, est, low, high, truth_t, truth_rpm, surface_rpm, shown_mask) -> dict:
    """Window rule and RMS of one trace (module docstring); speeds in rad/s except the truth
    (RPM on its own 100-Hz times) and ``surface_rpm`` (RPM at ``time_s``)."""
    est, low, high = (np.asarray(x) / RPM_TO_RAD_S for x in (est, low, high))
    truth_at = np.interp(time_s, truth_t, truth_rpm)
    grid = window_grid(float(time_s[0]), float(time_s[-1]) + float(np.median(np.diff(time_s))))
    rows = []
    for (a, b), shown in zip(grid, shown_mask, strict=True):
        m = (time_s >= a) & (time_s < b)
        mt = (truth_t >= a) & (truth_t < b)
        e, tr = float(est[m].mean()), float(truth_rpm[mt].mean())
        lo, hi = float(low[m].mean()), float(high[m].mean())
        ok = abs(e - tr) <= max(TOL_RPM, TOL_SHARE * abs(tr)) or lo <= tr <= hi
        rows.append({"a": a, "err": e - tr, "outside": max(lo - tr, tr - hi, 0.0), "ok": ok,
                     "shown": bool(shown), "surf_err": float(surface_rpm[m].mean()) - tr})
    late = settled_mask(time_s)
    rms = float(np.sqrt(np.mean((est[late] - truth_at[late]) ** 2)))
    rms_surface = float(np.sqrt(np.mean((surface_rpm[late] - truth_at[late]) ** 2)))
    shown = [r for r in rows if r["shown"]]
    return {"windows": len(rows), "shown": len(shown),
            "false_shown": sum(not r["ok"] for r in shown),
            "false_all": sum(not r["ok"] for r in rows),
            "worst_err": max((abs(r["err"]) for r in shown), default=float("nan")),
            "worst_outside": max((r["outside"] for r in shown), default=float("nan")),
            "worst_err_all": max(abs(r["err"]) for r in rows),
            "rms": rms, "rms_surface": rms_surface,
            "window_errs": [round(r["err"], 1) for r in rows]}


def shown_windows(settings, models, time_s, bit_rad_s, unknown) -> list[bool]:
    """Which 30-s windows the pipeline's kinematic window check lets through."""
    verdict = chain._windows(settings, models, time_s, bit_rad_s, unknown)
    grid = window_grid(float(time_s[0]), float(time_s[-1]) + float(np.median(np.diff(time_s))))
    return [(a, b) not in verdict.withheld for a, b in grid]


def segment_data(logged: pd.DataFrame, g: dict) -> SegmentData:
    rows = logged[(logged["time_s"] >= g["t_start_s"]) & (logged["time_s"] <= g["t_end_s"])]
    rows = rows[np.isfinite(rows["surface_rpm"]) & np.isfinite(rows["surface_torque_Nm"])]
    return SegmentData(rows["time_s"].to_numpy(float), rows["surface_rpm"].to_numpy(float),
                       rows["surface_torque_Nm"].to_numpy(float), float(g["bit_depth_m"]),
                       kind=Kind.ON_BOTTOM, wob_N=float(np.nanmedian(rows["wob_N"])),
                       bit_rpm=rows["bit_rpm"].to_numpy(float))


def probe_segment(settings, well, logged, g, frame, truth: dict, out_rate: float) -> list[dict]:
    """Every cap source's grade for one on-bottom segment."""
    data = segment_data(logged, g)
    est = chain.estimate_segment(settings, well.survey, data, output_rate_hz=out_rate)
    data2, _ = skew.correct(data, settings.torque_lag_s)
    models = chain.build_models(settings, well.survey, chain.while_moving(data2))
    t_rec = est.final.time_s
    settled = t_rec[settled_mask(t_rec)]
    unknown = () if est.mu_s_identifiable else ((t_rec[0], settled[0]),)
    sel = (frame["time_s"] >= g["t_start_s"] - 1.0) & (frame["time_s"] <= g["t_end_s"] + 1.0)
    truth_t = frame.loc[sel, "time_s"].to_numpy(float)
    truth_rpm = frame.loc[sel, "bit_rpm"].to_numpy(float)
    surface_rpm = np.interp(t_rec, models.meas.time_s, models.meas.surface_rad_s) / RPM_TO_RAD_S
    logging = chain.bit_speed_resolution(models)
    common = {"segment": g["id"], "resolved_by_logging": logging.resolved,
              "samples_per_cycle": logging.samples_per_cycle, "t_bit_est": g["bit_torque_Nm"],
              "t_bit_u": g["bit_torque_uncertainty_Nm"], "t_bit_true": truth["t_bit_power"],
              "mu_k_app": est.mu_k, "mu_s_seed_app": est.mu_s_seed,
              "stuck_true": float(np.mean(np.abs(truth_rpm) <= 1.0))}
    out = []

    def add(source, time_s, rad_s, low, high, **extra):
        shown = shown_windows(settings, models, time_s, rad_s, unknown)
        kin = bit_trace.check_segment_trace(models.string, models.meas, time_s, rad_s,
                                            settings.speed_noise_rad_s)
        whole = (kin.passed or kin.approximate) and sum(shown) >= (
            1.0 - bit_trace.MAX_WITHHELD_SHARE) * len(shown)
        out.append(common | {"source": source, "trace_kept": bool(whole)} | extra
                   | grade(time_s, rad_s, low, high, truth_t, truth_rpm, surface_rpm
                           if time_s is t_rec else np.interp(time_s, t_rec, surface_rpm),
                           shown))

    add("free", t_rec, est.bit.rad_s, est.bit.low_rad_s, est.bit.high_rad_s,
        mu=(est.mu_s_seed, est.mu_k))
    mu_true = (vd.MU_S, vd.MU_K)
    t_k, r = truth["t_k"], truth["ratio"]
    if r == 1.0:
        add("true", *capped_trace(settings, models, [t_k], *mu_true, out_rate), mu=mu_true)
    else:
        add("T_k", *capped_trace(settings, models, [t_k], *mu_true, out_rate), mu=mu_true)
        add("r·T_k", *capped_trace(settings, models, [r * t_k], *mu_true, out_rate),
            mu=mu_true)
        add("T_k..r·T_k", *capped_trace(settings, models, [t_k, r * t_k], *mu_true,
                                        out_rate), mu=mu_true)
        add("T_k±30 %", *capped_trace(settings, models, [0.7 * t_k, t_k, 1.3 * t_k],
                                      *mu_true, out_rate), mu=mu_true)
    if g["bit_torque_Nm"] is None:
        return out
    mu_k = g["bit_torque_mu_k"]
    mu_s = mu_k + max((est.mu_s_seed or est.mu_k) - est.mu_k, 0.0)
    t_bit, u = g["bit_torque_Nm"], g["bit_torque_uncertainty_Nm"] or 0.0
    add("est", *capped_trace(settings, models, [t_bit], mu_s, mu_k, out_rate), mu=(mu_s, mu_k))
    add("est±", *capped_trace(settings, models, [max(t_bit - u, 0.0), t_bit, t_bit + u],
                              mu_s, mu_k, out_rate), mu=(mu_s, mu_k))
    return out


def run_law(law: str, rates, work: Path) -> list[dict]:
    wob_t, bit_mu, ratio, weak_rpm = (*(float(x) for x in law.split(":")), 1.0, 10.0)[:4]
    name = f"probe-{law.replace(':', '_')}"
    folder = work / name
    folder.mkdir()
    wob_N = wob_t * 1000.0 * vd.G
    sim_cfg, est_cfg = vd.configs(folder, name, ROTATION_S, wob_N, bit_mu, ratio, weak_rpm)
    t0 = time.perf_counter()
    simulation = drillfric.simulate(sim_cfg)
    frame = pd.DataFrame(simulation.columns)
    t_k = bit_mu * wob_N * vd.D_BIT_M / 3.0
    print(f"# law {law}: simulated in {time.perf_counter() - t0:.0f} s", flush=True)
    rows = []
    for rate in rates:
        t0 = time.perf_counter()
        logged = trust.record(frame, rate, name)
        result = trust.run_logged(frame, rate, name, folder, est_cfg)
        well = drillfric.open_well(folder / f"{rate.replace(' ', '_')}.parquet",
                                   config=est_cfg, survey=folder / "path.survey.csv")
        settings = ChainSettings.from_config(well.config)
        out_rate = settings.observer.output_rate_hz
        for g in result.summary["segments"]:
            if g["kind"] != "on_bottom_rotating" or g["status"] != "ok":
                continue
            stand = next(s for s in simulation.stands if s.wob_N > 0
                         and s.t_start_s <= 0.5 * (g["t_start_s"] + g["t_end_s"]) <= s.t_end_s)
            truth = {"t_k": t_k, "ratio": ratio, "t_bit_power": stand.bit_power_torque_Nm}
            for row in probe_segment(settings, well, logged, g, frame, truth, out_rate):
                row |= {"law": law, "rate": rate, "stuck_stand": stand.bit_stuck_fraction}
                rows.append(row)
                print(line(row), flush=True)
        print(f"# {law} {rate}: {time.perf_counter() - t0:.0f} s", flush=True)
    return rows


def line(r: dict) -> str:
    t_bit = ("—" if r["t_bit_est"] is None
             else f"{r['t_bit_est'] / 1e3:.2f}±{r['t_bit_u'] / 1e3:.2f}")
    return (f"| {r['law']} | {r['rate']} | {r['segment']} | {r['source']} | "
            f"{r['stuck_stand']:.2f} | {t_bit} ({r['t_bit_true'] / 1e3:.2f}) | "
            f"{r['shown']}/{r['windows']} | {r['false_shown']} ({r['false_all']}) | "
            f"{r['worst_err']:.1f} / {r['worst_outside']:.1f} | {r['rms']:.1f} vs "
            f"{r['rms_surface']:.1f} | {r['window_errs']} | μ {r['mu'][0]:.3f}/{r['mu'][1]:.3f} |")


def summarise(rows: list[dict]) -> None:
    print("\n| law | rate | cap source | segments | windows shown/all | false shown (all) | "
          "worst shown window err [RPM] | worst outside band [RPM] | RMS trace | RMS surface |"
          " traces worse than surface |")
    print("|" + "---|" * 11)
    keys = []
    for r in rows:
        k = (r["law"], r["rate"], r["source"])
        if k not in keys:
            keys.append(k)
    for k in keys:
        mine = [r for r in rows if (r["law"], r["rate"], r["source"]) == k]
        shown = sum(r["shown"] for r in mine)
        print(f"| {k[0]} | {k[1]} | {k[2]} | {len(mine)} | {shown}/"
              f"{sum(r['windows'] for r in mine)} | {sum(r['false_shown'] for r in mine)} "
              f"({sum(r['false_all'] for r in mine)}) | "
              f"{_worst(mine, 'worst_err')} | {_worst(mine, 'worst_outside')} | "
              f"{min(r['rms'] for r in mine):.1f}–{max(r['rms'] for r in mine):.1f} | "
              f"{min(r['rms_surface'] for r in mine):.1f}–"
              f"{max(r['rms_surface'] for r in mine):.1f} | "
              f"{sum(r['rms'] > r['rms_surface'] for r in mine)} |")


def _worst(rows: list[dict], key: str) -> str:
    """The largest of ``key`` over the rows' shown windows ("—": none shown)."""
    values = [r[key] for r in rows if r["shown"]]
    return f"{max(values):.1f}" if values else "—"


def main() -> None:
    global ROTATION_S
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--laws", default=",".join(LAWS))
    parser.add_argument("--rates", default=",".join(vd.RATES))
    parser.add_argument("--mu-s", type=float, default=vd.MU_S,
                        help="the string's true μ_s (μ_k 0.25): 0.25 makes every stick-slip "
                        "bit-driven")
    parser.add_argument("--rotation", type=float, default=ROTATION_S,
                        help="off-bottom rotation per stand [s] (the friction log T_bit rests on)")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    vd.MU_S = args.mu_s
    ROTATION_S = args.rotation
    print("| law | rate | seg | cap source | stuck (stand) | T_bit est (true) [kN·m] | shown/"
          "windows | false shown (all) | worst err / outside band [RPM] | RMS trace vs "
          "surface [RPM] | window errors [RPM] |")
    rows = []
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for law in args.laws.split(","):
            rows += run_law(law, args.rates.split(","), Path(tmp))
    summarise(rows)
    print(f"\ntook {time.perf_counter() - t0:.0f} s")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1, default=float))


if __name__ == "__main__":
    main()
