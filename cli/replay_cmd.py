"""`drillfric replay FILE --to TARGET [--speed X]` (docs/live.md): a recorded well streamed
into a file as a rig logger would write it."""

from __future__ import annotations

from pathlib import Path

import click

from .common import UserError, echo


@click.command("replay")
@click.argument("file", type=click.Path(path_type=Path))
@click.option("--to", "target", type=click.Path(path_type=Path), required=True,
              help="CSV file to append to (new or empty).")
@click.option("--speed", type=float, default=1.0, show_default=True,
              help="Times real time (the log's span over its bytes).")
@click.option("--tick", type=float, default=0.1, show_default=True, metavar="SECONDS",
              help="Wall seconds between writes; each write cuts the text at a random byte "
                   "(lines are split across writes, as a logger's buffer does).")
@click.option("--seed", type=int, default=0, show_default=True,
              help="Seed of the random cuts.")
def command(file: Path, target: Path, speed: float, tick: float, seed: int) -> None:
    """Append FILE (a CSV's own bytes; any other readable well file as CSV of its canonical
    channels) to TARGET at SPEED times real time."""
    from drillfric.replay import recorded_text, replay

    if not speed > 0 or not tick > 0:
        raise UserError(f"--speed and --tick must be positive, got {speed:g} and {tick:g}")
    if target.exists() and target.stat().st_size:
        raise UserError(f"{target}: already holds data; give a new or empty file to replay "
                        "into")
    text, span_s = recorded_text(file)
    wall = replay(text, target, rate_bps=len(text) / span_s * speed, tick_s=tick, seed=seed)
    echo(f"replayed {len(text)} bytes ({span_s:.0f} s of log) into {target} in {wall:.1f} s")
