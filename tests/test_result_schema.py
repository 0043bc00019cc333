"""One result schema (drillfric.result): every writer, the report's data layer and the fleet
summary take their columns from it, and docs/outputs.md is generated from it."""

from __future__ import annotations

import re

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from drillfric.drag import DRAG_NAMES
from drillfric.fleet.run import WellOutcome, summary_frame
from drillfric.io.results import arrow_schema, write_segments
from drillfric.io.tracks import TRACK_CHANNELS
from drillfric.result import (
    ESTIMATE_NAMES,
    FLEET_WELL_COLUMNS,
    SEGMENT_FIELDS,
    Flag,
    SegmentRecord,
    outputs_markdown,
    segment_arrow_types,
)
from drillfric.vocabulary import Kind, Status
from tests.conftest import REPO

#: Columns of the other result tables (profiles.parquet, wellpath.parquet, tracks.parquet).
OTHER_TABLES = {"md_m", "inc_deg", "tension_N", "torque_Nm", "normal_force_N_m", "fc_Nm_m",
                "tvd_m", "north_m", "east_m", "inc_rad", "azi_rad", "dls_rad_m", "time_s",
                "timestamp", "rig_state", *TRACK_CHANNELS}


def test_docs_outputs_is_generated_from_the_schema():
    """docs/outputs.md ends with outputs_markdown() (datasette practice: docs cannot drift)."""
    doc = (REPO / "docs" / "outputs.md").read_text(encoding="utf-8")
    marker = "<!-- generated: drillfric.result.outputs_markdown() -->\n"
    assert doc.split(marker, 1)[1] == outputs_markdown(), "regenerate docs/outputs.md's tail"


def test_segments_parquet_has_the_schema_fields_and_types(tmp_path):
    """A column null in every row keeps its declared type (not Arrow's null type)."""
    records = [SegmentRecord(id=1, kind=Kind.OFF_BOTTOM, status=Status.SKIPPED,
                             message="too short")]
    write_segments(tmp_path / "s.parquet", records)
    schema = pq.read_schema(tmp_path / "s.parquet")
    assert tuple(schema.names) == SEGMENT_FIELDS
    types = segment_arrow_types()
    for name in SEGMENT_FIELDS:
        assert schema.field(name).type == types[name], name


def test_estimates_writer_columns_are_the_schema():
    assert tuple(arrow_schema(True, with_clock=True).names) == ESTIMATE_NAMES
    assert tuple(arrow_schema(False).names) == tuple(n for n in ESTIMATE_NAMES
                                                     if n not in ("bit_rpm", "timestamp"))
    assert arrow_schema(False, with_clock=True).field("timestamp").type == pa.timestamp(
        "us", tz="UTC")


def test_fleet_summary_columns_are_the_schema():
    seg = SegmentRecord(id=3, mu_k=0.2).to_json()
    frame = summary_frame([WellOutcome("A", "ok", summary={"mu_k": 0.2, "segments": [seg]}),
                           WellOutcome("B", "failed", "unreadable")])
    assert list(frame.columns) == list(FLEET_WELL_COLUMNS) + [f for f in SEGMENT_FIELDS
                                                               if f != "id"] + ["mu_apparent"]
    assert frame["segment_id"].tolist()[0] == 3 and pd.isna(frame["segment_id"].iloc[1])


def test_report_reads_only_columns_the_schema_declares():
    """Every column-like name the report subscripts (unit suffixes, μ names) is a column of a
    result table: a report listing a column the run does not write fails here."""
    known = set(SEGMENT_FIELDS) | set(ESTIMATE_NAMES) | OTHER_TABLES | set(DRAG_NAMES)
    known |= {f"{c}_{s}" for c in TRACK_CHANNELS for s in ("min", "max", "mean")}
    pattern = re.compile(r'\["((?:mu_\w+)|(?:\w+_(?:m|s|Nm|N|rpm|Pa|deg|rad|m3_s|N_m|Nm_m)))"\]')
    unknown = {}
    for path in sorted((REPO / "drillfric" / "report").glob("*.py")):
        text = path.read_text(encoding="utf-8")
        for name in pattern.findall(text):
            made_here = f'["{name}"] =' in text or f'"{name}":' in text  # the report's own
            if name not in known and not made_here:
                unknown.setdefault(path.name, set()).add(name)
    assert not unknown, unknown


def test_only_the_data_layer_reads_result_files():
    """The report reads result files through report/data.py alone (which takes its column
    lists from the schema)."""
    readers = re.compile(r"read_parquet\(|read_table\(|json\.load")
    others = [p.name for p in (REPO / "drillfric" / "report").glob("*.py")
              if p.name != "data.py" and readers.search(p.read_text(encoding="utf-8"))]
    assert not others, others


def test_results_flagged_observer_not_converged_still_load():
    """Issue 35: "converged" stood beside the flag ``observer_not_converged`` on every demo
    segment (the batch fit's μ_k converged while the observer's starts spread). The flag is
    now ``observer_starts_disagree``; results written before still read."""
    assert Flag("observer_not_converged") is Flag.OBSERVER_STARTS_DISAGREE
    assert Flag.OBSERVER_STARTS_DISAGREE.value == "observer_starts_disagree"
