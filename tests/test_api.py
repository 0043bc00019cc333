"""The public Python API (docs/api.md): the documented session runs as written."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest

from tests.conftest import REPO

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow


def _blocks(markdown: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", markdown, flags=re.S)


@pytest.mark.slow
def test_api_example_in_the_docs_runs_from_the_repository_root():
    """docs/api.md's notebook session, executed as a fresh process from the repository root
    (its asserts check μ_k within 5 % of the simulated truth and the read-back)."""
    code = "\n".join(_blocks((REPO / "docs" / "api.md").read_text(encoding="utf-8")))
    assert "drillfric.run(" in code
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True,
                          text=True, env=os.environ | {"MPLBACKEND": "Agg"}, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "report.html" in done.stdout


@pytest.mark.slow
def test_readme_python_snippet_runs_and_gives_a_mu_k():
    """Issue 35: README's snippet (`open_well(frame=df, …)`) gave status "not_estimated" —
    no block weight, so the string weight was unverified and μ withheld. Executed as
    written from the repository root, it gives a number."""
    (code,) = _blocks((REPO / "README.md").read_text(encoding="utf-8"))
    code += "\nprint('MU_K', result.mu_k, result.status)\n"
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True,
                          text=True, env=os.environ | {"MPLBACKEND": "Agg"}, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    mu_k, status = done.stdout.split("MU_K ")[1].split()
    assert status == "estimated" and 0.26 < float(mu_k) < 0.30  # truth 0.28


def test_import_is_cheap_and_exposes_the_api():
    """`import drillfric` loads none of the numerical stack (the API loads it when called)."""
    code = ("import sys, drillfric; heavy = [m for m in ('numpy', 'pandas', 'numba', 'scipy') "
            "if m in sys.modules]; print(heavy, sorted(drillfric.__all__))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.startswith("[]"), out
    for name in ("open_well", "run", "load_result", "torque_and_drag", "simulate"):
        assert name in out


def test_load_result_of_something_else_is_one_clear_error(tmp_path):
    import drillfric
    from drillfric.errors import InputError

    with pytest.raises(InputError, match="not a drillfric result directory"):
        drillfric.load_result(tmp_path)


# ----------------------------------------------------------------------------- data in memory
@pytest.fixture(scope="module")
def stand(tmp_path_factory):
    """A simulated 100-s stand on disk (data, config and survey sidecars)."""
    import drillfric

    path = tmp_path_factory.mktemp("stand") / "stand.parquet"
    drillfric.simulate(REPO / "examples" / "demo" / "demo.toml", out=path, bit_depth_m=2000.0,
                       duration_s=100.0, mu_s=0.5, mu_k=0.25, seed=3)
    return path


def _in_memory(path, **kw):
    """The well of ``path`` as a notebook holds it: DataFrame, survey table, config dict."""
    import tomllib

    import pandas as pd

    import drillfric

    return drillfric.open_well(
        frame=pd.read_parquet(path), survey=pd.read_csv(path.with_suffix(".survey.csv")),
        config=tomllib.loads(path.with_suffix(".toml").read_text()), **kw)


@pytest.mark.slow
def test_a_dataframe_gives_what_the_file_gives(stand):
    """One path through the code: the frame is read as the file is, so the estimates are
    the same to the bit (only summary.json ``inputs`` differs: no data file)."""
    import pandas as pd

    import drillfric

    from_file = drillfric.run(stand)
    from_frame = drillfric.run(_in_memory(stand, name="stand"))
    pd.testing.assert_frame_equal(from_frame.segments, from_file.segments, check_exact=True)
    pd.testing.assert_frame_equal(from_frame.estimates, from_file.estimates, check_exact=True)
    assert from_frame.mu_k == from_file.mu_k and from_frame.mu_k is not None
    assert "data" in from_file.summary["inputs"] and "data" not in from_frame.summary["inputs"]


def test_a_clock_time_index_is_the_time_channel(stand):
    """A historian's table: clock time as the index, units in the column names."""
    import numpy as np
    import pandas as pd

    import drillfric

    frame = pd.read_parquet(stand)
    clock = pd.Timestamp("2024-03-01T06:00:00Z") + pd.to_timedelta(frame.pop("time_s"), "s")
    frame = frame.set_axis(clock.rename("time")).rename(
        columns={"surface_torque_Nm": "TORQUE [kN.m]", "surface_rpm": "RPM [rpm]"})
    frame["TORQUE [kN.m]"] /= 1e3
    well = drillfric.open_well(frame=frame, config={}, name="historian")
    surface = well.load().surface
    expected = pd.read_parquet(stand)
    np.testing.assert_allclose(surface["time_s"], expected["time_s"], atol=1e-6)
    np.testing.assert_allclose(surface["surface_torque_Nm"], expected["surface_torque_Nm"],
                               rtol=1e-12)
    assert surface["timestamp"].iloc[0] == pd.Timestamp("2024-03-01T06:00:00Z")


def test_a_dataframe_well_reads_no_sidecar(stand, tmp_path, monkeypatch):
    """Nothing is read but what is given: files in the working directory named like the
    frame's label are not sidecars."""
    import pandas as pd

    import drillfric

    monkeypatch.chdir(tmp_path)
    for name in ("<DataFrame>.toml", "<DataFrame>.survey.csv", "well.toml"):
        (tmp_path / name).write_text("not read")
    well = drillfric.open_well(frame=pd.read_parquet(stand))
    assert (well.files.config, well.files.survey, well.survey) == (None, None, None)
    assert well.name == "well" and well.files.inputs == {}


@pytest.mark.parametrize("kw, error", [
    ({}, "one of the two"),
    ({"path": "x.csv", "frame": "df"}, "one of the two"),
    ({"frame": [[1.0, 2.0]]}, "not a pandas DataFrame"),
    ({"frame": "dup"}, "appears twice"),
    ({"frame": "ok", "survey": [0.0, 100.0]}, "survey is a list"),
    ({"frame": "ok", "config": 3}, "config is a int"),
], ids=["neither", "both", "not-a-frame", "duplicate-columns", "survey-type", "config-type"])
def test_bad_data_in_memory_is_one_clear_error(kw, error):
    import pandas as pd

    import drillfric
    from drillfric.errors import DrillfricError

    frames = {"dup": pd.DataFrame([[0.0, 1.0]], columns=["time_s", "time_s"]),
              "ok": pd.DataFrame({"time_s": [0.0, 1.0], "surface_rpm": [60.0, 60.0],
                                 "surface_torque_Nm": [9e3, 9e3]}),
              "df": pd.DataFrame()}
    if isinstance(kw.get("frame"), str):
        kw = kw | {"frame": frames[kw["frame"]]}
    with pytest.raises(DrillfricError, match=error):
        drillfric.open_well(**kw)


def test_well_result_headline_numbers_are_typed_and_shown_short():
    import pandas as pd

    from drillfric.result import WellResult

    counts = {"segments": 3, "estimated": 2, "converged": 1, "skipped": 1, "failed": 0}
    bounded = WellResult("A", {"mu_k": 0.2512, "mu_s": None, "mu_s_lower_bound": 0.31,
                               "counts": counts, "indicative": True}, pd.DataFrame())
    assert (bounded.mu_k, bounded.mu_s, bounded.mu_s_lower_bound) == (0.2512, None, 0.31)
    assert bounded.status == "estimated" and bounded.counts == counts and bounded.indicative
    assert repr(bounded) == ("<WellResult 'A': estimated, μ_k 0.251, μ_s ≥ 0.310; 3 segments "
                             "(1 converged, 0 failed); 0 warnings (indicative)>")
    none = WellResult("B", {"mu_k": None, "mu_s": None, "mu_s_lower_bound": None,
                            "counts": counts | {"converged": 0}}, pd.DataFrame())
    assert none.status == "not_estimated" and "μ_k —" in repr(none)
    empty = WellResult("C", {"mu_k": None, "counts": {"segments": 0}}, pd.DataFrame())
    assert empty.status == "no_segments"
    one = WellResult("D", {"mu_k": None, "counts": {"segments": 1}}, pd.DataFrame(),
                     warnings=["w"])
    assert "; 1 segment (" in repr(one) and "; 1 warning>" in repr(one)  # not "1 segments"


def test_notebook_reprs_are_one_line_not_the_arrays():
    """Issue 35 (15): a Well, a Simulation and a TDResult printed ~1000 lines of arrays in a
    notebook; each is one line naming what it holds."""
    import drillfric

    demo = REPO / "examples" / "demo"
    well = drillfric.open_well(demo / "demo.csv")
    shown = {"Well": repr(well),
             "TDResult": repr(drillfric.torque_and_drag(well, 2300.0, friction=0.25)),
             "Simulation": repr(drillfric.simulate(demo / "demo.toml", duration_s=60.0))}
    for name, text in shown.items():
        assert text.startswith(f"<{name} ") and "\n" not in text and len(text) < 300, text
    assert "2300.0 m" in shown["TDResult"] and "'demo'" in shown["Well"]
    # the key facts, in engineering units: sizes, depths, rate, loads
    assert "7 channels" in shown["Well"] and "59 stations to 2430 m" in shown["Well"]
    assert " kN," in shown["TDResult"] and " kN·m" in shown["TDResult"]
    assert "e+0" not in shown["TDResult"] and "1151 nodes" in shown["TDResult"]
    assert "4 stands at bit 2210–2300 m, 20801 rows at 20 Hz, 1040 s" in shown["Simulation"]


def test_dir_lists_the_public_api():
    import drillfric

    assert dir(drillfric) == sorted(drillfric.__all__)
    assert {"open_well", "run", "WellResult"} <= set(dir(drillfric))


@pytest.mark.slow
def test_pandas_friendly_results_flags_column_clash_none_vs_nan_json_lists_spaces(stand,
                                                                                  tmp_path):
    """Issue 25 item 9: no column shadows a DataFrame attribute (``flags``), missing numbers
    are NaN from run() as from load_result(), lists are lists (Arrow lists on disk), and a
    well name with blanks gives a folder name without them (the name shown stays)."""
    import pandas as pd
    import pyarrow.parquet as pq

    import drillfric

    ran = drillfric.run(stand, tmp_path, report=False, name="Well 7 ST")
    loaded = drillfric.load_result(ran.out_dir)
    assert ran.out_dir.name == "Well_7_ST" and ran.well == loaded.well == "Well 7 ST"
    for frame in (ran.segments, loaded.segments):
        assert "flags" not in frame.columns
        assert isinstance(frame.flags, pd.Flags)  # pandas' own attribute, not a column
        assert list(frame.quality_flags.iloc[0]) == list(
            ran.summary["segments"][0]["quality_flags"])
        assert len(frame.starts.iloc[0]) and len(frame.starts.iloc[0][0]) == 2
        assert frame["mu_s"].dtype == "float64" and frame["mu_s_spread"].dtype == "float64"
    pd.testing.assert_frame_equal(ran.segments, loaded.segments)
    schema = pq.read_schema(ran.out_dir / "segments.parquet")
    assert str(schema.field("quality_flags").type) == "list<element: string>"
    assert str(schema.field("starts").type) == "list<element: list<element: double>>"
