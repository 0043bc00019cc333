"""Unit conversion at the edges, with pint, including drilling spellings.

Everything inside drillfric is SI (m, s, rad, N, N·m, kg); rig logs arrive in kN·m,
ft·lbf, klbf, kkgf, ppg, RPM and friends. :func:`to_si` converts an array given a unit
string as written in a file header; :func:`parse_unit` normalises drilling spellings
(``kN.m``, ``kNm``, ``ft.lbf``, ``klbf``, ``kkgf``, ``g/cm3``, ``sg``, ``ppg``, ``rpm``,
``c/s``, ``deg``) before pint parses them.
"""

from __future__ import annotations

import re
from functools import lru_cache

import numpy as np
import pint

from drillfric.errors import InputError

UREG = pint.UnitRegistry()
UREG.define("kilopound_force = 1000 * force_pound = klbf")
UREG.define("kilokilogram_force = 1000 * kilogram_force = kkgf")
UREG.define("specific_gravity = 1000 * kilogram / meter ** 3 = sg")
UREG.define("pound_per_gallon = pound / gallon = ppg")

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
    "n.m": "newton*meter",
    "nm": "newton*meter",
    "n-m": "newton*meter",
    "ft.lbf": "foot*force_pound",
    "ft-lbf": "foot*force_pound",
    "ftlbf": "foot*force_pound",
    "ft.lb": "foot*force_pound",
    "ft-lb": "foot*force_pound",
    "lbf.ft": "foot*force_pound",
    "kft.lbf": "kilofoot*force_pound",
    "kft-lbf": "kilofoot*force_pound",
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
    "sg": "specific_gravity",
    "ppg": "pound_per_gallon",
    "lbm/gal": "pound_per_gallon",
    "ft": "foot",
    "f": "foot",  # LAS depth unit
    "feet": "foot",
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
    "%": "percent",
    # WITSML 1.x unit spellings (uom attributes, unitList)
    "lbm": "pound",
    "lbm/ft": "pound/foot",
    "ftus": "survey_foot",
    "hz": "hertz",
}

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
    key = text.strip().lower().replace(" ", "")
    expr = _ALIASES.get(key)
    candidates = [expr] if expr is not None else [
        re.sub(r"(?<=[A-Za-z])\.(?=[A-Za-z])", "*", spelled)
        for spelled in (text.strip(), text.strip().lower())]  # LAS headers are upper case
    for candidate in candidates:
        try:
            return UREG.parse_units(candidate)
        except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError,
                AttributeError, TypeError, ValueError, AssertionError):  # pint on "#1"
            continue
    raise InputError(f"unknown unit '{text}'",
                     fix="use a unit such as rpm, kN.m, ft.lbf, klbf, m, ft")


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
    """
    source = parse_unit(unit)
    target = UREG.parse_units(SI_UNITS[kind])
    try:
        return float(UREG.Quantity(1.0, source).to(target).magnitude)
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


RPM_TO_RAD_S = 2.0 * np.pi / 60.0
"""Revolutions per minute to radians per second [rad/s per RPM]."""
