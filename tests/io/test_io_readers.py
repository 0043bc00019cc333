"""Format readers: CSV dialects, Parquet, HDF5, LAS 2.0 — each read back into SI."""

from __future__ import annotations

import h5py
import lasio
import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from io_frames import surface_frame

from drillfric.errors import InputError
from drillfric.io.delimited import sniff_csv
from drillfric.io.readers import open_source
from drillfric.io.well import iter_surface, load_well

COLS = ["time_s", "surface_rpm", "surface_torque_Nm"]


def _same(a: pd.DataFrame, b: pd.DataFrame, cols=COLS, rtol=1e-9):
    # Tolerance: text files are written with 10 significant digits.
    for c in cols:
        np.testing.assert_allclose(a[c].to_numpy(), b[c].to_numpy(), rtol=rtol, atol=1e-9)


def _write_text(path, text: str, newline: str = "\n"):
    path.write_bytes(text.replace("\n", newline).encode())
    return path


# ------------------------------------------------------------------ CSV dialects
@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"], ids=["LF", "CRLF", "CR"])
def test_csv_line_endings(tmp_path, newline):
    p = _write_text(tmp_path / "a.csv", "TIME,RPM,TORQUE [kN.m]\n0,60,10\n0.2,61,11\n0.4,62,12\n",
                    newline)
    w = load_well(p)
    assert w.surface["surface_torque_Nm"].tolist() == [10e3, 11e3, 12e3]
    assert w.timebase.rows == 3 and w.timebase.rate_hz == pytest.approx(5.0)


@pytest.mark.parametrize("sep", [",", ";", "\t", "|"])
def test_csv_delimiters(tmp_path, sep):
    text = sep.join(["Time (s)", "SRPM", "Torque (ft.lbf)"]) + "\n" + "\n".join(
        sep.join(v) for v in [("0", "60", "1000"), ("1", "61", "1000"), ("2", "62", "1000")])
    w = load_well(_write_text(tmp_path / "a.csv", text + "\n"))
    assert w.surface["surface_torque_Nm"].iloc[0] == pytest.approx(1355.8179483314, rel=1e-9)
    assert w.channels["surface_torque_Nm"].unit == "ft.lbf"


def test_csv_decimal_comma_and_units_row(tmp_path):
    text = "TIME;SRPM;STOR;HKLD\ns;rpm;kN.m;kkgf\n0,0;60,5;10,25;100\n0,5;61,5;10,5;101\n" \
           "1,0;62;-999,25;102\n"
    layout = sniff_csv(_write_text(tmp_path / "a.csv", text))
    assert (layout.delimiter, layout.decimal, layout.units_row) == (";", ",", True)
    w = load_well(tmp_path / "a.csv")
    assert w.surface["surface_rpm"].tolist() == [60.5, 61.5, 62.0]
    assert w.surface["surface_torque_Nm"].iloc[1] == 10.5e3
    assert np.isnan(w.surface["surface_torque_Nm"].iloc[2])
    assert w.channels["hookload_N"].source == "units row"
    assert w.surface["hookload_N"].iloc[0] == pytest.approx(100 * 9806.65)
    assert w.channels["surface_torque_Nm"].null_fraction == pytest.approx(1 / 3)


def test_csv_nulls_empty_and_markers(tmp_path):
    text = "TIME,RPM,TORQUE,HKLD\n0,60,,1\n1,-9999,5,-999.25\n2,nan,6,2\n3,61,7,3\n"
    w = load_well(_write_text(tmp_path / "a.csv", text))
    assert w.surface["surface_rpm"].isna().tolist() == [False, True, True, False]
    assert w.channels["surface_torque_Nm"].null_fraction == 0.25
    assert w.channels["hookload_N"].null_fraction == 0.25


def test_csv_iso_timestamps(tmp_path):
    text = "DATETIME,SRPM,STOR\n2024-05-01T12:00:00Z,60,10\n2024-05-01T12:00:01Z,60,10\n" \
           "2024-05-01T12:00:02Z,60,10\n"
    w = load_well(_write_text(tmp_path / "a.csv", text))
    assert w.surface["time_s"].tolist() == [0.0, 1.0, 2.0]
    assert w.timebase.origin == pd.Timestamp("2024-05-01T12:00:00Z")
    assert w.surface["timestamp"].iloc[2] == pd.Timestamp("2024-05-01T12:00:02Z")


def test_csv_headerless_with_channel_indexes(tmp_path):
    _write_text(tmp_path / "a.csv", "0.5,60,1000,34.8\n1.5,61,1100,34.9\n2.5,62,1200,35\n")
    (tmp_path / "a.toml").write_text(
        '[channels]\ntime = { column = 0, unit = "s" }\nsurface_rpm = { column = 1 }\n'
        'surface_torque = { column = 2, unit = "ft.lbf" }\n'
        'hookload = { column = 3, unit = "klbf" }\n')
    w = load_well(tmp_path / "a.csv")
    assert w.channels["surface_torque_Nm"].column == "2"
    assert w.surface["hookload_N"].iloc[0] == pytest.approx(34.8e3 * 4.4482216152605)
    assert w.timebase.source_start_s == 0.5 and w.surface["time_s"].iloc[0] == 0.0


@pytest.mark.parametrize("size", [1, 2, 3, 5, 8, 13, 64])
def test_csv_comment_filter_at_any_block_boundary(size):
    """pandas reads in blocks; comment lines, CRLF pairs and partial lines split across
    any block boundary give the same text: the file without comment or leading blank
    lines, nothing else changed."""
    import io

    from drillfric.io.delimited import _CommentFree

    text = ("# rig\r\n\r\n#\rTIME,RPM\r\n0,1\r\n#x,y\n1,2\r3,4\n  # z\r\n\n5,6\r\n"
            "# end")
    expected = "TIME,RPM\r\n0,1\r\n1,2\r3,4\n\n5,6\r\n"
    stream = _CommentFree(io.StringIO(text, newline=""))
    pieces = iter(lambda: stream.read(size), "")
    assert "".join(pieces) == expected


def test_csv_ragged_rows_are_an_input_error(tmp_path):
    p = _write_text(tmp_path / "a.csv", "TIME,RPM,TORQUE\n0,1,2\n1,2,3,4,5,6\n")
    with pytest.raises(InputError, match="a.csv: cannot parse"):
        load_well(p)


# ------------------------------------------------------------------ other formats
def test_parquet_with_unit_metadata(tmp_path, frame):
    raw = frame.rename(columns={"surface_torque_Nm": "TQA", "time_s": "TIME"})
    raw["TQA"] /= 1e3
    table = pa.Table.from_pandas(raw, preserve_index=False)
    fields = [f.with_metadata({"unit": "kN.m"}) if f.name == "TQA" else f for f in table.schema]
    pq.write_table(table.cast(pa.schema(fields)), tmp_path / "w.parquet", row_group_size=100)
    w = load_well(tmp_path / "w.parquet")
    _same(w.surface, frame)
    assert w.channels["surface_torque_Nm"].unit == "kN.m"


def test_hdf5_pandas_table(tmp_path, frame):
    frame.to_hdf(tmp_path / "w.h5", key="surface", format="table")
    w = load_well(tmp_path / "w.h5")
    _same(w.surface, frame, COLS + ["hookload_N", "bit_depth_m"])


def test_hdf5_pandas_fixed_format(tmp_path, frame):
    frame.to_hdf(tmp_path / "w.h5", key="surface", format="fixed")
    _same(load_well(tmp_path / "w.h5").surface, frame)


def test_hdf5_plain_datasets_with_unit_attributes(tmp_path, frame):
    with h5py.File(tmp_path / "w.hdf5", "w") as h5:
        g = h5.create_group("surface")
        g["TIME"] = frame["time_s"].to_numpy()
        g["SRPM"] = frame["surface_rpm"].to_numpy()
        g["STOR"] = frame["surface_torque_Nm"].to_numpy() / 1e3
        g["STOR"].attrs["unit"] = "kN.m"
    w = load_well(tmp_path / "w.hdf5")
    _same(w.surface, frame)
    assert (w.channels["surface_torque_Nm"].unit, w.channels["surface_torque_Nm"].source) == (
        "kN.m", "header")


def test_las_time_indexed(tmp_path, frame):
    las = lasio.LASFile()
    las.append_curve("TIME", frame["time_s"].to_numpy(), unit="s")
    las.append_curve("SRPM", frame["surface_rpm"].to_numpy(), unit="rpm")
    las.append_curve("STOR", frame["surface_torque_Nm"].to_numpy() / 1e3, unit="kN.m")
    las.write(str(tmp_path / "w.las"), version=2.0)
    # Tolerance: lasio writes 5 decimals (0.5e-5 kN·m = 0.005 N·m).
    w = load_well(tmp_path / "w.las")
    np.testing.assert_allclose(w.surface["surface_torque_Nm"], frame["surface_torque_Nm"],
                               atol=0.006)
    assert w.channels["surface_torque_Nm"].unit == "kN.m"


# ------------------------------------------------------------------ chunked reading
def _writers(tmp_path, frame):
    frame.to_csv(tmp_path / "w.csv", index=False, float_format="%.10g")
    pq.write_table(pa.Table.from_pandas(frame, preserve_index=False), tmp_path / "w.parquet",
                   row_group_size=128)
    frame.to_hdf(tmp_path / "w.h5", key="surface", format="table")
    with h5py.File(tmp_path / "g.h5", "w") as h5:
        for c in frame.columns:
            h5[f"surface/{c}"] = frame[c].to_numpy()
    return ["w.csv", "w.parquet", "w.h5", "g.h5"]


@pytest.mark.parametrize("chunk_rows", [37, 97, 1000])
def test_chunked_read_equals_whole_read(tmp_path, chunk_rows):
    frame = surface_frame(rows=600)
    frame.loc[300, "time_s"] = frame.loc[299, "time_s"]  # a repeat across some boundary
    for name in _writers(tmp_path, frame):
        whole = load_well(tmp_path / name).surface
        parts = list(iter_surface(tmp_path / name, chunk_rows=chunk_rows))
        # each chunk's last time is held back to the next (the end of the data: one more)
        assert len(parts) <= -(-600 // chunk_rows) + 1
        assert all(len(p) <= chunk_rows + 1 for p in parts)
        pd.testing.assert_frame_equal(pd.concat(parts, ignore_index=True), whole)
        assert len(whole) == 598  # the repeated time holds other values: both rows dropped


def test_parquet_is_streamed_by_batches(tmp_path):
    # The raw reader yields blocks, never the whole table: proof that chunking reaches pyarrow.
    pq.write_table(pa.Table.from_pandas(surface_frame(rows=1000), preserve_index=False),
                   tmp_path / "w.parquet", row_group_size=100)
    raw = open_source(tmp_path / "w.parquet")
    assert raw.rows == 1000 and [len(c) for c in raw.chunks(250)] == [250] * 4


# ------------------------------------------------------------------ corrupt files
def test_truncated_parquet(tmp_path, frame):
    pq.write_table(pa.Table.from_pandas(frame), tmp_path / "w.parquet")
    data = (tmp_path / "w.parquet").read_bytes()
    (tmp_path / "w.parquet").write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match="truncated or corrupt"):
        load_well(tmp_path / "w.parquet")


def test_truncated_hdf5(tmp_path, frame):
    frame.to_hdf(tmp_path / "w.h5", key="surface", format="table")
    data = (tmp_path / "w.h5").read_bytes()
    (tmp_path / "w.h5").write_bytes(data[: len(data) // 3])
    with pytest.raises(InputError, match="truncated or corrupt"):
        load_well(tmp_path / "w.h5")


def test_parquet_and_hdf5_with_a_datetime_index(tmp_path, frame):
    # pandas users store time as a DatetimeIndex; it must be found as the time channel.
    stamps = pd.Timestamp("2025-01-02T03:04:05") + pd.to_timedelta(frame["time_s"], unit="s")
    indexed = frame.drop(columns="time_s").set_index(pd.DatetimeIndex(stamps, name="TIMESTAMP"))
    indexed.to_parquet(tmp_path / "w.parquet")
    indexed.to_hdf(tmp_path / "w.h5", key="surface", format="table")
    for name in ("w.parquet", "w.h5"):
        w = load_well(tmp_path / name)
        assert w.timebase.origin == pd.Timestamp("2025-01-02T03:04:05"), name
        _same(w.surface, frame)


def test_hdf5_compound_dataset_and_time_in_ms(tmp_path, frame):
    rec = np.zeros(len(frame), dtype=[("TIME", "f8"), ("RPM", "f8"), ("TORQUE", "f8")])
    rec["TIME"], rec["RPM"] = frame["time_s"] * 1e3, frame["surface_rpm"]
    rec["TORQUE"] = frame["surface_torque_Nm"] / 1e3
    with h5py.File(tmp_path / "w.h5", "w") as h5:
        h5["surface"] = rec
    (tmp_path / "w.toml").write_text('[channels]\ntime = { unit = "ms" }\n')
    _same(load_well(tmp_path / "w.h5").surface, frame)


# ------------------------------------------------------------------ limits (docs/security.md)
def _las_text(curves: int) -> str:
    names = [f"C{k}" for k in range(curves)]
    return ("~Version\nVERS. 2.0 :\nWRAP. NO :\n~Well\nNULL. -999.25 :\n~Other\nfree text\n"
            "~Curve\n# a comment\nTIME.s : time\n" + "".join(f"{n}.rpm : speed\n" for n in names)
            + "~ASCII\n" + "".join(" ".join([str(r)] + ["60"] * curves) + "\n"
                                   for r in range(3)))


def test_las_header_items_are_counted_per_section_without_comments_and_other(tmp_path):
    from drillfric.io.las import header_items

    path = tmp_path / "w.las"
    path.write_text(_las_text(5))
    assert header_items(path) == {"~V": 2, "~W": 1, "~C": 6}


def test_las_section_limit_refuses_one_item_more(tmp_path, monkeypatch):
    from drillfric.io import las

    monkeypatch.setattr(las, "MAX_SECTION_ITEMS", 6)
    path = tmp_path / "w.las"
    path.write_text(_las_text(5))  # TIME + 5 curves: 6 items, at the limit
    assert open_source(path).columns == ["TIME", "C0", "C1", "C2", "C3", "C4"]
    path.write_text(_las_text(6))
    with pytest.raises(InputError, match="~C holds 7 items: more than the 6"):
        open_source(path)


def test_parquet_row_limit_is_per_byte_of_file(tmp_path, monkeypatch):
    from drillfric.io import readers

    path = tmp_path / "w.parquet"
    pq.write_table(pa.table({"time_s": np.arange(1000.0)}), path)
    size = path.stat().st_size
    monkeypatch.setattr(readers, "MAX_ROWS_PER_BYTE", 1000 / size)  # exactly at the limit
    assert open_source(path).rows == 1000
    monkeypatch.setattr(readers, "MAX_ROWS_PER_BYTE", 999 / size)
    with pytest.raises(InputError, match="declares 1000 rows"):
        open_source(path)


def test_hdf5_packing_limit_is_per_byte_of_file(tmp_path, monkeypatch):
    from drillfric.io import hdf5

    path = tmp_path / "w.h5"
    with h5py.File(path, "w") as h5:
        for c in COLS:
            h5[f"surface/{c}"] = np.arange(1000.0)
    ratio = 8000 / path.stat().st_size  # each dataset declares 8000 bytes
    monkeypatch.setattr(hdf5, "MAX_PACKING_RATIO", ratio)
    assert open_source(path).rows == 1000
    monkeypatch.setattr(hdf5, "MAX_PACKING_RATIO", ratio * 0.999)
    with pytest.raises(InputError, match="declares 8000 bytes"):
        open_source(path)
