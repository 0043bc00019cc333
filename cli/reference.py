"""The CLI reference (docs/cli.md), generated from the commands' own ``--help``.

``python -m drillfric.cli.reference > docs/cli.md``; ``tests/test_cli.py`` fails when the
file and the commands differ, so the documentation cannot drift from the code.
"""

from __future__ import annotations

import click

from .main import cli


def _help(command: click.Command, name: str, parent: click.Context | None) -> str:
    ctx = click.Context(command, info_name=name, parent=parent, terminal_width=100,
                        max_content_width=100)
    return command.get_help(ctx)


def reference() -> str:
    """Markdown of ``drillfric --help`` and every sub-command's help."""
    root = click.Context(cli, info_name="drillfric", terminal_width=100,
                         max_content_width=100, **cli.context_settings)
    parts = ["# Command-line reference", "",
             "Generated from the commands' `--help` (`python -m drillfric.cli.reference > "
             "docs/cli.md`); a test fails when this file and the commands differ.", "",
             "Exit codes: 0 all good; 1 some wells or segments failed (the others completed "
             "and were written); 2 bad usage or unreadable input (one line naming the file, "
             "the problem and the fix; a traceback only with `--debug`).", "",
             "## drillfric", "", "```", cli.get_help(root), "```", ""]
    for name in sorted(cli.commands):
        parts += [f"## drillfric {name}", "", "```",
                  _help(cli.commands[name], name, root), "```", ""]
    return "\n".join(parts)


if __name__ == "__main__":
    print(reference(), end="")
