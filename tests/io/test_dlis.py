"""DLIS (RP66 v1) logs through open_source (drillfric.io.dlis).

dlisio reads DLIS but cannot write it: the files are built here with dliswriter (a
pure-Python RP66 v1 writer from PyPI, test dependency), and the channels must come back
through :func:`drillfric.io.readers.open_source` with their values and units unchanged.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd
import pytest

from drillfric.errors import InputError
from drillfric.io.channels import map_channels
from drillfric.io.readers import open_source

dliswriter = pytest.importorskip("dliswriter")

N = 50


def _write(path, frames: list[tuple[str, str, list[tuple[str, np.ndarray, str]]]]) -> None:
    """A DLIS file with one origin and ``frames`` of (name, index type, channels)."""
    logging.getLogger("dliswriter").setLevel(logging.ERROR)  # non-RP66 unit names warn
    dlis = dliswriter.DLISFile()
    logical = dlis.add_logical_file()
    logical.add_origin("ORIGIN")
    for name, index_type, channels in frames:
        items = [logical.add_channel(c, data=data, units=unit) for c, data, unit in channels]
        logical.add_frame(name, channels=items, index_type=index_type)
    dlis.write(str(path), output_chunk_size=1 << 16)  # the default buffer is 4 GiB


def _surface(rng) -> list[tuple[str, np.ndarray, str]]:
    return [("TIME", np.arange(N, dtype=float) * 0.5, "s"),
            ("SRPM", rng.uniform(0, 150, N), "rpm"),
            ("STOR", rng.uniform(5, 25, N), "kN.m"),
            ("HKLD", rng.uniform(100, 300, N), "klbf")]


def _gamma(rows: int) -> list[tuple[str, np.ndarray, str]]:
    return [("DEPT", 1000.0 + 0.1 * np.arange(rows), "m"), ("GR", np.full(rows, 80.0), "gAPI")]


def test_channels_round_trip_with_values_and_units(tmp_path):
    rng = np.random.default_rng(7)
    channels = _surface(rng)
    path = tmp_path / "surface.dlis"
    _write(path, [("SURFACE", "TIME", channels)])
    source = open_source(path)
    assert source.format == "dlis" and source.columns == ["TIME", "SRPM", "STOR", "HKLD"]
    assert {c: source.units[c] for c in source.columns} == {
        "TIME": "s", "SRPM": "rpm", "STOR": "kN.m", "HKLD": "klbf"}
    assert source.rows == N and source.depth_index is None
    frame = pd.concat(list(source.chunks(16)), ignore_index=True)
    for name, data, _ in channels:
        np.testing.assert_array_equal(frame[name].to_numpy(), data)  # float64 stored as is
    mapping = map_channels(source.columns, source.units, {})
    assert mapping["surface_torque"].factor == pytest.approx(1e3, rel=1e-15)


def test_the_surface_frame_is_read_from_several(tmp_path):
    """A larger depth frame listed first does not win over the frame with the surface
    channels."""
    _write(tmp_path / "two.dlis", [("GAMMA", "BOREHOLE-DEPTH", _gamma(4 * N)),
                                   ("SURFACE", "TIME", _surface(np.random.default_rng(1)))])
    source = open_source(tmp_path / "two.dlis")
    assert source.columns[:2] == ["TIME", "SRPM"] and source.rows == N


def test_depth_frame_is_depth_indexed(tmp_path):
    _write(tmp_path / "depth.dlis", [("GAMMA", "BOREHOLE-DEPTH", _gamma(10))])
    source = open_source(tmp_path / "depth.dlis")
    assert source.depth_index == "DEPT [m]"


def test_array_channels_are_left_out(tmp_path):
    channels = _surface(np.random.default_rng(2)) + [("IMAGE", np.ones((N, 3)), "")]
    _write(tmp_path / "img.dlis", [("SURFACE", "TIME", channels)])
    source = open_source(tmp_path / "img.dlis")
    assert "IMAGE" not in source.columns
    assert pd.concat(list(source.chunks())).shape == (N, 4)


def test_a_file_that_is_not_dlis_is_one_line(tmp_path):
    path = tmp_path / "fake.dlis"
    path.write_bytes(b"TIME,RPM\n" * 100)
    with pytest.raises(InputError, match="not a readable DLIS file") as info:
        open_source(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)
