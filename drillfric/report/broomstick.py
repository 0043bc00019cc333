"""Broomstick with measurements: the model's hook load and torque versus depth for a family
of friction factors, and what the rig measured on top (docs/reports.md "Broomstick").

Model lines come from the soft-string model (:func:`drillfric.torque_drag.broomstick`,
docs/theory.md §2) for pick-up, slack-off and rotating off bottom; measured points are one per
segment: its median hook load and mean rotating surface torque at its bit depth — from a
result directory's segments (``hookload_N``, ``surface_torque_mean_Nm``) or straight from a
log (:func:`measured_points_from_log`, used by ``drillfric td --broomstick WELL``).

The string-weight check (:func:`weight_check`). The hook carries the string *and* the
travelling block and top drive, so a measured off-bottom hook load is the string's
effective tension at surface plus a positive block weight. Rotating off bottom, the
soft-string model has no axial friction (σ = 0, docs/theory.md §2 step 3): its hook load is the
string's buoyed weight along the path, whatever μ is. A modelled rotating hook load above
the measured one at the same depth is therefore impossible; it means the configured string
is too heavy (linear masses, section lengths), the mud too light, or the hook-load channel
is off (units, zero). The check flags every off-bottom segment whose modelled rotating hook
load exceeds its measured median hook load by more than :data:`HOOKLOAD_TOLERANCE`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from drillfric.estimation.headline import STRING_WEIGHT_TOLERANCE
from drillfric.io.text import share
from drillfric.vocabulary import Kind, LoadCase

from .display import SI, Units

if TYPE_CHECKING:
    from drillfric.config import Config

#: Relative tolerance of the weight check (the run's, which flags it in summary.json).
HOOKLOAD_TOLERANCE = STRING_WEIGHT_TOLERANCE
#: Friction factors of the model lines.
DEFAULT_FRICTIONS = (0.1, 0.2, 0.3, 0.4, 0.5)
#: Load cases of the model lines.
CASES = ("rotating_off_bottom", "pick_up", "slack_off")
#: Columns of a measured-points table.
POINT_COLUMNS = ("segment_id", "kind", "bit_depth_m", "hookload_N", "surface_torque_Nm",
                 "hookload_model_N")


def measured_points(segments: pd.DataFrame) -> pd.DataFrame:
    """Measured points of a result's segments (those with a bit depth and a measurement).

    Missing columns (older results) give an empty table.
    """
    if "surface_torque_mean_Nm" not in segments or "hookload_N" not in segments:
        return pd.DataFrame(columns=list(POINT_COLUMNS))
    seg = segments[segments["bit_depth_m"].notna()
                   & (segments["hookload_N"].notna()
                      | segments["surface_torque_mean_Nm"].notna())]
    return pd.DataFrame({"segment_id": seg["id"].astype(int), "kind": seg["kind"],
                         "bit_depth_m": seg["bit_depth_m"], "hookload_N": seg["hookload_N"],
                         "surface_torque_Nm": seg["surface_torque_mean_Nm"],
                         "hookload_model_N": seg.get("hookload_model_N", np.nan)}
                        ).reset_index(drop=True)


def measured_points_from_windows(windows: pd.DataFrame) -> pd.DataFrame:
    """Measured points of a depth-indexed log: one per window of friction_log.parquet, its
    mean surface torque and hook load at its bit depth (docs/ingestion.md)."""
    need = ("segment_id", "kind", "bit_depth_m", "surface_torque_Nm", "hookload_N")
    if any(c not in windows for c in need):
        return pd.DataFrame(columns=list(POINT_COLUMNS))
    rows = windows[windows["bit_depth_m"].notna() & (windows["surface_torque_Nm"].notna()
                                                     | windows["hookload_N"].notna())]
    return pd.DataFrame({"segment_id": rows["segment_id"].astype(int), "kind": rows["kind"],
                         "bit_depth_m": rows["bit_depth_m"], "hookload_N": rows["hookload_N"],
                         "surface_torque_Nm": rows["surface_torque_Nm"],
                         "hookload_model_N": rows.get("hookload_model_N", np.nan)}
                        ).reset_index(drop=True)


def measured_points_from_log(surface: pd.DataFrame, cfg: Config) -> pd.DataFrame:
    """Measured points straight from a log: segment it (:mod:`drillfric.segmentation`) and
    take each rotating segment's median hook load and mean surface torque [N], [N·m].

    Segments without a known bit depth are left out (nowhere to draw them).
    """
    from drillfric.segmentation import segment

    rows = []
    for seg in segment(surface, cfg):
        if not np.isfinite(seg.bit_depth_m):
            continue
        part = surface.iloc[seg.i_start:seg.i_end]
        rows.append((seg.id, seg.kind, seg.bit_depth_m, _median(part, "hookload_N"),
                     _mean(part, "surface_torque_Nm"), np.nan))
    return pd.DataFrame(rows, columns=list(POINT_COLUMNS))


def _median(frame: pd.DataFrame, col: str) -> float:
    return float(frame[col].median()) if col in frame and frame[col].notna().any() else np.nan


def _mean(frame: pd.DataFrame, col: str) -> float:
    return float(frame[col].mean()) if col in frame and frame[col].notna().any() else np.nan


def model_table(cfg: Config, path, bit_depths_m, frictions=DEFAULT_FRICTIONS) -> pd.DataFrame:
    """The broomstick model lines (:func:`drillfric.torque_drag.broomstick`) of a config.

    ``path`` None: the assumed path of a well without survey (vertical with the nominal
    tortuosity, :func:`drillfric.wellpath.no_survey_path`).
    """
    from drillfric.torque_drag import broomstick
    from drillfric.wellpath import no_survey_path

    depths = np.asarray(bit_depths_m, dtype=float)
    if path is None:
        path = no_survey_path(float(depths.max()), cfg.tortuosity_rad_m)
    return broomstick(path, cfg.sections, depths, frictions, CASES,
                      mud_out_kg_m3=cfg.fluid.mud_density_kg_m3,
                      mud_in_kg_m3=cfg.inner_mud_density_kg_m3,
                      element_length_m=cfg.model.element_length_m)


def default_depths(cfg: Config, deepest_m: float, count: int = 40) -> np.ndarray:
    """Bit depths of the model lines: from just below the BHA to ``deepest_m``."""
    from drillfric.drillstring import build_string

    string = build_string(cfg.sections, deepest_m)
    shallowest = max(string.bit_depth_m - string.bha_top_m + 1.0, deepest_m / count)
    return np.linspace(min(shallowest, deepest_m), deepest_m, count)


def rotating_hookload(table: pd.DataFrame, depths_m) -> np.ndarray:
    """Modelled rotating off-bottom hook load at ``depths_m``, interpolated in the table
    (it does not depend on μ: no axial friction when rotating) [N]."""
    rot = table[table["load_case"] == LoadCase.ROTATING_OFF_BOTTOM]
    rot = rot[rot["friction_factor"] == rot["friction_factor"].min()].sort_values(
        "bit_depth_m")
    return np.interp(np.asarray(depths_m, dtype=float), rot["bit_depth_m"], rot["hookload_N"])


def weight_check(points: pd.DataFrame, table: pd.DataFrame | None = None,
                 tolerance: float = HOOKLOAD_TOLERANCE, units: Units = SI) -> dict:
    """The string-weight check (module docstring) over the off-bottom measured points
    (the warning's loads in display ``units``).

    Returns
    -------
    dict
        ``checked`` (segments compared), ``violations`` (segment ids whose modelled
        rotating hook load > (1 + tolerance) × measured), ``worst_ratio`` (largest
        modelled/measured, NaN when none compared), ``block_weight_N`` (median measured −
        modelled: the implied travelling-block weight, NaN when none compared) and
        ``warning`` (a sentence, or None).
    """
    off = points[(points["kind"] == Kind.OFF_BOTTOM) & points["hookload_N"].notna()]
    model = off["hookload_model_N"].to_numpy(float) if "hookload_model_N" in off else \
        np.full(len(off), np.nan)
    if table is not None and len(off) and not np.isfinite(model).any():
        # results without the segments' own modelled hook load (older ones, depth logs);
        # otherwise only the segments that have one count, as in summary.json (a skipped
        # segment's table value had made the report's worst case: issue 35 item 2)
        model = rotating_hookload(table, off["bit_depth_m"])
    good = np.isfinite(model) & (off["hookload_N"].to_numpy(float) > 0)
    measured, model, ids = (off["hookload_N"].to_numpy(float)[good], model[good],
                            off["segment_id"].to_numpy()[good])
    if not measured.size:
        return {"checked": 0, "violations": [], "worst_ratio": np.nan,
                "block_weight_N": np.nan, "warning": None}
    ratio = model / measured
    bad = ids[ratio > 1.0 + tolerance]
    warning = None
    if bad.size:
        k = int(np.argmax(ratio))
        force = units.label("force")
        warning = (f"string weight inconsistent with the hook load: in "
                   f"{share(bad.size, measured.size, 'off-bottom segment')} the modelled "
                   "rotating hook load "
                   f"exceeds the measured one by more than {tolerance:.0%} (worst: segment "
                   f"{ids[k]}, model {units.text(model[k], 'force')} {force} vs measured "
                   f"{units.text(measured[k], 'force')} {force}). The hook also carries the "
                   "block, so the model can only be lighter: check the string's linear "
                   "masses and lengths, the mud density and the hook-load channel's units.")
    return {"checked": int(measured.size), "violations": [int(i) for i in bad],
            "worst_ratio": float(ratio.max()),
            "block_weight_N": float(np.median(measured - model)), "warning": warning}
