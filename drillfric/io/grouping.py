"""Numbers whose thousands are grouped by a space or an apostrophe, as French, Swiss and
Excel-FR exports write them (``2 210,00``, ``2\u00a0210,00``, ``2\u202f210,00``,
``2'210.00``).

Such a value is read as its number when the grouping character stands between groups of
exactly three digits, the first of one to three digits; the decimal mark after the groups is
the one written (with a space or an apostrophe grouping, a comma or a dot can only be the
decimal mark). Digits split by one of these characters otherwise (``2 21,00``, ``12 5``) are
no number drillfric can tell: :func:`misgrouped` finds them, and the reader refuses the
column naming the value (they had been read as missing, in silence: issue 30, twelfth
attack F2).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

#: Characters that group thousands in the locales of a decimal comma or of a Swiss dot:
#: space, no-break space (U+00A0), narrow no-break space (U+202F), apostrophe and the right
#: single quotation mark Excel writes for it (U+2019).
GROUP_CHARS = " \u00a0\u202f'\u2019"
_G = "[ \u00a0\u202f'\u2019]"
GROUPED = re.compile(rf"[-+]?\d{{1,3}}(?P<g>{_G})\d{{3}}(?:(?P=g)\d{{3}})*(?:[.,]\d+)?")
_SPLIT_DIGITS = re.compile(rf"\d{_G}+\d")
_NAMES = {" ": "a space", "\u00a0": "a no-break space (U+00A0)",
          "\u202f": "a narrow no-break space (U+202F)", "'": "an apostrophe",
          "\u2019": "a right single quotation mark (U+2019)"}


def ungroup(text: str) -> str:
    """``text`` without its grouping characters when it is a number grouped by
    :data:`GROUP_CHARS` (its decimal mark kept), else as is.

    Examples
    --------
    >>> ungroup("2 210,00"), ungroup("2'210.5"), ungroup("-1\u202f234\u202f567"), ungroup("2 21,0")
    ('2210,00', '2210.5', '-1234567', '2 21,0')
    """
    if not GROUPED.fullmatch(text):
        return text
    return re.sub(_G, "", text)


def grouped_numbers(text: pd.Series) -> tuple[np.ndarray, np.ndarray]:
    """The numbers of the cells of ``text`` (stripped strings) grouped by :data:`GROUP_CHARS`,
    and where they are (a boolean mask; NaN elsewhere)."""
    mask = text.str.fullmatch(GROUPED).fillna(False).to_numpy(dtype=bool)
    out = np.full(len(text), np.nan)
    if mask.any():
        plain = text[mask].str.replace(_G, "", regex=True).str.replace(",", ".", regex=False)
        out[mask] = pd.to_numeric(plain, errors="coerce").to_numpy(dtype=float,
                                                                   na_value=np.nan)
    return out, mask


def misgrouped(text: pd.Series, read: np.ndarray) -> str | None:
    """The first cell of ``text`` not read as a number (``read`` NaN) whose digits are split
    by a grouping character, or None."""
    unread = np.isnan(read)
    if not unread.any():
        return None
    split = text.str.contains(_SPLIT_DIGITS).fillna(False).to_numpy(dtype=bool) & unread
    return str(text.iloc[int(np.argmax(split))]) if split.any() else None


def grouping_name(value: str) -> str:
    """The grouping character of ``value`` in words (``"a space"``)."""
    found = re.search(rf"\d({_G})\d", value)
    return _NAMES[found[1]] if found else "a space"


_DECIMAL_COMMA = r"^-?(?:\d{1,3}(?:\.\d{3})+|\d+),\d+$"  # 17.730,5 or 1234,5
#: Thousands commas where a cell shows them unambiguously: with a decimal point (16,111.8)
#: or two groups or more (1,234,567); a lone 16,950 stays a decimal comma (16.95).
_THOUSANDS_SURE = r"^-?\d{1,3}(?:(?:,\d{3})+\.\d+|(?:,\d{3}){2,}(?:\.\d+)?)$"


def text_numbers(text: pd.Series) -> np.ndarray:
    """Numbers from text; a column read as text because of one bad token may still use a
    decimal comma (and thousands dots), which are read as such (only the bad cell is NaN),
    or thousands commas where a cell shows them unambiguously (a quoted "16,111.8" in a
    comma-separated file was read as null: every segment skipped, exit 0).

    Examples
    --------
    >>> text_numbers(pd.Series(["1,5", "17.730,25", "***", "2.5"], dtype="string")).tolist()
    [1.5, 17730.25, nan, 2.5]
    >>> text_numbers(pd.Series(["16,111.8", "1,234,567", "-200"], dtype="string")).tolist()
    [16111.8, 1234567.0, -200.0]

    Thousands grouped by a space, a no-break space or an apostrophe (``2 210,00``,
    ``2'210.00``) are read too (:func:`grouped_numbers`; they had been read as missing
    in silence: issue 30, twelfth attack F2):

    >>> text_numbers(pd.Series(["2 210,00", "2\u00a0210,5", "2'210.25"], dtype="string")).tolist()
    [2210.0, 2210.5, 2210.25]
    """
    out = pd.to_numeric(text, errors="coerce").to_numpy(dtype=float, na_value=np.nan)
    spaced, where = grouped_numbers(text)
    out[where] = spaced[where]
    grouped = text.str.fullmatch(_THOUSANDS_SURE).fillna(False).to_numpy(dtype=bool)
    if grouped.any():  # cell by cell: the same in any chunking
        out[grouped] = pd.to_numeric(text[grouped].str.replace(",", "", regex=False),
                                     errors="coerce").to_numpy(dtype=float, na_value=np.nan)
    comma = text.str.fullmatch(_DECIMAL_COMMA).fillna(False).to_numpy(dtype=bool) & ~grouped
    if comma.any():
        fixed = text[comma].str.replace(".", "", regex=False).str.replace(",", ".", regex=False)
        out[comma] = pd.to_numeric(fixed, errors="coerce").to_numpy(dtype=float,
                                                                    na_value=np.nan)
    return out
