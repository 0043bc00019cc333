"""Regression tests of the twelfth hostile-input attack (issue 30), its config, option and
API findings (F5–F8), each named after what was found. The CSV findings are in
tests/test_hostile_twelfth_attack.py; the saved state after a survey change (F1) in
tests/test_fleet_incremental.py."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.config import config_from_dict
from drillfric.errors import ConfigError, InputError
from tests.conftest import DEMO


@pytest.mark.parametrize("bare, unit", [(1.25, "sg"), (10.4, "ppg"), (2, "sg")])
def test_a_bare_mud_density_of_1_25_is_no_kg_per_m3(bare, unit):
    """F5: `mud_density_kg_m3 = 1.25` (sg) or `10.4` (ppg) had been taken as kg/m³ — a
    string in a gas — and on a log without hook load put μ_k at 0.236 for 0.28, exit 0.
    A bare number in those ranges is refused naming its likely unit; with a unit, or a
    density of a mud, it is read."""
    with pytest.raises(ConfigError, match=f"is it in {unit}") as err:
        config_from_dict({"fluid": {"mud_density_kg_m3": bare}})
    assert f'"{bare:g} {unit}"' in err.value.fix
    for value, si in (("1.25 sg", 1250.0), (1250, 1250.0), ("1.25 kg/m3", 1.25)):
        assert config_from_dict({"fluid": {"mud_density_kg_m3": value}}
                                ).fluid.mud_density_kg_m3 == pytest.approx(si)


@pytest.mark.parametrize("option, value", [("--wob", "1e5 klbf"), ("--rpm", "1e9"),
                                           ("--bit-torque", "1e9"), ("--axial-speed", "nan")])
def test_td_wob_and_rpm_have_a_range(option, value):
    """F6: `td --wob "1e5 klbf"` printed a hook load of −99 822 klbf and a torque of
    6365 kft·lbf with exit 0, `--rpm 1e9` was taken; simulate refuses both. Beyond what any
    rig reaches is one line naming the option, exit 2."""
    result = CliRunner().invoke(cli, ["td", str(DEMO / "demo.toml"), option, value])
    assert result.exit_code == 2, result.output
    assert option in result.output and "Traceback" not in result.output


def _well(frame):
    import drillfric

    return drillfric.open_well(frame=frame, survey=pd.read_csv(DEMO / "demo.survey.csv"),
                               name="x")


def _frame(n=600):
    t = np.arange(n) * 0.1
    return pd.DataFrame({"time_s": t, "surface_rpm": 60.0, "surface_torque_Nm": 8000.0})


def test_engine_feed_of_a_chunk_missing_a_column_is_one_line():
    """F7: `Engine.feed()` with a chunk missing or renaming a column raised a raw
    `KeyError: 'surface_torque_Nm'`; it names the columns the well's data has."""
    import drillfric

    frame = _frame()
    engine = drillfric.Engine(_well(frame.iloc[:300]))
    engine.feed(frame.iloc[:300])
    with pytest.raises(InputError, match="lack 1 column of the well's data: "
                                         "'surface_torque_Nm'"):
        engine.feed(frame.iloc[300:].rename(columns={"surface_torque_Nm": "TORQUE"}))


def test_a_frame_with_name_and_unit_levels_keeps_its_units():
    """F8: a DataFrame with (name, unit) MultiIndex columns was refused with the fix
    "'_'.join(...)", whose names ('TORQUE_kft.lbf') no channel matched, the units lost.
    Two levels are read as a header and its units row: the torque in kft·lbf is converted."""
    frame = _frame()
    frame["surface_torque_Nm"] /= 1355.8179483314
    frame.columns = pd.MultiIndex.from_tuples([("TIME", "s"), ("RPM", "rpm"),
                                               ("TORQUE", "kft.lbf")])
    well = _well(frame)
    chunk = well.canonical(next(well.source.chunks(600)), None)
    assert chunk["surface_torque_Nm"].to_numpy() == pytest.approx(8000.0)
    three = _frame()
    three.columns = pd.MultiIndex.from_tuples([(c, "x", "y") for c in three.columns])
    with pytest.raises(InputError, match="3 levels"):
        _well(three)
