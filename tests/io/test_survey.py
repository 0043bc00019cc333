"""Survey readers (drillfric.io.survey) and the well path against operator surveys.

Reference data: Equinor's Volve definitive surveys (../shared/data/real/volve_surveys, read in
place; skipped when absent), whose TVD, offsets and DLS are the operator's own
minimum-curvature results; and the P-130 survey (origin unverified, CR-only line endings).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from drillfric.errors import InputError
from drillfric.io.survey import (
    read_survey,
    read_survey_table,
    survey_table_from_frame,
    wellpath_from_table,
    write_survey,
)
from drillfric.wellpath import minimum_curvature
from tests.conftest import REPO

FT = 0.3048
VOLVE = ["F-10", "F-11_B", "F-12", "F-14", "F-15D", "F-4", "F-5"]
VOLVE_STATIONS = {"F-10": 479, "F-11_B": 299, "F-12": 211, "F-14": 93, "F-15D": 114,
                  "F-4": 86, "F-5": 97}

# A few stations of F-10 in the Volve fixed-width layout (names row, units row with spaces).
VOLVE_TEXT = """\
MD        Inc       Azim      TVD       X_Offset_EW  Y_Offset_NS  X_COORD         Y_COORD         DLS
m RKB     deg       deg       m RKB     m               m               m               m               deg/30m
145.90    0.00      0.00      145.90    2.228           -3.911          435052.248      6478559.613     0.00
150.00    0.02      28.15     150.00    2.229           -3.911          435052.249      6478559.614     0.15
160.00    0.05      27.73     160.00    2.232           -3.905          435052.252      6478559.619     0.09
"""  # noqa: E501


# ------------------------------------------------------------------- Volve operator surveys

@pytest.mark.parametrize("well", VOLVE)
def test_volve_survey_matches_operator(real_data, well):
    """Every station reproduces the operator's TVD and N/E offsets within 0.05 m and DLS
    within 0.05°/30 m (issue 2 acceptance).

    The file prints angles to 0.01°, TVD and DLS to 0.01 and offsets to 0.001, so the same
    method reproduces it to ~0.005 m / ~0.005°/30 m (measured:
    docs/validation.md). The operator evidently computed from unrounded angles: over
    F-12's 10 m stations the ±0.005° rounding moves DLS by up to 0.03°/30 m and the offsets
    drift by a random walk of rounding (0.010 m). A method error shows up at once: balanced
    tangential (RF = 1) misses by 0.07–0.72 m on these wells. The surveys start at
    MD 145.9 m (RKB), so the path is tied in at the operator's TVD and offsets of the first
    station (read_survey's default). Y_Offset_NS is north, X_Offset_EW east.
    """
    path_file = real_data / "volve_surveys" / f"{well}_ACTUAL.txt"
    table = read_survey_table(path_file)
    assert len(table) == VOLVE_STATIONS[well]
    path = read_survey(path_file)
    assert np.max(np.abs(path.tvd_m - table["tvd_m"])) < 0.05
    assert np.max(np.abs(path.north_m - table["north_m"])) < 0.05
    assert np.max(np.abs(path.east_m - table["east_m"])) < 0.05
    dls = np.degrees(path.dls_rad_m) * 30.0
    assert np.max(np.abs(dls - table["dls_deg_30m"].to_numpy()[1:])) < 0.05


def test_volve_offsets_are_not_swapped(real_data):
    """A swapped N/E mapping would miss by metres (F-10 goes ~3 km north-east, unequally)."""
    table = read_survey_table(real_data / "volve_surveys" / "F-10_ACTUAL.txt")
    path = read_survey(real_data / "volve_surveys" / "F-10_ACTUAL.txt")
    assert np.max(np.abs(path.north_m - table["east_m"])) > 100.0
    assert np.max(np.abs(path.north_m - table["north_m"])) < 0.05


def test_volve_tie_in_matters(real_data):
    """Without the operator's tie-in the offsets are shifted by the first station's offsets
    (F-10: 2.228 m east, -3.911 m north) — the documented reason for the default tie-in."""
    table = read_survey_table(real_data / "volve_surveys" / "F-10_ACTUAL.txt")
    path = read_survey(real_data / "volve_surveys" / "F-10_ACTUAL.txt",
                       tie_in=(table["md_m"][0], 0.0, 0.0))
    assert np.median(table["north_m"] - path.north_m) == pytest.approx(-3.911, abs=0.01)
    assert np.median(table["east_m"] - path.east_m) == pytest.approx(2.228, abs=0.01)


# -------------------------------------------------------------------------------- P-130

def test_p130_cr_only_survey(real_data):
    """P-130: 163 stations, CR-only line endings, MD strictly increasing 18–2579.3 m.

    Its TVDKB column is not a minimum-curvature result all the way down: to 451 m it repeats
    MD to the whole metre (276 m is listed as 275, a typo: the hole cannot shorten by 1 m
    at 2.5°), so it ignores the ~0.42 m that the 2–3° upper hole loses. From 459.8 m on the
    file's TVD has decimals; tied in there, our TVD follows it within 0.2 m: MD and TVD are
    printed to 0.1 m, i.e. ±0.05 m each at a station and at the tie-in station
    (measured max 0.16 m, RMS 0.09 m; docs/validation.md).
    """
    f = real_data / "volve_surveys" / "P-130_deviation_survey.csv"
    raw = f.read_bytes()
    assert b"\r" in raw and b"\n" not in raw
    table = read_survey_table(f)
    assert len(table) == 163
    assert list(table.columns) == ["md_m", "inc_deg", "azi_deg", "tvd_m"]
    assert table["md_m"].iloc[0] == 18.0 and table["md_m"].iloc[-1] == 2579.3
    assert np.all(np.diff(table["md_m"]) > 0)
    upper = table["md_m"] <= 451.0
    assert np.sum(upper) == 16
    assert np.sum(table["tvd_m"][upper] != table["md_m"][upper]) == 1  # the 276/275 typo
    lower = table[~upper].reset_index(drop=True)
    path = wellpath_from_table(lower)  # ties in at the file's TVD of 459.8 m
    assert np.max(np.abs(path.tvd_m - lower["tvd_m"])) < 0.2
    # the whole survey from 18 m: the file's TVD is the upper part's ~0.42 m too deep
    full = read_survey(f)
    offset = np.median(lower["tvd_m"] - full.at(lower["md_m"])["tvd_m"])
    assert 0.35 < offset < 0.5


# ------------------------------------------------------------------------------- formats

def _write(tmp_path, name, text, newline="\n"):
    path = tmp_path / name
    path.write_bytes(text.replace("\n", newline).encode())
    return path


def test_volve_fixed_width_layout(tmp_path):
    """Names row, units row with spaces ('m RKB'), whitespace-separated numbers."""
    table = read_survey_table(_write(tmp_path, "F-10.txt", VOLVE_TEXT))
    assert list(table.columns) == ["md_m", "inc_deg", "azi_deg", "tvd_m", "north_m", "east_m",
                                   "dls_deg_30m"]
    assert table["north_m"].tolist() == [-3.911, -3.911, -3.905]
    assert table["east_m"].tolist() == [2.228, 2.229, 2.232]
    assert table["dls_deg_30m"].tolist() == [0.0, 0.15, 0.09]


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"])
def test_line_endings(tmp_path, newline):
    f = _write(tmp_path, "s.csv", "MD,INC,AZI\n0,0,0\n100,10,90\n250,20,95\n", newline)
    table = read_survey_table(f)
    assert table["md_m"].tolist() == [0.0, 100.0, 250.0]
    assert table["azi_deg"].tolist() == [0.0, 90.0, 95.0]


@pytest.mark.parametrize("header, md_factor", [
    ("md_m,inc_deg,azi_deg", 1.0),
    ("md_ft,inc_deg,azi_deg", FT),
    ("MD (ft),Inclination (deg),Azimuth (deg)", FT),
    ("MD [m],Incl [deg],Azim [deg]", 1.0),
    ("Measured Depth,Inclination,Azimuth", 1.0),
    ("DEPTH,DEVI,HAZI", 1.0),
])
def test_header_spellings(tmp_path, header, md_factor):
    f = _write(tmp_path, "s.csv", f"{header}\n0,0,0\n1000,30.5,359.5\n")
    table = read_survey_table(f)
    assert table["md_m"].tolist() == pytest.approx([0.0, 1000.0 * md_factor], rel=1e-15)
    assert table["inc_deg"].tolist() == [0.0, 30.5]
    assert table["azi_deg"].tolist() == [0.0, 359.5]


def test_units_row_in_feet_and_radians(tmp_path):
    """A units row under the header: ft → m (exactly 0.3048), rad → deg, deg/100ft → °/30 m."""
    f = _write(tmp_path, "s.csv", "MD,INC,AZI,TVD,DLS\nft,rad,rad,ft,deg/100ft\n"
                                  "0,0,0,0,0\n1000,0.5,1.0,990,3\n")
    table = read_survey_table(f)
    assert table["md_m"].tolist() == pytest.approx([0.0, 304.8], rel=1e-15)
    assert table["tvd_m"].iloc[1] == pytest.approx(990 * FT, rel=1e-15)
    assert table["inc_deg"].iloc[1] == pytest.approx(np.degrees(0.5), rel=1e-15)
    assert table["dls_deg_30m"].iloc[1] == pytest.approx(3 * 30 / 30.48, rel=1e-14)


@pytest.mark.parametrize("text", [
    "MD;INC;AZI\n0;0;0\n100,5;2,25;180,75\n",
    "MD\tINC\tAZI\n0\t0\t0\n100.5\t2.25\t180.75\n",
    "MD|INC|AZI\n0|0|0\n100.5|2.25|180.75\n",
    "MD  INC  AZI\n0  0  0\n100.5  2.25  180.75\n",
    '"MD","INC","AZI"\n0,0,0\n100.5,2.25,180.75\n',
])
def test_delimiters_and_decimal_comma(tmp_path, text):
    table = read_survey_table(_write(tmp_path, "s.txt", text))
    assert table.iloc[1].tolist() == [100.5, 2.25, 180.75]


def test_parquet(tmp_path):
    f = tmp_path / "s.parquet"
    pd.DataFrame({"MD (ft)": [0.0, 1000.0], "INC": [0.0, 10.0], "AZI": [0.0, 45.0]}).to_parquet(f)
    table = read_survey_table(f)
    assert table["md_m"].tolist() == pytest.approx([0.0, 304.8], rel=1e-15)
    assert table["azi_deg"].tolist() == [0.0, 45.0]


def test_sidecar_round_trip(tmp_path):
    """write_survey → read_survey gives back the same stations and positions."""
    md = np.array([0.0, 500.0, 900.0, 1500.0])
    inc = np.radians([0.0, 0.0, 40.0, 60.0])
    azi = np.radians([0.0, 0.0, 120.0, 135.0])
    original = minimum_curvature(md, inc, azi)
    f = tmp_path / "well.survey.csv"
    write_survey(f, original)
    assert f.read_text().splitlines()[0] == "md_m,inc_deg,azi_deg"
    back = read_survey(f)
    np.testing.assert_allclose(back.inc_rad, inc, atol=1e-12)
    np.testing.assert_allclose(back.tvd_m, original.tvd_m, atol=1e-8)
    np.testing.assert_allclose(back.east_m, original.east_m, atol=1e-8)


def test_frame_reader():
    frame = pd.DataFrame({"md_ft": [0.0, 100.0], "inc_deg": [0.0, 1.0], "azi_deg": [0.0, 2.0]})
    assert survey_table_from_frame(frame)["md_m"].tolist() == pytest.approx([0.0, 30.48])


def test_default_tie_in_without_positions(tmp_path):
    """Without TVD in the file, a vertical surface station is added above the first one."""
    path = read_survey(_write(tmp_path, "s.csv", "MD,INC,AZI\n100,0,0\n200,0,0\n"))
    assert path.md_m.tolist() == [0.0, 100.0, 200.0]
    assert path.tvd_m.tolist() == [0.0, 100.0, 200.0]


# ----------------------------------------------------------------------------- bad input

@pytest.mark.parametrize("name, content, problem", [
    ("s.csv", "MD,INC,AZI\n0,0,0\n100,1,0\n100,2,0\n",
     "survey stations 2 and 3 are both at MD 100 m with different values"),
    ("s.csv", "MD,INC,AZI\n0,0,0\n100,1,0\n90,2,0\n", "depths not increasing"),
    ("s.csv", "MD,INC,AZI\n0,0,0\n100,181,0\n", "inclination 181° at station 2 is outside"),
    ("s.csv", "MD,INC,AZI\n0,0,0\n100,-1,0\n", "inclination -1°"),
    ("s.csv", "MD,INC,AZI\n0,0,0\n100,1,361\n", "azimuth 361° at station 2 is outside 0–360°"),
    ("s.csv", "MD,INC,AZI\n0,0,0\n100,1,-5\n", "azimuth -5°"),
    ("s.csv", "MD,INC,DIR\n0,0,0\n100,1,5\n", "no azi_deg column (columns found: MD, INC"),
    ("s.csv", "DEPTH,X\n0,0\n", "no inc_deg/azi_deg column"),
    ("s.csv", "", "survey file is empty"),
    ("s.csv", "\r\n\r\n", "survey file is empty"),
    ("s.csv", "MD,INC,AZI\n", "survey has no stations"),
    ("s.csv", "MD,INC,AZI\n0,0,0\n", "single station"),
    ("s.csv", "0,0,0\n100,1,0\n", "no header row"),
    ("s.csv", "MD,INC,AZI\n0,0,0\n100,-999.25,0\n", "station 2 has no inc_deg value"),
    ("s.csv", "MD,INC,AZI\n0,0,0\n100,,0\n", "station 2 has no inc_deg value"),
    ("s.csv", "MD,INC,AZI\n0,0,0\n100,1.2.3,0\n", "non-numeric value '1.2.3' at station 2"),
    ("s.csv", "MD,INC,AZI\nfurlongz,deg,deg\n0,0,0\n", "column 'MD': unknown unit 'furlongz'"),
    ("s.csv", "MD,INC,AZI\nkg,deg,deg\n0,0,0\n", "column 'MD': unit 'kg' is not a length"),
    ("s.xlsx", "MD,INC,AZI\n0,0,0\n", "unknown survey file extension '.xlsx'"),
    ("s.parquet", "not a parquet file", "cannot read Parquet survey"),
])
def test_bad_input_is_one_line_with_file_and_fix(tmp_path, name, content, problem):
    f = _write(tmp_path, name, content)
    with pytest.raises(InputError) as info:
        read_survey_table(f)
    message = str(info.value)
    assert problem in message
    assert message.startswith(str(f)) and "fix:" in message and "\n" not in message


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="survey file not found"):
        read_survey(tmp_path / "nope.csv")


def test_tie_in_from_file_tvd_only(tmp_path):
    """A TVD column without offsets ties in at (TVD₀, 0, 0); an empty TVD₀ is ignored."""
    path = read_survey(_write(tmp_path, "s.csv", "MD,INC,AZI,TVD\n100,0,0,99.5\n200,0,0,\n"))
    assert path.tvd_m.tolist() == [99.5, 199.5]
    path = read_survey(_write(tmp_path, "t.csv", "MD,INC,AZI,TVD\n100,0,0,\n200,0,0,199\n"))
    assert path.tvd_m.tolist() == [0.0, 100.0, 200.0]  # no TVD₀: surface station added


def test_a_station_typo_bending_the_path_beyond_any_string_is_refused(tmp_path):
    """Ninth attack F1: the demo survey with the inclination at 1860 m written 5.0 for 50
    bends the path ≈ 45°/30 m on each side of it; the run printed μ_k = 0.182 for 0.28,
    converged, status ok. Such a survey is refused in one line naming the stations, unless
    ``[survey] max_dogleg_deg_30m`` allows it (a short-radius well)."""
    from drillfric.io.well import open_config

    table = pd.read_csv(REPO / "examples/demo/demo.survey.csv")
    md_col, inc_col = table.columns[0], table.columns[1]
    row = int(np.argmin(np.abs(table[md_col] - 1860.0)))
    assert table.loc[row, inc_col] > 40.0
    table.loc[row, inc_col] = table.loc[row, inc_col] / 10.0
    table.to_csv(tmp_path / "typo.survey.csv", index=False)
    (tmp_path / "typo.toml").write_text('[survey]\nfile = "typo.survey.csv"\n')
    with pytest.raises(InputError, match=r"bend the path \d+°/30 m, beyond survey\."
                                         r"max_dogleg_deg_30m = 30°/30 m"):
        open_config(tmp_path / "typo.toml")
    (tmp_path / "short.toml").write_text('[survey]\nfile = "typo.survey.csv"\n'
                                         "max_dogleg_deg_30m = 100.0\n")
    assert open_config(tmp_path / "short.toml")[2] is not None
    _, _, demo = open_config(REPO / "examples/demo/demo.toml")  # 3°/30 m at most
    assert demo is not None


def test_volve_f5_survey_txt_beside_its_log_is_its_sidecar(tmp_path):
    """A fleet's F-5 had ``USROP_F-5.survey.txt`` beside its log (the Volve survey is .txt):
    the sidecar finder looked for .csv/.parquet/.xml only, so the well ran as vertical and
    its μ read 37 % high, silently. Every extension read_survey reads is a sidecar."""
    from drillfric.io import survey as survey_io
    from drillfric.io.wellfiles import SURVEY_EXT, resolve_well

    assert set(SURVEY_EXT) == survey_io._TEXT_EXT | survey_io._PARQUET_EXT | {".xml"}
    (tmp_path / "F-5.csv").write_text("time_s,rpm,torque\n0,60,5000\n1,60,5000\n")
    (tmp_path / "F-5.survey.txt").write_text("md_m,inc_deg,azi_deg\n0,0,0\n1000,30,90\n")
    assert resolve_well(tmp_path / "F-5.csv").survey == tmp_path / "F-5.survey.txt"
