"""Shared pieces of the CLI: run context, error translation, progress bars."""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

import click

from drillfric.errors import DrillfricError


@dataclass
class RunContext:
    """Global options of the ``drillfric`` group."""

    debug: bool = False
    quiet: bool = False


class UserError(click.ClickException):
    """A problem the user can fix: one line on stderr, exit code 2."""

    exit_code = 2


def context() -> RunContext:
    """The current :class:`RunContext` (defaults outside a click invocation)."""
    ctx = click.get_current_context(silent=True)
    obj = ctx.find_object(RunContext) if ctx is not None else None
    return obj or RunContext()


def echo(message: str = "", *, err: bool = False) -> None:
    """Print unless ``--quiet`` (errors always print)."""
    if err or not context().quiet:
        click.echo(message, err=err)


def warn(message: str) -> None:
    """A warning line on stderr (shown even with ``--quiet``: warnings matter at night too)."""
    click.secho(f"warning: {message}", err=True, fg="yellow")


@contextmanager
def user_errors():
    """Translate library exceptions into one-line CLI errors (tracebacks only with --debug)."""
    try:
        yield
    except DrillfricError as exc:
        if _debug():
            raise
        raise UserError(exc.message) from None
    except (click.ClickException, click.exceptions.Exit, click.exceptions.Abort):
        raise
    except KeyboardInterrupt:
        raise
    except Exception as exc:  # noqa: BLE001 — last line of defence: no traceback for users
        if _debug():
            raise
        raise UserError(f"internal error: {type(exc).__name__}: {exc} (rerun with --debug "
                        "for the traceback)") from None


def _debug() -> bool:
    """--debug, read when an error happens (the group's options are parsed by then)."""
    import sys

    return context().debug or "--debug" in sys.argv[1:]


@contextmanager
def progress(description: str, total: float | None):
    """A rich progress bar with ETA on stderr; yields ``advance(amount)``. Silent with --quiet.

    The library reports progress through a callback; this turns the callback into a bar.
    """
    if context().quiet:
        yield lambda amount=1.0: None
        return
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = [TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
               TimeElapsedColumn(), TimeRemainingColumn()]
    with Progress(*columns, console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task(description, total=total)
        yield lambda amount=1.0: bar.advance(task, amount)
