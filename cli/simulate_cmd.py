"""`drillfric simulate` (INTERFACE.md) — not built yet."""

from __future__ import annotations

import click

from .common import UserError


@click.command("simulate", context_settings={"ignore_unknown_options": True})
@click.argument("args", nargs=-1, type=click.UNPROCESSED)
def command(args) -> None:
    """Not built yet."""
    raise UserError("'drillfric simulate' is not built yet in this version")
