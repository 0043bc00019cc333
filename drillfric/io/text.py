"""Text from untrusted files made safe to show: no terminal escapes, no raw bytes, bounded.

Messages may name what a file holds (a column name, a unit) only through :func:`printable`,
so a crafted header cannot move the cursor, recolour or clear a terminal, or flood a log
(docs/security.md).
"""

from __future__ import annotations

import unicodedata

#: Longest piece of file text quoted in a message [characters].
QUOTE_LIMIT = 40


def printable(text, limit: int = QUOTE_LIMIT) -> str:
    """``text`` with control and format characters replaced by ``?``, cut to ``limit``.

    Examples
    --------
    >>> printable("TORQUE\\x1b[2J")
    'TORQUE?[2J'
    >>> printable("x" * 50, 10)
    'xxxxxxxxx…'
    """
    text = str(text)
    clean = "".join("?" if unicodedata.category(c) in ("Cc", "Cf", "Cs", "Co", "Cn")
                    else c for c in text)
    return clean if len(clean) <= limit else clean[:limit - 1] + "…"
