"""`drillfric replay FILE --to TARGET [--speed X]` (docs/live.md): a recorded well streamed
into a file as a rig logger would write it, or served as a WITS level 0 stream."""

from __future__ import annotations

from pathlib import Path

import click

from drillfric.io.text import plural

from .common import UserError, echo

#: Fastest replay (times real time): a day of log in under a second; beyond, the pace is
#: meaningless (and infinity cannot be paced at all).
MAX_SPEED = 1e6
#: Longest wall pause between two writes [s].
MAX_TICK_S = 3600.0


@click.command("replay")
@click.argument("file", type=click.Path(path_type=Path))
@click.option("--to", "target", required=True, metavar="TARGET",
              help="CSV file to append to (new or empty), or wits0://HOST:PORT to serve the "
                   "well as WITS level 0 frames on that port (loopback: 127.0.0.1).")
@click.option("--speed", type=float, default=1.0, show_default=True,
              help="Times real time (the log's span over its bytes).")
@click.option("--tick", type=float, default=0.1, show_default=True, metavar="SECONDS",
              help="Wall seconds between writes; each write cuts the text at a random byte "
                   "(lines are split across writes, as a logger's buffer does).")
@click.option("--seed", type=int, default=0, show_default=True,
              help="Seed of the random cuts.")
@click.option("--drop-after", "drop_after", type=click.IntRange(min=0), hidden=True,
              help="Test aid (wits0 only): cut the first connection in the middle of the "
                   "frame after N frames.")
def command(file: Path, target: str, speed: float, tick: float, seed: int,
            drop_after: int | None) -> None:
    """Append FILE (a CSV's own bytes; any other readable well file as CSV of its canonical
    channels) to TARGET at SPEED times real time, or serve it over WITS level 0."""
    if not 0 < speed < MAX_SPEED or not 0 < tick <= MAX_TICK_S:
        raise UserError(f"--speed must lie in (0, {MAX_SPEED:g}) and --tick in (0, "
                        f"{MAX_TICK_S:g}] s, got {speed:.4g} and {tick:.4g} — fix: e.g. "
                        "--speed 20 --tick 0.1")
    if target.startswith("wits0:"):
        _wits0(file, target, speed, drop_after)
        return
    from drillfric.live.replay import recorded_text, replay

    path = Path(target)
    if path.is_symlink() or path.exists() and not path.is_file():
        raise UserError(f"{target}: not a regular file (a directory, a FIFO, a device or a "
                        "link) — fix: give a new or empty file to replay into")
    if path.exists() and path.stat().st_size:
        raise UserError(f"{target}: already holds data; give a new or empty file to replay "
                        "into")
    text, span_s = recorded_text(file)
    wall = replay(text, path, rate_bps=len(text) / span_s * speed, tick_s=tick, seed=seed)
    echo(f"replayed {plural(len(text), 'byte')} ({span_s:.0f} s of log) into {target} in "
         f"{wall:.1f} s")


def _wits0(file: Path, target: str, speed: float, drop_after: int | None) -> None:
    """Serve FILE at ``target`` until every frame was sent whole."""
    import time

    from drillfric.live.replay import recorded_frame
    from drillfric.live.wits0_receiver import parse_address
    from drillfric.live.wits0_server import frames_of, serve, start_clock

    address = parse_address(target, "--to")
    _, canonical, origin = recorded_frame(file)
    start = start_clock()
    frames = frames_of(canonical, origin, start)
    clock = "the log's clock" if origin is not None else f"clock from {start:%Y-%m-%d %H:%M:%S}"
    t0 = time.monotonic()
    served = serve(frames, canonical["time_s"].to_numpy(float), address.host, address.port,
                   speed=speed, drop_after=drop_after,
                   ready=lambda: echo(f"serving {plural(len(frames), 'WITS0 frame')} ({clock}) on "
                                      f"{address}"))
    echo(f"replayed {plural(served.frames, 'frame')} of {file} over "
         f"{plural(served.connections, 'connection')} to {address} in "
         f"{time.monotonic() - t0:.1f} s")
