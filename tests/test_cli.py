"""CLI skeleton: group options, version, one-line errors with exit code 2."""

from __future__ import annotations

from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric import __version__


def test_help_lists_interface_commands():
    result = CliRunner().invoke(cli, ["--help"])
    assert result.exit_code == 0
    for name in ("run", "simulate", "td", "inspect", "fleet", "report"):
        assert name in result.output


def test_version():
    result = CliRunner().invoke(cli, ["--version"])
    assert result.exit_code == 0 and __version__ in result.output


def test_cli_reference_is_current():
    """docs/cli.md is generated from --help and must not drift (datasette practice)."""
    from drillfric.cli.reference import reference

    from tests.conftest import REPO

    doc = (REPO / "docs" / "cli.md").read_text(encoding="utf-8")
    assert doc == reference(), "run: python -m drillfric.cli.reference > docs/cli.md"


def test_unknown_command_is_usage_error():
    result = CliRunner().invoke(cli, ["frobnicate"])
    assert result.exit_code == 2 and "Traceback" not in result.output
