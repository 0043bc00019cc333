"""One vocabulary (issue 31 item 2): each idea has one enum (drillfric.vocabulary: Status, Kind,
Method, Flag, LoadCase, RigState, WellStatus), the public strings are their values, and no
code compares an enum's value with a string literal — a misspelt literal would compare
false silently, a misspelt member fails at import."""

from __future__ import annotations

import ast

import pytest

from drillfric.result import Flag
from drillfric.segmentation import KINDS, RIG_STATES
from drillfric.torque_drag import LOAD_CASES
from drillfric.vocabulary import (
    KIND_LOAD_CASES,
    STATE_KINDS,
    Kind,
    LoadCase,
    Method,
    RigState,
    Status,
    WellStatus,
)
from tests.conftest import REPO

#: Values no other vocabulary shares: a literal of one is a comparison with the enum.
_DISTINCT = {str(m) for e in (Kind, Flag, LoadCase) for m in e} | set(RIG_STATES)
#: Values other vocabularies share ("ok" of a hook-load verdict, "none" of a unit): a
#: literal of one counts only when compared with something named status, kind or method.
_SHARED = {str(m) for e in (Status, Method, WellStatus) for m in e}


def _literal_comparisons(path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Compare):
            continue
        sides = [node.left, *node.comparators]
        text = ast.unparse(node)
        named = any(word in text for word in ("status", "kind", "method"))
        for side in sides:
            items = side.elts if isinstance(side, ast.Tuple | ast.List | ast.Set) else [side]
            for item in items:
                if isinstance(item, ast.Constant) and isinstance(item.value, str) and (
                        item.value in _DISTINCT or named and item.value in _SHARED):
                    where = path.relative_to(REPO) if path.is_relative_to(REPO) else path
                    found.append(f"{where}:{node.lineno}: {text}")
    return found


@pytest.mark.parametrize("folder", ["drillfric", "cli"])
def test_no_enum_value_is_compared_with_a_string_literal(folder):
    found = [hit for path in sorted((REPO / folder).rglob("*.py"))
             for hit in _literal_comparisons(path)]
    assert not found, "compare with the enum member instead:\n" + "\n".join(found)


def test_the_public_strings_are_the_enums_values():
    """INTERFACE.md binds summary.json's kind "off_bottom_rotating" and td's
    load_case="rotating_off_bottom"; the enums map them."""
    assert Kind.OFF_BOTTOM == "off_bottom_rotating" and LoadCase.ROTATING_OFF_BOTTOM == \
        "rotating_off_bottom"
    assert LOAD_CASES == tuple(LoadCase) and RIG_STATES == tuple(s.text for s in RigState)
    assert KINDS is STATE_KINDS


def test_one_mapping_between_rig_states_kinds_and_load_cases():
    """Every turning state makes a kind, every kind is modelled with one load case; the
    states that do not turn make none."""
    turning = {RigState.ROTATING_OFF_BOTTOM, RigState.ROTATING_ON_BOTTOM, RigState.REAMING,
               RigState.BACK_REAMING}
    assert {s for s in RigState if s.kind is not None} == turning
    assert set(KIND_LOAD_CASES) == set(Kind) == set(STATE_KINDS.values())
    assert KIND_LOAD_CASES[RigState.REAMING.kind] == LoadCase.ROTATING_SLACK_OFF  # runs in
    assert KIND_LOAD_CASES[RigState.BACK_REAMING.kind] == LoadCase.ROTATING_PICK_UP


def test_the_scan_catches_a_literal(tmp_path):
    """The scan itself: a comparison with a kind's literal is found."""
    path = tmp_path / "x.py"
    path.write_text('def f(seg):\n    return seg.kind == "off_bottom_rotating" or '
                    'seg["status"] in ("ok", "failed")\n')
    assert len(_literal_comparisons(path)) == 3
