"""Unit conversion at the edges, with pint, including drilling spellings.

Everything inside drillfric is SI (m, s, rad, N, N·m, kg); rig logs and users speak kN·m,
ft·lbf, klbf, kkgf, ppg, inches, RPM and friends. Three edges:

- **file headers** — :func:`to_si` converts an array given a unit as written in a header;
  :func:`parse_unit` normalises drilling spellings (``kN.m``, ``kNm``, ``ft.lbf``,
  ``klbf``, ``kkgf``, ``g/cm3``, ``sg``, ``ppg``, ``rpm``, ``c/s``, ``deg``) before pint
  parses them;
- **configuration values and command-line options** — :func:`quantity_value` reads
  ``"10.5 ppg"``, ``"5 1/2 in"``, ``"19.5 lb/ft"``, ``"40 klbf"`` or ``"8200 ft"`` in the
  unit a key or option is declared in, checks the dimension, and converts exactly (decimal
  arithmetic; the result is the float nearest the exact value, so a field-unit
  configuration and its SI twin give bit-for-bit the same numbers);
- **what people read** — :func:`display_unit`, :func:`to_display` and
  :func:`format_value` show SI values in the ``"si"`` or ``"field"`` system of
  :data:`DISPLAY_UNITS` (terminal summaries, report axes and tables; result files stay SI).

pint is imported and its registry built on first use (:func:`registry`), not at import:
``import drillfric.config`` must stay fast for commands that never meet a unit.
"""

from __future__ import annotations

import math
import re
from decimal import Decimal, InvalidOperation, localcontext
from functools import cache, lru_cache
from typing import TYPE_CHECKING

import numpy as np

from drillfric.errors import ConfigError, InputError

if TYPE_CHECKING:
    import pint

#: Units pint does not define, added to every registry.
_DEFINITIONS = (
    "kilopound_force = 1000 * force_pound = klbf",
    "kilokilogram_force = 1000 * kilogram_force = kkgf",
    "specific_gravity = 1000 * kilogram / meter ** 3 = sg",
    "pound_per_gallon = pound / gallon = ppg",
    "@alias turn = rev",  # a mud motor's "0.15 rev/gal" ([bha] motor_rev_per_litre)
)

#: Drilling spellings pint does not know, lower-cased, mapped to pint expressions.
_ALIASES = {
    "rpm": "revolution/minute",
    "r/min": "revolution/minute",
    "rev/min": "revolution/minute",
    "c/s": "revolution/second",  # cycles per second (WITSML)
    "rps": "revolution/second",
    "rad/s": "radian/second",
    "knm": "kilonewton*meter",
    "kn.m": "kilonewton*meter",
    "kn-m": "kilonewton*meter",
    "kn·m": "kilonewton*meter",
    "n.m": "newton*meter",
    "nm": "newton*meter",
    "n-m": "newton*meter",
    "n·m": "newton*meter",
    "ft.lbf": "foot*force_pound",
    "ft-lbf": "foot*force_pound",
    "ft·lbf": "foot*force_pound",
    "ftlbf": "foot*force_pound",
    "ft.lb": "foot*force_pound",
    "ft-lb": "foot*force_pound",
    "lbf.ft": "foot*force_pound",
    "kft.lbf": "kilofoot*force_pound",
    "kft-lbf": "kilofoot*force_pound",
    "kft·lbf": "kilofoot*force_pound",
    "klbf": "kilopound_force",
    "kips": "kilopound_force",
    "kip": "kilopound_force",
    "lbf": "force_pound",
    "kkgf": "kilokilogram_force",
    "tonf": "metric_ton*g0",
    "t": "metric_ton*g0",
    "kn": "kilonewton",
    "dan": "decanewton",
    "g/cm3": "gram/centimeter**3",
    "g/cc": "gram/centimeter**3",
    "kg/m3": "kilogram/meter**3",
    "kg/m³": "kilogram/meter**3",
    "sg": "specific_gravity",
    "ppg": "pound_per_gallon",
    "lbm/gal": "pound_per_gallon",
    "lb/gal": "pound_per_gallon",
    "ft": "foot",
    "f": "foot",  # LAS depth unit
    "feet": "foot",
    "in": "inch",
    "inch": "inch",
    "inches": "inch",
    '"': "inch",
    "klb": "kilopound_force",
    "klbs": "kilopound_force",
    "kftlb": "kilofoot*force_pound",
    "ms": "millisecond",  # not megasiemens
    "min": "minute",
    "hr": "hour",
    "kpa": "kilopascal",
    "mpa": "megapascal",
    "m": "meter",
    "s": "second",
    "sec": "second",
    "deg": "degree",
    "dega": "degree",
    "degrees": "degree",
    "°": "degree",
    "%": "percent",
    # WITSML 1.x unit spellings (uom attributes, unitList)
    "lbm": "pound",
    "lbm/ft": "pound/foot",
    "lb/ft": "pound/foot",
    "ppf": "pound/foot",
    "ftus": "survey_foot",
    "usft": "survey_foot",  # not micro-survey-foot (issue 30, tenth attack)
    "us-ft": "survey_foot",
    "hz": "hertz",
}
#: Units of a rotary speed that name no angle (Hz, 1/s, cps) count cycles: revolutions per
#: time, not radians (pint's Hz = 1/s = 1 rad/s had read a speed logged in Hz 6.3× low).
ANGLE_UNITS = frozenset({"radian", "turn", "degree", "gradian", "arcminute", "arcsecond"})


def names_angle(unit) -> bool:
    """Whether a parsed pint unit holds an angle unit — by what it is, not by its name (pint
    names gradians ``grade`` and prefixed ones ``milliradian``: a speed in ``gon/s`` or
    ``mrad/s`` was taken for cycles per time, 2π too fast: issue 30, tenth attack).

    Examples
    --------
    >>> names_angle(parse_unit("mrad/s")), names_angle(parse_unit("gon")), names_angle(
    ...     parse_unit("Hz"))
    (True, True, False)
    """
    reg = registry()
    return any(_angle_name(reg, name) for name in unit._units)


def _angle_name(reg, name: str) -> bool:
    try:
        return "radian" in reg.get_root_units(name)[1]._units
    except Exception:  # noqa: BLE001 — a name pint cannot reduce is no angle
        return False

#: SI target unit for each kind of quantity drillfric reads.
SI_UNITS = {
    "time": "second",
    "length": "meter",
    "angle": "radian",
    "angular_velocity": "radian/second",
    "rpm": "revolution/minute",
    "torque": "newton*meter",
    "force": "newton",
    "density": "kilogram/meter**3",
    "dimensionless": "dimensionless",
}

#: The unit labels of configuration keys and options (``Key.unit`` of
#: :data:`drillfric.config.SCHEMA`) as pint expressions, with the quantity's name for
#: messages. A quantity given for a key is converted to its label's unit.
LABEL_UNITS = {
    "m": ("meter", "length"),
    "kg/m³": ("kilogram/meter**3", "density"),
    "kg/m": ("kilogram/meter", "linear mass"),
    "kg·m²": ("kilogram*meter**2", "moment of inertia"),
    "N": ("newton", "force"),
    "N·m": ("newton*meter", "torque"),
    "N·m/rad": ("newton*meter/radian", "rotational stiffness"),
    "N·m·s/rad": ("newton*meter*second/radian", "rotational damping"),
    "Pa": ("pascal", "pressure"),
    "s": ("second", "time"),
    "h": ("hour", "time"),
    "Hz": ("hertz", "frequency"),
    "1/s": ("1/second", "rate"),
    "1/min": ("1/minute", "rate"),
    "RPM": ("revolution/minute", "rotary speed"),
    "rad/s": ("radian/second", "rotary speed"),
    "m/s": ("meter/second", "speed"),
    "m/h": ("meter/hour", "speed"),
    "m³/s": ("meter**3/second", "flow rate"),
    "°/30 m": ("degree/(30*meter)", "dogleg severity"),
    "rev/L": ("revolution/liter", "motor displacement"),
}

#: Units shown to people in each system (terminal summaries, report axes and tables), by
#: quantity: ``(label, pint expression)``. Result files (Parquet, JSON) stay SI.
DISPLAY_UNITS = {
    "si": {"length": ("m", "meter"), "diameter": ("mm", "millimeter"),
           "force": ("kN", "kilonewton"), "torque": ("kN·m", "kilonewton*meter"),
           "side force": ("N/m", "newton/meter"), "density": ("kg/m³", "kilogram/meter**3"),
           "linear mass": ("kg/m", "kilogram/meter"), "pressure": ("bar", "bar"),
           "rotary speed": ("RPM", "revolution/minute"), "flow rate": ("L/min", "liter/minute"),
           "speed": ("m/h", "meter/hour"), "time": ("s", "second"),
           "moment of inertia": ("kg·m²", "kilogram*meter**2"),
           "dogleg severity": ("°/30 m", "degree/(30*meter)")},
    "field": {"length": ("ft", "foot"), "diameter": ("in", "inch"),
              "force": ("klbf", "kilopound_force"),
              "torque": ("kft·lbf", "kilofoot*force_pound"),
              "side force": ("lbf/ft", "force_pound/foot"),
              "density": ("ppg", "pound_per_gallon"), "linear mass": ("lb/ft", "pound/foot"),
              "pressure": ("psi", "psi"), "rotary speed": ("RPM", "revolution/minute"),
              "flow rate": ("gpm", "gallon/minute"), "speed": ("ft/h", "foot/hour"),
              "time": ("s", "second"), "moment of inertia": ("lb·ft²", "pound*foot**2"),
              "dogleg severity": ("°/100 ft", "degree/(100*foot)")},
}
#: The SI unit each displayed quantity is stored in (the value handed to :func:`to_display`).
_STORED = {"length": "meter", "diameter": "meter", "force": "newton", "torque": "newton*meter",
           "side force": "newton/meter", "density": "kilogram/meter**3",
           "linear mass": "kilogram/meter", "pressure": "pascal",
           "rotary speed": "revolution/minute", "flow rate": "meter**3/second",
           "speed": "meter/second", "time": "second",
           "moment of inertia": "kilogram*meter**2", "dogleg severity": "degree/(30*meter)"}
#: Unit systems of :data:`DISPLAY_UNITS` (``--units``, ``[well] units``).
UNIT_SYSTEMS = tuple(DISPLAY_UNITS)

RPM_TO_RAD_S = 2.0 * np.pi / 60.0
"""Revolutions per minute to radians per second [rad/s per RPM]."""


@cache
def registry() -> pint.UnitRegistry:
    """The pint registry (float magnitudes) with drilling units, built on first use."""
    import pint

    reg = pint.UnitRegistry()
    for definition in _DEFINITIONS:
        reg.define(definition)
    return reg


@cache
def _exact_registry() -> pint.UnitRegistry:
    """A pint registry with :class:`~decimal.Decimal` magnitudes (exact decimal factors:
    1 in = 0.0254 m, 1 lb = 0.45359237 kg) for :func:`quantity_value`."""
    import pint

    reg = pint.UnitRegistry(non_int_type=Decimal)
    for definition in _DEFINITIONS:
        reg.define(definition)
    return reg


def __getattr__(name: str):
    """``UREG``: the registry of :func:`registry` (built when first asked for)."""
    if name == "UREG":
        return registry()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _candidates(text: str) -> list[str]:
    """pint expressions a unit spelling may stand for, most likely first."""
    key = text.strip().lower().replace(" ", "")
    expr = _ALIASES.get(key)
    if expr is not None:
        return [expr]
    return [re.sub(r"(?<=[A-Za-z])[.·](?=[A-Za-z])", "*", spelled)
            for spelled in (text.strip(), text.strip().lower())]  # LAS headers are upper case


#: Longest unit spelling handed to pint [characters]: real ones (``deg/(100 ft)``,
#: ``kg.m**2``, ``1/min``) are a few; pint's parser recurses per operator.
MAX_UNIT_CHARS = 40
#: A power whose exponent is not one small number (``m**2``, ``s^-1``, ``m**0.5``): pint
#: computes ``9**9**9`` as an exact integer of 370 million digits (a hang).
_BIG_POWER = re.compile(r"(\*\*|\^)(?!\s*\(?\s*[-+]?\d{1,2}(\.\d{1,3})?\s*\)?\s*(?:$|[^*^\d.eE]))")


def plausible_unit(text: str) -> bool:
    """Whether ``text`` may be handed to pint: at most :data:`MAX_UNIT_CHARS` characters
    and every power a small number (a unit from a file is data; pint evaluates numbers).

    Examples
    --------
    >>> plausible_unit("kg.m**2"), plausible_unit("deg/(100 ft)"), plausible_unit("s^-1")
    (True, True, True)
    >>> plausible_unit("N*m*9**9**9"), plausible_unit("m**99999")
    (False, False)
    """
    return len(text) <= MAX_UNIT_CHARS and not _BIG_POWER.search(text)


def _parse(reg, text: str, *, scaled: bool = False):
    """The units of ``text`` in registry ``reg`` (None when no candidate parses, or the
    spelling is not :func:`plausible_unit`); with ``scaled``, also a scaled unit such as
    ``deg/(100 ft)``, as a quantity."""

    if not plausible_unit(text):
        return None
    for candidate in _candidates(text):
        try:
            return reg.parse_expression(candidate) if scaled else reg.parse_units(candidate)
        except Exception:  # noqa: BLE001 — pint's parser raises a zoo on text it cannot read
            continue  # (UndefinedUnitError, AssertionError on "#1", ZeroDivisionError on
            # "N*m/0", OverflowError, RecursionError, tokenize.TokenError on "('a', 'b'"…)
    return None


@lru_cache(maxsize=256)
def parse_unit(text: str) -> pint.Unit:
    """Parse a unit as written in a log header into a pint unit.

    Parameters
    ----------
    text : str
        Unit spelling, e.g. ``"kN.m"``, ``"ft.lbf"``, ``"klbf"``, ``"RPM"``.

    Returns
    -------
    pint.Unit

    Raises
    ------
    InputError
        If the spelling is not a unit pint or the drilling aliases know.

    Examples
    --------
    >>> str(parse_unit("kN.m"))
    'kilonewton * meter'
    """
    reg = registry()
    unit = _parse(reg, text)
    if unit is None:
        raise InputError(f"unknown unit '{text}'",
                         fix="use a unit such as rpm, kN.m, ft.lbf, klbf, m, ft")
    for name in unit._units:
        size = reg.get_root_units(name)[0] if _angle_name(reg, name) else 0.0
        if size > 2.0 * math.pi * (1.0 + 1e-9):
            raise InputError(f"unit '{text}' reads as {name}s ({size:.4g} rad each: a "
                             "capital letter is an SI prefix, G giga, M mega): no angle is "
                             "logged in those", fix="write 'gon' for gradians (400 per turn), "
                             "'deg' for degrees (the German 'Grad'), 'rad' for radians")
    return unit


def conversion_factor(unit: str, kind: str) -> float:
    """Factor that turns values in ``unit`` into the SI unit of ``kind``.

    Parameters
    ----------
    unit : str
        Source unit spelling.
    kind : str
        One of :data:`SI_UNITS` keys.

    Raises
    ------
    InputError
        If ``unit`` is not a unit of that kind (e.g. ``klbf`` for a torque).

    Examples
    --------
    >>> round(conversion_factor("ft.lbf", "torque"), 6)
    1.355818
    >>> conversion_factor("Hz", "rpm")  # a rotary speed in Hz counts revolutions
    60.0
    """
    import pint

    reg = registry()
    source = parse_unit(unit)
    if kind in ("rpm", "angular_velocity") and not names_angle(source):
        source = source * reg.turn  # a frequency of the rotation: cycles per time
    target = reg.parse_units(SI_UNITS[kind])
    try:
        return float(reg.Quantity(1.0, source).to(target).magnitude)
    except pint.errors.DimensionalityError as exc:
        raise InputError(f"unit '{unit}' is not a {kind.replace('_', ' ')} unit",
                         fix=f"give a {kind.replace('_', ' ')} unit such as "
                             f"{_EXAMPLE[kind]}") from exc


_EXAMPLE = {
    "time": "s", "length": "m or ft", "angle": "deg", "angular_velocity": "rad/s",
    "rpm": "rpm", "torque": "N.m, kN.m or ft.lbf", "force": "N, kN, klbf or kkgf",
    "density": "kg/m3, g/cm3, sg or ppg", "dimensionless": "-",
}


def to_si(values, unit: str, kind: str) -> np.ndarray:
    """Convert an array from ``unit`` to the SI unit of ``kind`` (float64).

    Examples
    --------
    >>> to_si([1.0], "klbf", "force").round(2).tolist()
    [4448.22]
    """
    return np.asarray(values, dtype=float) * conversion_factor(unit, kind)


def from_si(values, unit: str, kind: str) -> np.ndarray:
    """Convert an SI array of ``kind`` back to ``unit`` (inverse of :func:`to_si`)."""
    return np.asarray(values, dtype=float) / conversion_factor(unit, kind)


# --------------------------------------------------------------------------- quantities
#: A number, optionally a whole number and a fraction (``5 1/2``, ``5-1/2``) or a fraction
#: alone (``3/8``), then the unit.
_QUANTITY = re.compile(
    r"^\s*(?:(?P<whole>[+-]?\d+)[\s-]+(?P<num>\d+)\s*/\s*(?P<den>\d+)"
    r"|(?P<fnum>[+-]?\d+)\s*/\s*(?P<fden>\d+)"
    r"|(?P<number>[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?))\s*(?P<unit>.*?)\s*$")
#: Unicode vulgar fractions written by hand (``5½ in``).
_VULGAR = {"½": " 1/2", "¼": " 1/4", "¾": " 3/4", "⅛": " 1/8", "⅜": " 3/8", "⅝": " 5/8",
           "⅞": " 7/8"}
#: Decimal digits of the exact conversion (far beyond float64's 17: correctly rounded).
_DIGITS = 50


def _magnitude(match: re.Match) -> Decimal | None:
    """The number of a :data:`_QUANTITY` match, exactly (``5 1/2`` → 5.5); None for a
    fraction over 0."""
    if match["whole"] is not None:
        if int(match["den"]) == 0:
            return None
        whole, frac = Decimal(match["whole"]), Decimal(match["num"]) / Decimal(match["den"])
        return whole - frac if match["whole"].startswith("-") else whole + frac
    if match["fnum"] is not None:
        return None if int(match["fden"]) == 0 else Decimal(match["fnum"]) / Decimal(
            match["fden"])
    return Decimal(match["number"])


#: A number inside a unit as written: digits (with separators), and what comes before them.
_UNIT_NUMBER = re.compile(r"(?P<before>\S?)\s*(?P<digits>[\d.,][\d.,]*)")


def _number_in_unit(spelled: str) -> bool:
    """Whether the unit part of a quantity holds a number of its own: ``",300 m"`` of
    ``"2,300 m"``, ``"300 m"`` of ``"2 300 m"`` (pint would multiply it in: 600 m; the
    eleventh attack of issue 30). A unit's own digits are allowed: an exponent (``m2``,
    ``m**3``, ``ft^3``), a scale after ``/`` or ``(`` (``deg/100ft``, ``deg/(30 m)``) and
    a leading ``1/`` (``1/s``).

    Examples
    --------
    >>> [_number_in_unit(u) for u in (",300 m", "300 m", "kg.m**2", "deg/(100 ft)", "1/s")]
    [True, True, False, False, False]
    """
    if re.match(r"\s*1\s*/", spelled):
        spelled = spelled[spelled.index("/"):]
    for m in _UNIT_NUMBER.finditer(spelled):
        before, start = m["before"], m.start("digits")
        attached = bool(before) and start == m.end("before") and before.isalpha()
        if not (before in ("/", "(", "*", "^") or attached):
            return True
    return False


def quantity_value(text: str, unit: str, *, what: str = "", file=None,
                   bare: bool = False) -> float:
    """A quantity written by a person, in ``unit``: ``"10.5 ppg"`` → 1258.177… (kg/m³).

    The number may be a decimal, ``5 1/2``, ``5-1/2``, ``5½`` or ``3/8``; the unit any
    spelling of :func:`parse_unit` (``in``, ``ft``, ``ppg``, ``sg``, ``lb/ft``, ``klbf``,
    ``kN.m``, ``ft.lbf``, ``rpm`` …). The conversion is exact (decimal arithmetic with 50
    digits) and the result the float nearest to it, so ``"5 in"`` gives exactly the float
    ``0.127``.

    Parameters
    ----------
    text : str
        The quantity as written.
    unit : str
        Target unit: a label of :data:`LABEL_UNITS` (``"kg/m³"``, ``"m"``, ``"RPM"``) or
        a pint expression.
    what : str
        What the value is, for messages (``"key 'fluid.mud_density_kg_m3'"``); empty when
        the caller names it (a command-line option).
    file : str or Path, optional
        Where the value was written, for messages.
    bare : bool
        Accept a number without a unit as already in ``unit`` (command-line options);
        otherwise a unit is required.

    Raises
    ------
    ConfigError
        Not a number with a unit, an unknown unit, or a unit of another dimension (naming
        what was given and what is expected).

    Examples
    --------
    >>> quantity_value("5 in", "m"), quantity_value("5 1/2 in", "m")
    (0.127, 0.1397)
    >>> round(quantity_value("10.5 ppg", "kg/m³"), 3)
    1258.177
    """
    expr, name = LABEL_UNITS.get(unit, (unit, None))
    text = str(text)
    for char, spelled in _VULGAR.items():
        text = text.replace(char, spelled)
    match = _QUANTITY.match(text)
    example = f'"{_EXAMPLE_VALUE.get(name, "1.0 " + unit)}"'
    given = f"{what} = '{_shown(text.strip())}'" if what else f"'{_shown(text.strip())}'"
    if match is None:
        problem = (f"{what} must be a number or a number with a unit, got "
                   f"'{_shown(text.strip())}'" if what else f"{given} is not a number")
        raise ConfigError(problem, file=file, fix=f"write e.g. {example}")
    if not match["unit"] and _magnitude(match) is not None:
        if bare:
            return float(_magnitude(match))
        raise ConfigError(f"{given} has no unit", file=file,
                          fix=f"write the number without quotes (in {unit}) or with its unit, "
                              f"e.g. {example}")
    magnitude = _magnitude(match)
    if magnitude is None:
        raise ConfigError(f"{given} divides by 0", file=file, fix=f"write e.g. {example}")
    if _number_in_unit(match["unit"]):
        raise ConfigError(f"{given} has a number in its unit part ('{_shown(match['unit'])}'): "
                          "a thousands separator or a decimal comma is not read", file=file,
                          fix=f"write the number with digits and a decimal point only, e.g. "
                              f"{example}")
    expected = f"{name} ({unit})" if name else unit
    try:
        return _convert(magnitude, match["unit"], expr, expected, given, file, example)
    except ConfigError:
        _trailing_word(text[:match.start("unit")].strip(), match["unit"], expr, given, file)
        raise


def _trailing_word(number: str, spelled: str, expr: str, given: str, file) -> None:
    """Raise for a unit followed by words that are no part of it (``"8200 ft MD"``: pint
    read ``ft MD`` as feet × mega-darcies, "of dimension [length] ** 2 * [time] *
    [current]" — issue 30, eleventh attack), naming the word; return when the unit's
    leading words are no unit of the expected kind either."""
    words = spelled.split()
    reg = _exact_registry()
    target = reg.parse_expression(expr)
    for k in range(len(words) - 1, 0, -1):
        head = " ".join(words[:k])
        unit = _parse(reg, head, scaled=True)
        if isinstance(unit, reg.Quantity) and unit.dimensionality == target.dimensionality:
            rest = " ".join(words[k:])
            raise ConfigError(f"{given} has an unknown word '{_shown(rest)}' after its unit "
                              f"'{_shown(head)}' (a depth reference such as MD or TVD, a "
                              "note?)", file=file,
                              fix=f"write the number and the unit only, e.g. "
                                  f"\"{_shown(number)} {_shown(head)}\" (a note goes in a "
                                  "# comment)")


def _convert(magnitude: Decimal, spelled: str, expr: str, expected: str, what: str, file,
             example: str) -> float:
    """``magnitude`` ``spelled`` in the unit ``expr``, exactly, then rounded to a float."""
    import pint

    reg = _exact_registry()
    source = _parse(reg, spelled, scaled=True)
    if not isinstance(source, reg.Quantity):
        raise ConfigError(f"{what} has an unknown unit '{_shown(spelled)}'", file=file,
                          fix=f"use a unit such as in, ft, m, ppg, sg, lb/ft, klbf, kN.m, "
                              f"ft.lbf, rpm; e.g. {example}")
    with localcontext() as ctx:
        ctx.prec = _DIGITS
        target = reg.parse_expression(expr)
        try:
            ratio = (magnitude * source / target).to("dimensionless").magnitude
        except ArithmeticError:  # decimal Overflow/InvalidOperation: "1e999999 ft*1e308"
            raise ConfigError(f"{what} is out of range", file=file,
                              fix=f"give a plain number and unit, e.g. {example}") from None
        except pint.errors.DimensionalityError:
            given = _dimension_name(source)
            raise ConfigError(f"{what} is {given}, not a {expected}", file=file,
                              fix=f"give a {expected.split(' (')[0]}, e.g. {example}") from None
        try:
            return float(Decimal(ratio))
        except (InvalidOperation, TypeError, ValueError):
            return float(ratio)


#: Example values for messages, by quantity.
_EXAMPLE_VALUE = {"length": "8200 ft", "density": "10.5 ppg", "linear mass": "19.5 lb/ft",
                  "force": "40 klbf", "torque": "25 kft.lbf", "pressure": "3000 psi",
                  "rotary speed": "120 rpm", "time": "2 min", "moment of inertia":
                  "2900 kg.m**2", "dogleg severity": "3 deg/(100 ft)",
                  "motor displacement": "0.15 rev/gal"}


#: Further quantities named in messages (a value given in kg where a length is expected).
_OTHER_QUANTITIES = (("kilogram", "mass"), ("meter**2", "area"), ("meter**3", "volume"),
                     ("dimensionless", "pure number"))


def _dimension_name(quantity) -> str:
    """'a length', 'a density' … for a pint quantity (its dimensionality when unnamed)."""
    reg = quantity._REGISTRY
    for expr, name in (*LABEL_UNITS.values(), *_OTHER_QUANTITIES):
        if reg.parse_expression(expr).dimensionality == quantity.dimensionality:
            return f"a {name}"
    return f"of dimension {quantity.dimensionality}"


def _shown(text: str) -> str:
    """Text of a value for a message: printable and short."""
    text = "".join(c if c.isprintable() else "?" for c in str(text))
    return text if len(text) <= 40 else text[:37] + "..."


# --------------------------------------------------------------------------- display
def _system(system: str | None) -> dict:
    table = DISPLAY_UNITS.get(system or "si")
    if table is None:
        raise ConfigError(f"unknown unit system '{system}'",
                          fix=f"use one of: {', '.join(UNIT_SYSTEMS)}")
    return table


def display_unit(quantity: str, system: str | None = "si") -> str:
    """Label of the unit ``quantity`` is shown in, e.g. ``display_unit("force", "field")``
    → ``"klbf"``.

    Parameters
    ----------
    quantity : str
        A key of :data:`DISPLAY_UNITS` tables: ``length``, ``diameter``, ``force``,
        ``torque``, ``side force``, ``density``, ``linear mass``, ``pressure``,
        ``rotary speed``, ``flow rate``, ``speed``, ``time``, ``moment of inertia``,
        ``dogleg severity``.
    system : str
        ``"si"`` (default) or ``"field"``.

    Examples
    --------
    >>> display_unit("torque", "field"), display_unit("torque")
    ('kft·lbf', 'kN·m')
    """
    return _system(system)[quantity][0]


@lru_cache(maxsize=64)
def display_factor(quantity: str, system: str | None = "si") -> float:
    """Factor from the stored SI unit of ``quantity`` to its display unit.

    Examples
    --------
    >>> round(display_factor("length", "field"), 6)
    3.28084
    """
    reg = registry()  # expressions, not units: "degree/(30*meter)" has a scale
    ratio = reg.parse_expression(_STORED[quantity]) / reg.parse_expression(
        _system(system)[quantity][1])
    return float(ratio.to("dimensionless").magnitude)


def to_display(values, quantity: str, system: str | None = "si"):
    """SI values of ``quantity`` in the display unit of ``system`` (scalar or array).

    Examples
    --------
    >>> round(to_display(1000.0, "length", "field"), 1)
    3280.8
    """
    scaled = np.asarray(values, dtype=float) * display_factor(quantity, system)
    return float(scaled) if scaled.ndim == 0 else scaled


#: Largest magnitude written without an exponent (a 1e308 from a broken log must not print
#: as a 309-digit number; no physical quantity drillfric shows comes near it).
PLAIN_LIMIT = 1e9
#: Most decimals a number without a stated resolution is written with.
MAX_DECIMALS = 6


def number(value, resolution: float | None = None, digits: int = 4) -> str:
    """A physical value as people read it: ``digits`` significant digits (trailing zeros
    dropped), never finer than ``resolution`` (the quantity's resolution in the unit
    shown, e.g. 0.1 for RPM), a value below half the resolution as ``0`` (a numerical zero
    such as 1.173e-34 RPM is 0), and no exponent below :data:`PLAIN_LIMIT` (issue 35: an
    inspect median printed as "1.173e-34"); "—" for None or NaN.

    Examples
    --------
    >>> number(24999.4), number(254.93), number(None), number(3e12)
    ('24999', '254.9', '—', '3e+12')
    >>> number(1.173e-34, 0.1), number(-0.04, 0.1), number(0.2312, 0.1), number(0.0035)
    ('0', '0', '0.2', '0.0035')
    >>> number(1e-34), number(float("inf"))
    ('0', 'inf')
    """
    if value is None:
        return "—"
    value = float(value)
    if value != value:
        return "—"
    if abs(value) == float("inf"):
        return "inf" if value > 0 else "-inf"
    if abs(value) >= PLAIN_LIMIT:
        return f"{value:.{digits}g}"
    step = MAX_DECIMALS if not resolution or resolution <= 0 else max(
        0, -math.floor(math.log10(resolution) + 1e-9))
    if resolution and resolution > 0 and abs(value) < resolution / 2:
        return "0"
    magnitude = math.floor(math.log10(abs(value))) if value else 0
    decimals = max(0, min(digits - 1 - magnitude, step, MAX_DECIMALS))
    text = f"{value:.{decimals}f}"
    if "." in text:  # as .4g writes it: 254.9, not 254.90
        text = text.rstrip("0").rstrip(".")
    return "0" if float(text) == 0 else text


#: Resolution of each display quantity in its stored SI unit (:data:`_STORED`): what a rig
#: sensor resolves at best — finer digits are noise, and a value below half of it is zero
#: (issue 35: a bit speed of 1.173e-34 RPM). :func:`display_resolution` gives it in the unit
#: shown.
RESOLUTION_SI = {"length": 1e-3, "diameter": 1e-4, "force": 10.0, "torque": 0.1,
                 "side force": 0.1, "density": 0.1, "linear mass": 0.01, "pressure": 100.0,
                 "rotary speed": 0.1, "flow rate": 1e-6, "speed": 1e-5, "time": 1e-3,
                 "moment of inertia": 0.1, "dogleg severity": 0.01}


def display_resolution(quantity: str, system: str | None = "si") -> float:
    """:data:`RESOLUTION_SI` of ``quantity`` in its display unit, down to a power of ten.

    Examples
    --------
    >>> display_resolution("rotary speed"), display_resolution("force", "field")
    (0.1, 0.001)
    """
    shown = RESOLUTION_SI[quantity] * display_factor(quantity, system)
    return float(10.0 ** math.floor(math.log10(shown) + 1e-9))


def format_number(value, quantity: str, system: str | None = "si") -> str:
    """An SI value of ``quantity`` as a number in its display unit, at its resolution
    (:func:`number`: a numerical zero is 0, no exponent), e.g. in
    inspect's channel table.

    Examples
    --------
    >>> format_number(1.173e-34, "rotary speed"), format_number(254900.0, "force")
    ('0', '254.9')
    """
    if value is None:
        return "—"
    return number(to_display(value, quantity, system), display_resolution(quantity, system))


def format_value(value, quantity: str, system: str | None = "si", spec: str = ".1f") -> str:
    """An SI value as text in the display unit, e.g. ``"8202.1 ft"`` (``"—"`` for None/NaN).

    Examples
    --------
    >>> format_value(2500.0, "length", "field", ".0f"), format_value(None, "force")
    ('8202 ft', '—')
    """
    if value is None or not np.isfinite(value):
        return "—"
    return f"{format(to_display(value, quantity, system), spec)} {display_unit(quantity, system)}"


#: SI quantities written in run messages (summary.json is SI): unit as written, the
#: quantity it is, and the factor to that quantity's stored unit — longest units first.
_MESSAGE_UNITS = (("kN·m", "torque", 1e3), ("N·m", "torque", 1.0), ("kg/m³", "density", 1.0),
                  ("m/s", "length", 1.0), ("m/h", "length", 1.0), ("MN", "force", 1e6),
                  ("kN", "force", 1e3), ("N", "force", 1.0), ("m", "length", 1.0))
_MESSAGE_NUMBER = r"[-−+]?\d+(?:\.\d+)?"
_MESSAGE_QUANTITY = re.compile(
    rf"(?<![\w.])({_MESSAGE_NUMBER})(?:\s?([–-]|to)\s?({_MESSAGE_NUMBER}))?\s?"
    rf"({'|'.join(re.escape(u) for u, _, _ in _MESSAGE_UNITS)})(?![\w/·³²])")


def message_text(text: str, system: str | None = "si", *, inline: bool = True) -> str:
    """A message drillfric wrote in SI (a segment's reason, what was assumed, a warning)
    with its quantities — m, m/s, m/h, N, kN, MN, N·m, kN·m, kg/m³ — in the display units
    of ``system``: ``inline`` in place of the SI ones ("WOB ≤ 2.25 klbf", as inspect's
    lines read in field units), else after them in brackets ("WOB ≤ 10 kN [2.25 klbf]", the
    report, which keeps summary.json's SI words). Unchanged in ``"si"``.

    Examples
    --------
    >>> message_text("rows that log WOB ≤ 10 kN, +0.05 to +0.15 m/s", "field")
    'rows that log WOB ≤ 2.25 klbf, +0.164 to +0.492 ft/s'
    >>> message_text("a 2804–2835 m window", "field", inline=False)
    'a 2804–2835 m [9199–9301 ft] window'
    """
    if (system or "si") == "si" or not text:
        return text
    per = {u: (q, f) for u, q, f in _MESSAGE_UNITS}

    def shown(written: str, factor: float, quantity: str) -> str:
        value = float(written.replace("−", "-")) * factor * display_factor(quantity, system)
        text = number(value, display_resolution(quantity, system), digits=3)
        return ("+" + text) if written.startswith("+") and not text.startswith("-") else text

    def convert(match: re.Match) -> str:
        first, dash, second, unit = match.groups()
        quantity, factor = per[unit]
        label = display_unit(quantity, system)
        if unit in ("m/s", "m/h"):
            label += unit[1:]
        value = shown(first, factor, quantity)
        if second is not None:
            gap = " " if dash == "to" else ""
            value += gap + dash + gap + shown(second, factor, quantity)
        return f"{value} {label}" if inline else f"{match.group(0)} [{value} {label}]"

    return _MESSAGE_QUANTITY.sub(convert, text)


#: Quantities drillfric's own notes (what was assumed) write in SI, by their spelling after
#: the number ("1200 kg/m³", "1.0°/30 m"), for :func:`display_text`.
_NOTE_UNITS = {"°/30 m": "dogleg severity", " kg/m³": "density",
               " kg·m²": "moment of inertia", " m": "length"}
_NOTE_QUANTITY = re.compile(r"(\d+(?:\.\d+)?)(" + "|".join(_NOTE_UNITS)
                            + r")(?![\w/·³²])")


def display_text(text: str, system: str | None = "si") -> str:
    """A note of drillfric's own (what was assumed) with its SI quantities — lengths
    ``m``, densities ``kg/m³``, inertias ``kg·m²``, doglegs ``°/30 m`` — in the display
    units of ``system``; unchanged in ``"si"``, whose display units these are.

    Examples
    --------
    >>> display_text("mud density 1200 kg/m³, 110 m of HWDP, 1.0°/30 m", "field")
    'mud density 10.0 ppg, 361 ft of HWDP, 1.02°/100 ft'
    >>> display_text("top-drive inertia 2900 kg·m²", "si")
    'top-drive inertia 2900 kg·m²'
    """
    def shown(match: re.Match) -> str:
        spelled = match.group(2)
        quantity = _NOTE_UNITS[spelled]
        label = display_unit(quantity, system)
        if label == spelled.strip():
            return match.group(0)
        value = float(match.group(1)) * display_factor(quantity, system)
        number = f"{value:.0f}" if abs(value) >= 100 else f"{value:#.3g}"
        return f"{number}{spelled[:len(spelled) - len(spelled.lstrip())]}{label}"

    return _NOTE_QUANTITY.sub(shown, text)
