"""A recorded well served as a WITS level 0 stream (``drillfric replay FILE --to
wits0://HOST:PORT``, docs/live.md): frames paced at X times the log's own time, a client
that connects getting them from the first frame not completely sent to the one before."""

from __future__ import annotations

import math
import select
import socket
import time
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.io.wits0 import encode, item_map


def frames_of(canonical: pd.DataFrame, origin, start: datetime) -> list[bytes]:
    """One WITS0 frame per row of ``canonical`` (``time_s`` and SI channels) in the metric
    units of :data:`drillfric.io.wits0.ITEMS`, stamped with the log's clock time (``origin``
    + ``time_s``, whole seconds) or, without one, ``start`` + ``time_s``."""
    slots = item_map({})
    base = start if origin is None else pd.Timestamp(origin).tz_localize(None).to_pydatetime()
    names = [c for c in canonical.columns if c != "time_s"]
    out = []
    for row in canonical[["time_s", *names]].itertuples(index=False, name=None):
        clock = (base + timedelta(seconds=float(row[0]))).replace(microsecond=0)
        out.append(encode(dict(zip(names, row[1:], strict=True)), slots, clock))
    return out


@dataclass
class Served:
    """What a replay served: frames sent whole, connections, frames cut by a drop."""

    frames: int = 0
    connections: int = 0
    cut: int = 0


def serve(frames: list[bytes], time_s: np.ndarray, host: str, port: int, *, speed: float,
          drop_after: int | None = None, ready=None) -> Served:
    """Listen on ``host:port`` and send ``frames`` (log times ``time_s`` [s]) at ``speed``
    times real time to one client at a time, until all were sent whole; after a client
    drops, the next gets them from the first frame not completely sent (the pace restarts
    there). ``drop_after``: cut the first connection in the middle of the frame after that
    many (a test aid). ``ready`` is called once listening.

    Raises
    ------
    InputError
        The address cannot be listened on.
    """
    try:
        listener = socket.create_server((host, port))
    except OSError as exc:
        raise InputError(f"cannot listen on wits0://{host}:{port} ({exc.strerror or exc})",
                         file="--to", fix="give a free port on this machine, e.g. "
                                          "wits0://127.0.0.1:5000") from None
    served = Served()
    with listener:
        if ready is not None:
            ready()
        while served.frames < len(frames):
            conn, _ = listener.accept()
            served.connections += 1
            cut_at = drop_after if served.connections == 1 else None
            _send(conn, frames, time_s, speed, served, cut_at)
    return served


def _send(conn: socket.socket, frames: list[bytes], time_s: np.ndarray, speed: float,
          served: Served, cut_at: int | None) -> None:
    """Frames from ``served.frames`` on, paced, until done or the client goes."""
    first, t0, sent = served.frames, time.monotonic(), 0
    try:
        while served.frames < len(frames):
            i = served.frames
            time.sleep(max(0.0, t0 + (time_s[i] - time_s[first]) / speed - time.monotonic()))
            if _gone(conn):
                return
            if cut_at is not None and sent == cut_at:
                conn.sendall(frames[i][:math.ceil(len(frames[i]) / 2)])
                served.cut += 1
                return
            conn.sendall(frames[i])
            served.frames, sent = i + 1, sent + 1
    except OSError:
        return  # the client went mid-frame: that frame is sent again whole
    finally:
        _close(conn)


def _gone(conn: socket.socket) -> bool:
    """Whether the client closed its end (what it sends — handshakes — is read and
    dropped)."""
    while select.select([conn], [], [], 0)[0]:
        if not conn.recv(4096):
            return True
    return False


def _close(conn: socket.socket) -> None:
    """Close after the client has read everything (closing with its handshakes unread
    would reset the connection and lose frames in flight)."""
    try:
        conn.shutdown(socket.SHUT_WR)
        conn.settimeout(2.0)
        while conn.recv(4096):
            pass
    except OSError:
        pass
    conn.close()


def start_clock() -> datetime:
    """The clock time given to a log without one: now (UTC, whole seconds, no zone)."""
    return datetime.now(UTC).replace(tzinfo=None, microsecond=0)
