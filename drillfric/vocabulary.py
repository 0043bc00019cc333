"""drillfric's vocabulary: the enums every layer shares, in a module that imports nothing
heavy (the CLI compares with them before it loads pandas). Their values are the public
strings INTERFACE.md binds (summary.json ``kind`` "off_bottom_rotating", ``td``'s
``load_case`` "rotating_off_bottom"); compare with the members, never with a literal
(tests/test_vocabulary.py holds this)."""

from __future__ import annotations

from enum import IntEnum, StrEnum


class Status(StrEnum):
    """What became of a segment."""

    OK = "ok"  #: estimated (the numbers may still be flagged or not converged)
    SKIPPED = "skipped"  #: nothing to estimate (too short, nulls, no side force)
    FAILED = "failed"  #: the estimation could not be done (e.g. torque in the wrong unit)


class WellStatus(StrEnum):
    """What became of a well in a fleet run (manifest.json, fleet_summary.parquet
    ``well_status``)."""

    OK = "ok"  #: processed now
    SKIPPED = "skipped"  #: unchanged since an ok run: its results stand
    FAILED = "failed"  #: could not be processed (its message says why)


#: What drillfric calls the stop of rotation to add (or break out) a stand — the string set
#: in the slips (rig state ``in_slips``) with the pick-up before it and the slack-off after
#: it (drag_log.parquet's rows, summary.json ``drag.connections``). The report, the terminal
#: and the fleet name these periods with this word and no other (issue 35, fourth newcomer:
#: "in slips", "tripping" and "slack-offs" had each named them somewhere).
CONNECTION = "connection"


class Kind(StrEnum):
    """The load case of a rotating segment (docs/theory.md §2 item 5)."""

    OFF_BOTTOM = "off_bottom_rotating"
    ON_BOTTOM = "on_bottom_rotating"
    REAMING = "reaming"  #: turning while running in faster than segmentation.ream_speed_m_s
    BACK_REAMING = "back_reaming"  #: turning while pulling out (bit speed withheld)


#: Kinds in which the pipe moves along the hole as it turns: their μ_k (the moving load case,
#: docs/theory.md §3.3) is kept out of the well μ_k and the report's friction log for now
#: (docs/outputs.md).
MOVING_KINDS = (Kind.REAMING, Kind.BACK_REAMING)


class LoadCase(StrEnum):
    """A torque-and-drag load case (docs/theory.md §2 step 3; docs/torque_drag.md): σ, the
    axial share of the wall friction, is +1 pulling out, −1 running in, 0 rotating; the
    rotating pick-up and slack-off split it between axial and tangential."""

    ROTATING_OFF_BOTTOM = "rotating_off_bottom"
    ROTATING_ON_BOTTOM = "rotating_on_bottom"
    PICK_UP = "pick_up"
    SLACK_OFF = "slack_off"
    ROTATING_PICK_UP = "rotating_pick_up"
    ROTATING_SLACK_OFF = "rotating_slack_off"
    SLIDING = "sliding"  #: slack-off with weight on bit and no rotation (motor drilling)


class RigState(IntEnum):
    """What the rig does at a sample (docs/segmentation.md): the codes stored per row
    (tracks, the segmenter's state); :attr:`text` is the public name (live.json
    ``rig_state``, tracks.parquet)."""

    ROTATING_OFF_BOTTOM = 0
    ROTATING_ON_BOTTOM = 1
    IN_SLIPS = 2
    TRIPPING = 3
    IDLE = 4
    UNKNOWN = 5
    SLIDING_ON_BOTTOM = 6
    REAMING = 7
    BACK_REAMING = 8

    @property
    def text(self) -> str:
        """The public name, e.g. ``"rotating_off_bottom"``."""
        return self.name.lower()

    @property
    def kind(self) -> Kind | None:
        """The kind of segment a run of this state makes (None: the string does not turn)."""
        return STATE_KINDS.get(self)


class Method(StrEnum):
    """Which estimator produced a segment's friction factors."""

    BATCH = "batch"  #: the speed-driven fit (docs/theory.md §6.4)
    OBSERVER = "observer"  #: the adaptive observer's consensus (§5), the fit gave no μ_k
    TD_BACKCALC = "td_backcalc"  #: static torque-and-drag back-calculation of a depth log
    NONE = "none"  #: no estimate (skipped or failed)


#: The segment kind of each turning rig state (the one mapping between the two vocabularies).
STATE_KINDS = {RigState.ROTATING_OFF_BOTTOM: Kind.OFF_BOTTOM,
               RigState.ROTATING_ON_BOTTOM: Kind.ON_BOTTOM,
               RigState.REAMING: Kind.REAMING, RigState.BACK_REAMING: Kind.BACK_REAMING}
#: The load case each segment kind is modelled with (reaming: running in while turning).
KIND_LOAD_CASES = {Kind.OFF_BOTTOM: LoadCase.ROTATING_OFF_BOTTOM,
                   Kind.ON_BOTTOM: LoadCase.ROTATING_ON_BOTTOM,
                   Kind.REAMING: LoadCase.ROTATING_SLACK_OFF,
                   Kind.BACK_REAMING: LoadCase.ROTATING_PICK_UP}
