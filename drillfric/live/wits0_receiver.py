"""A WITS level 0 stream recorded for ``drillfric live wits0://HOST:PORT`` (docs/live.md).

:class:`Receiver` connects to the recorder, reconnects with a doubling wait when the stream
drops, sends a handshake frame every ``[wits0] handshake_s`` and writes every complete frame
as one line of :class:`Recording` — ``OUT/NAME.wits0.csv``, absolute time plus the SI
channels, flushed per frame. :class:`~drillfric.live.run.LiveRun` then follows that file as it
follows any growing CSV, so a restarted live run continues the recording and resumes from
its saved state, no row lost or read twice.
"""

from __future__ import annotations

import math
import re
import socket
import sys
import threading
import time
from dataclasses import dataclass, replace
from datetime import UTC, datetime, timedelta
from pathlib import Path

from drillfric.config import read_toml
from drillfric.errors import DrillfricError, InputError, OutputError
from drillfric.io.atomic import open_appending, output_error, own_file, refuse_link
from drillfric.io.text import printable
from drillfric.io.wellfiles import safe_name
from drillfric.io.wits0 import Decoder, Row, frame_clock, item_map

SCHEME = "wits0://"
#: Sent to the recorder every ``handshake_s`` (the keep-alive Pason-style recorders expect).
HANDSHAKE = b"&&\r\n0111-9999\r\n!!\r\n"
#: First wait before reconnecting [s] (doubles up to ``[wits0] reconnect_max_s``).
RECONNECT_MIN_S = 0.2
#: Bytes received without one frame after which the port is reported as not WITS level 0.
NOT_WITS_BYTES = 65536
#: Latest place of a frame within its second [s]: frames sharing a one-second stamp are
#: spaced by their arrival, kept inside that second.
WITHIN_SECOND_S = 0.999
_MIN_STEP_S = 0.001
#: Silence that ends a burst of frames [s]: reads closer together than this are one burst
#: (a recorder's flush split by TCP into several reads), gathered for at most
#: :data:`GATHER_MAX_S` before its frames are timed.
BURST_GAP_S = 0.02
GATHER_MAX_S = 0.5
#: Longest time between bursts that frames without date and time are spread over [s]: after
#: a longer silence the stream stalled, and when the frames it then brings were taken is not
#: known (they are timed as they arrive).
MAX_SPREAD_S = 5.0
#: Furthest a frame's date and time may lie ahead of the wall clock [s] (time zones span
#: UTC-12 to UTC+14): a frame dated later is a wrong clock, not recorded — it would make
#: every true frame after it look "before the previous one" and be dropped for good.
MAX_AHEAD_S = 86400.0
#: A frame's time of day within this of midnight on either side [s]: a time of day that
#: wraps from the last to the first :data:`MIDNIGHT_WINDOW_S` of a day under an unchanged
#: date is midnight passing on a recorder whose DATE item does not roll over (issue 30,
#: eleventh attack: every frame after midnight had been dropped as "before" the previous).
MIDNIGHT_WINDOW_S = 600.0


@dataclass(frozen=True)
class Address:
    """A ``wits0://HOST:PORT`` address."""

    host: str
    port: int

    def __str__(self) -> str:
        return f"{SCHEME}{self.host}:{self.port}"


def parse_address(text: str, what: str = "SOURCE") -> Address:
    """``wits0://HOST:PORT`` (an IPv6 host in brackets); ``what`` names the argument in the
    error (``SOURCE`` of live, ``--to`` of replay).

    Raises
    ------
    InputError
        Not such an address.

    Examples
    --------
    >>> parse_address("wits0://127.0.0.1:5000")
    Address(host='127.0.0.1', port=5000)
    """
    match = re.fullmatch(r"wits0://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9.-]{1,253}):(\d{1,5})", text)
    port = int(match[2]) if match else 0
    if not match or not 0 < port < 65536:
        raise InputError(f"'{printable(text, 80)}' is no WITS0 address", file=what,
                         fix="write wits0://HOST:PORT with a port 1–65535, e.g. "
                             "wits0://127.0.0.1:5000")
    return Address(match[1].strip("[]"), port)


@dataclass(frozen=True)
class Setup:
    """What a WITS0 live run needs from ``--config``: the items read, the ``[wits0]``
    settings, and :func:`~drillfric.io.well.open_well` keywords for the recording (the
    configuration read once, without ``[channels]``, which name WITS items, not recording
    columns; the survey it names)."""

    row: Row
    units: str
    utc_offset_h: float | None
    handshake_s: float
    reconnect_max_s: float
    open_kw: dict
    name: str


def setup(address: Address, config: Path | None, name: str | None) -> Setup:
    """The :class:`Setup` of ``address`` with ``config`` (a TOML file or None).

    Raises
    ------
    ConfigError
        The configuration cannot be read or maps items wrongly.
    """
    from drillfric.config import config_from_dict

    raw = {} if config is None else read_toml(config)
    cfg = config_from_dict(raw, file=config)  # every key checked, [channels] too
    settings = cfg.wits0
    row = Row(item_map(cfg.channels, settings.units, file=config))
    open_kw: dict = {"config": replace(cfg, channels={})}
    named = raw.get("survey", {}).get("file") if isinstance(raw.get("survey"), dict) else None
    if isinstance(named, str) and config is not None:
        open_kw["survey"] = Path(config).parent / named
    shown = name or cfg.well.name or f"wits0_{address.host}_{address.port}"
    open_kw["name"] = shown
    return Setup(row, settings.units, settings.utc_offset_h, settings.handshake_s,
                 settings.reconnect_max_s, open_kw, safe_name(shown, config))


class FrameClock:
    """The recorded time of each frame [s since 1970 on the recorded clock]: the frame's
    date and time items, else its arrival; frames sharing a one-second stamp are spaced by
    their arrival within that second; always increasing.

    Parameters
    ----------
    utc_offset_h : float or None
        The rig clock's UTC offset [h] (None: rig clock kept as is).
    last_s : float or None
        The last recorded time (a continued recording).
    """

    def __init__(self, utc_offset_h: float | None, last_s: float | None = None):
        self.offset_s = 0.0 if utc_offset_h is None else utc_offset_h * 3600.0
        self.last_s = last_s
        self._stamp: float | None = None
        self._first_arrival = 0.0
        self._rig_arrival: float | None = None  # arrival of the last frame on the rig clock
        self._burst_s: float | None = None  # arrival of the last burst that brought frames
        self._step: float | None = None  # spacing of this burst's frames without date/time
        self.out_of_order = 0
        self._sent: datetime | None = None  # the last date/time as the recorder sent it
        self._days = 0  # days added to the recorder's date (a DATE that did not roll over)

    def rolled(self, clock: datetime | None) -> tuple[datetime | None, datetime | None]:
        """``clock`` as the recorder sent it, with the days its DATE item failed to roll
        over at midnight added; and, when this frame is such a midnight, the date and time
        sent before it (else None). A time of day wrapping from the day's last
        :data:`MIDNIGHT_WINDOW_S` to its first under one date is the next day (and back
        again, a frame sent anew from before midnight, the day before); the recorder's date
        moving on its own ends the correction.

        Examples
        --------
        >>> fc = FrameClock(None)
        >>> fc.rolled(datetime(2024, 12, 1, 23, 59, 59))[1] is None
        True
        >>> fc.rolled(datetime(2024, 12, 1, 0, 0, 0))[0]
        datetime.datetime(2024, 12, 2, 0, 0)
        >>> fc.rolled(datetime(2024, 12, 1, 0, 0, 1))
        (datetime.datetime(2024, 12, 2, 0, 0, 1), None)
        """
        if clock is None:
            return None, None
        sent, self._sent = self._sent, clock
        if sent is None:  # a continued recording: its last line is the previous frame
            return self._continued(clock)
        if clock.date() != sent.date():
            self._days = 0  # the recorder's own date moved: it is right again
            return clock, None
        before, after = (3600 * c.hour + 60 * c.minute + c.second for c in (sent, clock))
        late, early = 86400.0 - MIDNIGHT_WINDOW_S, MIDNIGHT_WINDOW_S
        midnight = before >= late and after < early
        if midnight:
            self._days += 1
        elif before < early and after >= late and self._days:
            self._days -= 1  # back before midnight: that day's frames, sent again
        return clock + timedelta(days=self._days), sent if midnight else None

    def _continued(self, clock: datetime) -> tuple[datetime, datetime | None]:
        """The first frame of a continued recording: a time of day in the first
        :data:`MIDNIGHT_WINDOW_S` of the day before the recording's last line, which lies
        in the first minutes of its day, is a recorder whose date did not roll over (live
        restarted after such a midnight had dropped every frame)."""
        if self.last_s is None:
            return clock, None
        last = datetime.fromtimestamp(self.last_s + self.offset_s, UTC).replace(tzinfo=None)
        early = MIDNIGHT_WINDOW_S
        if (clock + timedelta(days=1)).date() == last.date() and \
                3600 * clock.hour + 60 * clock.minute + clock.second < early and \
                3600 * last.hour + 60 * last.minute + last.second < early:
            self._days = 1
            return clock + timedelta(days=1), last
        return clock, None

    def burst(self, unstamped: int, frames: int, arrival_s: float) -> float | None:
        """``frames`` frames arrived together at ``arrival_s`` (monotonic [s]),
        ``unstamped`` of them without date and time: those are spread evenly over the time
        since the previous burst — a recorder flushing 10-Hz frames once a second puts them
        0.1 s apart, not 1 ms (issue 30, ninth attack). Returns that spacing [s], or None
        (no earlier burst, or more than :data:`MAX_SPREAD_S` of silence before this one:
        the frames are timed as they arrive)."""
        self._step = None
        if unstamped and self._burst_s is not None:
            since = arrival_s - self._burst_s
            if 0.0 < since <= MAX_SPREAD_S:
                self._step = since / unstamped
        if frames:
            self._burst_s = arrival_s
        return self._step

    def ahead(self, clock: datetime | None, wall_s: float) -> bool:
        """Whether the date/time ``clock`` lies more than :data:`MAX_AHEAD_S` after the wall
        time ``wall_s`` (UTC, [s] since 1970)."""
        if clock is None:
            return False
        return clock.replace(tzinfo=UTC).timestamp() - self.offset_s > wall_s + MAX_AHEAD_S

    def time_s(self, clock: datetime | None, arrival_s: float, wall_s: float) -> float | None:
        """The time of a frame with date/time ``clock`` arriving at ``arrival_s`` (monotonic
        [s]) and wall time ``wall_s`` (UTC, [s] since 1970); None when it lies before the
        last recorded frame (counted in :attr:`out_of_order`, not recorded). A frame without
        date/time after frames with them keeps to the rig's clock: the last recorded time
        plus the arrival time since (on the computer's UTC clock, one unstamped frame of a
        rig clock behind UTC had put every later frame "before" it: all dropped). A frame
        without date/time in a burst (:meth:`burst`) follows the last time by the burst's
        spacing."""
        if clock is None:
            if self._step is not None and self.last_s is not None:
                t = self.last_s + max(self._step, _MIN_STEP_S)
                if self._rig_arrival is not None:
                    self._rig_arrival = arrival_s
            elif self._rig_arrival is not None:
                t = self.last_s + max(arrival_s - self._rig_arrival, _MIN_STEP_S)
                self._rig_arrival = arrival_s
            else:
                t = wall_s if self.last_s is None else max(wall_s, self.last_s + _MIN_STEP_S)
            self.last_s, self._stamp = t, None
            return t
        stamp = clock.replace(tzinfo=UTC).timestamp() - self.offset_s
        if stamp != self._stamp:
            self._stamp, self._first_arrival = stamp, arrival_s
        latest = stamp + WITHIN_SECOND_S
        if self.last_s is not None and latest <= self.last_s:
            self.out_of_order += 1
            return None
        t = stamp + min(arrival_s - self._first_arrival, WITHIN_SECOND_S)
        if self.last_s is not None:
            t = min(max(t, self.last_s + _MIN_STEP_S), latest)
        self.last_s, self._rig_arrival = t, arrival_s
        return t


class Recording:
    """The received frames as a CSV growing in the output folder: a fixed header
    (``time`` and the SI channel names), one line per frame, flushed per frame.

    Parameters
    ----------
    path : Path
        ``OUT/NAME.wits0.csv``; an existing recording is continued (a last line cut by a
        kill is removed first: it was never read).
    names : list of str
        The channel columns.
    utc : bool
        Times are UTC (written with ``+00:00``) rather than the rig clock without zone.

    Raises
    ------
    InputError
        An existing file with another header (another configuration).
    OutputError
        The path is a symbolic link (dangling or not): drillfric writes through no link.
    """

    def __init__(self, path: Path, names: list[str], utc: bool):
        self.path, self.utc = Path(path), utc
        self.header = ",".join(["time", *names]) + "\n"
        refuse_link(self.path)
        if self.path.exists():
            try:
                own_file(self.path)  # a FIFO there would hang the open
            except ValueError as exc:
                raise OutputError(f"cannot record the stream: {exc}", file=self.path,
                                  fix="remove it, or choose another --out") from None
        self.last_s = self._continue() if self.path.exists() else None
        if self.last_s is not None and self.last_s > time.time() + MAX_AHEAD_S:
            raise InputError("this recording of a WITS0 stream ends with a line dated more "
                             "than a day after this computer's clock: every frame would be "
                             "taken as older and dropped", file=self.path,
                             fix="give another --out (or remove the file)")
        self._fh = None

    def _continue(self) -> float | None:
        """Check the header, cut a partial last line; the last recorded time. (No message
        quotes the file: it may not be drillfric's.)"""
        with open(self.path, "rb") as fh:
            head = fh.readline(len(self.header) + 1).decode("utf-8", "replace")
        if head != self.header:
            raise InputError("this recording of a WITS0 stream has other columns than this "
                             f"configuration's ({printable(self.header.strip(), 120)})",
                             file=self.path,
                             fix="give another --out (or remove the file) when the "
                                 "configuration's items changed")
        with open(self.path, "r+b") as fh:
            size = fh.seek(0, 2)
            fh.seek(max(0, size - 4096))
            tail = fh.read()
            end = size - len(tail) + tail.rfind(b"\n") + 1
            fh.truncate(end)
            lines = tail[:tail.rfind(b"\n")].split(b"\n")
        last = lines[-1].split(b",")[0].decode("utf-8", "replace") if lines else ""
        if not last or last == "time":
            return None
        try:
            stamp = datetime.fromisoformat(last)
        except ValueError:
            raise InputError("this recording of a WITS0 stream ends with a line without a "
                             "time: not written by live",
                             file=self.path, fix="give another --out (or remove the file)") \
                from None
        return stamp.replace(tzinfo=UTC).timestamp() if stamp.tzinfo is None else \
            stamp.timestamp()

    def write(self, time_s: float, values: dict[str, float]) -> None:
        """One line: the time (ISO 8601, µs) and the values (empty when NaN).

        Raises
        ------
        OutputError
            The line cannot be written (disk full …, named by path) or the path became a link.
        """
        stamp = datetime.fromtimestamp(time_s, UTC)
        text = stamp.isoformat(timespec="microseconds") if self.utc else \
            stamp.replace(tzinfo=None).isoformat(timespec="microseconds")
        cells = ["" if math.isnan(v) else repr(v) for v in values.values()]
        line = (",".join([text, *cells]) + "\n").encode()
        try:
            if self._fh is None:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                self._fh = open_appending(self.path)
                if self._fh.tell() == 0:
                    self._fh.write(self.header.encode())
            self._fh.write(line)
            self._fh.flush()
        except OSError as exc:
            raise output_error(exc, self.path) from None

    def close(self) -> None:
        """Close the file (a write that failed was said by :meth:`write`: not again)."""
        if self._fh is not None:
            fh, self._fh = self._fh, None
            try:
                fh.close()
            except OSError:
                pass


class Receiver:
    """The WITS0 client: run :meth:`run` in a thread; set :attr:`stop` to end it.

    Parameters
    ----------
    address : Address
        The recorder's address.
    setup : Setup
        Items and ``[wits0]`` settings.
    recording : Recording
        Where the frames go.
    warn : callable
        Prints one warning line (stderr by default).
    """

    def __init__(self, address: Address, setup: Setup, recording: Recording, *,
                 warn=None):
        self.address, self.setup, self.recording = address, setup, recording
        self.clock = FrameClock(setup.utc_offset_h, recording.last_s)
        self.decoder = Decoder()
        self.stop = threading.Event()
        self.frames = self.connections = 0
        #: What ended the receiver for good (a recording that cannot be written), else None.
        self.error: DrillfricError | None = None
        self.warn = warn or (lambda text: print(f"warning: {text}", file=sys.stderr))
        self._received = 0
        self._warned: set[str] = set()
        #: Frames not recorded, by why (``"order"``, ``"future"``): said in one warning
        #: line each as they start and counted by :meth:`dropped_note` at the end.
        self.dropped: dict[str, int] = {}

    def run(self) -> None:
        """Connect, record, reconnect (waiting 0.2 s, doubling to ``reconnect_max_s``)
        until :attr:`stop`, or until the recording cannot be written (:attr:`error`: the
        caller says it in one line; no thread traceback)."""
        try:
            self._connect_loop()
        except DrillfricError as exc:
            self.error = exc
            self.stop.set()
        finally:
            self.recording.close()

    def _connect_loop(self) -> None:
        wait = RECONNECT_MIN_S
        while not self.stop.is_set():
            try:
                conn = socket.create_connection((self.address.host, self.address.port),
                                                timeout=2.0)
            except OSError as exc:
                why = exc.strerror or exc
                self._once("connect", f"{self.address}: cannot connect ({why}); retrying")
                self.stop.wait(wait)
                wait = min(2 * wait, self.setup.reconnect_max_s)
                continue
            self.connections += 1
            if self._session(conn):
                wait = RECONNECT_MIN_S
            else:
                self.stop.wait(wait)
                wait = min(2 * wait, self.setup.reconnect_max_s)

    def _session(self, conn: socket.socket) -> bool:
        """Record frames until the connection drops; True when a frame came."""
        got = self.frames
        handshake_due = time.monotonic()
        conn.settimeout(0.1)
        try:
            with conn:
                while not self.stop.is_set():
                    if self.setup.handshake_s and time.monotonic() >= handshake_due:
                        conn.sendall(HANDSHAKE)
                        handshake_due = time.monotonic() + self.setup.handshake_s
                    try:
                        data = conn.recv(65536)
                    except TimeoutError:
                        continue
                    if not data:
                        break
                    self._take(*self._gather(conn, data))
        except OSError:
            pass  # dropped: reconnect
        finally:
            self.decoder.reset()  # a frame the drop cut is discarded
        return self.frames > got

    def _gather(self, conn: socket.socket, data: bytes) -> tuple[bytes, float]:
        """``data`` and the reads that follow it within :data:`BURST_GAP_S` of each other
        (one burst, however TCP cut it; at most :data:`GATHER_MAX_S` and
        :data:`NOT_WITS_BYTES`), and the arrival of its last read (monotonic [s])."""
        arrival = time.monotonic()
        parts, size, until = [data], len(data), arrival + GATHER_MAX_S
        conn.settimeout(BURST_GAP_S)
        try:
            while size < NOT_WITS_BYTES and time.monotonic() < until:
                try:
                    more = conn.recv(65536)
                except OSError:  # a timeout (the burst ended) or a drop: the next read says
                    break
                if not more:
                    break  # closed: the next read says so again
                arrival = time.monotonic()
                parts.append(more)
                size += len(more)
        finally:
            try:
                conn.settimeout(0.1)
            except OSError:
                pass
        return b"".join(parts), arrival

    def _take(self, data: bytes, arrival: float | None = None) -> None:
        """Record the frames of one burst of ``data`` arriving at ``arrival`` (monotonic
        [s]; default now)."""
        arrival, wall = time.monotonic() if arrival is None else arrival, time.time()
        self._received += len(data)
        frames = list(self.decoder.feed(data))
        stamps = [frame_clock(frame) for frame in frames]
        unstamped = sum(stamp is None for stamp in stamps)
        step = self.clock.burst(unstamped, len(frames), arrival)
        if unstamped > 1 and (step is not None or self.frames):
            late = step is None  # after a silence longer than MAX_SPREAD_S
            self._once("burst-late" if late else "burst",
                       f"{self.address}: {unstamped} frames without a date and time arrived "
                       "together (a recorder sending in bursts): "
                       + (f"after more than {MAX_SPREAD_S:g} s of silence, so recorded 1 ms "
                          "apart (the bit trace over them is withheld)" if late else
                          f"spread evenly over the {step * unstamped:.3g} s since the "
                          f"previous burst, {step:.3g} s apart")
                       + "; frames carrying their date and time (items 0105, 0106) are "
                         "timed exactly")
        for frame, sent in zip(frames, stamps, strict=True):
            # the row takes a frame's items only once the frame is recorded: a frame refused
            # for its clock gave its values to the next frame (issue 30, tenth attack)
            stamp, previous = self.clock.rolled(sent)
            if previous is not None:  # once a night (a frame sent again repeats no midnight)
                self._once(f"midnight {stamp:%Y-%m-%d}",
                           f"{self.address}: a frame dated {sent:%Y-%m-%d %H:%M:%S} follows "
                           f"one of {previous:%Y-%m-%d %H:%M:%S}: a recorder whose date (item "
                           f"0105) does not roll over at midnight; recorded as "
                           f"{stamp:%Y-%m-%d} from here (set the recorder's date)")
            if self.clock.ahead(stamp, wall):
                self._drop("future", f"{self.address}: a frame dated "
                                     f"{stamp:%Y-%m-%d %H:%M:%S}, more than a day after this "
                                     "computer's clock: not recorded (see the rig clock)")
                continue
            t = self.clock.time_s(stamp, arrival, wall)
            if t is None:
                self._drop("order", f"{self.address}: a frame dated "
                                    f"{stamp:%Y-%m-%d %H:%M:%S} lies before the previous "
                                    "frame's date and time: not recorded (see the rig clock; "
                                    "the count follows at the end)")
                continue
            self.recording.write(t, self.setup.row.update(frame))
            self.frames += 1
        if not self.frames and self._received > NOT_WITS_BYTES:
            self._once("garbage", f"{self.address}: {self._received} bytes without one WITS "
                                  "level 0 frame ('&&' … '!!'): is this a WITS0 port?")

    def _drop(self, kind: str, text: str) -> None:
        self.dropped[kind] = self.dropped.get(kind, 0) + 1
        self._once(kind, text)

    def dropped_note(self) -> str | None:
        """One line counting the frames not recorded for their date and time, or None."""
        if not self.dropped:
            return None
        why = {"order": "dated before the previous frame",
               "future": "dated more than a day after this computer's clock"}
        parts = [f"{n} {why[kind]}" for kind, n in sorted(self.dropped.items())]
        total = sum(self.dropped.values())
        return (f"{self.address}: {total} of {total + self.frames} frames not recorded ("
                + "; ".join(parts) + "): see the rig clock")

    def _once(self, kind: str, text: str) -> None:
        if kind not in self._warned:
            self._warned.add(kind)
            self.warn(text)


def recording_path(out_root: Path, setup: Setup) -> Path:
    """``OUT/NAME.wits0.csv``: beside OUT/NAME, which each publication replaces."""
    return Path(out_root) / f"{setup.name}.wits0.csv"


def start(address: Address, out_root: Path, setup: Setup) -> tuple[Receiver, threading.Thread]:
    """A :class:`Receiver` recording into ``OUT/NAME.wits0.csv``, running in a daemon thread."""
    recording = Recording(recording_path(out_root, setup), setup.row.names,
                          utc=setup.utc_offset_h is not None)
    receiver = Receiver(address, setup, recording)
    thread = threading.Thread(target=receiver.run, name="drillfric-wits0", daemon=True)
    thread.start()
    return receiver, thread

