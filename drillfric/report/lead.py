"""What a segment's section leads with: what was found, and what was withheld and why.

An engineer opening a segment wants its result and its caveats before the estimator's
detail (issue 35 item 11: the demo's first stand opened on 14 notes). The lead is built
from the segment's record alone — the numbers of summary.json and the notes of its
``message`` that withhold something — so it cannot say other than the result files do;
the full notes follow (folded in the HTML, after the panels in the PDF).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from drillfric.io.text import split_notes
from drillfric.vocabulary import Status

from .display import fmt
from .render import (
    bit_speed_text,
    bit_speed_unresolved,
    is_apparent,
    mu_name,
    mu_s_text,
    severity_text,
    status_text,
)

#: A note that says something was withheld, not reported or did not converge.
_WITHHOLDING = re.compile(r"\bwithheld\b|\bnot reported\b|: not converged\b")
#: The bookkeeping note of a withheld segment ("3 notes stating … left out"): not a reason.
_LEFT_OUT = "stating the withheld friction factors left out"


@dataclass(frozen=True)
class Lead:
    """A segment's lead: ``found`` (one sentence of its numbers) and ``withheld`` (each
    thing withheld with the start of its reason, as its note in summary.json begins)."""

    found: str
    withheld: tuple[str, ...]

    def lines(self) -> list[str]:
        """The lead as text lines: "Found: …" and, when anything was withheld,
        "Withheld: … · …"."""
        lines = [f"Found: {self.found}"]
        if self.withheld:
            lines.append("Withheld: " + " · ".join(self.withheld))
        return lines


def segment_lead(row: dict) -> Lead:
    """The lead of an estimated segment (a summary.json ``segments`` record or a row of
    segments.parquet).

    Examples
    --------
    >>> lead = segment_lead({"status": "ok", "kind": "off_bottom_rotating", "mu_k": 0.2785,
    ...     "converged": True, "method": "batch", "mu_s": None, "mu_s_identifiable": False,
    ...     "mu_s_lower_bound": 0.3026, "message": "fit note; the creep fit's μ_s is not "
    ...     "reported: the halves cannot be compared: noise ±15 % > 6 %"})
    >>> print("\\n".join(lead.lines()))
    Found: μ_k 0.279, converged (batch fit); μ_s ≥ 0.303 (a lower bound)
    Withheld: the creep fit's μ_s is not reported: the halves cannot be compared …
    """
    withheld = [short_reason(note) for note in withheld_notes(row)]
    if bit_speed_unresolved(row) and row.get("status") == Status.OK:
        withheld.append(short_reason(f"bit speed {bit_speed_text(row)}"))
    return Lead(_found(row), tuple(withheld))


def withheld_notes(row: dict) -> list[str]:
    """The notes of the segment's ``message`` that say what was withheld, not reported or
    not converged, and why — in full, in the message's order."""
    return [note for note in split_notes(str(row.get("message") or ""))
            if _WITHHOLDING.search(note) and _LEFT_OUT not in note]


def short_reason(note: str) -> str:
    """A note cut after the first clause of its reason: what it says, its first ``": "``,
    then the reason up to its next ``": "``, ``", "`` or ``"; "`` outside brackets, with "…"
    when cut (the whole note is in the segment's detail).

    >>> short_reason("friction factors withheld: the hook load contradicts the string: "
    ...              "it weighs 0.21× the model")
    'friction factors withheld: the hook load contradicts the string …'
    >>> short_reason("severe stick-slip: severity withheld, the estimate is 2.1 or more")
    'severe stick-slip: severity withheld …'
    >>> short_reason("only 63 s of rotation (< 90 s): not converged")
    'only 63 s of rotation (< 90 s): not converged'
    """
    depth, subject = 0, False
    for i, char in enumerate(note):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if depth or not note.startswith((": ", ", ", "; "), i):
            continue
        if subject:
            return note[:i] + " …"
        subject = note.startswith(": ", i)
    return note


def _found(row: dict) -> str:
    """The segment's numbers in one sentence: μ_k (or apparent μ) and its status, μ_s,
    the stick-slip severity."""
    mu_k = fmt(row.get("mu_k"))
    if mu_k == "—":
        parts = [f"no {mu_name(row)}"]
    else:
        status = status_text(row).removeprefix("ok, ").removeprefix("μ_k ")
        apparent = " (bit torque in it)" if is_apparent(row) else ""
        parts = [f"{mu_name(row)} {mu_k}{apparent}, {status}"]
    mu_s = mu_s_text(row.get("mu_s"), bool(row.get("mu_s_identifiable")),
                     row.get("mu_s_lower_bound"))
    parts.append(f"μ_s {mu_s}" + {"≥": " (a lower bound)", "n": ""}.get(mu_s[0], " (identified)"))
    severity = severity_text(row)
    if severity == "severe":
        parts.append("severe stick-slip")
    elif severity != "—":
        parts.append(f"stick-slip severity {severity}")
    return "; ".join(parts)
