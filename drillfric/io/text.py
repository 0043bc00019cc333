"""Text from untrusted files made safe to show: no terminal escapes, no raw bytes, bounded.

Messages may name what a file holds (a column name, a unit) only through :func:`printable`,
so a crafted header cannot move the cursor, recolour or clear a terminal, or flood a log
(docs/security.md).
"""

from __future__ import annotations

import unicodedata

#: Longest piece of file text quoted in a message [characters].
QUOTE_LIMIT = 40
#: Longest line drillfric prints [characters] (an error or warning line).
LINE_LIMIT = 4000


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


def one_line(text, limit: int = LINE_LIMIT) -> str:
    """``text`` as one printable line: line breaks and tabs become spaces, every other
    control or format character ``?`` (:func:`printable`), cut to ``limit``.

    The last filter of every error and warning line drillfric prints (the CLI applies it),
    whatever the text carries from a file, a configuration or a library.

    Examples
    --------
    >>> one_line("bad\\ncolumn\\x1b[2J\\x07")
    'bad column?[2J?'
    """
    return printable(str(text).replace("\r\n", " ").translate(_BLANKS), limit)


def terminal_text(text) -> str:
    """``text`` with its lines kept and everything else that could drive a terminal (ESC,
    BEL, CR, DEL, …) replaced as :func:`one_line` does; for multi-line output (tables).

    Examples
    --------
    >>> terminal_text("a\\x1b[31m\\nb\\r")
    'a?[31m\\nb '
    """
    return "\n".join(one_line(line) for line in str(text).split("\n"))


_BLANKS = str.maketrans({"\n": " ", "\r": " ", "\t": " "})


def plural(n, noun: str, many: str | None = None, spec: str = "") -> str:
    """``n`` (formatted with ``spec``) and ``noun`` in the number ``n`` asks for:
    ``"1 segment"``, ``"2 segments"`` (``many``: the plural of a noun that does not take an
    ``s``); every count shown to people goes through it.

    Examples
    --------
    >>> plural(1, "segment"), plural(0, "warning"), plural(2, "box", "boxes")
    ('1 segment', '0 warnings', '2 boxes')
    >>> plural(20801, "row", spec=",")
    '20,801 rows'
    """
    return f"{n:{spec}} {noun if n == 1 else many or noun + 's'}"


def share(part: int, whole: int, noun: str, many: str | None = None) -> str:
    """``part`` of ``whole`` counted as one says it: ``"the only segment"``, ``"all 4
    segments"``, ``"2 of 9 segments"`` — never "1 of 1 segments" (:func:`plural` for the
    noun).

    Examples
    --------
    >>> share(1, 1, "off-bottom segment"), share(4, 4, "segment"), share(1, 3, "segment")
    ('the only off-bottom segment', 'all 4 segments', '1 of 3 segments')
    >>> share(0, 1, "segment")
    '0 of 1 segment'
    """
    if part == whole == 1:
        return f"the only {noun}"
    if part == whole > 1:
        return f"all {plural(whole, noun, many)}"
    return f"{part} of {plural(whole, noun, many)}"


def split_notes(message: str) -> list[str]:
    """A segment's message as its notes: split at "; " outside brackets (the notes of the
    estimation steps are joined with "; ", and a note may hold one in brackets).

    Examples
    --------
    >>> split_notes("fit note; μ_k = 0.279 ± 0.014 (95 %: 5 %; statistical ± 0.002)")
    ['fit note', 'μ_k = 0.279 ± 0.014 (95 %: 5 %; statistical ± 0.002)']
    """
    parts, depth, start = [], 0, 0
    for i, char in enumerate(message):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if depth == 0 and message.startswith("; ", i):
            parts.append(message[start:i])
            start = i + 2
    parts.append(message[start:])
    return [p.strip() for p in parts if p.strip()]


def listing(names, *, recognised: bool, limit: int = 12) -> str:
    """Column names for a message, or a word saying why they are not shown.

    A file's column names are quoted only when the file is recognisably the expected kind
    (``recognised``: at least one of its columns was understood): an unrelated file named by
    mistake — a secrets file as a survey — must not have its first line printed, logged by a
    nightly job or copied into a fleet manifest. Names are sanitised (:func:`printable`) and
    at most ``limit`` are shown.

    Examples
    --------
    >>> listing(["MD", "INC", "X\\x1b"], recognised=True)
    'MD, INC, X?'
    >>> listing(["API_KEY=secret"], recognised=False)
    'none recognisable (not shown)'
    """
    names = [str(n) for n in names]
    if not names:
        return "none"
    if not recognised:
        return "none recognisable (not shown)"
    shown = ", ".join(printable(n) for n in names[:limit])
    return shown + (f", … ({len(names)} in all)" if len(names) > limit else "")
