"""Missing-channel hints and channels judged by their units (issue 15, item 7), and the
interval min/avg/max channels (TORQUE_MIN/AVG/MAX, HKLD_MIN/AVG/MAX, RPM_MIN/MAX)."""

from __future__ import annotations

import numpy as np
import pytest

from drillfric.errors import InputError
from drillfric.io import load_well
from drillfric.io.channels import map_channels


def _hint(columns, units=None) -> str:
    with pytest.raises(InputError) as info:
        map_channels(columns, units or {}, {}, file="w.csv")
    return info.value.fix


# ------------------------------------------------------------------ regression: issue 15 #7
def test_missing_torque_hint_suggested_the_rpm_column():
    """Before: a log with TIME and "Surface RPM" but no torque got the hint
    ``surface_torque = { column = "Surface RPM", unit = "kN.m" }`` (the RPM column, picked by
    name likeness among all columns once every column was mapped)."""
    fix = _hint(["TIME", "Surface RPM"])
    assert "Surface RPM" not in fix and 'column = "NAME"' in fix


@pytest.mark.parametrize("columns", [
    ["TIME", "SRPM", "HKLD [kN]"],           # another channel's column, not yet mapped
    ["Time", "Top drive RPM", "Block position"],
    ["TIME", "RPM", "MOTOR CURRENT [A]"],     # a unit of another quantity
])
def test_missing_channel_hint_never_names_another_channels_column(columns):
    fix = _hint(columns)
    assert all(f'"{c}"' not in fix for c in columns[1:]) and 'column = "NAME"' in fix


def test_missing_channel_hint_names_a_column_with_the_channels_unit():
    """A column stating a torque unit is the plausible one; the unit then comes from the
    file, so the hint does not state one."""
    fix = _hint(["TIME", "RPM", "DEPTH", "M1 [kN.m]"])
    assert 'surface_torque = { column = "M1 [kN.m]" }' in fix


def test_missing_channel_hint_names_a_column_with_a_close_mnemonic():
    fix = _hint(["TIME", "RPM", "TRQ_X", "DEPTH"])
    assert 'column = "TRQ_X", unit = "kN.m"' in fix


def test_optional_channel_with_a_unit_of_another_quantity_is_left_unmapped():
    """WITSML FLOWOUT is a flow rate in m3/s; flow_out is a percentage of flow in."""
    mapping = map_channels(["TIME", "RPM", "TORQUE", "FLOWOUT"], {"FLOWOUT": "m3/s"}, {})
    assert "flow_out" not in mapping


def test_required_channel_with_a_unit_of_another_quantity_stays_an_error():
    with pytest.raises(InputError, match="is not a torque unit"):
        map_channels(["TIME", "RPM", "TORQUE [klbf]"], {}, {})


# ------------------------------------------------------------------ min/avg/max channels
MINMAX_CSV = """\
TIME,SURF_RPM_MIN,SURF_RPM,SURF_RPM_MAX,TORQUE_MIN,TORQUE_AVG,TORQUE_MAX,HKLD_MIN,HKLD_AVG,HKLD_MAX
s,rpm,rpm,rpm,kN.m,kN.m,kN.m,klbf,klbf,klbf
0,58,60,62,9.5,10,10.5,199,200,201
1,59,61,63,10.5,11,11.5,200,201,202
2,60,62,64,11.5,12,12.5,201,202,203
"""


def test_average_maps_to_the_channel_and_min_max_to_their_own(tmp_path):
    path = tmp_path / "minmax.csv"
    path.write_text(MINMAX_CSV)
    well = load_well(path)
    surface = well.surface
    assert well.channels["surface_torque_Nm"].column == "TORQUE_AVG"
    assert well.channels["hookload_N"].column == "HKLD_AVG"
    np.testing.assert_allclose(surface["surface_torque_min_Nm"], [9.5e3, 10.5e3, 11.5e3],
                               rtol=1e-15)
    np.testing.assert_allclose(surface["surface_torque_max_Nm"], [10.5e3, 11.5e3, 12.5e3],
                               rtol=1e-15)
    assert surface["surface_rpm_min"].tolist() == [58, 59, 60]
    assert surface["surface_rpm_max"].tolist() == [62, 63, 64]
    lbf = 4.4482216152605  # N per lbf (exact by definition)
    np.testing.assert_allclose(surface["hookload_max_N"], np.array([201, 202, 203]) * 1e3 * lbf,
                               rtol=1e-12)
    assert (surface["hookload_min_N"] <= surface["hookload_N"]).all()


def test_min_max_channels_can_be_mapped_in_the_config(tmp_path):
    path = tmp_path / "w.csv"
    path.write_text("TIME,RPM,TORQUE,TQ_LOW\ns,rpm,kN.m,kN.m\n0,1,2,1.5\n1,1,2,1.5\n")
    (tmp_path / "w.toml").write_text('[channels]\nsurface_torque_min = { column = "TQ_LOW" }\n')
    assert load_well(path).surface["surface_torque_min_Nm"].tolist() == [1500.0, 1500.0]


def test_volve_f9_min_avg_max_sets(real_data):
    """README (volve_witsml): F-9 A has TORQUE/HKLD MIN/AVG/MAX sets; MIN ≤ AVG ≤ MAX fails
    in 280 rows (torque) and 771 rows (hook load); TORQUE_MAX clips at 32 767 N·m with 10
    rows ≥ 32 700; 1 710 rows rotate faster than 5 rpm (SURF_RPM in c/s). A swapped
    min/max mapping would break the order in almost every row."""
    well = load_well(real_data / "volve_witsml" / "F-9_time_log_1.xml")
    s = well.surface
    assert well.channels["surface_torque_min_Nm"].column == "TORQUE_MIN"
    assert well.channels["hookload_max_N"].column == "HKLD_MAX"

    def unordered(prefix: str, suffix: str) -> int:
        low, mid, high = (s[f"{prefix}{x}{suffix}"].to_numpy() for x in ("_min", "", "_max"))
        return int(((low > mid) | (mid > high)).sum())

    assert unordered("surface_torque", "_Nm") == 280
    assert unordered("hookload", "_N") == 771
    assert s["surface_torque_max_Nm"].max() == 32767.0
    assert int((s["surface_torque_max_Nm"] >= 32700).sum()) == 10
    assert int((s["surface_rpm"] > 5).sum()) == 1710
