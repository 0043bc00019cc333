"""How far a well's headline numbers can be trusted, said in summary.json: the confidence of
the well μ_k, the well-level ``quality_flags`` and a warning line for each (docs/outputs.md
"Headline"), so that a nightly job can catch from summary.json alone what the report warns
about.

The numbers themselves (value, uncertainty, support) are the consensus's
(:func:`drillfric.estimation.consensus.consensus`); this module judges them and never
changes them.
"""

from __future__ import annotations

from drillfric.estimation.verdict import TYPICAL_MU
from drillfric.io.text import plural, share
from drillfric.result import Flag, WellFlag
from drillfric.vocabulary import Kind, Status

#: A well μ_k resting on fewer segments than this is low-confidence: two segments cannot
#: show which of them is the odd one out.
MIN_SUPPORT = 3
#: A well μ_k whose uncertainty exceeds this share of it is low-confidence [-] (the
#: segments disagree by more than the estimator's accuracy on synthetic truths, ±5–10 %:
#: docs/validation.md).
MAX_RELATIVE_UNCERTAINTY = 0.25
#: Relative tolerance of the string-weight check on the hook load: dead-line hook-load
#: sensors are specified to about ±2–3 % of reading and the mud density (buoyancy) is rarely
#: known better than ±2 %; 5 % keeps a consistent string from being flagged by those alone.
STRING_WEIGHT_TOLERANCE = 0.05
#: How the warning of assumed defaults begins (the command line lists them one by one).
INDICATIVE_WARNING = "indicative:"
#: How the string-weight warning begins (the report replaces it by its own, in display units).
STRING_WEIGHT_WARNING = "string weight inconsistent with the hook load"
#: The flags that make a well μ_k low-confidence (the others are told, not judged).
LOWERING = (WellFlag.LOW_SUPPORT, WellFlag.WIDE_SPREAD, WellFlag.INDICATIVE,
             WellFlag.SEGMENTS_OUTSIDE_TYPICAL_RANGE, WellFlag.STRING_WEIGHT_INCONSISTENT,
             WellFlag.HOOKLOAD_CONTRADICTS_STRING, WellFlag.STRING_WEIGHT_UNVERIFIED,
             WellFlag.STRING_WEIGHT_NOT_CHECKED)


def judge(summary: dict) -> dict:
    """``mu_k_confidence``, ``mu_k_reason``, ``quality_flags`` and the warnings they add, from
    a well's summary.json (its ``segments``, ``counts``, ``assumed``, ``hookload`` and the
    consensus fields).

    ``mu_k_confidence`` is ``"supported"`` (a well μ_k and nothing against it), ``"low"`` (a
    well μ_k with the ``quality_flags`` of :data:`LOWERING` against it: read it with its
    uncertainty and the reasons), ``"withheld"`` (segments were estimated, none gives a well
    μ_k: ``mu_k_reason`` says why) or ``"none"`` (nothing was estimated).

    Returns
    -------
    dict
        The keys above and ``warnings`` (the summary's, with one line per new flag).
    """
    found = _flags(summary)
    mu_k = summary.get("mu_k")
    reason = summary.get("mu_k_reason") or (None if mu_k is not None else _no_mu_k(summary))
    if mu_k is not None:
        confidence = "low" if any(f in LOWERING for f, _ in found) else "supported"
    else:
        confidence = "withheld" if summary["counts"].get("estimated") else "none"
        if confidence == "withheld":  # the hook-load check says it in its own warning
            said = summary.get("mu_k_reason") and (summary.get("hookload") or {}).get(
                "withheld_segments")
            found.insert(0, (WellFlag.MU_K_WITHHELD, "" if said else f"no well μ_k: {reason}"))
    warnings = list(summary.get("warnings") or [])
    warnings += [line for flag, line in found if line and line not in warnings]
    if confidence == "none" and summary.get("segments"):
        warnings.append(_nothing_estimated(summary["segments"]))
    return {"mu_k_confidence": confidence, "mu_k_reason": reason,
            "quality_flags": [flag.value for flag, _ in found], "warnings": warnings}


def _nothing_estimated(segments: list[dict]) -> str:
    """The warning of a log whose segments were all skipped or failed: nothing estimated
    (a column of unreadable numbers made every segment's nulls too many, exit 0, silent)."""
    first = next((s.get("message") for s in segments if s.get("message")), "")
    return (f"nothing estimated: no segment was estimated ({plural(len(segments), 'segment')} "
            f"skipped or failed" + (f"; the first says: {first})" if first else ")"))


def _no_mu_k(summary: dict) -> str:
    """Why a summary without a well μ_k has none."""
    log_reason = (summary.get("friction_log") or {}).get("mu_k_reason")
    if log_reason:
        return str(log_reason)
    segments = summary.get("segments") or []
    off = [s for s in segments if s.get("kind") == Kind.OFF_BOTTOM]
    done = [s for s in off if s.get("status") == Status.OK]
    if not segments:
        return "no rotating segment in the log"
    if not off:
        return "no off-bottom rotating segment: only apparent friction on bottom"
    if not done:
        return (f"no off-bottom segment was estimated ({plural(len(off), 'off-bottom segment')} "
                "skipped or failed)")
    return (f"no off-bottom segment converged ({plural(len(done), 'estimated off-bottom segment')}"
            "; their messages say why)")


def _flags(summary: dict) -> list[tuple[WellFlag, str]]:
    """The well-level flags raised, each with its warning line ("" when another line of the
    run already says it)."""
    segments = summary.get("segments") or []
    found = []
    support = summary.get("mu_k_support") or {}
    mu_k, u = summary.get("mu_k"), summary.get("mu_k_uncertainty")
    if mu_k is not None and support.get("segments", 0) < MIN_SUPPORT:
        backing = share(support.get("segments", 0), support.get("of", 0), "off-bottom segment")
        found.append((WellFlag.LOW_SUPPORT, f"the well μ_k {mu_k:.3f} rests on {backing} "
                      f"(fewer than {MIN_SUPPORT}): low confidence"))
    if mu_k is not None and u is not None and u > MAX_RELATIVE_UNCERTAINTY * mu_k:
        found.append((WellFlag.WIDE_SPREAD, f"the well μ_k {mu_k:.3f} ± {u:.3f}: its "
                      f"segments disagree by more than {MAX_RELATIVE_UNCERTAINTY:.0%}"))
    if summary.get("assumed"):
        found.append((WellFlag.INDICATIVE, f"{INDICATIVE_WARNING} "
                      f"{plural(len(summary['assumed']), 'default')} assumed (summary.json "
                      "assumed), e.g. "
                      f"{summary['assumed'][0]}"))
    # only where the μ is shown: a withheld segment's μ is no reading to check (issue 35
    # item 6: "13 segments outside the typical μ range" beside 13 withheld μ)
    outside = [s["id"] for s in segments if Flag.OUTSIDE_TYPICAL_RANGE in
               (s.get("quality_flags") or ()) and s.get("mu_k") is not None]
    if outside:
        found.append((WellFlag.SEGMENTS_OUTSIDE_TYPICAL_RANGE, f"{plural(len(outside), 'segment')} "
                      f"outside the typical μ range {TYPICAL_MU[0]}–{TYPICAL_MU[1]} "
                      f"({_ids(outside)}): check the string, the survey and the torque units"))
    heavy = _heavier_than_measured(segments)
    if heavy:
        found.append((WellFlag.STRING_WEIGHT_INCONSISTENT, f"{STRING_WEIGHT_WARNING}: in "
                      f"{plural(len(heavy), 'off-bottom segment')} ({_ids(heavy)}) the modelled "
                      "rotating hook load exceeds the measured one by more than "
                      f"{STRING_WEIGHT_TOLERANCE:.0%}; check the string's linear masses and "
                      "lengths, the mud density and the hook-load channel"))
    hook = summary.get("hookload") or {}
    if hook.get("verdict") == "not_checked" and mu_k is not None:
        found.append((WellFlag.STRING_WEIGHT_NOT_CHECKED, ""))  # the check's own warning
    elif hook.get("verdict") == "unverified":
        found.append((WellFlag.STRING_WEIGHT_UNVERIFIED, ""))  # the check's own warning
    elif hook.get("verdict") == "contradicted" or hook.get("withheld_segments"):
        found.append((WellFlag.HOOKLOAD_CONTRADICTS_STRING, ""))  # the check's own warning
    failed = [s for s in segments if s.get("status") == Status.FAILED]
    if failed:
        first = str(failed[0].get("message") or "").split("; ")[0]
        found.append((WellFlag.SEGMENTS_FAILED, f"{plural(len(failed), 'segment')} failed "
                      f"({_ids([s['id'] for s in failed])}): their messages say why (segment "
                      f"{failed[0]['id']}: {first})"))
    return found


def _heavier_than_measured(segments: list[dict]) -> list[int]:
    """Off-bottom segments whose modelled rotating hook load exceeds the measured one by
    more than :data:`STRING_WEIGHT_TOLERANCE` (the hook also carries the block, so the model
    can only be lighter; docs/reports.md "Broomstick")."""
    out = []
    for s in segments:
        hook, model = s.get("hookload_N"), s.get("hookload_model_N")
        if s.get("kind") == Kind.OFF_BOTTOM and hook and model and hook > 0 \
                and model > (1.0 + STRING_WEIGHT_TOLERANCE) * hook:
            out.append(s["id"])
    return out


def _ids(ids: list[int], shown: int = 8) -> str:
    """``segments 1, 4, 7`` (the first ``shown``, then how many more)."""
    more = f" and {len(ids) - shown} more" if len(ids) > shown else ""
    return f"segment{'s' * (len(ids) > 1)} {', '.join(map(str, ids[:shown]))}{more}"
