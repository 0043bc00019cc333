"""The process's layout cache (issue 17, :meth:`drillfric.report.interactive.Embedder.add_like`).

A report's Bokeh layouts (time tracks, friction log, each segment's evidence) are built once
per signature and process; a later well with the same signature gets a copy of that JSON with
its own data in the named ColumnDataSources. The invariant: such a page is, item for item,
the page built from scratch for that well (Bokeh's ids aside, which differ from build to
build), and its data are its own well's.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drillfric.report import write_well_report
from drillfric.report.interactive import _LAYOUTS, forget_layouts
from tests.test_report import bokeh_items, copy_result, evidence_dir, sources

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

#: Factor applied to the other well's tracks and torques (any change of the data will do).
_SCALE = 1.1


@pytest.fixture(scope="module")
def evidence(tmp_path_factory) -> Path:
    return evidence_dir(tmp_path_factory)


def other_well(evidence: Path, dst: Path) -> Path:
    """The evidence results with other numbers: μ shifted, tracks and torques scaled."""
    def edit(summary):
        summary["well"] = "other"
        for seg in summary["segments"]:
            if seg["mu_k"] is not None:
                seg["mu_k"] += 0.05

    result = copy_result(evidence, dst, edit)
    tracks = pd.read_parquet(result / "tracks.parquet")
    numbers = [c for c in tracks.columns if c.endswith(("_min", "_max", "_mean"))]
    tracks[numbers] = tracks[numbers] * _SCALE
    tracks.to_parquet(result / "tracks.parquet")
    est = pd.read_parquet(result / "estimates.parquet")
    torques = [c for c in est.columns if c.startswith("surface_torque")]
    est[torques] = est[torques] * _SCALE
    est.to_parquet(result / "estimates.parquet")
    return result


def _renumbered(items: dict[str, dict]) -> str:
    """The items as JSON with Bokeh's model ids ("p1234") numbered in order of appearance."""
    text = json.dumps(items, sort_keys=True, ensure_ascii=False)
    ids: dict[str, str] = {}
    return re.sub(r'"p\d+"', lambda m: ids.setdefault(m.group(0), f'"#{len(ids)}"'), text)


def test_refilled_layouts_equal_layouts_built_from_scratch(evidence, tmp_path):
    other = other_well(evidence, tmp_path / "other")
    forget_layouts()
    first = bokeh_items(write_well_report(evidence).read_text(encoding="utf-8"))
    kinds = len(_LAYOUTS)
    warm = bokeh_items(write_well_report(other).read_text(encoding="utf-8"))
    assert len(_LAYOUTS) == kinds  # nothing new was built: every layout was a copy
    forget_layouts()
    fresh = bokeh_items(write_well_report(other).read_text(encoding="utf-8"))
    assert set(warm) == set(fresh) and "bk-tracks" in warm and "bk-friction" in warm
    assert _renumbered(warm) == _renumbered(fresh)
    seg = next(k for k in warm if k.startswith("bk-segment-"))
    np.testing.assert_allclose(sources(warm[seg])["panel:torque"]["measured"],
                               sources(first[seg])["panel:torque"]["measured"] * _SCALE,
                               rtol=1e-6)


def test_layouts_in_other_units_are_built_again(evidence):
    """The unit system is part of a layout's signature: its axis labels differ."""
    forget_layouts()
    write_well_report(evidence, units="si")
    field = bokeh_items(write_well_report(evidence, units="field").read_text(
        encoding="utf-8"))
    text = json.dumps(field["bk-tracks"], ensure_ascii=False)
    assert "hook load [klbf]" in text and "[kN" not in text
    assert "bit depth [ft]" in json.dumps(field["bk-friction"], ensure_ascii=False)


def test_cache_keeps_the_most_recent_signatures(monkeypatch):
    """At most LAYOUT_CACHE_SIZE layouts are kept; the least recently used goes first."""
    from bokeh.models import ColumnDataSource
    from bokeh.plotting import figure

    from drillfric.report import interactive

    def build():
        fig = figure()
        fig.line("x", "y", source=ColumnDataSource({"x": [0.0], "y": [0.0]}, name="s"))
        return fig

    monkeypatch.setattr(interactive, "LAYOUT_CACHE_SIZE", 2)
    forget_layouts()
    embed = interactive.Embedder()
    data = {"s": {"x": np.array([1.0]), "y": np.array([2.0])}}
    for signature in ("a", "b", "a", "c"):  # "a" used again, so "b" is the oldest
        embed.add_like(signature, build, data, signature)
    assert list(_LAYOUTS) == ["a", "c"]
    forget_layouts()
