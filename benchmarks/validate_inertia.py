"""Top-drive inertia (issue 34 item 2; docs/validation.md "Top-drive inertia").

drillfric's simulator (the demo well, a stand at 2300 m, μ_s 0.6, μ_k 0.25: stick-slip) runs
with a true top-drive inertia of 0.4–2.5× the 2900 kg·m² the estimator is configured with (a
gear change), logged at 100, 10, 5 and 1 Hz and as 1-s means, on the stands of
``validate_skew``: ``steps`` (set-point steps from rest), ``stick-slip`` (the creep stand cut to
its steady rotation on a stiff drive) and ``soft drive`` (a soft-torque drive whose surface
speed dips to ~0 between slips). The channels are stated in step (the demo's
``[channels] lag_s = 0``), so that nothing but the inertia check withholds the trace.

Every record runs through the whole pipeline (:func:`drillfric.run`) and is graded:

- inertia: a segment's identified inertia within ±25 % of the truth and its stated ±
  covering it, or "not identified" / "immaterial";
- μ_k within 5 % of the truth (or withheld);
- bit speed: every 30-s window of a trace shown has its mean within max(2 RPM, 5 %) of the
  truth's or the truth inside the band (or the trace is withheld);
- stick-slip statistics: a stated severity within max(0.1, 15 %) of the truth's.

With ``--unchecked`` the check's verdict is ignored (the trace shown as before issue 34 item
2): what it prevents, and which right numbers it withholds.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/validate_inertia.py [--quick] [--unchecked]
[--json FILE]`` (about 5 minutes on one core; ``--quick``: 10 Hz and 1-s means, 0.4, 1 and
2.5×).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
import tomllib
from collections import Counter
from dataclasses import replace
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from validate_skew import RATES, STANDS, STEADY_S, grade, record  # noqa: E402
from validate_trust import PLANTS, _config  # noqa: E402

import drillfric  # noqa: E402
from drillfric.estimation import chain  # noqa: E402
from drillfric.io.writers import dumps_toml  # noqa: E402

CONFIGURED = 2900.0
FACTORS = (0.4, 0.5, 1.0, 2.0, 2.5)
#: The issue's tolerance of an identified inertia.
INERTIA_TOL = 0.25


def simulate(stand: str, factor: float, folder: Path) -> tuple[pd.DataFrame, Path]:
    """The 100 Hz simulation of ``stand`` with a top drive ``factor`` × the configured
    inertia, and the estimator's configuration (the configured inertia, channels in step)."""
    folder.mkdir(parents=True)
    plant, spec = STANDS[stand]
    sim_cfg, est_cfg = _config(folder, plant, PLANTS[plant], spec)
    raw = tomllib.loads(sim_cfg.read_text(encoding="utf-8"))
    raw["rig"]["top_drive_inertia_kg_m2"] = factor * CONFIGURED
    sim_cfg.write_text(dumps_toml(raw), encoding="utf-8")
    est = tomllib.loads(est_cfg.read_text(encoding="utf-8"))
    assert est["rig"]["top_drive_inertia_kg_m2"] == CONFIGURED
    frame = pd.DataFrame(drillfric.simulate(sim_cfg).columns)
    if stand == "stick-slip":
        t = frame["time_s"]
        frame = frame[(t >= STEADY_S[0]) & (t <= STEADY_S[1])].reset_index(drop=True)
    return frame, est_cfg


def grade_inertia(result, truth_kg_m2: float) -> dict:
    """The inertia verdicts of the record's segments, and whether any stated one is false."""
    segs = [g for g in result.summary["segments"] if g["status"] == "ok"]
    sources = Counter(g.get("top_drive_inertia_source") for g in segs)
    stated = [(g["top_drive_inertia_kg_m2_identified"], g["top_drive_inertia_uncertainty_kg_m2"])
              for g in segs if g.get("top_drive_inertia_kg_m2_identified") is not None]
    ok = all(abs(v / truth_kg_m2 - 1.0) <= INERTIA_TOL and abs(v - truth_kg_m2) <= pm + 1e-9
             for v, pm in stated)
    share = max((g.get("top_drive_inertia_share") or 0.0 for g in segs), default=None)
    return {"inertia_sources": dict(sources), "inertia_stated": stated, "inertia_ok": ok,
            "inertia_share": share}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--json", type=Path)
    ap.add_argument("--unchecked", action="store_true",
                    help="ignore the inertia check's verdict (as before issue 34 item 2)")
    ap.add_argument("--table", type=Path, help="print the table of a --json file and exit")
    args = ap.parse_args()
    if args.table:
        _table_from(args.table)
        return
    if args.unchecked:
        checked = chain.top_drive_inertia
        chain.top_drive_inertia = lambda *a: replace(checked(*a), reason=None)
    rates = ("10 Hz", "1-s means") if args.quick else RATES
    factors = (0.4, 1.0, 2.5) if args.quick else FACTORS
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for stand in STANDS:
            for factor in factors:
                folder = Path(tmp) / f"{stand.replace(' ', '_')}_{factor}"
                frame, est_cfg = simulate(stand, factor, folder)
                for rate in rates:
                    data = folder / f"{rate.replace(' ', '_')}.parquet"
                    record(frame, rate, 0.0).to_parquet(data, index=False)
                    t0 = time.perf_counter()
                    result = drillfric.run(drillfric.open_well(
                        data, config=est_cfg, survey=folder / "path.survey.csv"))
                    row = {"stand": stand, "rate": rate, "factor": factor,
                           **grade(result, 0.0), **grade_inertia(result, factor * CONFIGURED),
                           "run_s": time.perf_counter() - t0}
                    row["false"] = row["false"] or not row["inertia_ok"]
                    rows.append(row)
                    print(_line(row), flush=True)
    print(f"\n{len(rows)} records, {sum(r['false'] for r in rows)} with a false number")
    print("\n" + table(rows))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1, default=float), encoding="utf-8")


def _table_from(path: Path) -> None:
    """Print the table of a ``--json`` file (``python benchmarks/validate_inertia.py --table
    FILE``)."""
    print(table(json.loads(path.read_text(encoding="utf-8"))))


def table(rows: list[dict]) -> str:
    """The docs/validation.md table: one line per stand and rate over the factors."""
    out = ["| stand | rate | inertia: identified / immaterial / not identified | μ_k "
           "(truth 0.25) | 30-s windows shown (false) | severities stated (false) | "
           "share |", "|---|---|---|---|---|---|---|"]
    keys = dict.fromkeys((r["stand"], r["rate"]) for r in rows)
    for stand, rate in keys:
        group = [r for r in rows if (r["stand"], r["rate"]) == (stand, rate)]
        src = Counter()
        for r in group:
            src.update(r["inertia_sources"])
        ident = src["confirmed"] + src["contradicted"]
        mus = [r["mu_k"] for r in group if r["mu_k"] is not None]
        withheld = len(group) - len(mus)
        mu = (f"{min(mus):.3f}–{max(mus):.3f}" if mus else "—") + (
            f", {withheld} withheld" if withheld else "")
        shown = sum(r["windows_shown"] for r in group)
        false = sum(r["windows_false"] for r in group)
        sev = sum(r["severity_stated"] for r in group)
        sev_false = sum(not r["severity_ok"] for r in group)
        shares = [r["inertia_share"] or 0.0 for r in group]
        out.append(f"| {stand} | {rate} | {ident} / {src['immaterial']} / "
                   f"{src['not identified']} | {mu} | {shown} ({false}) | {sev} ({sev_false}) "
                   f"| {min(shares):.2f}–{max(shares):.2f} |")
    return "\n".join(out)


def _line(r: dict) -> str:
    mu = "—" if r["mu_k"] is None else f"{r['mu_k']:.3f}"
    return (f"{r['stand']:<10} {r['rate']:<9} I_true {r['factor']:.1f}× → "
            f"{r['inertia_sources']} stated {r['inertia_stated']} share "
            f"{r['inertia_share'] or 0:.2f}; μ_k {mu} windows {r['windows_shown']} "
            f"({r['windows_false']} false) severity {r['severity_stated']} "
            f"{'FALSE' if r['false'] else 'ok'} ({r['run_s']:.1f} s)")


if __name__ == "__main__":
    main()
