"""Channel recognition: the one mnemonic table, and the mapping of source columns to channels.

Every canonical surface channel of docs/ingestion.md is declared once in :data:`CHANNELS` (its
``[channels]`` key, canonical column with unit suffix, quantity, unit assumed when the file
states none, and the mnemonics recognised). :func:`map_channels` matches a file's columns to
these channels and decides each channel's source unit, in this order of precedence:

1. ``[channels]`` in the well configuration (``column``, ``unit``, extra ``mnemonics``);
2. the unit stated by the file (``TORQUE [kN.m]``, ``Torque (ft.lbf)``, a units row, LAS or
   HDF5 unit attributes, a trailing unit word like ``Average Surface Torque kN.m``);
3. the canonical suffix (``surface_torque_Nm`` is in N·m, as ``drillfric simulate`` writes);
4. the documented default of :data:`CHANNELS` (reported as ``source = "default"``).

A unit stated in ``[channels]`` that disagrees with the file's own is an error
(inconsistent unit), as is a unit of the wrong kind (``klbf`` for a torque).
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

from drillfric.errors import InputError
from drillfric.io.text import listing, printable
from drillfric.units import names_angle, parse_unit, registry


@dataclass(frozen=True)
class Channel:
    """One canonical surface channel.

    Attributes
    ----------
    key : str
        Key in ``[channels]`` (canonical name without the unit suffix).
    name : str
        Canonical column name with its unit suffix (``surface_torque_Nm``).
    kind : str
        Quantity, for messages (``torque``).
    unit : str
        Unit of the canonical column (pint expression; ``surface_rpm`` stays in RPM).
    default_unit : str
        Unit assumed when neither the file nor the configuration states one.
    mnemonics : tuple of str
        Names recognised in files (compared case-, space- and punctuation-insensitively).
    required : bool
        Whether a well without this channel is rejected.
    index : str or None
        ``"time"`` or ``"depth"`` for the index of a time- or depth-indexed log: mapped
        (and required) only in logs of that index; None for the other channels.
    """

    key: str
    name: str
    kind: str
    unit: str
    default_unit: str
    mnemonics: tuple[str, ...]
    required: bool = False
    index: str | None = None


#: The mnemonic table (the only one): canonical channels in output column order. Interval
#: averages (``TORQUE_AVG``) are the channel itself; interval minima and maxima
#: (``TORQUE_MIN``/``_MAX``, WITS ``HKLX``/``TQX``) are optional channels of their own.
CHANNELS: tuple[Channel, ...] = (
    Channel("time", "time_s", "time", "second", "s",
            ("TIME", "DATETIME", "DATE_TIME", "TIMESTAMP", "TIME_S", "ETIM", "ELAPSED TIME",
             "TIM", "DATE TIME", "RIG TIME"), required=True, index="time"),
    Channel("measured_depth", "measured_depth_m", "length", "meter", "m",
            ("DEPT", "DEPTH", "MD", "MEASURED DEPTH", "DEPTH MD", "MD DEPTH",
             "MEASURED DEPTH MD"), required=True, index="depth"),
    Channel("surface_rpm", "surface_rpm", "rotary speed", "revolution/minute", "rpm",
            ("RPM", "SRPM", "TDRPM", "RPMA", "RPMS", "TDS", "ROTARY SPEED", "TOP DRIVE SPEED",
             "AVERAGE ROTARY SPEED", "SURFACE RPM", "SURFACE ROTARY SPEED", "TOP DRIVE RPM",
             "TD SPEED", "TD RPM", "ROTARY RPM", "RPM SURFACE", "SURF_RPM", "SURF_RPM_AVG",
             "RPM_AVG", "SRPM_AVG"), required=True),
    Channel("surface_torque", "surface_torque_Nm", "torque", "newton*meter", "kN.m",
            ("TORQUE", "STOR", "TQA", "TDTORQUE", "TORQ", "TQ", "SURFACE TORQUE",
             "TOP DRIVE TORQUE", "AVERAGE SURFACE TORQUE", "TD TORQUE", "ROTARY TORQUE",
             "STQ", "TDTQ", "TORQUE_AVG", "TQ_AVG", "STOR_AVG"), required=True),
    Channel("hookload", "hookload_N", "force", "newton", "kN",
            ("HKLD", "HKLA", "HKL", "HOOKLOAD", "HOOK LOAD", "AVERAGE HOOKLOAD",
             "AVERAGE HOOK LOAD", "HKLD_AVG", "HKL_AVG", "HOOKLOAD_AVG")),
    Channel("bit_depth", "bit_depth_m", "length", "meter", "m",
            ("BITDEP", "DBTM", "BDEP", "BIT DEPTH", "BIT POSITION", "DEPTH BIT")),
    Channel("hole_depth", "hole_depth_m", "length", "meter", "m",
            ("DMEA", "HDTH", "HOLE DEPTH", "HOLEDEPTH", "DEPTH HOLE", "HOLE DEPTH MD",
             "MDEPTH")),
    Channel("wob", "wob_N", "force", "newton", "kN",
            ("WOB", "SWOB", "WOBA", "WEIGHT ON BIT", "SURFACE WOB", "WOB_AVG")),
    Channel("rop", "rop_m_s", "speed", "meter/second", "m/h",
            ("ROP", "ROPA", "ROP_AVG", "RATE OF PENETRATION", "AVERAGE ROP",
             "AVERAGE RATE OF PENETRATION")),
    Channel("block_position", "block_position_m", "length", "meter", "m",
            ("BPOS", "BLKPOS", "BLOCK POSITION", "BLOCK HEIGHT", "BLOCK", "HOOK POSITION")),
    Channel("bit_rpm", "bit_rpm", "rotary speed", "revolution/minute", "rpm",
            ("BITRPM", "DRPM", "BIT RPM", "DOWNHOLE RPM", "BIT SPEED", "BIT_RPM_AVG")),
    Channel("standpipe_pressure", "standpipe_pressure_Pa", "pressure", "pascal", "kPa",
            ("SPP", "SPPA", "SPPR", "STANDPIPE PRESSURE", "AVERAGE STANDPIPE PRESSURE",
             "PUMP PRESSURE", "SPP_AVG", "PUMP", "PUMP_AVG")),
    Channel("flow_in", "flow_in_m3_s", "flow rate", "meter**3/second", "L/min",
            ("FLOWIN", "MFIA", "TFLO", "FLOW IN", "MUD FLOW IN", "FLOW IN RATE")),
    Channel("flow_out", "flow_out_pct", "percentage", "percent", "%",
            ("FLOWOUT", "MFOP", "FLOW OUT", "FLOW OUT PERCENT", "RETURN FLOW")),
    Channel("pump_rate", "pump_rate_spm", "pump rate", "1/minute", "spm",
            ("SPM", "TSPM", "TOTAL SPM", "PUMP RATE", "STROKE RATE", "TOTAL STROKE RATE",
             "STRATESUM")),
    Channel("surface_torque_min", "surface_torque_min_Nm", "torque", "newton*meter", "kN.m",
            ("TORQUE_MIN", "TQ_MIN", "STOR_MIN", "MIN_TORQUE", "TQMN")),
    Channel("surface_torque_max", "surface_torque_max_Nm", "torque", "newton*meter", "kN.m",
            ("TORQUE_MAX", "TQ_MAX", "STOR_MAX", "MAX_TORQUE", "TQX", "TQMX")),
    Channel("surface_rpm_min", "surface_rpm_min", "rotary speed", "revolution/minute", "rpm",
            ("SURF_RPM_MIN", "RPM_MIN", "SRPM_MIN", "MIN_RPM")),
    Channel("surface_rpm_max", "surface_rpm_max", "rotary speed", "revolution/minute", "rpm",
            ("SURF_RPM_MAX", "RPM_MAX", "SRPM_MAX", "MAX_RPM")),
    Channel("hookload_min", "hookload_min_N", "force", "newton", "kN",
            ("HKLD_MIN", "HKL_MIN", "HOOKLOAD_MIN", "MIN_HOOKLOAD")),
    Channel("hookload_max", "hookload_max_N", "force", "newton", "kN",
            ("HKLD_MAX", "HKLX", "HKL_MAX", "HOOKLOAD_MAX", "MAX_HOOKLOAD")),
)

BY_KEY: dict[str, Channel] = {c.key: c for c in CHANNELS}
BY_NAME: dict[str, Channel] = {c.name: c for c in CHANNELS}

#: Unit spellings that neither pint nor drillfric.units parse (flow, pump rate, scaled).
_EXTRA_UNITS = {
    "spm": "1/minute", "stk/min": "1/minute", "strokes/min": "1/minute",
    "1/min": "1/minute", "gpm": "gallon/minute", "lpm": "liter/minute",
    "l/min": "liter/minute", "m3/min": "meter**3/minute", "m3/s": "meter**3/second",
    "bbl/min": "oil_barrel/minute", "pct": "percent", "psia": "psi", "psig": "psi",
    # scaled spellings that drillfric.units maps to expressions pint rejects as units
    "kft.lbf": "kilofoot*force_pound", "kft-lbf": "kilofoot*force_pound",
    "dan": "decanewton",
}

#: Per-minute spellings that mean RPM on a rotation channel (strokes per minute elsewhere).
_PER_MINUTE = frozenset({"1/min", "u/min", "min-1", "min^-1", "1/minute", "rev/min"})

#: Unit as spelled in the canonical suffix of each channel (``surface_torque_Nm`` → N.m).
SUFFIX_UNITS = {"time": "s", "measured_depth": "m", "surface_rpm": "rpm",
                "surface_torque": "N.m", "hookload": "N", "bit_depth": "m", "hole_depth": "m",
                "wob": "N", "rop": "m/s", "block_position": "m",
                "bit_rpm": "rpm", "standpipe_pressure": "Pa", "flow_in": "m3/s",
                "flow_out": "%", "pump_rate": "spm", "surface_torque_min": "N.m",
                "surface_torque_max": "N.m", "surface_rpm_min": "rpm", "surface_rpm_max": "rpm",
                "hookload_min": "N", "hookload_max": "N"}

_UNIT_IN_NAME = re.compile(r"^\s*(?P<name>.*?)\s*[\[({](?P<unit>[^\])}]*)[\])}]\s*$")


def normalise(name: str) -> str:
    """Comparison form of a mnemonic: upper case, letters and digits only.

    Examples
    --------
    >>> normalise("Top Drive Speed")
    'TOPDRIVESPEED'
    """
    return re.sub(r"[^0-9A-Z]", "", str(name).upper())


def split_unit(header: str) -> tuple[str, str | None]:
    """Split ``"TORQUE [kN.m]"`` or ``"Torque (ft.lbf)"`` into name and unit.

    Examples
    --------
    >>> split_unit("Torque (ft.lbf)")
    ('Torque', 'ft.lbf')
    >>> split_unit("SRPM")
    ('SRPM', None)
    """
    match = _UNIT_IN_NAME.match(str(header))
    if match and match["name"]:
        return match["name"], match["unit"].strip() or None
    return str(header), None


_FT, _LBF, _GAL, _KGF = 0.3048, 4.4482216152605, 3.785411784e-3, 9.80665
#: Exact factors of the common spellings to each canonical unit, so that reading a usual
#: log does not build pint's registry (≈ 0.6 s); anything else goes through pint.
_COMMON = {
    "second": {"s": 1.0, "sec": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0, "hr": 3600.0},
    "revolution/minute": {"rpm": 1.0, "rev/min": 1.0, "r/min": 1.0, "c/s": 60.0,
                          "rev/s": 60.0, "rps": 60.0, "hz": 60.0, "1/s": 60.0, "cps": 60.0},
    "newton*meter": {"n.m": 1.0, "nm": 1.0, "n·m": 1.0, "n-m": 1.0, "n*m": 1.0,
                     "kn.m": 1e3, "knm": 1e3, "kn·m": 1e3, "kn-m": 1e3, "kn*m": 1e3,
                     "ft.lbf": _FT * _LBF, "ft-lbf": _FT * _LBF, "ft·lbf": _FT * _LBF,
                     "lbf.ft": _FT * _LBF, "kft.lbf": 1e3 * _FT * _LBF,
                     "kft-lbf": 1e3 * _FT * _LBF,
                     # rig spellings with the pound of force written "lb" (an EDR's FTLB
                     # had been femto-troy-pounds to pint, the log refused: issue 30)
                     **dict.fromkeys(("ftlb", "ft.lb", "ft-lb", "ft lb", "ft.lbs", "ft-lbs",
                                      "ftlbs", "lb.ft", "lb-ft", "lbft", "lbf-ft", "ft lbf",
                                      "ftlbf"), _FT * _LBF),
                     **dict.fromkeys(("kftlb", "kft.lb", "kft-lb", "klb.ft", "klb-ft",
                                      "kftlbf", "kft.lbs", "klbf.ft", "klbf-ft"),
                                     1e3 * _FT * _LBF)},
    "newton": {"n": 1.0, "kn": 1e3, "dan": 10.0, "kdn": 1e4, "kdan": 1e4, "lbf": _LBF,
               "klbf": 1e3 * _LBF, "kgf": _KGF, "kkgf": 1e3 * _KGF},  # KDN: WITS kilo-daN
    "meter": {"m": 1.0, "ft": _FT, "cm": 1e-2, "mm": 1e-3, "in": 0.0254},
    "pascal": {"pa": 1.0, "kpa": 1e3, "mpa": 1e6, "bar": 1e5, "psi": _LBF / 0.0254 ** 2},
    "meter**3/second": {"m3/s": 1.0, "l/min": 1e-3 / 60.0, "lpm": 1e-3 / 60.0,
                        "m3/min": 1.0 / 60.0, "gpm": _GAL / 60.0},
    "percent": {"%": 1.0, "pct": 1.0, "percent": 1.0},
    "1/minute": {"spm": 1.0, "stk/min": 1.0, "1/min": 1.0},
}


def factor(unit: str, channel: Channel, *, file: str | None = None) -> float:
    """Factor turning values in ``unit`` into the canonical unit of ``channel``.

    Raises
    ------
    InputError
        Unknown unit, or a unit of the wrong kind (an inconsistent unit).

    Examples
    --------
    >>> round(factor("ft.lbf", BY_KEY["surface_torque"]), 6)
    1.355818
    >>> round(factor("klbf", BY_KEY["hookload"]), 3)
    4448.222
    """
    common = _COMMON.get(channel.unit, {}).get(unit.strip().lower().replace(" ", ""))
    if common is not None:
        return common
    import pint

    source = _source_unit(unit, channel, file)
    if "revolution" in channel.unit and not names_angle(source):
        source = source * registry().turn  # a rotary speed in Hz counts revolutions
    try:
        return float(registry().Quantity(1.0, source).to(channel.unit).magnitude)
    except pint.errors.DimensionalityError as exc:
        raise InputError(f"unit '{printable(unit)}' of {channel.name} is not a {channel.kind} "
                         f"unit (it measures {_dimension(source)})", file=file,
                         fix=f"give a {channel.kind} unit — {accepted_units(channel)} or "
                             f"another pint spelling — e.g. {channel.key} = "
                             f'{{ unit = "{channel.default_unit}" }}') from exc


def _source_unit(unit: str, channel: Channel, file: str | None):
    """The pint unit of a spelling, read as the channel reads it (1/min is RPM on a speed)."""
    key = unit.strip().lower().replace(" ", "")
    spelled = _EXTRA_UNITS.get(key, unit)
    if key in _PER_MINUTE and "revolution" in channel.unit:
        spelled = "revolution/minute"  # 1/min, U/min, min-1: the European spellings of RPM
    try:
        return parse_unit(spelled)
    except InputError as exc:
        if " reads as " in exc.problem:  # a unit pint reads, as nothing a rig logs
            raise InputError(f"{channel.name}: {printable(exc.problem, 200)}", file=file,
                             fix=exc.fix) from exc
        raise InputError(f"unknown unit '{printable(unit)}' for {channel.name}: no {channel.kind} "
                         f"unit is spelled so (nor any unit pint knows)", file=file,
                         fix=f"write a {channel.kind} unit drillfric reads — "
                             f"{accepted_units(channel)} or another pint spelling — in the "
                             f"file's header or in [channels], e.g. {channel.key} = "
                             f'{{ unit = "{channel.default_unit}" }}') from exc


def _dimension(unit) -> str:
    """What a pint unit measures, in words (``"[mass]"``, ``"[length] / [time]"``)."""
    return str(registry().Quantity(1.0, unit).dimensionality) or "nothing (dimensionless)"


def accepted_units(channel: Channel) -> str:
    """The common spellings of ``channel``'s quantity drillfric reads (one per unit).

    Examples
    --------
    >>> accepted_units(BY_KEY["surface_torque"])
    'n.m, kn.m, ft.lbf, kft.lbf'
    """
    seen: dict[float, str] = {}
    for spelling, value in _COMMON.get(channel.unit, {}).items():
        seen.setdefault(value, spelling)
    return ", ".join(seen.values()) or channel.default_unit


def unit_fits(unit: str, channel: Channel) -> bool | None:
    """Whether ``unit`` measures the quantity of ``channel`` (None: an unknown spelling).

    Examples
    --------
    >>> unit_fits("kN.m", BY_KEY["surface_torque"]), unit_fits("rpm", BY_KEY["surface_torque"])
    (True, False)
    >>> unit_fits("blorps", BY_KEY["surface_torque"]) is None
    True
    """
    try:
        source = _source_unit(unit, channel, None)
    except InputError:
        return None
    reg = registry()
    return (reg.Quantity(1.0, source).dimensionality
            == reg.Quantity(1.0, channel.unit).dimensionality)


@dataclass(frozen=True)
class Mapping:
    """Where one channel comes from.

    Attributes
    ----------
    channel : Channel
    column : str
        Source column label (its position as text for headerless files).
    unit : str
        Source unit as found or assumed.
    source : str
        ``"config"``, ``"header"``, ``"units row"``, ``"name suffix"`` or ``"default"``.
    factor : float
        Multiplier from the source unit to the canonical unit.
    note : str or None
        Why this column was taken over one the mnemonic table prefers (that one holds no
        changing value: :func:`drillfric.io.well.prefer_live`), for the run's warnings.
    """

    channel: Channel
    column: str
    unit: str
    source: str
    factor: float
    note: str | None = None


def _rank(column: str, channel: Channel, extra: tuple[str, ...]) -> tuple[tuple, str | None]:
    """Match rank of ``column`` for ``channel`` (``()`` = no match) and a unit in its name.

    The canonical name beats any mnemonic; among mnemonics the earlier in the list wins
    (``[channels]`` extra mnemonics come first), so a file with both HKLD and HKLA maps HKLD.
    """
    if column == channel.name:
        return (3, 0), None
    names = _normalised(extra + channel.mnemonics)
    base, unit = split_unit(column)
    words = str(column).split()
    head = normalise(" ".join(words[:-1]))
    if len(words) > 1 and head in names:
        try:  # a trailing unit word, as in "Average Surface Torque kN.m", "TIME / s"
            factor(words[-1], channel)
        except InputError:
            words = []
    if normalise(base) in names:
        # "TIME / s" and "Time, s" are also the mnemonic TIME_S: the unit they state is
        # read all the same, as for "TORQUE / ft.lbf" (it had been "assumed unit of time_s
        # … nothing in the file says": issue 30, twelfth attack F9)
        said = unit or (words[-1] if len(words) > 1 and head in names else None)
        return (2, -names.index(normalise(base))), said
    if len(words) > 1 and head in names:
        return (1, -names.index(head)), words[-1]
    return (), None


@lru_cache(maxsize=256)
def _normalised(mnemonics: tuple[str, ...]) -> list[str]:
    """:func:`normalise` of each mnemonic, computed once per channel (a file of thousands
    of columns ranks every column against every channel)."""
    return [normalise(m) for m in mnemonics]


def _find_column(columns: list[str], channel: Channel, spec: dict, file: str | None,
                 file_units: dict | None = None,
                 passed_over: frozenset = frozenset()) -> tuple[str | None, str | None]:
    """The column a channel maps to (from ``[channels]`` or mnemonics) and the unit in its name.

    A column found by mnemonic whose stated unit measures another quantity (``FLOWOUT`` in
    m3/s is a flow rate, not the percentage ``flow_out``) is passed over; a required channel
    keeps it when no other column fits, so that the unit error names it.
    """
    wanted = spec.get("column")
    if wanted is not None:
        if isinstance(wanted, int):
            if not 0 <= wanted < len(columns):
                raise InputError(f"[channels] {channel.key} column {wanted} does not exist "
                                 f"(the file has {len(columns)} columns, 0-based)", file=file,
                                 fix="use a 0-based column index below the column count")
            return columns[wanted], None
        if wanted in columns:
            return wanted, split_unit(wanted)[1]
        by_base = [c for c in columns if split_unit(c)[0] == wanted]
        if len(by_base) == 1:
            return by_base[0], split_unit(by_base[0])[1]
        raise InputError(f"[channels] {channel.key} column '{printable(wanted)}' not found; "
                         f"columns are: {listing(columns, recognised=_recognisable(columns))}",
                         file=file,
                         fix="use one of the listed column names (or a 0-based index)")
    ranked = _candidates(columns, channel, spec, file_units)
    ranked = [r for r in ranked if r[1] not in passed_over]
    if not ranked:
        return None, None
    best = max(r[0] for r in ranked)
    top = [r for r in ranked if r[0] == best]
    if len(top) > 1:
        names = " and ".join(f"'{printable(r[1])}'" for r in top)
        raise InputError(f"columns {names} both look like {channel.name}", file=file,
                         fix=f'choose one in [channels], e.g. {channel.key} = '
                             f'{{ column = "{printable(top[0][1])}" }}')
    return top[0][1], top[0][2]


def _candidates(columns: list[str], channel: Channel, spec: dict,
                file_units: dict | None) -> list[tuple[tuple, str, str | None]]:
    """(rank, column, unit in its name) of every column the mnemonics match for ``channel``,
    best first (a column whose stated unit measures another quantity only when none fits)."""
    extra = tuple(spec.get("mnemonics", ()))
    ranked = [(rank, col, unit) for col in columns
              for rank, unit in [_rank(col, channel, extra)] if rank]
    fitting = [r for r in ranked if _unit_agrees(r[1], r[2], channel, file_units or {}, spec)]
    if fitting or not channel.required:
        ranked = fitting
    # a qualifier read as a unit ('RPM (setpoint)', 'TORQUE (max)') gives way to a column
    # whose unit is one ('SRPM [rpm]'): it had refused the log "unknown unit 'setpoint'"
    # (issue 30, eleventh attack); alone, it stays, and the unit error names it
    known = [r for r in ranked if _unit_known(r[1], r[2], channel, file_units or {}, spec)]
    if known:
        ranked = known
    return sorted(ranked, key=lambda r: r[0], reverse=True)


def _unit_known(column: str, name_unit: str | None, channel: Channel, file_units: dict,
                spec: dict) -> bool:
    """False when the unit stated for ``column`` is no unit drillfric knows (a qualifier
    such as ``setpoint`` or ``max`` in parentheses)."""
    unit = spec.get("unit") or name_unit or file_units.get(column)
    return channel.key == "time" or not unit or unit_fits(unit, channel) is not None


def candidate_columns(columns: list[str], key: str, config_channels: dict,
                      file_units: dict | None = None) -> list[str]:
    """Every column that could be channel ``key`` by its name, the mnemonic table's choice
    first; none when ``[channels]`` names the column (the user chose).

    Examples
    --------
    >>> candidate_columns(["time_s", "TDRPM", "RPM"], "surface_rpm", {})
    ['RPM', 'TDRPM']
    >>> candidate_columns(["TDRPM", "RPM"], "surface_rpm", {"surface_rpm": {"column": "RPM"}})
    []
    """
    spec = config_channels.get(key, {})
    if spec.get("column") is not None:
        return []
    return [r[1] for r in _candidates(columns, BY_KEY[key], spec, file_units)]


def _unit_agrees(column: str, name_unit: str | None, channel: Channel, file_units: dict,
                 spec: dict) -> bool:
    """False when the unit a file states for ``column`` measures another quantity."""
    unit = spec.get("unit") or name_unit or file_units.get(column)
    return channel.key == "time" or not unit or unit_fits(unit, channel) is not False


def _recognisable(columns: list[str]) -> bool:
    """Whether any column is a known channel (the file is a log, not something else)."""
    return any(_rank(c, ch, ())[0] for ch in CHANNELS for c in columns)


def find_column(columns: list[str], key: str, config_channels: dict, *,
                file: str | None = None) -> str | None:
    """The column channel ``key`` maps to (``[channels]`` or its mnemonics), or None.

    Examples
    --------
    >>> find_column(["DEPT", "ETIM", "SRPM"], "time", {})
    'ETIM'
    >>> find_column(["DEPT", "SRPM"], "time", {}) is None
    True
    """
    channel = BY_KEY[key]
    return _find_column(columns, channel, config_channels.get(key, {}), file)[0]


def _unit_for(channel: Channel, column: str, name_unit: str | None, file_units: dict,
              spec: dict, file: str | None) -> tuple[str, str]:
    """Source unit of a mapped column and where it came from (precedence in module doc).

    A file that states two different units for one column (its header name, its units row
    or field metadata, a canonical name's suffix) is refused unless ``[channels]`` names
    one of them: one had been taken silently, μ_k −27 % to +35 % (issue 30, tenth attack)."""
    states = _stated_units(channel, column, name_unit, file_units)
    stated, stated_source = states[0] if states else (None, None)
    configured = spec.get("unit")
    if configured is None and any(_differ(u, stated, channel) for u, _ in states[1:]):
        said = "; ".join(f"its {where} says '{printable(u)}'" for u, where in states)
        raise InputError(f"the file states two units for {channel.name} (column "
                         f"'{printable(column)}'): {said}", file=file,
                         fix=f"say which in the configuration, e.g. [channels] {channel.key} = "
                             f'{{ unit = "{printable(states[-1][0])}" }}')
    if configured is not None:
        if any(not _differ(u, configured, channel) for u, _ in states[1:]):
            return configured, "config"
        if stated_source == "header" and len(states) == 1 and \
                unit_fits(stated, channel) is None:
            return configured, "config"  # a qualifier in the name ('TORQUE (max)'), no unit
        if stated is not None and not _same_unit(stated, configured, channel, file):
            raise InputError(f"inconsistent unit for {channel.name}: column "
                             f"'{printable(column)}' says '{printable(stated)}' but [channels] "
                             f"says '{printable(configured)}'", file=file,
                             fix=f"remove unit from [channels] {channel.key} or correct it")
        return configured, "config"
    if stated is not None:
        return stated, stated_source
    return channel.default_unit, "default"


def _stated_units(channel: Channel, column: str, name_unit: str | None,
                  file_units: dict) -> list[tuple[str, str]]:
    """(unit, where) of every unit the file states for ``column``, in precedence order."""
    states = []
    if name_unit:
        states.append((name_unit, "header"))
    if file_units.get(column):
        states.append((file_units[column], file_units.get(("source", column), "header")))
    if file_units.get(("also", column)):  # a format stating it twice (WITSML)
        states.append(tuple(file_units[("also", column)]))
    if column == channel.name:
        states.append((SUFFIX_UNITS[channel.key], "name suffix"))
    return states


def _differ(a: str, b: str, channel: Channel) -> bool:
    """Whether two stated units of one column convert differently (a spelling neither
    drillfric nor pint reads does not count: the one in effect is checked where it is
    used)."""
    try:
        return not _same_unit(a, b, channel, None)
    except InputError:
        return False


def _same_unit(a: str, b: str, channel: Channel, file: str | None) -> bool:
    fa, fb = factor(a, channel, file=file), factor(b, channel, file=file)
    return abs(fa - fb) <= 1e-9 * max(abs(fa), abs(fb))


def _claimed_twice(found: dict, channel: Channel, column: str, config_channels: dict,
                   file: str | None) -> None:
    """Refuse one column configured for two channels (the eleventh attack of issue 30:
    ``surface_torque = { column = "surface_rpm" }`` ran, the speed read as the torque)."""
    for key, other in found.items():
        configured = any("column" in (config_channels.get(k) or {}) for k in (key, channel.key))
        if other.column == column and configured:
            raise InputError(f"column '{printable(str(column))}' is taken for both {key} and "
                             f"{channel.key}", file=file,
                             fix=f"give [channels] {channel.key} and {key} a column each")


def log_index(columns: list[str], config_channels: dict, *, depth_index: str | None = None,
              file: str | None = None) -> str:
    """Whether a log is indexed by ``"time"`` or by ``"depth"`` (docs/ingestion.md).

    A log with a time column (by mnemonic or ``[channels] time``) is a time log. Without
    one, a log whose reader found a depth index (LAS, WITSML, DLIS: ``depth_index``) or
    that has a measured-depth column (``MD``, ``DEPTH``, ``Measured Depth``, or
    ``[channels] measured_depth``) is a depth log. Otherwise it is taken as a time log (whose
    missing time column is then the error).

    Raises
    ------
    InputError
        The time column is the log's depth index or its measured-depth column: a depth is
        never read as a time.

    Examples
    --------
    >>> log_index(["TIME", "DEPTH", "RPM", "TORQUE"], {}), log_index(["MD", "RPM"], {})
    ('time', 'depth')
    """
    time = find_column(columns, "time", config_channels, file=file)
    depth = (split_unit(depth_index)[0] if depth_index else
             find_column(columns, "measured_depth", config_channels, file=file))
    if time is None:
        return "depth" if depth is not None else "time"
    if time == depth or (depth is None and _rank(time, BY_KEY["measured_depth"], ())[0]):
        raise InputError(f"column '{time}' is a measured depth, not a time: this log is "
                         "depth-indexed", file=file,
                         fix="remove [channels] time; drillfric reads a depth-indexed log as "
                             "a friction log by depth (docs/ingestion.md)")
    return "time"


def map_channels(columns: list[str], file_units: dict, config_channels: dict, *,
                 file: str | None = None, index: str = "time",
                 log_shaped: Callable[[], bool] | None = None,
                 passed_over: dict | None = None) -> dict[str, Mapping]:
    """Match source columns to canonical channels.

    Parameters
    ----------
    columns : list of str
        Source column labels in file order (``"0"``, ``"1"``, … for headerless files).
    file_units : dict
        Units the file states per column (``{column: unit}``) plus, optionally,
        ``{("source", column): "units row"}`` to say where they came from.
    config_channels : dict
        The ``[channels]`` table of the configuration (``Config.channels``).
    file : str, optional
        File name for messages.
    index : str
        ``"time"`` or ``"depth"`` (:func:`log_index`): which index channel is mapped and
        required (``time`` or ``measured_depth``).
    log_shaped : callable, optional
        Asked only when a required channel is missing and no column name is known: whether
        the file is recognisably a data log all the same (its header is then listed).
    passed_over : dict, optional
        ``{channel key: set of columns}`` not to take for that channel by mnemonic (columns
        holding no changing value while another candidate does).

    Returns
    -------
    dict
        ``{channel key: Mapping}`` for every channel found, in :data:`CHANNELS` order.

    Raises
    ------
    InputError
        A required channel is missing (the message lists the columns found and the
        ``[channels]`` line that would map one), two columns claim one channel, or a unit
        is unknown, of the wrong kind or inconsistent.
    """
    out: dict[str, Mapping] = {}
    for channel in CHANNELS:
        if channel.index not in (None, index):
            continue
        spec = config_channels.get(channel.key, {})
        column, name_unit = _find_column(columns, channel, spec, file, file_units,
                                         frozenset((passed_over or {}).get(channel.key, ())))
        if column is None:
            if channel.required:
                raise _missing(channel, columns, file_units, config_channels, out, file,
                               log_shaped)
            continue
        _claimed_twice(out, channel, column, config_channels, file)
        unit, source = _unit_for(channel, column, name_unit, file_units, spec, file)
        try:
            scale = factor(unit, channel, file=file)
        except InputError as exc:
            if channel.key != "time":
                if source == "header" and unit_fits(unit, channel) is None:
                    raise InputError(  # 'TORQUE (max)': a qualifier, not a unit
                        f"column '{printable(column)}' ({channel.name}): unknown unit "
                        f"'{printable(unit)}' in its name: no {channel.kind} unit is spelled "
                        "so (a qualifier such as max or setpoint?)",
                        file=file, fix=f"give the unit in [channels], e.g. {channel.key} = "
                                       f'{{ column = "{printable(column)}", unit = '
                                       f'"{channel.default_unit}" }}, or map another '
                                       "column") from exc
                raise
            scale = float("nan")  # e.g. "yyyy-mm-dd hh:mm:ss" over a timestamp column
        out[channel.key] = Mapping(channel, column, unit, source,
                                   scale * float(spec.get("scale", 1.0)))
    return out


def _missing(channel: Channel, columns: list[str], file_units: dict, config_channels: dict,
             out: dict[str, Mapping], file: str | None,
             log_shaped: Callable[[], bool] | None = None) -> InputError:
    """The error for a missing required channel, with a ``[channels]`` line to map it.

    The line names a column only when one plausibly holds the channel (see
    :func:`suggest_column`); otherwise a placeholder, never another channel's column.
    """
    used = {m.column for m in out.values()}
    unit = f', unit = "{channel.default_unit}"'
    if columns and all(str(c).isdigit() for c in columns):  # headerless: nothing to judge by
        free = [c for c in columns if c not in used]
        example = free[0] if free else "N"
    else:
        pick = suggest_column(channel, columns, file_units, config_channels, used)
        example = '"NAME"' if pick is None else f'"{printable(pick)}"'
        if pick is not None and (split_unit(pick)[1] or file_units.get(pick)):
            unit = ""  # the file states it
    shown = listing(columns, recognised=bool(out) or example != '"NAME"' or (
        log_shaped is not None and log_shaped()))
    depth_log = ('; a depth-indexed log needs its measured-depth column instead, e.g. '
                 '[channels] measured_depth = { column = "NAME", unit = "m" }'
                 if channel.key == "time" else "")
    return InputError(f"required channel {channel.name} not found; columns found: {shown}",
                      file=file, fix=f"map the column holding the {channel.kind} in the well "
                                     f"config, e.g. [channels] {channel.key} = "
                                     f"{{ column = {example}{unit} }}{depth_log}")


def suggest_column(channel: Channel, columns: list[str], file_units: dict,
                   config_channels: dict, used=()) -> str | None:
    """A column that plausibly holds ``channel``, for a hint, or None.

    Plausible: not mapped to (``used``) nor named like another channel, no stated unit of
    another quantity, and either a stated unit of the channel's quantity or a name close to
    one of its mnemonics (difflib ratio ≥ 0.6). A unit match ranks above a name match.

    Examples
    --------
    >>> suggest_column(BY_KEY["surface_torque"], ["TIME", "Surface RPM", "HKLD"], {}, {},
    ...                ["TIME", "Surface RPM"]) is None
    True
    >>> suggest_column(BY_KEY["surface_torque"], ["TIME", "RPM", "M1 [kN.m]"], {}, {})
    'M1 [kN.m]'
    """
    claimed = set(used) | {c for c in columns for other in CHANNELS if other is not channel
                           and _rank(c, other, tuple(config_channels.get(other.key, {})
                                                     .get("mnemonics", ())))[0]}
    best = None
    for column in columns:
        base, name_unit = split_unit(column)
        unit = name_unit or file_units.get(column)
        fits = unit_fits(unit, channel) if unit else None
        if column in claimed or fits is False:
            continue
        likeness = max(difflib.SequenceMatcher(None, normalise(base), normalise(m)).ratio()
                       for m in channel.mnemonics + (channel.key,))
        score = (bool(fits), likeness)
        if (fits or likeness >= 0.6) and (best is None or score > best[0]):
            best = (score, column)
    return None if best is None else best[1]


def mnemonics_markdown() -> str:
    """The mnemonic table of docs/ingestion.md, rendered from :data:`CHANNELS`."""
    lines = ["| `[channels]` key | column | unit | default source unit | required | "
             "mnemonics |", "|---|---|---|---|---|---|"]
    for c in CHANNELS:
        names = ", ".join(f"`{m}`" for m in c.mnemonics)
        required = f"{c.index} logs" if c.index else "yes" if c.required else ""
        lines.append(f"| `{c.key}` | `{c.name}` | {SUFFIX_UNITS[c.key]} | {c.default_unit} | "
                     f"{required} | {names} |")
    return "\n".join(lines)
