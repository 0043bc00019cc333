"""Agreement of drillfric's rig-state classification with the published DSATS labels.

Reads the DSATS "Project Data Clarity" 1 Hz sample (``SampleData1.csv``) and its rig-state
labels (``RigStatesForSampleData1.txt``, one code per row, 2 = drilling), classifies every
sample with :func:`drillfric.segmentation.classify` and prints drilling-vs-not-drilling
accuracy, precision and recall of "drilling", a confusion table (our states × their codes)
and the segments found, on all the data and on the two halves (the thresholds were tuned
on the first half only, t < 25 000 s).

Run from the repository root (the data are read in place, never copied)::

    python benchmarks/validate_segmentation_dsats.py [DATA_DIR]

DATA_DIR defaults to ../shared/data/real/dsats_1hz. Results: docs/validation.md.
"""

from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.config import config_from_dict
from drillfric.segmentation import DRILLING_STATES, RIG_STATES, classify, segment
from drillfric.units import UREG, to_si

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data" / "real" / "dsats_1hz"
NULL = -999.25
#: Published code for drilling (the other codes are only compared as "not drilling").
DRILLING_CODE = 2
#: Thresholds for this rig, tuned on the first half of the record (t < 25 000 s).
SEGMENTATION = {
    "slips_hookload_N": float(to_si([40.0], "klbf", "force")[0]),  # empty hook ≈ 30–35 klbf
    "on_bottom_m": 0.3,
    "pumps_on_spm": 20.0,
    "start_bit_depth_m": float(to_si([3000.0], "ft", "length")[0]),  # the publishers' start
}
TUNING_END_S = 25_000.0
PSI_TO_PA = float(UREG.Quantity(1.0, "psi").to("Pa").magnitude)


def config():
    """Configuration used for the DSATS file: the example channels + the thresholds above."""
    return config_from_dict({"segmentation": dict(SEGMENTATION)},
                            file="benchmarks/validate_segmentation_dsats.py")


def read_dsats_raw(data_dir: Path = DATA) -> pd.DataFrame:
    """Headerless 12-column SampleData1.csv as canonical SI columns, one row per file row."""
    raw = pd.read_csv(data_dir / "SampleData1.csv", header=None).replace(NULL, np.nan)
    return pd.DataFrame({
        "time_s": raw[0].to_numpy(float),
        "block_position_m": to_si(raw[1], "ft", "length"),
        "flow_out_pct": raw[2].to_numpy(float),
        "hookload_N": to_si(raw[3], "klbf", "force"),
        "surface_rpm": raw[4].to_numpy(float),
        "pump_rate_spm": raw[5].to_numpy(float),  # pump 1, as examples/dsats_1hz.toml
        "standpipe_pressure_Pa": raw[7].to_numpy(float) * PSI_TO_PA,
        "surface_torque_Nm": to_si(raw[8], "ft.lbf", "torque"),
    })


def read_labels(data_dir: Path = DATA) -> np.ndarray:
    """Published rig-state code of every row of SampleData1.csv."""
    return np.loadtxt(data_dir / "RigStatesForSampleData1.txt").astype(int)


def load(data_dir: Path = DATA) -> tuple[pd.DataFrame, np.ndarray, str]:
    """Surface frame, the label of each of its rows, and which reader produced it.

    Uses ``drillfric.io.well.load_well`` with examples/dsats_1hz.toml when it is available
    (it drops duplicate timestamps and starts the time at 0: labels are matched by time),
    else :func:`read_dsats_raw`.
    """
    labels = read_labels(data_dir)
    raw_t = pd.read_csv(data_dir / "SampleData1.csv", header=None, usecols=[0])[0].to_numpy()
    try:
        from drillfric.io.well import load_well

        well = load_well(data_dir / "SampleData1.csv", config=REPO / "examples" / "dsats_1hz.toml")
        frame = well.surface
        rel = raw_t - raw_t[0]
        idx = np.clip(np.searchsorted(rel, frame["time_s"].to_numpy() - 1e-6), 0, rel.size - 1)
        if np.all(np.abs(rel[idx] - frame["time_s"].to_numpy()) < 1e-6):
            return frame.reset_index(drop=True), labels[idx], "drillfric.io.well.load_well"
    except (ImportError, AttributeError):
        pass
    return read_dsats_raw(data_dir), labels, "pandas reader (benchmark helper)"


def scores(pred: np.ndarray, truth: np.ndarray) -> dict:
    """Accuracy, precision and recall of boolean drilling predictions."""
    tp = int(np.sum(pred & truth))
    return {"rows": int(pred.size), "accuracy": float(np.mean(pred == truth)),
            "precision": tp / max(int(pred.sum()), 1), "recall": tp / max(int(truth.sum()), 1),
            "tp": tp, "fp": int(np.sum(pred & ~truth)), "fn": int(np.sum(~pred & truth)),
            "tn": int(np.sum(~pred & ~truth))}


def evaluate(data_dir: Path = DATA) -> dict:
    """Classify the DSATS record and compare with the labels (all, first and second half)."""
    frame, labels, reader = load(data_dir)
    cfg = config()
    states = classify(frame, cfg)
    pred = np.isin(states, DRILLING_STATES)
    truth = labels == DRILLING_CODE
    t = frame["time_s"].to_numpy()
    first = t < TUNING_END_S
    table = pd.crosstab(pd.Series([RIG_STATES[s] for s in states], name="drillfric"),
                        pd.Series(labels, name="DSATS code"))
    return {"reader": reader, "all": scores(pred, truth),
            "tuning half": scores(pred[first], truth[first]),
            "held-out half": scores(pred[~first], truth[~first]),
            "confusion": table, "segments": segment(frame, cfg, states=states)}


def main(argv: list[str]) -> int:
    data_dir = Path(argv[1]) if len(argv) > 1 else DATA
    if not (data_dir / "SampleData1.csv").is_file():
        print(f"DSATS data not found in {data_dir}")
        return 2
    result = evaluate(data_dir)
    print(f"reader: {result['reader']}")
    print("thresholds:", ", ".join(f"{k} = {v:g}" for k, v in SEGMENTATION.items()))
    print("| part | rows | accuracy | precision | recall | TP | FP | FN | TN |")
    print("|---|---|---|---|---|---|---|---|---|")
    for part in ("all", "tuning half", "held-out half"):
        s = result[part]
        print(f"| {part} | {s['rows']} | {s['accuracy']:.3f} | {s['precision']:.3f} | "
              f"{s['recall']:.3f} | {s['tp']} | {s['fp']} | {s['fn']} | {s['tn']} |")
    print("\nconfusion (rows: drillfric state, columns: DSATS code):")
    print(result["confusion"].to_string())
    segs = result["segments"]
    kinds = Counter((s.kind, s.status) for s in segs)
    print(f"\nsegments: {len(segs)}; " + "; ".join(f"{k} {st}: {n}"
                                                  for (k, st), n in sorted(kinds.items())))
    ok = [s for s in segs if s.status == "ok"]
    if ok:
        print(f"ok segments: duration median {np.median([s.duration_s for s in ok]):.0f} s, "
              f"bit depth {min(s.bit_depth_m for s in ok):.1f}–"
              f"{max(s.bit_depth_m for s in ok):.1f} m")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
