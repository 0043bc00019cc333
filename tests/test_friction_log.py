"""Depth-indexed drilling logs: a static friction log by torque-and-drag back-calculation
(drillfric.estimation.friction_log and drillfric.runner.depth_log, docs/ingestion.md
"Depth-indexed logs").

The synthetic depth log is built from the soft-string model itself at a known friction
factor: each 30 m window holds five rows at depths k·30 + 3, 9, 15, 21, 27 m, so the median
depth is the middle row's and (the surface torque grows with depth) the median torque is
the torque at that depth — the back-calculation must return the friction factor to the
root finder's tolerance. The USROP F-5 log (../shared/data/real, read in place, skipped
when absent) checks a real log against the plausibility range its README gives.
"""

from __future__ import annotations

import json

import lasio
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.config import config_from_dict, read_toml
from drillfric.drillstring import build_string
from drillfric.errors import InputError
from drillfric.estimation.friction_log import bit_torque_Nm, friction_log
from drillfric.io.survey import read_survey
from drillfric.io.well import open_well
from drillfric.result import Flag
from drillfric.runner.depth_log import run_depth_log
from drillfric.torque_drag import solve
from drillfric.vocabulary import Kind, Method, Status
from tests.conftest import REPO, documented_result_files

MU = 0.27  # the synthetic log's friction factor
WOB_N = 80e3  # on-bottom windows' weight on bit
#: brentq's tolerances (xtol 1e-8, rtol 1e-10) bound the back-calculated μ's error; the model
#: is the one that made the data, so nothing else differs.
ROOT_TOL = 1e-6
FIRST, WINDOWS, WIDTH = 1800.0, 8, 30.0

SURVEY = ("md_m,inc_deg,azi_deg\n0,0,0\n500,0,0\n900,40,30\n2500,40,30\n")
CONFIG = """
[fluid]
mud_density_kg_m3 = 1250.0
[[string.sections]]
name = "5in DP"
od_m = 0.127
id_m = 0.1086
tool_joint_od_m = 0.1651
linear_mass_kg_m = 31.0
[[string.sections]]
name = "6.5in collars"
od_m = 0.1651
id_m = 0.0714
length_m = 150.0
[friction_log]
bit_mu = 0.3
bit_diameter_m = 0.2159
"""


def _rows(cfg, path) -> pd.DataFrame:
    """The synthetic log: windows alternate off bottom (WOB 0) and on bottom (WOB 80 kN)."""
    out = []
    for k in range(WINDOWS):
        on = k % 2 == 1
        for offset in (3.0, 9.0, 15.0, 21.0, 27.0):
            depth = FIRST + k * WIDTH + offset
            wob = WOB_N if on else 0.0
            td = solve(path, build_string(cfg.sections, depth), friction=MU,
                       load_case="rotating_on_bottom" if on else "rotating_off_bottom",
                       wob_N=wob, bit_torque_Nm=bit_torque_Nm(wob, cfg) if on else 0.0,
                       mud_out_kg_m3=cfg.fluid.mud_density_kg_m3,
                       element_length_m=cfg.model.element_length_m)
            out.append({"MD": depth, "RPM": 120.0, "TORQUE": td.surface_torque_Nm / 1e3,
                        "WOB": wob / 1e3, "HKLD": td.hookload_N / 1e3})
    return pd.DataFrame(out)


@pytest.fixture(scope="module")
def depth_log(tmp_path_factory):
    """A CSV depth log with its config and survey sidecars, and the rows it holds."""
    folder = tmp_path_factory.mktemp("depthlog")
    (folder / "d.survey.csv").write_text(SURVEY)
    (folder / "d.toml").write_text(CONFIG)
    cfg = config_from_dict(read_toml(folder / "d.toml"))
    rows = _rows(cfg, read_survey(folder / "d.survey.csv"))
    data = rows.rename(columns={"MD": "MD [m]", "RPM": "RPM [rpm]", "TORQUE": "TORQUE [kN.m]",
                                "WOB": "WOB [kN]", "HKLD": "HKLD [kN]"})
    data.to_csv(folder / "d.csv", index=False)
    return folder / "d.csv", rows


def _check_recovered(records, *, apparent: bool = False):
    assert [r.status for r in records] == [Status.OK] * WINDOWS
    assert [r.kind for r in records] == [Kind.OFF_BOTTOM, Kind.ON_BOTTOM] * (WINDOWS // 2)
    np.testing.assert_allclose([r.bit_depth_m for r in records],
                               FIRST + WIDTH * np.arange(WINDOWS) + 15.0)
    for r in records:
        assert r.method is Method.TD_BACKCALC and r.mu_td == r.mu_k
        assert r.mu_s is None and not r.mu_s_identifiable and "no observer" in r.message
        assert (Flag.BIT_TORQUE_IN_FRICTION in r.quality_flags) == (r.kind is Kind.ON_BOTTOM)
        if not (apparent and r.kind is Kind.ON_BOTTOM):
            assert r.mu_k == pytest.approx(MU, abs=ROOT_TOL)


def test_friction_log_recovers_the_friction_factor_of_a_synthetic_depth_log(depth_log):
    well = open_well(depth_log[0])
    assert well.depth_indexed and well.channels["measured_depth_m"].column == "MD [m]"
    _check_recovered(friction_log(well))


def test_apparent_friction_holds_the_bit_torque_over_T_N(depth_log):
    """With no bit torque separated (bit_mu = 0), a rotating string's surface torque is
    linear in μ (soft string, σ = 0: docs/theory.md §2), T = T_bit + μ·T_N, so the apparent
    factor is μ + T_bit/T_N."""
    well = open_well(depth_log[0], overrides={"friction_log.bit_mu": 0.0})
    records = friction_log(well)
    _check_recovered(records, apparent=True)
    t_bit = 0.3 * WOB_N * 0.2159 / 3.0
    for r in records:
        if r.kind is Kind.ON_BOTTOM:
            assert r.mu_k == pytest.approx(MU + t_bit / r.T_N_Nm, abs=ROOT_TOL)


def test_depth_log_windows_follow_the_measured_depth_column(depth_log):
    """Regression (issue 15): a depth log run through the hint of the old refusal gave every
    segment one fake depth (the survey's last station); each window is at its own depth."""
    records = friction_log(open_well(depth_log[0]))
    depths = [r.bit_depth_m for r in records]
    assert len(set(depths)) == WINDOWS and min(depths) > FIRST and max(depths) < 2100.0


def test_a_depth_column_is_never_read_as_time(depth_log, tmp_path):
    """Regression (issue 15): mapping time to the measured depth, as the old hint invited,
    ran with exit 0 and nonsense; it is now one line saying the log is depth-indexed."""
    (tmp_path / "c.toml").write_text(CONFIG + '[channels]\ntime = { column = "MD [m]" }\n')
    with pytest.raises(InputError, match="is a measured depth, not a time"):
        open_well(depth_log[0], config=tmp_path / "c.toml")


def test_missing_index_names_both_kinds_of_log(tmp_path):
    path = tmp_path / "x.csv"
    path.write_text("RPM,TORQUE\n60,10\n60,11\n")
    with pytest.raises(InputError, match=r"\[channels\] measured_depth"):
        open_well(path)


def _las(path, rows: pd.DataFrame):
    las = lasio.LASFile()
    las.append_curve("DEPT", rows["MD"].to_numpy(), unit="M")
    for name, unit in (("RPM", "RPM"), ("TORQUE", "KN.M"), ("WOB", "KN"), ("HKLD", "KN")):
        las.append_curve(name, rows[name].to_numpy(), unit=unit)
    las.write(str(path), version=2.0)


def _witsml(path, rows: pd.DataFrame):
    """A WITSML 1.4.1 depth log (index type measured depth)."""
    names, units = "DEPTH,SURF_RPM,TORQUE,WOB", "m,c/s,kN.m,kN"
    curves = "".join(f'<logCurveInfo uid="{m}"><mnemonic>{m}</mnemonic><unit>{u}</unit>'
                     "<typeLogData>double</typeLogData></logCurveInfo>"
                     for m, u in zip(names.split(","), units.split(","), strict=True))
    data = "".join(f"<data>{r.MD!r},{r.RPM / 60!r},{r.TORQUE!r},{r.WOB!r}</data>"
                   for r in rows.itertuples())
    path.write_text('<?xml version="1.0" encoding="UTF-8"?><logs xmlns="http://www.witsml.org/'
                    'schemas/1series" version="1.4.1.1"><log uidWell="W" uidWellbore="B" '
                    'uid="D"><nameWell>W</nameWell><name>Depth</name><indexType>measured '
                    "depth</indexType><indexCurve>DEPTH</indexCurve><nullValue>-999.25"
                    f"</nullValue>{curves}<logData><mnemonicList>{names}</mnemonicList>"
                    f"<unitList>{units}</unitList>{data}</logData></log></logs>")


@pytest.mark.parametrize("fmt", ["las", "xml", "parquet"])
def test_depth_logs_of_every_format_give_the_friction_log(depth_log, tmp_path, fmt):
    """LAS (index curve DEPT) and WITSML (index type measured depth) are depth-indexed by
    their reader; a Parquet table by its measured-depth column."""
    rows = depth_log[1]
    path = tmp_path / f"d.{fmt}"
    if fmt == "las":
        _las(path, rows)
    elif fmt == "xml":
        _witsml(path, rows)
    else:
        rows.rename(columns={"MD": "measured_depth_m", "TORQUE": "TORQUE [kN.m]",
                             "WOB": "WOB [kN]", "HKLD": "HKLD [kN]"}).to_parquet(path)
    folder = depth_log[0].parent
    well = open_well(path, config=folder / "d.toml", survey=folder / "d.survey.csv")
    assert well.depth_indexed
    _check_recovered(friction_log(well))


def test_run_writes_the_result_files_of_a_time_log(depth_log, tmp_path):
    path = depth_log[0]
    result = CliRunner().invoke(cli, ["run", str(path), "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    assert "friction log of a depth-indexed log, 8 windows of 30 m" in result.output
    assert "no observer" in result.output
    folder = tmp_path / "out" / "d"
    summary = json.loads((folder / "summary.json").read_text())
    binding = {"well", "drillfric_version", "mu_s", "mu_k", "mu_s_lower_bound", "segments",
               "inputs", "config", "assumed", "counts", "warnings", "run_time_s"}
    assert binding <= set(summary) and summary["index"] == "depth"
    assert summary["mu_k"] == pytest.approx(MU, abs=ROOT_TOL)  # off-bottom consensus
    assert summary["friction_log"]["mu_apparent"] == pytest.approx(MU, abs=ROOT_TOL)
    assert summary["friction_log"]["mu_k_reason"] is None
    assert any("no observer" in w for w in summary["warnings"])
    # its μ rests on the configured string: told, not hidden (docs/theory.md §2.1)
    assert summary["hookload"]["verdict"] == "not_checked"
    assert "string_weight_not_checked" in summary["quality_flags"]
    assert summary["mu_k_confidence"] == "low"
    assert any("string weight not checked" in w for w in summary["warnings"])
    segments = pd.read_parquet(folder / "segments.parquet")
    assert list(segments["method"]) == ["td_backcalc"] * WINDOWS
    assert segments["mu_s"].isna().all()
    assert len(pd.read_parquet(folder / "estimates.parquet")) == 0
    table = pd.read_parquet(folder / "friction_log.parquet")
    np.testing.assert_allclose(table["mu"], MU, atol=ROOT_TOL)
    profiles = pd.read_parquet(folder / "profiles.parquet")
    assert set(profiles["segment_id"]) == set(range(1, WINDOWS + 1))
    assert (folder / "wellpath.parquet").is_file() and (folder / "report.html").is_file()
    assert {p.name for p in folder.iterdir()} <= documented_result_files()  # issue 35
    # issue 35 item 9: nothing of the dynamic estimate in a depth log's report — no creep
    # break-over advice, no friction law, no "withheld" badge for μ_k
    html = (folder / "report.html").read_text(encoding="utf-8")
    assert 'id="mu-s-advice"' not in html and "step law" not in html
    assert 'id="headline-confidence">withheld' not in html


def _with_columns(depth_log, folder, drop=(), **columns):
    """The synthetic depth log written to ``folder/d.csv`` with ``columns`` added (name →
    values) and ``drop`` removed, beside the fixture's config and survey."""
    source = depth_log[0]
    data = pd.read_csv(source).drop(columns=list(drop)).assign(**columns)
    data.to_csv(folder / "d.csv", index=False)
    for sidecar in ("d.toml", "d.survey.csv"):
        (folder / sidecar).write_text((source.parent / sidecar).read_text())
    return folder / "d.csv"


def test_drilled_rows_logging_zero_wob_are_on_bottom_not_off_bottom(depth_log, tmp_path):
    """Regression (issue 15 item 3): USROP F-5, a log of on-bottom drilling only, logs WOB
    ≈ 0 (0.01 kkgf) over 731 rows drilled at 7–79 m/h; WOB alone labelled three windows
    "rotating off bottom" and their apparent on-bottom μ became the summary's off-bottom μ_k
    (0.168). Here every row makes hole (ROP 20 m/h) and half the windows log WOB 0: every
    window is on bottom (apparent, flagged), there is no off-bottom μ_k, and the summary says
    why. The windows logging WOB 0 were made with no WOB or bit torque at the bit, which the
    back-calculation then also puts there, so μ is still recovered to the root tolerance."""
    rows = len(depth_log[1])
    path = _with_columns(depth_log, tmp_path, **{"ROP [m/h]": np.full(rows, 20.0)})
    well = open_well(path)
    assert well.channels["rop_m_s"].column == "ROP [m/h]"
    result = run_depth_log(well)
    records = friction_log(well)
    assert [r.kind for r in records] == [Kind.ON_BOTTOM] * WINDOWS
    assert all(Flag.BIT_TORQUE_IN_FRICTION in r.quality_flags for r in records)
    np.testing.assert_allclose([r.mu_k for r in records], MU, atol=ROOT_TOL)
    assert result.summary["mu_k"] is None
    assert "no rotating row is off bottom" in result.summary["friction_log"]["mu_k_reason"]
    light = (depth_log[1]["WOB"] == 0).sum()
    assert any(f"on bottom in {light} of {rows} rows that log WOB ≤ 10 kN" in note
               for note in result.summary["assumed"])
    text = CliRunner().invoke(cli, ["run", str(path), "--out", str(tmp_path / "out"),
                                    "--no-report"])
    assert text.exit_code == 0, text.output
    assert "μ off bottom: none (no rotating row is off bottom" in text.output


def test_zero_wob_where_the_hole_did_not_advance_is_off_bottom(depth_log, tmp_path):
    """The counterpart: a logged ROP of 0 with WOB 0 (no hole made) leaves WOB to decide, so
    those windows stay off bottom and give the string's kinetic factor."""
    rop = np.where(depth_log[1]["WOB"] > 0, 20.0, 0.0)
    records = friction_log(open_well(_with_columns(depth_log, tmp_path, **{"ROP [m/h]": rop})))
    _check_recovered(records)


def test_depth_log_without_rop_wob_or_hole_depth_has_an_unknown_load_case(depth_log,
                                                                          tmp_path):
    """Nothing in the data tells the load case: every window is counted on bottom (apparent
    friction, never the off-bottom μ_k) and the summary and each window say it is unknown."""
    result = run_depth_log(open_well(_with_columns(depth_log, tmp_path, drop=["WOB [kN]"])))
    kinds = {seg["kind"] for seg in result.summary["segments"]}
    assert kinds == {Kind.ON_BOTTOM.value} and result.summary["mu_k"] is None
    assert result.summary["friction_log"]["mu_k_reason"] is not None
    assert any(f"load case unknown in {5 * WINDOWS} of {5 * WINDOWS} rows" in note
               for note in result.summary["assumed"])
    assert all("load case unknown in 5 of 5 rows" in seg["message"]
               for seg in result.summary["segments"])


def test_run_depth_log_in_memory_writes_nothing(depth_log, tmp_path):
    result = run_depth_log(open_well(depth_log[0]))
    assert result.out_dir is None and result.failed == 0 and len(result.segments) == WINDOWS
    assert result.estimates.empty


def test_inspect_says_the_log_is_depth_indexed(depth_log):
    text = CliRunner().invoke(cli, ["inspect", str(depth_log[0])])
    assert text.exit_code == 0, text.output
    assert "depth-indexed log" in text.output
    assert "windows    8 of 30 m: 8 usable (4 off bottom rotating, 4 on bottom rotating)" \
        in text.output
    doc = json.loads(CliRunner().invoke(cli, ["inspect", str(depth_log[0]), "--json"]).output)
    assert doc["index"] == "depth" and doc["rate_hz"] is None and doc["rows"] == 5 * WINDOWS
    assert doc["channels"]["measured_depth_m"]["column"] == "MD [m]"
    assert doc["md_start_m"] == FIRST + 3.0


def test_fleet_runs_depth_logs(depth_log, tmp_path):
    result = CliRunner().invoke(cli, ["fleet", str(depth_log[0].parent), "--out",
                                      str(tmp_path / "fleet"), "--workers", "1",
                                      "--no-report"])
    assert result.exit_code == 0, result.output
    table = pd.read_parquet(tmp_path / "fleet" / "fleet_summary.parquet")
    assert set(table["method"]) == {"td_backcalc"}


# --------------------------------------------------------------------------- real data
def test_usrop_f5_gives_a_plausible_friction_log(real_data):
    """USROP F-5, 8½in section, with the string of examples/usrop_f5.toml (an assumption)
    and the operator's survey. The data's README: on-bottom drilling only, and a 5½in DP /
    ~150 m BHA soft-string inversion gives apparent factors around 0.13–0.19 (plausibility,
    not truth); ours also carry the whole bit torque (bit_mu = 0), so the band is widened to
    0.25 upwards. Every window is on bottom, including the rows that log WOB below the
    on-bottom threshold while the hole advanced (issue 15 item 3), counted from the raw file."""
    path = real_data / "volve_usrop_f5" / "USROP_F-5_depth.csv"
    well = open_well(path, config=REPO / "examples" / "usrop_f5.toml",
                     survey=real_data / "volve_surveys" / "F-5_ACTUAL.txt")
    assert well.depth_indexed
    summary = run_depth_log(well).summary
    segments = summary["segments"]
    assert all(s["status"] == Status.OK.value for s in segments)
    assert {s["kind"] for s in segments} == {Kind.ON_BOTTOM.value}
    assert summary["mu_k"] is None and summary["friction_log"]["mu_k_reason"]
    depths = [s["bit_depth_m"] for s in segments]
    assert min(depths) < 2850 and max(depths) > 3770 and len(set(depths)) > 30
    apparent = [s["mu_k"] for s in segments]
    assert 0.13 <= float(np.median(apparent)) <= 0.25
    assert all(0.1 <= mu <= 0.3 for mu in apparent)
    raw = pd.read_csv(path)
    kkgf = well.config.segmentation.wob_on_bottom_N / 9.80665e3  # 1 kkgf = 9.80665 kN
    light = int(((raw["Weight on Bit kkgf"] <= kkgf)
                 & (raw["Rate of Penetration m/h"] > 0)).sum())
    assert light > 0 and any(f"on bottom in {light} of {len(raw)} rows" in note
                             for note in summary["assumed"])


def test_a_hook_load_below_the_configured_string_withholds_the_depth_log(depth_log, tmp_path):
    """Ninth attack F4: depths and survey in ft read as m put the logged hook load at 0.35×
    the model's, and the friction log printed μ 54 % low, every window ok. The block only
    adds to the hook load, so a depth log's may not lie below the modelled string by more
    than hookload.tolerance: every window's friction withheld, the reason said."""
    path, rows = depth_log
    light = tmp_path / "light"
    light.mkdir()
    for name in ("d.toml", "d.survey.csv"):
        (light / name).write_text((path.parent / name).read_text())
    data = pd.read_csv(path)
    data["HKLD [kN]"] = data["HKLD [kN]"] * 0.35
    data.to_csv(light / "d.csv", index=False)
    result = CliRunner().invoke(cli, ["run", str(light / "d.csv"), "--out",
                                      str(tmp_path / "out"), "--no-report"])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "out" / "d" / "summary.json").read_text())
    assert summary["hookload"]["verdict"] == "contradicted"
    assert "0.35× the configured string's weight" in summary["hookload"]["reason"]
    assert summary["mu_k"] is None and "hook-load check" in summary["mu_k_reason"]
    assert all(s["mu_k"] is None and "hookload_contradicts_string" in s["quality_flags"]
               for s in summary["segments"])
    table = pd.read_parquet(tmp_path / "out" / "d" / "friction_log.parquet")
    assert table["mu"].isna().all()


@pytest.mark.parametrize("ratio, withheld", [(1.0, False), (0.97, False), (1.8, False),
                                             (0.9, True), (0.35, True)])
def test_light_string_is_one_sided(ratio, withheld):
    """The block weight is unknown in a depth log but only adds: any hook load above the
    model passes, one more than the tolerance below it does not."""
    from drillfric.hookload import light_string

    model = np.array([1.0e6, 1.1e6, 1.2e6, 1.3e6])
    assert bool(light_string(ratio * model, model, 0.05)) is withheld
    assert light_string(ratio * model[:2], model[:2], 0.05) == ""  # too few windows to say
