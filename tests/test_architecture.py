"""The layers of the house (issue 21): kernels → physics → io/estimation → run → report →
cli, declared once as an import-linter contract in pyproject.toml and checked here."""

from __future__ import annotations

import tomllib

import pytest
from importlinter.cli import lint_imports

from tests.conftest import REPO

CONTRACT = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["importlinter"]


def _layered_modules(contract: str = "layers") -> set[str]:
    (layers,) = [c["layers"] for c in CONTRACT["contracts"] if c["id"] == contract]
    return {name.strip() for layer in layers for name in layer.replace("|", ":").split(":")}


def test_no_module_imports_from_a_layer_above_it(monkeypatch):
    """A run that imported the report, or io that imported the run, breaks the contract
    (lint-imports names the import); the cache is off so nothing is written."""
    monkeypatch.chdir(REPO)
    assert lint_imports(config_filename=str(REPO / "pyproject.toml"), no_cache=True,
                        no_logo=True) == 0, "an import runs up the layers: run lint-imports"


@pytest.mark.parametrize("path", sorted(
    p for p in (REPO / "drillfric").iterdir()
    if (p.suffix == ".py" and p.name != "__init__.py") or (p / "__init__.py").is_file()),
    ids=lambda p: p.name)
def test_every_module_has_a_layer(path):
    """A new module outside every layer would be unchecked: each must be placed."""
    assert f"drillfric.{path.stem}" in _layered_modules(), (
        f"drillfric/{path.name} is in no layer of [tool.importlinter] in pyproject.toml")


@pytest.mark.parametrize("path", sorted(
    p for family in ("fleet", "live", "sim") for p in (REPO / "drillfric" / family).glob("*.py")
    if p.name != "__init__.py"), ids=lambda p: f"{p.parent.name}.{p.stem}")
def test_every_module_of_a_family_has_a_layer_in_it(path):
    """The families (issue 31) keep their own order: the entry module above its parts."""
    family = path.parent.name
    assert f"drillfric.{family}.{path.stem}" in _layered_modules(family), (
        f"drillfric/{family}/{path.name} is in no layer of the '{family}' contract")
