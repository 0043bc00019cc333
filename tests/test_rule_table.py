"""One rule table for the flags (issue 31 item 4): ``drillfric.result.FLAG_RAISED_BY`` names,
for every flag, the pure rule(s) that raise it, and no other function of drillfric raises one.

A flag raised anywhere else would be a decision the table does not show: the scan below
reads every ``Flag.X`` of the package outside a comparison (a comparison reads a flag, it
does not raise it) and checks that its function is the one the table names. The string-
weight check's rule, the last that was decided inline, is tested here by its table.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path
from types import SimpleNamespace

import pytest

from drillfric.hookload import weight_verdict
from drillfric.result import FLAG_RAISED_BY, Flag
from drillfric.vocabulary import Method, Status

PACKAGE = Path(__file__).resolve().parents[1] / "drillfric"
TESTS = Path(__file__).resolve().parent


def _resolve(dotted: str):
    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(module), name, None)


def test_every_flag_has_a_rule_that_exists():
    assert set(FLAG_RAISED_BY) == set(Flag)
    for flag, rules in FLAG_RAISED_BY.items():
        for dotted in rules:
            assert callable(_resolve(dotted)), f"{flag.value}: {dotted} does not exist"


def _raising_functions(path: Path, root: Path = PACKAGE.parent) -> list[tuple[str, str]]:
    """(flag member, dotted function) of every ``Flag.X`` in ``path`` (a module under
    ``root``) outside a comparison and inside a function (module constants group flags, they
    raise none)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    module = ".".join(path.relative_to(root).with_suffix("").parts)
    found = []

    def visit(node, function, comparing):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            function = node.name if function is None else function
        comparing = comparing or isinstance(node, ast.Compare)
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.value.id == "Flag" and function and not comparing:
            found.append((node.attr, f"{module}.{function}"))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id == "Flag" and function:
            found.append(("<built from a string>", f"{module}.{function}"))
        for child in ast.iter_child_nodes(node):
            visit(child, function, comparing)

    visit(tree, None, False)
    return found


def test_no_function_outside_the_table_raises_a_flag():
    built = {r for f in (Flag.OBSERVER_STARTS_DISAGREE, Flag.OBSERVER_DEADLOCK_AVERTED)
             for r in FLAG_RAISED_BY[f]}
    stray = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "result.py":
            continue
        for member, function in _raising_functions(path):
            allowed = built if member.startswith("<") else FLAG_RAISED_BY[Flag[member]]
            if function not in allowed:
                stray.append(f"{member} in {function}")
    assert not stray, f"flags raised outside drillfric.result.FLAG_RAISED_BY: {stray}"


def test_the_scan_sees_a_planted_flag(tmp_path):
    """The scan itself: a flag appended in a function is seen, a comparison is not."""
    planted = tmp_path / "drillfric" / "probe.py"
    planted.parent.mkdir()
    planted.write_text("def raise_one(flags):\n    flags.append(Flag.POOLED)\n"
                       "def read_one(flags):\n    return Flag.POOLED in flags\n")
    assert _raising_functions(planted, tmp_path) == [("POOLED", "drillfric.probe.raise_one")]


def test_every_flag_is_exercised_by_a_test():
    """Each flag's rule is held by a test that names the flag (this file aside)."""
    text = "\n".join(p.read_text(encoding="utf-8") for p in TESTS.glob("test_*.py")
                     if p.name != Path(__file__).name)
    untested = [f.value for f in Flag if f"Flag.{f.name}" not in text
                and f'"{f.value}"' not in text and f"'{f.value}'" not in text
                and f.value.removeprefix("observer_") not in text]
    assert not untested


#: The string-weight rule, case by case: (status, contradiction, unverified, calibrated) →
#: (withheld, flag), and why.
WEIGHT_CASES = [
    (Status.OK, "", "", False, False, None, "nothing against the string: shown, no flag"),
    (Status.OK, "the hook load says 1.4×", "", False, True, Flag.HOOKLOAD_CONTRADICTS_STRING,
     "a contradiction withholds"),
    (Status.OK, "the hook load says 1.4×", "no block", True, True,
     Flag.HOOKLOAD_CONTRADICTS_STRING, "a contradiction outranks the rest"),
    (Status.OK, "", "no block weight", False, True, Flag.STRING_WEIGHT_UNVERIFIED,
     "a string weight the log cannot measure withholds"),
    (Status.OK, "", "", True, False, Flag.STRING_WEIGHT_CALIBRATED,
     "a calibrated string is shown, marked"),
    (Status.SKIPPED, "the hook load says 1.4×", "", True, False, None,
     "a segment not estimated has nothing to withhold or mark"),
    (Status.FAILED, "", "no block weight", False, False, None, "nor has a failed one"),
]


@pytest.mark.parametrize("status, contradiction, unverified, calibrated, withheld, flag, why",
                         WEIGHT_CASES, ids=[c[-1] for c in WEIGHT_CASES])
def test_weight_verdict(status, contradiction, unverified, calibrated, withheld, flag, why):
    rule = weight_verdict(status, contradiction, unverified, calibrated)
    assert bool(rule.withhold) is withheld and rule.flag is flag, why
    if withheld:
        assert rule.withhold == (contradiction or unverified)


#: The rule of a segment's stated μ_k interval: (method, converged after both verdicts) →
#: the interval stated? A μ_k not converged was off by −20 % to +80 % on the lumped plant,
#: beyond the validated tolerance its ± rests on (docs/validation.md "Calibrated intervals").
INTERVAL_CASES = [
    (Method.BATCH, True, True, "a converged batch μ_k states its 95 % interval"),
    (Method.BATCH, False, False, "a batch μ_k not converged states none, and says so"),
    (Method.OBSERVER, False, False, "the observer's consensus has no batch interval"),
]


@pytest.mark.parametrize("method, converged, stated, why", INTERVAL_CASES,
                         ids=[c[-1] for c in INTERVAL_CASES])
def test_interval_note(method, converged, stated, why):
    from drillfric.estimation.chain import _interval_note

    refined = SimpleNamespace(interval_note="μ_k = 0.200 ± 0.010 (95 %: …)")
    notes = _interval_note(refined, SimpleNamespace(method=method, mu_k=0.2),
                           SimpleNamespace(converged=converged))
    assert any("(95 %" in n for n in notes) is stated, why
    if method is Method.BATCH and not converged:
        assert notes == ("μ_k = 0.200 is not converged: no interval is stated for it (the "
                         "flags say why)",)


#: The rule of a segment's friction factors withheld outright: (method, converged, flags)
#: → withheld, and why.
WITHHELD_CASES = [
    (Method.BATCH, True, (), False, "a converged fit is shown"),
    (Method.BATCH, False, (Flag.ESTIMATORS_DISAGREE,), False,
     "a batch μ_k the observer disagrees with is shown, not converged (its fit stands)"),
    (Method.BATCH, False, (Flag.MU_K_UNCERTAIN,), False, "so is an uncertain one"),
    (Method.OBSERVER, False, (Flag.ROTATION_TOO_SHORT,), True,
     "an observer consensus that did not converge has nothing under it"),
    (Method.OBSERVER, True, (), False, "a converged observer consensus is shown"),
    (Method.BATCH, False, (Flag.FACTORS_RUN_AWAY,), True,
     "factors that run the bit away do not describe the record"),
]


@pytest.mark.parametrize("method, converged, flags, withheld, why", WITHHELD_CASES,
                         ids=[c[-1] for c in WITHHELD_CASES])
def test_withheld_factors(method, converged, flags, withheld, why):
    from drillfric.estimation.verdict import withheld_factors

    assert bool(withheld_factors(method, converged, flags)) is withheld, why


def test_a_withheld_segment_keeps_its_flags_once_and_states_no_factor():
    """Applying it: every friction number null, the reason in the message, the notes that
    stated a factor left out, and no flag doubled."""
    from drillfric.hookload import withhold_friction
    from drillfric.result import SegmentRecord

    record = SegmentRecord(mu_k=0.2, mu_k_observer=0.21, converged=False,
                           quality_flags=(Flag.FACTORS_RUN_AWAY,),
                           message="fit note; μ_k = 0.200 is not converged")
    out = withhold_friction(record, "the factors do not describe this record", None)
    assert out.mu_k is None and out.mu_k_observer is None and not out.converged
    assert out.quality_flags == (Flag.FACTORS_RUN_AWAY,)
    assert "0.200" not in out.message and out.message.endswith(
        "friction factors withheld: the factors do not describe this record")
