"""The ``drillfric`` command group (docs/cli.md): run, simulate, td, inspect, fleet, report,
live, replay."""

from __future__ import annotations

import os
import signal
import sys
from contextlib import contextmanager

import click

from drillfric import __version__

from .common import (
    RunContext,
    catch_sigterm,
    interrupted_exit_code,
    library_output,
    user_errors,
)


class _Group(click.Group):
    """Command group whose sub-commands turn library errors into one readable line, library
    warnings into drillfric's own warning lines, and an interruption (Ctrl-C, SIGTERM) into
    a clean stop with exit code 128 + signal."""

    def invoke(self, ctx: click.Context):
        catch_sigterm()
        try:
            with user_errors(), library_output(), _reader_gone():
                return super().invoke(ctx)
        except KeyboardInterrupt:
            click.secho("interrupted: nothing half-written was left; run the command again "
                        "to complete it", err=True, fg="yellow")
            ctx.exit(interrupted_exit_code())


@contextmanager
def _reader_gone():
    """The reader of standard output went away (``drillfric td … | head``): stop quietly
    with the shell's exit code for SIGPIPE, as a command-line tool does, not an internal
    error."""
    try:
        yield
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error
        raise click.exceptions.Exit(128 + signal.SIGPIPE) from None


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="drillfric")
@click.option("--debug", is_flag=True, help="Show full tracebacks on errors.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bars or chatter (nightly jobs).")
@click.pass_context
def cli(ctx: click.Context, debug: bool, quiet: bool) -> None:
    """drillfric — downhole friction factors and bit speed from rig surface data.

    Estimates static and kinetic friction factors (μ_s, μ_k) and the downhole bit speed
    with the adaptive observer of Aarsnes et al. (JPSE 2019), refined by a batch fit.
    """
    ctx.obj = RunContext(debug=debug, quiet=quiet)


def _register() -> None:
    from . import (
        fleet_cmd,
        inspect_cmd,
        live_cmd,
        replay_cmd,
        report_cmd,
        run_cmd,
        simulate_cmd,
        td_cmd,
    )

    for module in (run_cmd, simulate_cmd, td_cmd, inspect_cmd, fleet_cmd, report_cmd, live_cmd,
                   replay_cmd):
        module.command.params += [_global_flag("--quiet", "-q", "quiet"),
                                  _global_flag("--debug", None, "debug")]
        cli.add_command(module.command)


def _global_flag(name: str, short: str | None, field: str) -> click.Option:
    """The group's ``--quiet``/``--debug`` accepted after the command too (``drillfric run
    W -q`` had failed: "No such option '-q'")."""

    def set_flag(ctx: click.Context, _param, value: bool) -> None:
        obj = ctx.find_object(RunContext)
        if value and obj is not None:
            setattr(obj, field, True)

    return click.Option([name] + ([short] if short else []), is_flag=True, expose_value=False,
                        callback=set_flag, help="As before the command.")


_register()


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point."""
    cli.main(args=argv if argv is not None else sys.argv[1:], prog_name="drillfric")


if __name__ == "__main__":
    main()
