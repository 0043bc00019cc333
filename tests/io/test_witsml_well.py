"""WITSML wells on disk (drillfric.io.well, docs/ingestion.md): a log split over numbered
files read as one well, the trajectory and tubular found beside it as survey and string,
the fleet finding one well per log; the Volve F-4 export end to end through the CLI.

The files are built in the tests; the Volve end-to-end test reads
../shared/data/real/volve_witsml in place (cropped to the rows it needs) and skips when the
folder is absent.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.errors import InputError
from drillfric.fleet.discovery import discover
from drillfric.io.well import open_well
from drillfric.io.witsml_objects import tubular_sections
from tests.io.test_witsml import _component, _curve, _doc, _log, _station

T0 = pd.Timestamp("2024-05-01T12:00:00Z")
MNEMONICS = "TIME,SURF_RPM,TORQUE,HKLD,BITDEP"
UNITS = "unitless,rpm,N.m,N,m"


def _surface_log(seconds, *, uid: str = "L1", name: str = "Surface") -> str:
    """A time log of the surface channels, one row per second in ``seconds`` (RPM = 60 +
    the second, so the rows can be told apart after merging)."""
    curves = "".join(_curve(m, u) for m, u in zip(MNEMONICS.split(","), UNITS.split(","),
                                                   strict=True))
    rows = [f"{(T0 + pd.Timedelta(seconds=s)).isoformat()},{60 + s},{1000 + s},5e5,1500"
            for s in seconds]
    return _doc(_log(rows, mnemonics=MNEMONICS, units=UNITS, curves=curves, uid=uid,
                     name=name))


def _trajectory() -> str:
    stations = (_station(0, 0, 0, md_uom="m", ang_uom="dega")
                + _station(1000, 0, 0, md_uom="m", ang_uom="dega")
                + _station(2000, 30, 90, md_uom="m", ang_uom="dega"))
    return _doc(f'<trajectory uid="t">{stations}</trajectory>', root="trajectorys")


def _tubular() -> str:
    parts = (_component("drill collar", 1, 6.5, 2.8125, 600.0)
             + _component("drill pipe", 2, 5.0, 4.276, 9000.0))
    return _doc(f'<tubular uid="s">{parts}</tubular>', root="tubulars")


def _rpm(well) -> list[float]:
    return well.load().surface["surface_rpm"].round(9).tolist()


# --------------------------------------------------------------------------- split logs
def test_numbered_parts_in_a_folder_are_one_well(tmp_path):
    """A WITSML store's export: 00001.xml, 00002.xml … in the log's folder. The folder or
    any part is the well; its sidecars are named after the folder; every part is hashed."""
    folder = tmp_path / "GwdTime"
    folder.mkdir()
    (folder / "00001.xml").write_text(_surface_log(range(0, 10)))
    (folder / "00002.xml").write_text(_surface_log(range(10, 20)))
    (tmp_path / "GwdTime.toml").write_text("[segmentation]\nmax_gap_s = 3.0\n")
    for given in (folder, folder / "00002.xml"):
        well = open_well(given)
        assert well.name == "GwdTime" and well.files.data == folder
        assert [p.name for p in well.files.parts] == ["00001.xml", "00002.xml"]
        assert well.files.config == tmp_path / "GwdTime.toml"
        assert well.config.segmentation.max_gap_s == 3.0
        assert _rpm(well) == [60.0 + s for s in range(20)]
    assert set(well.files.inputs) == {"data 00001.xml", "data 00002.xml", "config"}
    data = well.load()
    assert data.timebase.origin == T0 and data.surface["time_s"].tolist() == list(range(20))


def test_named_parts_are_one_well_with_trajectory_and_tubular_beside(tmp_path):
    """NAME_1.xml, NAME_2.xml … are one log named NAME; NAME.survey.xml (a trajectory) is
    the survey, NAME.tubular.xml the string, so neither is assumed any more."""
    (tmp_path / "F-4_1.xml").write_text(_surface_log(range(0, 10)))
    (tmp_path / "F-4_2.xml").write_text(_surface_log(range(10, 20)))
    (tmp_path / "F-4.survey.xml").write_text(_trajectory())
    (tmp_path / "F-4.tubular.xml").write_text(_tubular())
    well = open_well(tmp_path / "F-4_1.xml")
    assert well.name == "F-4" and len(well.files.parts) == 2
    assert _rpm(well) == [60.0 + s for s in range(20)]
    assert well.files.survey == tmp_path / "F-4.survey.xml"
    # a 30° bend over the last 1000 m: the minimum-curvature end inclination is 30°
    assert np.degrees(well.survey.inc_rad[-1]) == pytest.approx(30.0, abs=1e-9)
    assert well.files.string == tmp_path / "F-4.tubular.xml"
    sections = tubular_sections(tmp_path / "F-4.tubular.xml")
    assert [s["name"] for s in well.config.sections] == [s["name"] for s in sections]
    assert not any("drill string" in a for a in well.config.assumed)


def test_configured_string_wins_over_the_tubular_beside(tmp_path):
    (tmp_path / "w.xml").write_text(_surface_log(range(5)))
    (tmp_path / "w.tubular.xml").write_text(_tubular())
    (tmp_path / "w.toml").write_text('[[string.sections]]\nname = "mine"\nod_m = 0.127\n'
                                     "id_m = 0.1086\nlength_m = 3000.0\n")
    well = open_well(tmp_path / "w.xml")
    assert well.files.string is None and [s["name"] for s in well.config.sections] == ["mine"]


def test_string_option_names_a_tubular_kept_elsewhere(tmp_path):
    """Issue 35 (fourth newcomer): a Volve WITSML log kept read-only could not have its
    tubular placed beside it as NAME.tubular.xml. ``--string`` (open_well(string=), the
    manifest's ``string`` column) names it wherever it is; it overrides a sidecar; a
    missing file, a file that is no tubular, or a configuration that also gives sections is
    one line, exit 2."""
    logs, strings = tmp_path / "logs", tmp_path / "strings"
    logs.mkdir(), strings.mkdir()
    (logs / "w.xml").write_text(_surface_log(range(5)))
    (strings / "run3.xml").write_text(_tubular())
    well = open_well(logs / "w.xml", string=strings / "run3.xml")
    sections = tubular_sections(strings / "run3.xml")
    assert well.files.string == strings / "run3.xml"
    assert well.files.inputs["string"] == strings / "run3.xml"
    assert [s["name"] for s in well.config.sections] == [s["name"] for s in sections]
    assert not any("drill string" in a for a in well.config.assumed)
    (logs / "w.tubular.xml").write_text(_tubular().replace("drill collar", "drill pipe"))
    assert open_well(logs / "w.xml", string=strings / "run3.xml").files.string \
        == strings / "run3.xml"
    out = CliRunner().invoke(cli, ["inspect", str(logs / "w.xml"), "--string",
                                   str(strings / "run3.xml"), "--json"])
    assert out.exit_code == 0, out.output
    assert json.loads(out.output)["files"]["string"] == str(strings / "run3.xml")
    (logs / "m.csv").write_text(f"data,string\n{logs / 'w.xml'},{strings / 'run3.xml'}\n")
    assert discover(logs / "m.csv")[0].string == strings / "run3.xml"
    (strings / "w.toml").write_text('[[string.sections]]\nname = "mine"\nod_m = 0.127\n'
                                    "id_m = 0.1086\nlength_m = 3000.0\n")
    for args, words in (([str(tmp_path / "none.xml")], "string file (--string) not found"),
                        ([str(logs / "w.xml")], "holds no tubular"),
                        ([str(strings / "run3.xml"), "--config", str(strings / "w.toml")],
                         "gives [[string.sections]] and --string names a tubular")):
        bad = CliRunner().invoke(cli, ["inspect", str(logs / "w.xml"), "--string", *args])
        assert bad.exit_code == 2 and words in bad.output, bad.output
        assert len(bad.output.strip().splitlines()) == 1


def test_string_option_in_run(tmp_path):
    """``run --string`` reads the tubular as the string: summary.json assumes no string."""
    (tmp_path / "w.xml").write_text(_surface_log(range(5)))
    (tmp_path / "s.xml").write_text(_tubular())
    ran = CliRunner().invoke(cli, ["-q", "run", str(tmp_path / "w.xml"), "--string",
                                   str(tmp_path / "s.xml"), "--out", str(tmp_path / "o"),
                                   "--no-report"])
    summary = json.loads((tmp_path / "o" / "w" / "summary.json").read_text())
    assert ran.exit_code in (0, 1), ran.output
    assert not any("drill string" in a for a in summary["assumed"])


def test_lone_numbered_file_is_read_alone(tmp_path):
    (tmp_path / "run_3.xml").write_text(_surface_log(range(5)))
    (tmp_path / "run_4.csv").write_text("not a part")  # another extension: no sibling part
    well = open_well(tmp_path / "run_3.xml")
    assert (well.name, well.files.parts, well.files.data) == ("run_3", (),
                                                              tmp_path / "run_3.xml")


def test_store_folder_named_by_a_number_takes_the_log_title(tmp_path):
    """A store numbers its folders (log/1/8/1/00003.xml): the name is the log's wellbore
    (nameWell here) and log names instead of "1"."""
    folder = tmp_path / "log" / "1"
    folder.mkdir(parents=True)
    (folder / "00003.xml").write_text(_surface_log(range(0, 5), name="GwdTime"))
    (folder / "00004.xml").write_text(_surface_log(range(5, 10), name="GwdTime"))
    assert open_well(folder / "00003.xml").name == "W GwdTime"


def test_part_of_another_log_is_refused_naming_it(tmp_path):
    (tmp_path / "L_1.xml").write_text(_surface_log(range(5)))
    (tmp_path / "L_2.xml").write_text(_surface_log(range(5, 9), uid="OTHER"))
    with pytest.raises(InputError, match="part is log 'OTHER'") as info:
        open_well(tmp_path / "L_1.xml")
    assert "L_2.xml" in str(info.value) and "\n" not in str(info.value)


def test_one_file_holding_log_trajectory_and_tubular(tmp_path):
    """A wrapper root around <logs>, <trajectorys>, <tubulars>: the log is the data, the
    trajectory the survey and the tubular the string (the same file in each role)."""
    body = "".join(re.sub(r"<\?xml[^>]*\?>", "", text)
                   for text in (_surface_log(range(5)), _trajectory(), _tubular()))
    path = tmp_path / "all.xml"
    path.write_text(f'<?xml version="1.0"?><witsml>{body}</witsml>')
    well = open_well(path)
    assert well.files.survey == path and well.files.string == path
    assert len(well.config.sections) == 2 and _rpm(well) == [60.0 + s for s in range(5)]


def test_fleet_finds_one_well_per_log(tmp_path):
    """Parts of one log are one well; trajectories, tubulars and sidecars are not wells."""
    (tmp_path / "F-4_1.xml").write_text(_surface_log(range(0, 10)))
    (tmp_path / "F-4_2.xml").write_text(_surface_log(range(10, 20)))
    (tmp_path / "F-4.survey.xml").write_text(_trajectory())
    (tmp_path / "F-4.tubular.xml").write_text(_tubular())
    (tmp_path / "F-4_trajectory.xml").write_text(_trajectory())
    store = tmp_path / "GenTime"
    store.mkdir()
    (store / "00001.xml").write_text(_surface_log(range(5)))
    (store / "00002.xml").write_text(_surface_log(range(5, 9)))
    (tmp_path / "single.xml").write_text(_surface_log(range(5)))
    found = sorted(s.data.name for s in discover(tmp_path))
    assert found == ["F-4_1.xml", "GenTime", "single.xml"]


# --------------------------------------------------------------------------- Volve end to end
VOLVE_F4_CROP = ("2016-10-05T02:00:00", "2016-10-05T05:00:00")


def _crop_log(source, target, start: str, end: str) -> int:
    """Copy a one-line Volve WITSML log keeping only the data rows whose time is within
    [start, end): the header (curves, units) is kept byte for byte. Returns the rows kept."""
    text = source.read_text(encoding="utf-8")
    rows = re.findall(r"<data>([^<]*)</data>", text)
    kept = [r for r in rows if start <= r.split(",", 1)[0][:19] < end]
    head, tail = text.split("<data>", 1)[0], text.rsplit("</data>", 1)[1]
    target.write_text(head + "".join(f"<data>{r}</data>" for r in kept) + tail,
                      encoding="utf-8")
    return len(kept)


@pytest.fixture(scope="module")
def volve_f4(tmp_path_factory):
    """The F-4 GwdTime log cropped to 02:00–05:00 on 2016-10-05 (3 h at 15 s, bit at
    2290–2616 m, three of its rotation bursts) as F-4.xml with the F-4 trajectory and the
    run-3 tubular beside it under the sidecar names, and max_gap_s above its 15 s spacing."""
    from tests.conftest import REAL_DATA

    real = REAL_DATA / "volve_witsml"
    if not real.is_dir():
        pytest.skip(f"real field data not available at {real}")
    folder = tmp_path_factory.mktemp("volve")
    rows = _crop_log(real / "F-4_time_log_1.xml", folder / "F-4.xml", *VOLVE_F4_CROP)
    assert 700 < rows <= 720  # 3 h at 15 s, less the README's few 30/45 s gaps
    (folder / "F-4.survey.xml").write_bytes((real / "F-4_trajectory.xml").read_bytes())
    (folder / "F-4.tubular.xml").write_bytes((real / "F-4_tubular_run3.xml").read_bytes())
    (folder / "F-4.toml").write_text("[segmentation]\nmax_gap_s = 60.0\n")
    return folder


def test_volve_f4_inspect_lists_channels_with_units(volve_f4):
    result = CliRunner().invoke(cli, ["inspect", str(volve_f4 / "F-4.xml"), "--json"])
    assert result.exit_code == 0, result.output
    info = json.loads(result.output)
    units = {k: (c["column"], c["unit"], c["unit_source"]) for k, c in info["channels"].items()}
    assert units["time_s"] == ("Time", "ISO 8601", "values")
    assert units["surface_rpm"] == ("SURF_RPM", "c/s", "header")
    assert units["surface_torque_Nm"] == ("TORQUE", "N.m", "header")
    assert units["hookload_N"] == ("HKLD", "N", "header")
    assert units["bit_depth_m"] == ("BITDEP", "m", "header")
    assert not any("time_s" in a for a in info["assumed"])


def test_volve_f4_run_says_why_each_rotation_is_skipped(volve_f4, tmp_path):
    """README: the F-4 rotations are bursts of ≤ 1 min of top-drive make-up at 15 s logging
    — a few samples each, too short for the estimator. The run must succeed, keep the clock
    (UTC start/end per segment inside the crop) and name the reason for each skip; the
    survey and the string come from the trajectory and tubular beside the log."""
    result = CliRunner().invoke(cli, ["run", str(volve_f4 / "F-4.xml"), "--out",
                                      str(tmp_path), "--no-report"])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "F-4" / "summary.json").read_text())
    assert set(summary["inputs"]) >= {"data", "config", "survey", "string"}
    assert summary["time_origin_utc"].startswith("2016-10-05T02:00")
    assert not any("drill string" in a or "vertical" in a for a in summary["assumed"])
    segments = summary["segments"]
    assert segments and summary["counts"]["segments"] == len(segments)
    for seg in segments:
        assert seg["status"] == "skipped"
        # issue 35: rotations in the slips (hook load at the block's), said as such
        assert re.fullmatch(r"rotation in the slips: .* not an off-bottom rotation, .*; "
                            r"(only \d+ samples|too short: .*)", seg["message"]), seg
        start = pd.Timestamp(seg["clock_start_utc"])
        assert pd.Timestamp(VOLVE_F4_CROP[0], tz="UTC") <= start < pd.Timestamp(
            VOLVE_F4_CROP[1], tz="UTC")
        assert 2287 <= seg["bit_depth_m"] <= 2620  # README: bursts at 2387–2616 m


def test_volve_f4_split_in_two_parts_runs_as_the_whole(volve_f4, tmp_path):
    """The cropped log cut in two numbered parts gives the same segments as the whole."""
    from tests.conftest import REAL_DATA

    real = REAL_DATA / "volve_witsml" / "F-4_time_log_1.xml"
    store = tmp_path / "F-4"
    store.mkdir()
    middle = "2016-10-05T03:30:00"
    _crop_log(real, store / "00001.xml", VOLVE_F4_CROP[0], middle)
    _crop_log(real, store / "00002.xml", middle, VOLVE_F4_CROP[1])
    for name in ("F-4.survey.xml", "F-4.tubular.xml", "F-4.toml"):
        (tmp_path / name).write_bytes((volve_f4 / name).read_bytes())
    whole, split = open_well(volve_f4 / "F-4.xml").load(), open_well(store).load()
    pd.testing.assert_frame_equal(whole.surface, split.surface)
    assert whole.timebase.origin == split.timebase.origin


# --------------------------------------------------------------------------- hostile sidecars
BOMB = ('<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol">'
        + "".join(f'<!ENTITY lol{i} "{("&lol" + str(i - 1) + ";") * 10}">'
                  for i in range(1, 10)).replace("&lol0;", "&lol;")
        + ']><tubulars xmlns="http://www.witsml.org/schemas/1series">&lol9;</tubulars>')


@pytest.mark.parametrize("sidecar", ["w.tubular.xml", "w.survey.xml"])
def test_xml_bomb_found_beside_a_log_is_refused_in_one_line(tmp_path, sidecar):
    """The sidecars are read without being asked for, so they get the hardened parser too:
    a billion-laughs file (10⁹ "lol"s were it expanded, about 3 GB) in the tubular or
    survey sidecar's place stops the run with one line naming it, before any expansion."""
    (tmp_path / "w.xml").write_text(_surface_log(range(5)))
    (tmp_path / sidecar).write_text(BOMB)
    result = CliRunner().invoke(cli, ["run", str(tmp_path / "w.xml"), "--out",
                                      str(tmp_path / "out")])
    assert result.exit_code == 2, result.output
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and sidecar in lines[0] and "DTD" in lines[0]
    assert "lol" not in lines[0].replace(sidecar, "")


def test_fleet_discovery_keeps_a_hostile_xml_as_a_failing_well(tmp_path):
    """Discovery looks at each .xml's root to leave out trajectories and tubulars; an XML
    bomb is not expanded there and stays a well, which then fails on its own."""
    (tmp_path / "bomb.xml").write_text(BOMB)
    (tmp_path / "ok.xml").write_text(_surface_log(range(5)))
    assert sorted(s.data.name for s in discover(tmp_path)) == ["bomb.xml", "ok.xml"]
