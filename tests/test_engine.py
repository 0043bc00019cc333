"""The incremental engine (issue 23): a well fed in chunks of any size, its state saved to
disk and loaded between them, gives the results of one run over the whole file."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from drillfric.errors import InputError
from drillfric.io.well import open_well
from drillfric.runner import run_well
from drillfric.runner.engine import Engine
from drillfric.runner.state import read_state, write_state
from tests.conftest import DEMO

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

#: Relative agreement of the friction numbers with the whole-file run (issue 23).
AGREE = 0.005


def _same_results(result, whole) -> None:
    a, b = result.segments, whole.segments
    assert a["id"].tolist() == b["id"].tolist()
    assert a["kind"].tolist() == b["kind"].tolist()
    assert a["status"].tolist() == b["status"].tolist()
    for name in ("mu_k", "mu_s", "mu_s_lower_bound", "t_end_s"):
        x, y = a[name].to_numpy(float), b[name].to_numpy(float)
        assert (np.isnan(x) == np.isnan(y)).all(), name
        np.testing.assert_allclose(x[~np.isnan(x)], y[~np.isnan(y)], rtol=AGREE, err_msg=name)
    if whole.summary["mu_k"] is None:  # withheld for the well: withheld alike
        assert result.summary["mu_k"] is None
    else:
        assert result.summary["mu_k"] == pytest.approx(whole.summary["mu_k"], rel=AGREE)


@pytest.mark.parametrize("plant, seed", [("stands", s) for s in range(1, 11)]
                         + [("stick_slip", s) for s in range(1, 11)])
def test_chunks_of_random_size_and_a_saved_state_give_the_whole_run(request, tmp_path, plant,
                                                                    seed):
    """Chunks of 1 … 20 000 rows (boundaries inside stands, pre-rolls, connections and
    stick-slip stalls), a peek at the results half-way and the state written to disk and
    read back between chunks: the same segments, kinds, statuses and friction numbers as
    the whole file — for a stiff drive turning smoothly and a soft one that stick-slips."""
    path, whole = request.getfixturevalue(plant)
    frame = pd.read_csv(path)
    rng = np.random.default_rng(seed)
    cuts = np.cumsum(rng.integers(1, 20_000, size=40))
    cuts = np.unique(np.r_[0, cuts[cuts < len(frame)], len(frame)])
    well = open_well(frame=frame.iloc[:cuts[1]], config=path.with_suffix(".toml"),
                     survey=path.with_suffix(".survey.csv"), name=path.stem)
    engine = Engine(well)
    for k, (a, b) in enumerate(zip(cuts[:-1], cuts[1:], strict=True)):
        engine.feed(frame.iloc[a:b])
        if k == len(cuts) // 2:
            assert engine.result().counts["segments"] <= len(whole.segments)  # a peek
            engine.save(tmp_path / "state")
            engine = Engine.load(tmp_path / "state", well)
    _same_results(engine.result(), whole)


def test_run_with_out_keeps_its_state_and_a_resumed_engine_ends_alike(stands, tmp_path):
    """`run --out` leaves OUT/NAME/state/; an engine loaded from it and fed the rest of a
    grown file ends with the whole file's results (and says what it revised)."""
    path, whole = stands
    frame = pd.read_csv(path)
    half = tmp_path / "part" / path.name
    half.parent.mkdir()
    frame.iloc[: len(frame) // 2].to_csv(half, index=False)
    for sidecar in (".toml", ".survey.csv"):
        half.with_suffix(sidecar).write_text(path.with_suffix(sidecar).read_text())
    first = run_well(open_well(half), tmp_path / "out")
    assert (first.out_dir / "state" / "engine.json").is_file()
    well = open_well(frame=frame.iloc[:10], config=half.with_suffix(".toml"),
                     survey=half.with_suffix(".survey.csv"), name="three")
    engine = Engine.load(first.out_dir / "state", well)
    engine.feed(frame.iloc[len(frame) // 2:])
    result = engine.result()
    _same_results(result, whole)
    open_before = first.summary["segments"][-1]["id"]
    assert any(r["segment"] == open_before for r in result.summary["revisions"])


def test_a_state_of_another_configuration_is_refused(stands, tmp_path):
    path, _ = stands
    frame = pd.read_csv(path).iloc[:3000]
    well = open_well(frame=frame, config=path.with_suffix(".toml"),
                     survey=path.with_suffix(".survey.csv"))
    engine = Engine(well)
    engine.feed(frame)
    engine.save(tmp_path / "s")
    other = open_well(frame=frame, config=path.with_suffix(".toml"),
                      survey=path.with_suffix(".survey.csv"),
                      overrides={"segmentation.rotating_rpm": 7.0})
    with pytest.raises(InputError, match="configuration changed"):
        Engine.load(tmp_path / "s", other)


def test_state_with_pickled_array_or_foreign_table_name_is_refused(tmp_path):
    """A state is input: an object array (pickle) or a table outside the folder is refused
    with one InputError, nothing executed (attack: state_pickle_array)."""
    write_state(tmp_path, {"a": np.arange(3.0), "f": pd.DataFrame({"x": [1.0]})})
    assert read_state(tmp_path)["a"].tolist() == [0.0, 1.0, 2.0]
    np.savez(tmp_path / "arrays.npz", a0=np.array([{"x": 1}], dtype=object))
    with pytest.raises(InputError, match="engine state not readable"):
        read_state(tmp_path)
    write_state(tmp_path, {"a": 1})
    doc = json.loads((tmp_path / "engine.json").read_text())
    doc["state"] = {"$frame": "../../etc/passwd"}
    (tmp_path / "engine.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match="engine state not readable"):
        read_state(tmp_path)


@pytest.fixture(scope="module")
def weighed_demo(tmp_path_factory):
    """The demo's four stands behind 60 s in the slips with a 150-kN block on the hook (the
    first stand's string 3 % heavier), and a configured string 30 % too light that the hook
    load calibrates (docs/theory.md §2.1)."""
    from tests.test_hookload import BLOCK_N, _masses

    folder = tmp_path_factory.mktemp("weighed_demo")
    demo = pd.read_csv(DEMO / "demo.csv")
    t = np.arange(0.0, 60.0, 0.05)
    slips = pd.DataFrame({"time_s": t, "surface_rpm": 0.0, "surface_torque_Nm": 0.0,
                          "hookload_N": BLOCK_N + np.random.default_rng(22).normal(0, 2e3, t.size),
                          "bit_depth_m": 2210.0, "hole_depth_m": 2215.0, "bit_rpm": 0.0,
                          "string_torque_Nm": 0.0})
    demo = demo.assign(time_s=demo["time_s"] + 60.0, hookload_N=demo["hookload_N"] + BLOCK_N)
    first = demo["time_s"] < 290.0  # the first stand weighs 3 % more: the scale moves later
    demo.loc[first, "hookload_N"] += 0.03 * (demo.loc[first, "hookload_N"] - BLOCK_N)
    frame = pd.concat([slips, demo], ignore_index=True)
    base = (DEMO / "demo.toml").read_text()
    config = folder / "weighed.toml"
    config.write_text(_masses(base[:base.index("\n[simulate]")], 0.7)
                      + "\n[hookload]\ncalibrate_string_weight = true\n")
    return frame, config


def test_a_calibrated_string_streamed_in_chunks_revises_to_the_whole_run(weighed_demo, tmp_path):
    """With hookload.calibrate_string_weight the scale the rows so far support moves as
    stands arrive: segments estimated with an earlier scale are re-estimated at the end
    (summary.json revisions) and the results are those of the whole data in one chunk."""
    frame, config = weighed_demo
    survey = DEMO / "demo.survey.csv"
    whole = run_well(open_well(frame=frame, config=config, survey=survey))
    assert whole.summary["hookload"]["verdict"] == "calibrated"
    engine = Engine(open_well(frame=frame.iloc[:100], config=config, survey=survey))
    for a in range(0, len(frame), 2_500):
        engine.feed(frame.iloc[a:a + 2_500])
        if a == 10_000:
            engine.save(tmp_path / "state")
            engine = Engine.load(tmp_path / "state", engine.well)
    result = engine.result()
    _same_results(result, whole)
    assert result.summary["hookload"]["calibration_scale"] == pytest.approx(
        whole.summary["hookload"]["calibration_scale"], rel=1e-12)
    revised = [r for r in result.summary["revisions"] if "calibration" in r["reason"]]
    assert revised and revised[0]["segment"] == 1  # the first stand's scale alone was off
