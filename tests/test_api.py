"""The public Python API (docs/api.md): the documented session runs as written."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest

from tests.conftest import REPO


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
