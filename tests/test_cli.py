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
