"""WITS level 0: the ASCII frames rig recorders stream (docs/live.md "WITS level 0").

A frame is ``&&`` CR LF, one line per item — a 4-digit code (2-digit record, 2-digit item)
followed directly by the value — then ``!!`` CR LF. Here:

- :data:`ITEMS` — the record-1 items drillfric reads, with the channel each feeds and its
  unit in the recorder's metric and field settings;
- :func:`item_map` — those items as a receiver reads them: the unit setting and any item's
  code or unit overridden in ``[channels]``;
- :class:`Decoder` — bytes in, complete frames out (bounded: no line, frame or buffer grows
  without limit; a frame cut by a dropped connection is discarded by :meth:`Decoder.reset`);
- :func:`frame_clock`, :class:`Row` — a frame's date/time items and its values in SI;
- :func:`encode` — a row back into a frame (``drillfric replay --to wits0://``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from datetime import datetime

from drillfric.errors import ConfigError, InputError
from drillfric.io.channels import BY_KEY, Channel, factor
from drillfric.io.source import NULL_VALUES


@dataclass(frozen=True)
class Item:
    """One WITS item drillfric reads.

    Attributes
    ----------
    code : str
        Record and item number, 4 digits (``"0114"``).
    mnemonic : str
        The specification's mnemonic (``HKLA``).
    channel : str
        The canonical channel it feeds (a key of :data:`drillfric.io.channels.BY_KEY`).
    metric_unit, field_unit : str
        Its unit when the recorder sends metric or field units.
    """

    code: str
    mnemonic: str
    channel: str
    metric_unit: str
    field_unit: str


#: Record 1 (time-based general drilling), the items drillfric maps (../shared/reference/
#: WITS0.md; KDN is the kilo-decanewton, 10 kN).
ITEMS: tuple[Item, ...] = (
    Item("0108", "DBTM", "bit_depth", "m", "ft"),
    Item("0110", "DMEA", "hole_depth", "m", "ft"),
    Item("0112", "BPOS", "block_position", "m", "ft"),
    Item("0113", "ROPA", "rop", "m/h", "ft/h"),
    Item("0114", "HKLA", "hookload", "KDN", "klbf"),
    Item("0116", "WOBA", "wob", "KDN", "klbf"),
    Item("0118", "TQA", "surface_torque", "kN.m", "kft.lbf"),
    Item("0120", "RPMA", "surface_rpm", "rpm", "rpm"),
    Item("0121", "SPPA", "standpipe_pressure", "kPa", "psi"),
)
#: The date (YYMMDD) and time-of-day (HHMMSS) items of record 1.
DATE_CODE, TIME_CODE = "0105", "0106"
#: Longest item line accepted [bytes] and most items in one frame: a longer line or a
#: bigger frame is not WITS and is dropped (hostile input cannot grow a buffer).
MAX_LINE = 256
MAX_ITEMS = 1000
#: The value a frame gives for an absent reading (WITS and LAS convention).
NULL_TEXT = "-999.25"

_CODE = re.compile(r"^\d{4}$")
_STAMP = re.compile(r"^\d{1,6}(\.0*)?$")
#: An item's value as WITS writes a number: ASCII digits, an optional sign, decimal point
#: and exponent. Python's ``float`` reads more — ``1_0`` as 10, ``nan``, ``infinity``,
#: non-ASCII digits — none of which a recorder sends as a reading (issue 30, tenth attack).
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


@dataclass(frozen=True)
class Slot:
    """How one received item becomes a channel value: SI value = text × ``factor``."""

    code: str
    channel: Channel
    factor: float


def item_map(channels: dict, units: str = "metric", *, file=None) -> dict[str, Slot]:
    """The items a receiver maps, by code: :data:`ITEMS` in the recorder's ``units``
    (``"metric"`` or ``"field"``) with ``[channels]`` overrides (``column`` a 4-digit item
    code, ``unit``, ``scale``); an override may also map an item of another record.

    Raises
    ------
    ConfigError
        A column that is no item code, a unit of the wrong kind, two channels on one item.

    Examples
    --------
    >>> item_map({})["0114"].factor, item_map({}, "field")["0118"].factor
    (10000.0, 1355.8179483314004)
    >>> item_map({"hookload": {"unit": "kN"}})["0114"].factor
    1000.0
    """
    where = "" if file is None else str(file)
    spec = {i.channel: (i.code, i.metric_unit if units == "metric" else i.field_unit, 1.0)
            for i in ITEMS}
    for key, override in channels.items():
        code, unit, scale = spec.get(key, (None, None, 1.0))
        if "column" in override:
            code = _code(override["column"], key, where)
        if code is None:
            raise ConfigError(f"channels.{key}: a WITS0 source needs the item's code",
                              file=where or None,
                              fix=f'e.g. {key} = {{ column = "0199", unit = '
                                  f'"{BY_KEY[key].default_unit}" }}')
        if "mnemonics" in override:
            raise ConfigError(f"channels.{key}.mnemonics has no meaning for a WITS0 source "
                              "(items are numbered)", file=where or None,
                              fix='give the item code: column = "0114"')
        spec[key] = (code, override.get("unit", unit or BY_KEY[key].default_unit),
                     float(override.get("scale", 1.0)))
    slots: dict[str, Slot] = {}
    for key, (code, unit, scale) in spec.items():
        if code in slots:
            raise ConfigError(f"WITS item {code} is mapped to both {slots[code].channel.key} "
                              f"and {key}", file=where or None,
                              fix="give each channel its own item code in [channels]")
        if code in (DATE_CODE, TIME_CODE):
            raise ConfigError(f"WITS item {code} is the date or time, not {key}",
                              file=where or None, fix="give another item code")
        channel = BY_KEY[key]
        try:
            slots[code] = Slot(code, channel, factor(unit, channel) * scale)
        except InputError as exc:  # a unit in the configuration: a configuration error
            raise ConfigError(f"channels.{key}: {exc.problem}", file=where or None,
                              fix=exc.fix) from None
    return slots


def _code(column, key: str, where: str) -> str:
    """A ``[channels]`` column as a 4-digit item code (``114`` → ``"0114"``)."""
    code = f"{column:04d}" if isinstance(column, int) and 0 <= column <= 9999 else str(column)
    if not _CODE.match(code) or key in ("time", "measured_depth"):
        raise ConfigError(f"channels.{key}.column = {column!r} is no WITS item code for "
                          f"{key} (4 digits: record and item)", file=where or None,
                          fix='e.g. hookload = { column = "0114", unit = "kN" }')
    return code


@dataclass
class Decoder:
    """Complete frames from a byte stream, each a ``{code: value text}`` mapping.

    Tolerates blank lines, ``\\n``, ``\\r\\n`` or bare ``\\r`` line ends, lines outside a
    frame and lines that are no item (counted in :attr:`ignored`); a frame left open by a
    new ``&&`` is discarded (:attr:`discarded`), and so is a frame giving one item twice with
    two different values (which is the reading cannot be told; the same value twice is read
    once). A discarded frame's items are never read. Nothing grows without bound: a line longer than
    :data:`MAX_LINE` or a frame of more than :data:`MAX_ITEMS` items is dropped.
    """

    frames: int = 0
    ignored: int = 0
    discarded: int = 0
    _pending: bytearray = field(default_factory=bytearray)
    _items: dict | None = None
    _overlong: bool = False

    def feed(self, data: bytes) -> list[dict[str, str]]:
        """The frames completed by ``data``."""
        out = []
        start = 0
        data = data.replace(b"\r", b"\n")  # a bare CR ends a line too (CR LF: a blank line)
        while (end := data.find(b"\n", start)) >= 0:
            piece, start = data[start:end], end + 1
            if self._overlong or len(self._pending) + len(piece) > MAX_LINE:
                self._drop_line()
                continue
            self._pending += piece
            line, self._pending = bytes(self._pending), bytearray()
            frame = self._line(line.strip())
            if frame is not None:
                out.append(frame)
        rest = data[start:]
        if self._overlong or len(self._pending) + len(rest) > MAX_LINE:
            self._overlong = True  # the rest of this line is dropped when its newline comes
            self._pending = bytearray()
        else:
            self._pending += rest
        return out

    def reset(self) -> None:
        """Forget the partial line and frame (the connection dropped: a frame it cut is
        discarded; the recorder sends it again whole or not at all)."""
        if self._items is not None:
            self.discarded += 1
        self._pending, self._items, self._overlong = bytearray(), None, False

    def _drop_line(self) -> None:
        self.ignored += 1
        self._pending, self._overlong = bytearray(), False
        if self._items is not None:  # a frame with a mangled line is not trusted
            self._items, self.discarded = None, self.discarded + 1

    def _line(self, line: bytes) -> dict[str, str] | None:
        if line.startswith(b"&&"):
            if self._items is not None:
                self.discarded += 1
            self._items = {}
        elif line.startswith(b"!!"):
            frame, self._items = self._items, None
            if frame is not None:
                self.frames += 1
                return frame
        elif self._items is not None and len(line) > 4 and line[:4].isdigit() \
                and line.isascii():
            code, value = line[:4].decode(), line[4:].decode().strip()
            if len(self._items) >= MAX_ITEMS or self._items.get(code, value) != value:
                self._items, self.discarded = None, self.discarded + 1
            else:
                self._items[code] = value
        elif line:
            self.ignored += 1
        return None


def number(text: str) -> float:
    """An item's value as a float (NaN when it is no finite number as WITS writes one — an
    ASCII decimal with optional sign and exponent — or a null marker).

    Examples
    --------
    >>> number("18.42"), number("-999.25"), number("abc"), number("1.5E+02")
    (18.42, nan, nan, 150.0)
    >>> number("1_0"), number("nan"), number("inf"), number("\u0661\u0660")
    (nan, nan, nan, nan)
    """
    if not _NUMBER.fullmatch(text):
        return math.nan
    try:
        value = float(text)
    except ValueError:
        return math.nan
    return value if math.isfinite(value) and value not in NULL_VALUES else math.nan


def frame_clock(frame: dict[str, str]) -> datetime | None:
    """The frame's date and time items (YYMMDD, HHMMSS; rig clock, no zone), or None when
    either is absent or no valid date/time.

    Examples
    --------
    >>> frame_clock({"0105": "261127", "0106": "143015"})
    datetime.datetime(2026, 11, 27, 14, 30, 15)
    >>> frame_clock({"0105": "261127"}) is None, frame_clock({"0105": "261399",
    ...                                                      "0106": "0"}) is None
    (True, True)
    """
    date, time = frame.get(DATE_CODE), frame.get(TIME_CODE)
    if date is None or time is None or not _STAMP.match(date) or not _STAMP.match(time):
        return None  # digits only: "-9899" or "2.6e5" would give a date the rig never sent
    try:
        day, clock = int(date.split(".")[0]), int(time.split(".")[0])
        return datetime(2000 + day // 10000, day // 100 % 100, day % 100,
                        clock // 10000, clock // 100 % 100, clock % 100)
    except (ValueError, OverflowError):
        return None


@dataclass
class Row:
    """The current values of the mapped channels [SI]: a frame updates the items it gives
    and keeps the last value of those it omits (WITS0 recorders may send changes only)."""

    slots: dict[str, Slot]
    values: dict[str, float] = field(default_factory=dict)

    @property
    def names(self) -> list[str]:
        """Canonical column names in the order of the item table."""
        return [s.channel.name for s in self.slots.values()]

    def update(self, frame: dict[str, str]) -> dict[str, float]:
        """The values after ``frame`` (unreadable values and null markers are NaN)."""
        for code, text in frame.items():
            slot = self.slots.get(code)
            if slot is not None:  # a finite text can overflow in SI (1e308 KDN): missing
                value = number(text) * slot.factor
                self.values[slot.channel.name] = value if math.isfinite(value) else math.nan
        return {name: self.values.get(name, math.nan) for name in self.names}


def encode(values: dict[str, float], slots: dict[str, Slot],
           clock: datetime | None = None) -> bytes:
    """One frame holding ``clock`` (date and time items) and the values of the ``slots``
    present in ``values`` [SI], converted to the slots' units (NaN as :data:`NULL_TEXT`).

    Examples
    --------
    >>> encode({"hookload_N": 1.5e6}, item_map({}), datetime(2026, 11, 27, 14, 30, 15))
    b'&&\\r\\n0105261127\\r\\n0106143015\\r\\n0114150.0\\r\\n!!\\r\\n'
    """
    lines = ["&&"]
    if clock is not None:
        lines += [f"{DATE_CODE}{clock:%y%m%d}", f"{TIME_CODE}{clock:%H%M%S}"]
    for slot in slots.values():
        value = values.get(slot.channel.name)
        if value is None:
            continue
        lines.append(slot.code + (repr(float(value) / slot.factor) if math.isfinite(value)
                                  else NULL_TEXT))
    return ("\r\n".join(lines + ["!!"]) + "\r\n").encode()
