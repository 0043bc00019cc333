"""The units a report shows: SI results in the unit system the reader asked for, and how a
value is written (:func:`fmt`).

Result files stay SI (docs/outputs.md); the report shows lengths, forces, torques,
pressures and flows in the ``"si"`` or ``"field"`` system of
:data:`drillfric.units.DISPLAY_UNITS` — ``drillfric report --units`` (or ``run --units``),
else the run's ``[well] units``, else SI (:func:`report_units`). Axes, tables, hover texts
and the notes of the HTML and the PDF all go through one :class:`Units`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from drillfric.units import UNIT_SYSTEMS, display_factor, display_unit, message_text

#: Display units of quantities the terminal never shows (so not in DISPLAY_UNITS):
#: ``(label, pint expression of the display unit, pint expression of the stored SI unit)``.
_EXTRA = {
    "torque per length": {"si": ("N·m/m", "newton", "newton"),
                          "field": ("ft·lbf/ft", "force_pound", "newton")},
}


def row_flags(row: dict) -> list[str]:
    """A segment's ``quality_flags`` as strings, whether a list, a tuple or an array (from
    parquet), and none where missing or null."""
    flags = row.get("quality_flags")
    if flags is None or isinstance(flags, float | str):
        return []
    return [str(f) for f in flags]


def fmt(value, spec: str = ".3f") -> str:
    """``value`` formatted with ``spec``, or "—" for None / NaN / non-numbers."""
    if value is None or isinstance(value, bool):
        return "—" if value is None else ("yes" if value else "no")
    try:
        number = float(value)
    except (TypeError, ValueError):
        return "—"
    return "—" if not math.isfinite(number) else format(number, spec)


@dataclass(frozen=True)
class Units:
    """Display units of one report (``system``: ``"si"`` or ``"field"``)."""

    system: str = "si"

    def label(self, quantity: str) -> str:
        """Unit label of ``quantity`` (e.g. ``"ft"`` for ``"length"`` in field units)."""
        if quantity in _EXTRA:
            return _EXTRA[quantity][self.system][0]
        return display_unit(quantity, self.system)

    def factor(self, quantity: str) -> float:
        """Factor from the SI value of ``quantity`` to its display value."""
        if quantity in _EXTRA:
            from drillfric.units import registry

            _, shown, stored = _EXTRA[quantity][self.system]
            return float(registry().Quantity(1.0, stored).to(shown).magnitude)
        return display_factor(quantity, self.system)

    def axis(self, name: str, quantity: str) -> str:
        """An axis or column heading: ``"bit depth [ft]"``."""
        return f"{name} [{self.label(quantity)}]"

    def value(self, value, quantity: str):
        """An SI value in the display unit (None for a missing or non-numeric value)."""
        try:
            number = float(value)
        except (TypeError, ValueError):
            return None
        return number * self.factor(quantity)

    def text(self, value, quantity: str, spec: str = ".0f") -> str:
        """An SI value as display text without its unit ("—" when missing)."""
        return fmt(self.value(value, quantity), spec)

    def pair(self, a, b, quantity: str, spec: str = ".0f") -> str:
        """``"a / b"`` in display units; "—" when both are missing."""
        left, right = self.text(a, quantity, spec), self.text(b, quantity, spec)
        return "—" if left == right == "—" else f"{left} / {right}"


def message_in(text: str, units: Units) -> str:
    """A run message (written in SI) for a report in ``units``: in field units each SI
    quantity keeps its value and gets the field one after it in brackets — "2804–2835 m
    [9199–9301 ft]", "WOB ≤ 10 kN [2.2 klbf]" (issue 35: an F-5 report in ft and klbf
    printed its messages in m and kN alone). SI reports: the text unchanged
    (:func:`drillfric.units.message_text`).

    >>> message_in("a 2804–2835 m window, WOB ≤ 10 kN", Units("field"))
    'a 2804–2835 m [9199–9301 ft] window, WOB ≤ 10 kN [2.25 klbf]'
    """
    return message_text(text, units.system, inline=False)


#: The default: SI display units (m, kN, kN·m, bar, L/min).
SI = Units("si")


def report_units(summary: dict, option: str | None = None) -> Units:
    """The units of a report: ``option`` (``--units``), else the run's ``[well] units``
    recorded in summary.json, else SI.

    Raises
    ------
    ConfigError
        ``option`` names no unit system.
    """
    from drillfric.errors import ConfigError

    if option is None:
        well = ((summary.get("config") or {}).get("well") or {})
        option = well.get("units") if well.get("units") in UNIT_SYSTEMS else "si"
    if option not in UNIT_SYSTEMS:
        raise ConfigError(f"unknown unit system '{option}'",
                          fix=f"use one of: {', '.join(UNIT_SYSTEMS)}")
    return Units(str(option))
