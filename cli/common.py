"""Shared pieces of the CLI: run context, error translation, progress bars."""

from __future__ import annotations

import logging
import signal
import sys
import time
import warnings
from contextlib import contextmanager
from dataclasses import dataclass

import click

from drillfric.errors import DrillfricError
from drillfric.io.text import one_line, plural, terminal_text


@dataclass
class RunContext:
    """Global options of the ``drillfric`` group."""

    debug: bool = False
    quiet: bool = False


class UserError(click.ClickException):
    """A problem the user can fix: one printable line on stderr, exit code 2."""

    exit_code = 2

    def __init__(self, message: str):
        super().__init__(one_line(message))


def context() -> RunContext:
    """The current :class:`RunContext` (defaults outside a click invocation)."""
    ctx = click.get_current_context(silent=True)
    obj = ctx.find_object(RunContext) if ctx is not None else None
    return obj or RunContext()


def echo(message: str = "", *, err: bool = False) -> None:
    """Print unless ``--quiet`` (errors always print)."""
    if err or not context().quiet:
        click.echo(terminal_text(message), err=err)


def warn(message: str) -> None:
    """A warning line on stderr (shown even with ``--quiet``: warnings matter at night too)."""
    click.secho(f"warning: {one_line(message)}", err=True, fg="yellow")


def error(message: str) -> None:
    """An error line on stderr for one well of several (the others carry on)."""
    click.secho(f"error: {one_line(message)}", err=True, fg="red")


class _WarningLines(logging.Handler):
    """Library log records (lasio, …) as drillfric warning lines."""

    def emit(self, record: logging.LogRecord) -> None:
        warn(f"{record.name}: {record.getMessage()}")


@contextmanager
def library_output():
    """Warnings of libraries (Python warnings, logged warnings) while a command runs, as
    drillfric's own one-line, printable warnings: no raw text from a file, no library path
    (docs/security.md)."""
    handler = _WarningLines(logging.WARNING)
    root = logging.getLogger()
    root.addHandler(handler)
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning
            yield
    finally:
        root.removeHandler(handler)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    ours = category.__module__.startswith("drillfric")
    warn(f"{message}" if ours else f"{category.__name__}: {message}")


#: Signals received while a command ran (SIGTERM is turned into KeyboardInterrupt).
RECEIVED: list[int] = []


def _terminate(signum, frame):
    RECEIVED.append(signum)
    raise KeyboardInterrupt


def catch_sigterm() -> None:
    """Turn SIGTERM into KeyboardInterrupt, so a stopped run cleans up like Ctrl-C (its
    temporary directory goes, nothing half-written stays)."""
    signal.signal(signal.SIGTERM, _terminate)


def interrupted_exit_code() -> int:
    """128 + the signal that stopped the command (130 for Ctrl-C, 143 for SIGTERM)."""
    return 128 + (RECEIVED[-1] if RECEIVED else signal.SIGINT)


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
    return context().debug or "--debug" in sys.argv[1:]


@contextmanager
def progress(description: str, total: float | None):
    """A rich progress bar with ETA on stderr; yields ``advance(amount)``. Silent with --quiet.

    The library reports progress through a callback; this turns the callback into a bar.
    Without a terminal (a nightly job's log) a line per 10 % is printed instead.
    """
    if context().quiet:
        yield lambda amount=1.0: None
        return
    if not sys.stderr.isatty():
        with _progress_lines(description, total) as advance:
            yield advance
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


@contextmanager
def _progress_lines(description: str, total: float | None):
    """Progress as plain lines on stderr, one per 10 % (for logs, no terminal)."""
    state = {"done": 0.0, "shown": 0, "t0": time.monotonic()}

    def advance(amount: float = 1.0) -> None:
        state["done"] += amount
        if not total:
            return
        tenth = int(10 * state["done"] / total)
        if tenth > state["shown"]:
            state["shown"] = tenth
            elapsed = time.monotonic() - state["t0"]
            left = elapsed * (total / state["done"] - 1.0) if state["done"] else 0.0
            click.echo(f"{description}: {10 * tenth} % ({elapsed:.0f} s, about {left:.0f} s "
                       "left)", err=True)

    yield advance


def compile_kernels_once() -> None:
    """The first run after an install: compile the kernels ahead of the run, in two
    places at once (:mod:`drillfric.runner.warmup`), saying what happens and ticking the
    elapsed seconds on a terminal (one line at the start and one at the end without one);
    nothing to do once this installation's kernels are in the per-user cache."""
    from drillfric.kernels.cache import cache_dir
    from drillfric.runner import warmup

    if not warmup.needed():
        return
    quiet, tty = context().quiet, sys.stderr.isatty()
    if not quiet:
        click.echo("first run of this installation: compiling the numerical kernels once "
                   f"(15–60 s, longer on a busy machine; kept in {cache_dir()})", err=True)
    t0 = time.monotonic()
    if quiet or not tty:
        ok = warmup.warm_up()
    else:
        from rich.console import Console

        with Console(stderr=True).status("compiling kernels") as status:
            ok = warmup.warm_up(lambda s: status.update(f"compiling kernels … {s:.0f} s"))
    if not quiet:
        click.echo(f"kernels compiled in {time.monotonic() - t0:.0f} s" if ok else
                   "kernels will be compiled during the run", err=True)


@contextmanager
def well_progress(name: str):
    """Progress within one well's run: yields a callback for
    :class:`drillfric.result.RunProgress` events — a bar with rows read, segments done and
    the ETA on a terminal, a line per 10 % on stderr without one, nothing with --quiet."""
    if context().quiet:
        yield lambda event: None
        return
    if not sys.stderr.isatty():
        with _progress_lines(name, 1.0) as advance:
            state = {"fraction": 0.0}

            def line(event) -> None:
                if event.fraction is not None and event.fraction > state["fraction"]:
                    advance(event.fraction - state["fraction"])
                    state["fraction"] = event.fraction

            yield line
        return
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        Progress,
        TaskProgressColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = [TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(),
               TextColumn("{task.fields[detail]}"), TimeElapsedColumn(), TimeRemainingColumn()]
    with Progress(*columns, console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task(name, total=None, detail="opening")

        def update(event) -> None:
            bar.update(task, completed=event.rows_done, total=event.rows_total,
                       detail=f"{plural(event.rows_done, 'row', spec=',')}, "
                              f"{plural(event.segments_done, 'segment')}")

        yield update


class Quantity(click.ParamType):
    """A physical option value: a number in the option's unit, or a number with a unit
    (``--bit-depth "8200 ft"``), converted exactly (:func:`drillfric.units.quantity_value`).

    Parameters
    ----------
    unit : str
        The option's unit, a label of :data:`drillfric.units.LABEL_UNITS` (``"m"``,
        ``"N"``, ``"N·m"``, ``"RPM"``, ``"s"``, ``"Hz"``, ``"m/s"``).
    limit : float, optional
        Largest plausible magnitude in ``unit``: beyond it the value is a typo or a wrong
        unit, refused naming the option (``td --wob "1e5 klbf"`` had printed a hook load of
        −99 822 klbf, exit 0; issue 30, twelfth attack).
    """

    name = "quantity"

    def __init__(self, unit: str, limit: float | None = None):
        self.unit = unit
        self.limit = limit

    def get_metavar(self, param, ctx=None) -> str:
        """The unit as the metavar (``--bit-depth M``, ``--rate HZ``), as docs/cli.md writes."""
        return {"N·m": "NM", "m/s": "M/S", "m³/s": "M3/S"}.get(self.unit, self.unit.upper())

    def convert(self, value, param, ctx):
        converted = self._number(value, param, ctx)
        if self.limit is not None and not abs(converted) <= self.limit:
            self.fail(f"{value} is {converted:.4g} {self.unit}, beyond the {self.limit:g} "
                      f"{self.unit} any rig reaches (a typo or a wrong unit?)", param, ctx)
        return converted

    def _number(self, value, param, ctx) -> float:
        if isinstance(value, int | float) and not isinstance(value, bool):
            return float(value)
        try:
            return float(value)  # a plain number: no pint needed
        except (TypeError, ValueError):
            pass
        from drillfric.errors import ConfigError
        from drillfric.units import quantity_value

        try:
            return quantity_value(value, self.unit, bare=True)
        except ConfigError as exc:
            self.fail(f"{exc.problem} (a number in {self.unit}, or with a unit such as "
                      f"\"8200 ft\")", param, ctx)


def units_option(command):
    """``--units si|field`` for a command that prints physical values."""
    return click.option("--units", "units", type=click.Choice(["si", "field"]),
                        help="Units of the printed summary: si (m, kN, kN·m) or field (ft, "
                             "klbf, kft·lbf, ppg). Default: the configuration's [well] "
                             "units, else si. JSON and result files stay SI.")(command)


def unit_system(option: str | None, config) -> str:
    """The unit system to print in: ``--units``, else ``[well] units`` of ``config`` (a
    Config or its ``to_dict()``), else ``"si"``."""
    if option:
        return option
    if isinstance(config, dict):
        return (config.get("well") or {}).get("units") or "si"
    return getattr(getattr(config, "well", None), "units", None) or "si"
