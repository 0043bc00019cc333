"""The hook load's own evidence (drillfric.hookload, docs/theory.md §2.1): the block weight
from the slips, the string weight from the rotating hook load, the check of the configured
string against them, and the calibration.

Analytic references: a vertical string's rotating hook load is its buoyed weight
ρ_steel·A·L·g·(1 − ρ_mud/ρ_steel) (docs/theory.md §2 step 1, σ = 0); a synthetic log with
known slips and hanging plateaus for the plateau finder; the demo well's first stand behind
a slips period with configured strings 30–40 % off. The DSATS regression (issue #22: a
string 3.4× heavier than its hook load gave μ_k in bold with no warning) is
tests/test_pipeline.py::test_dsats_runs_end_to_end (one 4-minute run of that log).
"""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric import hookload
from drillfric.config import config_from_dict, load_config
from drillfric.drillstring import G_ACCEL
from drillfric.estimation.consensus import consensus
from drillfric.result import Flag, SegmentRecord
from drillfric.torque_drag import TDSettings
from drillfric.vocabulary import Kind, Status
from tests.conftest import REPO

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

DEMO = REPO / "examples" / "demo"
PIPE = {"name": "pipe", "od_m": 0.127, "id_m": 0.1086}


def _vertical(mud=1200.0, sections=(PIPE,)):
    return config_from_dict({"survey": {"tortuosity_deg_30m": 0.0},
                             "fluid": {"mud_density_kg_m3": mud},
                             "string": {"sections": [{k: v for k, v in s.items() if v is not None}
                                                     for s in sections]}})


# --------------------------------------------------------------------------- physics
@pytest.mark.parametrize("mud", [0.0, 1200.0, 1800.0])
def test_vertical_string_weight_is_its_buoyed_weight(mud):
    """Vertical, one plain-steel section, bit off bottom: hook load = ρ_s·A·L·g·(1 − ρ_m/ρ_s)
    (to rounding: the march sums the same weights element by element)."""
    area = np.pi * (PIPE["od_m"] ** 2 - PIPE["id_m"] ** 2) / 4.0
    expected = 7850.0 * area * 1500.0 * G_ACCEL * (1.0 - mud / 7850.0)
    got = hookload.modelled_string_weight_N(TDSettings.from_config(_vertical(mud)), None,
                                            1500.0)
    assert got == pytest.approx(expected, rel=1e-9)


def test_scaled_sections_scale_the_buoyed_weight_only():
    """Scaling by c multiplies the buoyed weight by c exactly, diameters untouched."""
    sections = (PIPE, {"name": "dc", "od_m": 0.2032, "id_m": 0.0714, "length_m": 120.0})
    cfg = _vertical(1300.0, sections)
    for scale in (0.65, 1.4):
        scaled = hookload.scaled_sections(cfg.sections, scale, 1300.0, 1300.0)
        twin = _vertical(1300.0, scaled)
        weight = [hookload.modelled_string_weight_N(TDSettings.from_config(c), None, 2000.0)
                  for c in (twin, cfg)]
        assert weight[0] == pytest.approx(scale * weight[1], rel=1e-9)
        assert [s["od_m"] for s in scaled] == [s["od_m"] for s in cfg.sections]


@pytest.mark.parametrize(("hook", "block", "bad"), [
    (400e3, 150e3, False),   # string 250 kN = model
    (400e3, 150e3 - 30e3, True),  # 280 kN: 12 % heavier than the model
    (200e3, None, True),     # below the modelled string: it cannot be that heavy
    (240e3, None, False),    # within the tolerance below the model
    (1200e3, None, True),    # above model + the heaviest block
    (900e3, None, False),    # a heavy block is possible
])
def test_point_problem(hook, block, bad):
    assert bool(hookload.point_problem(hook, 250e3, block, 0.10)) is bad


# --------------------------------------------------------------------------- plateaus
def _slips_log(seed=3, slips=True):
    """1-Hz log: 60 s hanging still (block 150 + string 250 kN), 300 s rotating, 120 s in
    the slips (the first 40 s with the block moving up), 60 s hanging still; noise 1 kN."""
    rng = np.random.default_rng(seed)
    parts = [(60, 0.0, 400e3, 0.0), (300, 60.0, 400e3, 0.0),
             (40, 0.0, 150e3 if slips else 400e3, 0.5), (80, 0.0, 150e3 if slips else 400e3,
                                                         0.0),
             (60, 0.0, 400e3, 0.0)]
    rpm, hook, speed = (np.concatenate([np.full(n, v[i]) for n, *v in parts])
                        for i in range(3))
    block = 20.0 + np.cumsum(speed)
    return pd.DataFrame({"time_s": np.arange(rpm.size, dtype=float), "surface_rpm": rpm,
                         "hookload_N": hook + rng.normal(0.0, 1e3, rpm.size),
                         "block_position_m": block})


def test_plateau_finder_finds_the_slips_and_the_hanging_string():
    plateaus = hookload.find_plateaus(_slips_log(), load_config())
    levels = sorted(round(p.level_N / 1e3) for p in plateaus)
    assert levels[0] == 150 and levels[-1] == 400
    [slips] = [p for p in plateaus if p.level_N < 200e3]
    assert slips.t_start_s >= 400 and slips.t_end_s == 479  # the still part of the slips
    points = pd.DataFrame({"hookload_N": [400e3], "bit_depth_m": [2000.0]})
    block = hookload.block_weight(plateaus, points, configured=False)
    assert block.weight_N == pytest.approx(150e3, rel=0.01) and block.source == "log"
    evidence = block.evidence()
    assert evidence["rows"] == slips.rows and evidence["first_s"] == slips.t_start_s


def test_plateau_finder_streams():
    """Fed in chunks of 37 rows, the same plateaus as the whole log."""
    frame, cfg = _slips_log(), load_config()
    finder = hookload.PlateauFinder(cfg)
    for start in range(0, len(frame), 37):
        finder.feed(frame.iloc[start:start + 37])
    assert finder.close() == hookload.find_plateaus(frame, cfg)


def test_configured_slips_threshold_counts_the_moving_block():
    cfg = load_config(overrides={"segmentation.slips_hookload_N": 200e3})
    plateaus = hookload.find_plateaus(_slips_log(), cfg)
    block = hookload.block_weight(plateaus, pd.DataFrame(), configured=True)
    assert block.source == "slips_hookload_N"
    assert block.evidence()["first_s"] == 360 and block.weight_N == pytest.approx(150e3,
                                                                                  rel=0.01)


def test_a_hanging_string_is_not_the_slips():
    """No slips in the log: the lowest plateau is the string hanging, which lies above the
    rotating hook load less the lightest string's weight: the block weight is unknown."""
    plateaus = hookload.find_plateaus(_slips_log(slips=False), load_config())
    assert plateaus
    points = pd.DataFrame({"hookload_N": [400e3], "bit_depth_m": [2000.0]})
    block = hookload.block_weight(plateaus, points, configured=False)
    assert block.weight_N is None and "no slips" in block.reason


def test_stop_on_bottom_with_wob_held_is_not_the_slips():
    """Regression (issue 22, the 1 Hz heavy-WOB gap): a 12-t WOB held through a 10-s stop
    after drilling hangs the string 118 kN lighter than off bottom, more than the lightest
    string's weight at 2150 m; logged at 1 Hz the stop made a plateau that was taken for the
    slips, every friction factor of the well withheld (string weight "0.16×"). The bit on
    bottom (hole − bit depth ≤ on_bottom_m) is neither the slips nor the string hanging."""
    wob, free = 118e3, 775e3
    t = np.arange(0.0, 60.0)
    on = t < 30.0
    frame = pd.DataFrame({"time_s": t, "surface_rpm": np.zeros(t.size),
                          "hookload_N": np.where(on, free - wob, free),
                          "bit_depth_m": np.where(on, 2150.0, 2145.0),
                          "hole_depth_m": np.full(t.size, 2150.0)})
    frame.loc[29, "bit_depth_m"] = 2147.5  # the lift
    plateaus = hookload.find_plateaus(frame, load_config())
    assert [round(p.level_N / 1e3) for p in plateaus] == [775]  # the string hanging only
    points = pd.DataFrame({"hookload_N": [free], "bit_depth_m": [2145.0]})
    assert hookload.block_weight(plateaus, points, configured=False).weight_N is None
    off = frame.assign(hole_depth_m=2160.0)  # the same stop 10 m off bottom: a plateau
    assert len(hookload.find_plateaus(off, load_config())) == 2


# --------------------------------------------------------------------------- the check
def _record(i, hook, model, kind=Kind.OFF_BOTTOM):
    return SegmentRecord(id=i, kind=kind, bit_depth_m=2000.0, mu_k=0.25, mu_s_lower_bound=0.3,
                         converged=True, status=Status.OK, hookload_N=hook,
                         hookload_model_N=model, duration_s=200.0)


def test_judge_withholds_every_segment_when_the_string_is_contradicted():
    plateaus = [hookload.Plateau(0.0, 60.0, 61, 150e3)]
    records = [_record(1, 400e3, 400e3), _record(2, 410e3, 400e3),
               _record(3, 900e3, 1e6, Kind.ON_BOTTOM)]
    cfg = load_config(overrides={"segmentation.slips_hookload_N": 200e3})
    out = hookload.judge(records, plateaus, cfg)
    assert out.summary["verdict"] == "contradicted"
    assert out.summary["string_weight_ratio"] == pytest.approx(0.6375)
    for r in out.records:
        assert r.mu_k is None and r.mu_s_lower_bound is None and not r.converged
        assert Flag.HOOKLOAD_CONTRADICTS_STRING in r.quality_flags
    assert consensus(out.records)["mu_k"] is None
    assert "withheld" in out.mu_k_reason(None) and out.warnings


@pytest.mark.parametrize("level_N, slips_N", [(147295.2, 177929.0), (62e3, 80e3),
                                               (1.52e6, 2e6)])
def test_block_weight_message_states_the_summary_value_and_its_source(level_N, slips_N):
    """Issue 35 (DSATS): the message said "block weight 147 kN from slips_hookload_N" while
    the configuration showed slips_hookload_N 177.9 kN — two numbers for one name. The
    message states summary.json's block_weight_N (same number) and where it comes from (the
    in-slips plateaus), telling the threshold apart by its own value."""
    plateaus = [hookload.Plateau(0.0, 60.0, 61, level_N)]
    records = [_record(1, level_N + 100e3, 400e3), _record(2, level_N + 110e3, 400e3)]
    cfg = load_config(overrides={"segmentation.slips_hookload_N": slips_N})
    out = hookload.judge(records, plateaus, cfg)
    assert out.summary["block_weight_N"] == level_N
    assert out.summary["block_weight_source"] == "slips_hookload_N"
    said = " ".join([out.summary["reason"], *out.warnings])
    stated = re.findall(r"block weight ([0-9.]+) kN", said)
    assert stated and {float(x) for x in stated} == {float(f"{level_N / 1e3:.3g}")
                                                     if level_N < 1e5 else
                                                     round(level_N / 1e3)}
    assert "from slips_hookload_N" not in said
    assert "in-slips plateaus, those below segmentation.slips_hookload_N = " in said
    threshold = re.search(r"slips_hookload_N = ([0-9.]+) kN", said).group(1)
    assert float(threshold) != float(stated[0])


def test_rotation_in_the_slips_is_skipped_as_such_not_off_bottom():
    """Issue 35 (Volve F-4): top-drive make-up/break-out bursts with the string in the slips
    (hook load at the block's, 0.63 MN, against 1.5 MN hanging) were off-bottom rotations.
    Without segmentation.slips_hookload_N they are skipped, saying they are in the slips; a
    rotation with the string hanging, and the slips threshold configured, are left alone."""
    plateaus = [hookload.Plateau(0.0, 60.0, 5, 585e3), hookload.Plateau(100.0, 200.0, 8, 1.5e6),
                hookload.Plateau(300.0, 400.0, 8, 1.52e6)]
    records = [_record(1, 633e3, 1.2e6), _record(2, 1.48e6, 0.9e6)]
    out = hookload.judge(records, plateaus, load_config())
    slips, hanging = out.records
    assert slips.status is Status.SKIPPED and slips.mu_k is None
    assert slips.message.startswith("rotation in the slips: its hook load 633 kN")
    assert "not an off-bottom rotation" in slips.message
    assert hanging.status is Status.OK and "slips" not in (hanging.message or "")
    configured = hookload.judge(records, plateaus, load_config(
        overrides={"segmentation.slips_hookload_N": 1e6}))
    assert "rotation in the slips" not in (configured.records[0].message or "")
    # a shallow string hanging 20 kN above the block is no slips (lighter than any string)
    assert hookload.in_slips_reason(605e3, 300.0, plateaus) == ""
    assert hookload.in_slips_reason(600e3, 2600.0, plateaus) != ""


def test_volve_f4_make_up_rotations_are_in_the_slips(real_data, tmp_path):
    """Issue 35 on the real log: F-4's eight rotations (RigActivityCode 114, rotating in
    slips) are skipped as rotations in the slips, none left as a plain off-bottom stand."""
    witsml = real_data / "volve_witsml"
    config = tmp_path / "f4.toml"
    config.write_text('[well]\nname = "F-4"\n[segmentation]\nmax_gap_s = 60\n',
                      encoding="utf-8")
    result = CliRunner().invoke(cli, ["-q", "run", str(witsml / "F-4_time_log_1.xml"),
                                      "--config", str(config), "--survey",
                                      str(witsml / "F-4_trajectory.xml"), "--no-report",
                                      "--out", str(tmp_path / "out")])
    assert result.exit_code in (0, 1), result.output
    summary = json.loads((tmp_path / "out" / "F-4" / "summary.json").read_text())
    assert len(summary["segments"]) == 8
    for seg in summary["segments"]:
        assert seg["status"] == "skipped" and seg["mu_k"] is None
        assert seg["message"].startswith("rotation in the slips"), seg["message"]


def test_judge_keeps_a_consistent_string_and_withholds_a_lone_outlier():
    plateaus = [hookload.Plateau(0.0, 60.0, 61, 150e3)]
    records = [_record(1, 400e3, 250e3), _record(2, 405e3, 252e3), _record(3, 150e3, 250e3)]
    cfg = load_config(overrides={"segmentation.slips_hookload_N": 200e3})
    out = hookload.judge(records, plateaus, cfg)
    assert out.summary["verdict"] == "consistent"
    assert [r.mu_k for r in out.records] == [0.25, 0.25, None]
    assert out.summary["withheld_segments"] == [3]
    assert out.mu_k_reason(0.25) is None


# --------------------------------------------------------------------------- end to end
BLOCK_N = 150e3


@pytest.fixture(scope="module")
def weighed_stand(tmp_path_factory):
    """The demo's first stand (truth μ_k = 0.28, plant string of demo.toml) behind 60 s in
    the slips, with a 150-kN block on the hook throughout (the simulator's hook load has
    none): the log then holds its own calibration."""
    folder = tmp_path_factory.mktemp("weighed")
    stand = pd.read_csv(DEMO / "demo.csv")
    stand = stand[stand["time_s"] < 230.0].copy()
    rate = 20.0
    t = np.arange(0.0, 60.0, 1.0 / rate)
    noise = np.random.default_rng(22).normal(0.0, 2e3, t.size)
    slips = pd.DataFrame({"time_s": t, "surface_rpm": 0.0, "surface_torque_Nm": 0.0,
                          "hookload_N": BLOCK_N + noise, "bit_depth_m": 2210.0,
                          "hole_depth_m": 2215.0, "bit_rpm": 0.0, "string_torque_Nm": 0.0})
    stand["time_s"] += 60.0
    stand["hookload_N"] += BLOCK_N
    pd.concat([slips, stand], ignore_index=True).to_csv(folder / "well.csv", index=False)
    shutil.copy(DEMO / "demo.survey.csv", folder / "demo.survey.csv")
    base = (DEMO / "demo.toml").read_text()
    return folder, base[:base.index("\n[simulate]")].replace('data = "demo.csv"',
                                                               'data = "well.csv"')


def _masses(text: str, factor: float) -> str:
    """demo.toml with every section's linear mass × factor (collars given one)."""
    text = text.replace("linear_mass_kg_m = 41.41", f"linear_mass_kg_m = {41.41 * factor}")
    text = text.replace("linear_mass_kg_m = 74.5", f"linear_mass_kg_m = {74.5 * factor}")
    collar = 7850.0 * np.pi * (0.2032 ** 2 - 0.0714 ** 2) / 4.0
    return text.replace('name = "8in collars"', f'name = "8in collars"\nlinear_mass_kg_m = '
                        f"{collar * factor}")


def _run(folder, config_text, name):
    (folder / f"{name}.toml").write_text(config_text)
    result = CliRunner().invoke(cli, ["-q", "run", str(folder / "well.csv"), "--config",
                                      str(folder / f"{name}.toml"), "--out",
                                      str(folder / name), "--no-report"])
    assert result.exit_code == 0, result.output
    return json.loads((folder / name / "demo" / "summary.json").read_text())


def _ratio(folder, config_text, plant_text):
    """Configured string weight / plant string weight at 2210 m."""
    from drillfric.io.survey import read_survey

    path = read_survey(folder / "demo.survey.csv")
    weights = []
    for name, text in (("cfg", config_text), ("plant", plant_text)):
        (folder / f"{name}.toml").write_text(text)
        td = TDSettings.from_config(load_config(folder / f"{name}.toml"))
        weights.append(hookload.modelled_string_weight_N(td, path, 2210.0))
    return weights[0] / weights[1]


def test_correct_string_unchanged(weighed_stand):
    folder, base = weighed_stand
    summary = _run(folder, base, "right")
    check = summary["hookload"]
    assert check["verdict"] == "consistent", check
    assert check["block_weight_N"] == pytest.approx(BLOCK_N, rel=0.01)
    assert check["block_weight_source"] == "log"
    assert abs(check["string_weight_ratio"] - 1.0) < 0.02
    assert abs(summary["mu_k"] / 0.28 - 1.0) <= 0.05
    assert not any("hook" in w for w in summary["warnings"])


@pytest.mark.parametrize(("factor", "weight"), [(0.7, (0.6, 0.7)), (1.3, (1.3, 1.4))])
def test_wrong_string_withheld(weighed_stand, factor, weight):
    """A string 30–40 % lighter or heavier (buoyed) than the plant: μ_k withheld well-wide,
    with the reason in summary.json warnings, mu_k_reason and the segment's flags."""
    folder, base = weighed_stand
    text = _masses(base, factor)
    assert weight[0] <= _ratio(folder, text, base) <= weight[1]
    summary = _run(folder, text, f"wrong{factor}")
    assert summary["mu_k"] is None and summary["mu_s"] is None
    assert summary["mu_s_lower_bound"] is None
    assert "hook-load check" in summary["mu_k_reason"]
    assert summary["hookload"]["verdict"] == "contradicted"
    assert any("contradicts the configured string" in w for w in summary["warnings"])
    ok = [s for s in summary["segments"] if s["status"] == "ok"]
    assert ok and all(s["mu_k"] is None and "hookload_contradicts_string" in s["quality_flags"]
                      for s in ok)


def test_wrong_string_calibrated_when_allowed(weighed_stand):
    folder, base = weighed_stand
    text = _masses(base, 0.7) + "\n[hookload]\ncalibrate_string_weight = true\n"
    lighter = _ratio(folder, text, base)
    summary = _run(folder, text, "calibrated")
    check = summary["hookload"]
    assert check["verdict"] == "calibrated" and check["calibration_scale"] == pytest.approx(
        1 / lighter, rel=0.02)
    assert abs(summary["mu_k"] / 0.28 - 1.0) <= 0.05
    assert any("calibrated" in w for w in summary["warnings"])
    ok = [s for s in summary["segments"] if s["status"] == "ok"]
    assert all("string_weight_calibrated" in s["quality_flags"] for s in ok)


def _scaled(folder, text: str, scale: float, extra: str = "") -> str:
    """``text`` (demo.toml) with the string's buoyed weight × ``scale`` exactly
    (:func:`hookload.scaled_sections`), plus ``extra`` TOML."""
    from drillfric.io.writers import dumps_toml

    (folder / "base.toml").write_text(text)
    cfg = load_config(folder / "base.toml")
    sections = hookload.scaled_sections(cfg.sections, scale, cfg.fluid.mud_density_kg_m3,
                                        cfg.inner_mud_density_kg_m3)
    body = text[:text.index("[[string.sections]]")]
    return body + dumps_toml({"string": {"sections": [
        {k: v for k, v in s.items() if v is not None} for s in sections]}}) + extra


def test_string_8_percent_heavy_withheld(weighed_stand):
    """Regression (issue 22 sweep, docs/validation.md "Real wells, round two"): with the
    check's tolerance at 10 % a string configured 10 % heavy passed as consistent and μ_k
    came out 9 % low, converged. μ ∝ 1/W: the default tolerance is now the μ_k one, 5 %."""
    folder, base = weighed_stand
    summary = _run(folder, _scaled(folder, base, 1.08), "heavy8")
    assert summary["hookload"]["tolerance"] == 0.05
    assert summary["hookload"]["string_weight_ratio"] == pytest.approx(1 / 1.08, rel=0.02)
    assert summary["hookload"]["verdict"] == "contradicted" and summary["mu_k"] is None


@pytest.fixture(scope="module")
def hanging_stand(weighed_stand):
    """The weighed stand without its slips period: the block weight is not in the log."""
    folder, base = weighed_stand
    sub = folder / "no_slips"
    sub.mkdir()
    frame = pd.read_csv(folder / "well.csv")
    frame[frame["time_s"] >= 60.0].to_csv(sub / "well.csv", index=False)
    shutil.copy(folder / "demo.survey.csv", sub / "demo.survey.csv")
    return sub, base


def test_no_slips_is_unverified_not_consistent(hanging_stand):
    """Regression: without the slips a 25 % heavy string was reported `consistent` (μ_k 20 %
    low), then `unverified` with μ_k still printed (92 false μ_k in the no-slips arm of
    docs/validation.md "String weight"). The log cannot weigh the string, so every friction
    factor is withheld with the reason and the fix, for the right string as for the wrong."""
    folder, base = hanging_stand
    for name, text in (("unverified_heavy", _scaled(folder, base, 1.25)),
                       ("unverified_right", base)):
        summary = _run(folder, text, name)
        check = summary["hookload"]
        assert check["verdict"] == "unverified" and check["block_weight_N"] is None
        assert summary["mu_k"] is None and summary["mu_k_confidence"] == "withheld"
        assert "string weight is unverified" in summary["mu_k_reason"]
        assert "string_weight_unverified" in summary["quality_flags"]
        assert any("hookload.block_weight_N" in w for w in summary["warnings"])
        estimated = [s for s in summary["segments"] if s["status"] == "ok"]
        assert estimated and all(s["mu_k"] is None and s["mu_s"] is None
                                 and "string_weight_unverified" in s["quality_flags"]
                                 for s in estimated)
        # issue 35 item 6: no friction factor printed in a withheld segment's notes
        assert not any(re.search(r"μ_[ks][^;]{0,12}?(=|≥|≤|≈)\s*\d", s["message"] or "")
                       for s in estimated), [s["message"] for s in estimated]
        # issue 34 item 6: nor in estimates.parquet's μ_k(t) (the seeded rows); the starts'
        # rows keep the observer's adaptation (documented as traces, not a result)
        rows = pd.read_parquet(folder / name / "demo" / "estimates.parquet")
        seeded = rows["start_id"] == -1
        assert rows.loc[seeded, "mu_k"].isna().all()
        assert rows.loc[seeded, "mu_k_half_width"].isna().all()
        assert rows.loc[~seeded, "mu_k"].notna().any()


def test_no_slips_configured_block_weight_catches_wrong_string(hanging_stand):
    """hookload.block_weight_N stands in for the slips: a 25 % heavy string is withheld,
    the right one is consistent with its μ_k within 5 %."""
    folder, base = hanging_stand
    block = f"\n[hookload]\nblock_weight_N = {BLOCK_N}\n"
    wrong = _run(folder, _scaled(folder, base, 1.25, block), "block_wrong")
    assert wrong["hookload"]["verdict"] == "contradicted" and wrong["mu_k"] is None
    assert wrong["hookload"]["block_weight_source"] == "config"
    right = _run(folder, base + block, "block_right")
    assert right["hookload"]["verdict"] == "consistent"
    assert abs(right["mu_k"] / 0.28 - 1.0) <= 0.05


def test_no_hookload_channel_is_told_not_hidden(hanging_stand, tmp_path):
    """A log without a hook load cannot check the string either: its friction factors rest
    on the configured weight (the paper's method) — printed, but with low confidence, the
    flag string_weight_not_checked and a warning saying how to check it."""
    folder, base = hanging_stand
    bare = tmp_path / "bare"
    bare.mkdir()
    pd.read_csv(folder / "well.csv").drop(columns="hookload_N").to_csv(bare / "well.csv",
                                                                         index=False)
    shutil.copy(folder / "demo.survey.csv", bare / "demo.survey.csv")
    summary = _run(bare, base, "no_hook")
    assert summary["hookload"]["verdict"] == "not_checked"
    assert abs(summary["mu_k"] / 0.28 - 1.0) <= 0.05
    assert summary["mu_k_confidence"] == "low"
    assert "string_weight_not_checked" in summary["quality_flags"]
    assert any("string weight not checked" in w and "log the hook load" in w
               for w in summary["warnings"])


def test_drilling_only_log_without_block_weight_withholds_its_apparent_friction():
    """Regression (second reader, issue 22): a log with a hook load but only on-bottom
    rotation, no slips and no block weight fell into `not_checked` and printed its apparent μ
    with no flag — the same unweighable string weight the off-bottom case withholds. Now
    withheld as `string_weight_unverified`; with a block weight known it is `not_checked`
    (no off-bottom rotating hook load to weigh the string against) and says so."""
    from drillfric import hookload
    from drillfric.config import config_from_dict
    from drillfric.result import SegmentRecord
    from drillfric.vocabulary import Kind, Status

    records = [SegmentRecord(id=i, status=Status.OK, kind=Kind.ON_BOTTOM, mu_k=0.3,
                             bit_depth_m=2000.0, hookload_N=900e3, hookload_model_N=600e3)
               for i in (1, 2)]
    out = hookload.judge(records, [], config_from_dict({}))
    assert out.summary["verdict"] == "unverified"
    assert all(r.mu_k is None and "string_weight_unverified" in r.quality_flags
               for r in out.records)
    assert any("hookload.block_weight_N" in w for w in out.warnings)
    known = hookload.judge(records, [], config_from_dict({"hookload": {"block_weight_N": 3e5}}))
    assert known.summary["verdict"] == "not_checked"
    assert [r.mu_k for r in known.records] == [0.3, 0.3]
    assert any("string weight not checked" in w for w in known.warnings)


def test_report_titles_the_mu_traces_of_a_withheld_segment(hanging_stand):
    """Second reader: the report's evidence panel drew each observer start's μ̂ traces for a
    segment whose friction factors the check withheld, and the final pass ends at the
    withheld μ_k. The panel is now titled as withheld (HTML and PDF share mu_withheld)."""
    from drillfric.report.evidence import mu_withheld

    assert mu_withheld({"quality_flags": ["string_weight_unverified"]}).startswith(
        "friction factors withheld (string weight unverified)")
    assert mu_withheld({"quality_flags": ["pooled"]}) == ""
    folder, base = hanging_stand
    (folder / "report.toml").write_text(base)
    result = CliRunner().invoke(cli, ["-q", "run", str(folder / "well.csv"), "--config",
                                      str(folder / "report.toml"), "--out",
                                      str(folder / "with_report")])
    assert result.exit_code == 0, result.output
    html = (folder / "with_report" / "demo" / "report.html").read_text(encoding="utf-8")
    assert "friction factors withheld (string weight unverified)" in html
