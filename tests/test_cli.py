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


def test_quiet_and_debug_are_accepted_after_the_command(tmp_path):
    """Regression (the fourth newcomer): ``drillfric run W -q`` failed with "No such option
    '-q'" — the nightly-job flag worked only before the command. Both places work."""
    demo = tmp_path / "missing.csv"
    after = CliRunner().invoke(cli, ["run", str(demo), "--out", str(tmp_path / "o"), "-q"])
    assert "No such option" not in after.output and after.exit_code == 2
    assert "not found" in after.output
    helped = CliRunner().invoke(cli, ["td", "--help"])
    assert "--quiet" in helped.output and "--debug" in helped.output
