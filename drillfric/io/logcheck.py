"""Checks of a surface log as it streams by, so that a run never ends in silence.

A log can be read without error and still give nothing to estimate: a constant time column,
time in milliseconds labelled as seconds (every sample a gap), a torque column with no
numbers, a top drive logged with the opposite sign. :class:`LogCheck` watches the canonical
chunks of a run and says so — an :class:`~drillfric.errors.InputError` naming the channel and
the fix where the log cannot be meant that way, a warning where a run found nothing to do
(docs/ingestion.md "No silent empty results").
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.io.text import printable
from drillfric.io.well import CLOCK_UNIT
from drillfric.segmentation import is_gap

#: Loads below this are no reading of a string's weight [N] (zeros, noise): the WOB and
#: hook-load comparison (:meth:`LogCheck.finish`) leaves such rows out.
SWAP_FLOOR_N = 10e3
#: Share of the rows with a WOB above the hook load beyond which the two columns are taken
#: as swapped (the hook carries the block and the string; drilling puts part of the
#: string's weight on the bit, never more than the hook holds but for moments).
SWAP_SHARE = 0.9
#: Sample spacing [s] below which a time column that gives nothing to estimate is suspected
#: of being in minutes or hours read as seconds (above 250 Hz: faster than rig surface logs).
FAST_SPACING_S = 1.0 / 250.0


class LogCheck:
    """Accumulates what the checks need from every chunk of a run (constant memory).

    Parameters
    ----------
    well : drillfric.io.well.Well
        The well being read (for file, column names and thresholds).
    """

    def __init__(self, well):
        self.well = well
        self.rows = 0
        self.finite = {"surface_rpm": 0, "surface_torque_Nm": 0}
        self.turning = 0  # samples with |rpm| above the rotation threshold
        self.backwards = 0  # of those, turning backwards
        self.rpm_min = np.inf
        self.rpm_max = -np.inf
        self.spacing_s = np.nan  # median sample spacing of the first chunk [s]
        self.loaded = 0  # rows with WOB and hook load, one of them above SWAP_FLOOR_N
        self.wob_over = 0  # of those, WOB above the hook load
        self.wob_sum = self.hook_sum = 0.0  # their sums [N] (for the message)
        # rows whose hole depth reads above the bit depth by more than on_bottom_m, the
        # most it does [m] and the first such row's time [s]
        self.above, self.above_max_m, self.above_first_s = 0, 0.0, np.nan
        # consecutive samples turning above the rotation threshold: now, and the most so far
        self.turn_run = self.turn_longest = 0

    def feed(self, chunk: pd.DataFrame) -> None:
        """Take in one canonical chunk (the first one also checks the sample spacing)."""
        if self.rows == 0 and len(chunk) > 1:
            self._spacing(chunk["time_s"].to_numpy(float))
            dt = np.diff(chunk["time_s"].to_numpy(float))
            self.spacing_s = float(np.median(dt[dt > 0])) if (dt > 0).any() else np.nan
        self.rows += len(chunk)
        for name in self.finite:
            if name in chunk:
                self.finite[name] += int(np.isfinite(chunk[name].to_numpy(float)).sum())
        if "wob_N" in chunk and "hookload_N" in chunk:
            wob, hook = chunk["wob_N"].to_numpy(float), chunk["hookload_N"].to_numpy(float)
            both = np.isfinite(wob) & np.isfinite(hook)
            both[both] = np.maximum(wob[both], hook[both]) > SWAP_FLOOR_N
            self.loaded += int(both.sum())
            self.wob_over += int((wob[both] > hook[both]).sum())
            self.wob_sum += float(wob[both].sum())
            self.hook_sum += float(hook[both].sum())
        if "bit_depth_m" in chunk and "hole_depth_m" in chunk:
            excess = chunk["bit_depth_m"].to_numpy(float) - chunk["hole_depth_m"].to_numpy(float)
            over = np.flatnonzero(excess > self.well.config.segmentation.on_bottom_m)
            if over.size:
                if not self.above:
                    self.above_first_s = float(chunk["time_s"].to_numpy(float)[over[0]])
                self.above += int(over.size)
                self.above_max_m = max(self.above_max_m, float(excess[over].max()))
        rpm = chunk["surface_rpm"].to_numpy(float)
        self._runs(np.abs(rpm) > self.well.config.segmentation.rotating_rpm)
        rpm = rpm[np.isfinite(rpm)]
        if rpm.size:
            fast = np.abs(rpm) > self.well.config.segmentation.rotating_rpm
            self.turning += int(fast.sum())
            self.backwards += int((rpm[fast] < 0).sum())
            self.rpm_min = min(self.rpm_min, float(rpm.min()))
            self.rpm_max = max(self.rpm_max, float(rpm.max()))

    def _runs(self, fast: np.ndarray) -> None:
        """Carry the longest run of consecutive turning samples across chunks."""
        if not fast.size:
            return
        if fast.all():
            self.turn_run += fast.size
        else:
            stops = np.flatnonzero(~fast)
            head = int(stops[0])  # turning samples continuing the last chunk's run
            edges = np.diff(np.concatenate(([-1], stops, [fast.size]))) - 1
            self.turn_longest = max(self.turn_longest, self.turn_run + head, int(edges.max()))
            self.turn_run = int(fast.size - 1 - stops[-1])
        self.turn_longest = max(self.turn_longest, self.turn_run)

    def state(self) -> dict:
        """The counters (plain values and arrays)."""
        return {"rows": self.rows, "finite": dict(self.finite), "turning": self.turning,
                "backwards": self.backwards, "rpm_range": np.array([self.rpm_min, self.rpm_max]),
                "spacing_s": self.spacing_s,
                "loads": np.array([self.loaded, self.wob_over, self.wob_sum, self.hook_sum]),
                "hole_above": np.array([self.above, self.above_max_m, self.above_first_s]),
                "turn_runs": np.array([self.turn_run, self.turn_longest])}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self.rows, self.turning = int(state["rows"]), int(state["turning"])
        self.backwards = int(state["backwards"])
        self.finite = {k: int(v) for k, v in state["finite"].items()}
        self.rpm_min, self.rpm_max = (float(v) for v in state["rpm_range"])
        self.spacing_s = float(state.get("spacing_s", np.nan))
        above = state.get("hole_above")
        if above is not None:
            self.above, self.above_max_m = int(above[0]), float(above[1])
            self.above_first_s = float(above[2])
        runs = state.get("turn_runs")
        if runs is not None:
            self.turn_run, self.turn_longest = int(runs[0]), int(runs[1])
        loads = state.get("loads")
        if loads is not None:
            self.loaded, self.wob_over = int(loads[0]), int(loads[1])
            self.wob_sum, self.hook_sum = float(loads[2]), float(loads[3])

    def _spacing(self, time_s: np.ndarray) -> None:
        """Every sample a gap: time in ms read as s, or a log slower than max_gap_s (the
        only reading for timestamps, whose unit cannot be wrong)."""
        dt = np.diff(time_s)
        dt = dt[dt > 0]
        limit = self.well.config.segmentation.max_gap_s
        if not dt.size or not is_gap(np.median(dt), limit):
            return
        time, median = self.well.mappings["time"], float(np.median(dt))
        slow = (f"raise segmentation.max_gap_s above the spacing, e.g. [segmentation] "
                f"max_gap_s = {4 * median:.4g} (a log this slow resolves no stick-slip "
                "cycle: rotations shorter than a few samples are skipped)")
        clock = time.unit == CLOCK_UNIT
        raise InputError(f"time column '{printable(time.column)}'"
                         + (" (timestamps)" if clock else "")
                         + f" has samples {median:.4g} s apart: more than "
                           f"segmentation.max_gap_s ({limit:.4g} s), so every sample would "
                           "be a gap", file=self.well.files.data,
                         fix=slow if clock else 'if the time is in milliseconds, say so: '
                             '[channels] time = { unit = "ms" }; if the log really is this '
                             "slow, " + slow)

    def finish(self, duplicates: int) -> None:
        """Raise for logs that cannot be meant as read (after the last chunk)."""
        file = self.well.files.data
        if self.rows <= 1 and duplicates > 0:
            time = self.well.mappings["time"]
            raise InputError(f"time column '{printable(time.column)}' holds one value for all "
                             f"{duplicates + self.rows} rows", file=file,
                             fix="map the column that holds the sample times in [channels] "
                                 'time = { column = "..." }')
        for name, count in self.finite.items():
            if self.rows and count == 0:
                m = self.well.channels[name]
                raise InputError(f"column '{printable(m.column)}' ({name}) holds no numbers in "
                                 f"any of {self.rows} rows", file=file,
                                 fix=f"map the column that holds {m.channel.kind} in "
                                     f'[channels] {m.channel.key} = {{ column = "..." }}')
        if self.loaded >= 10 and self.wob_over > SWAP_SHARE * self.loaded:
            wob, hook = self.well.channels["wob_N"], self.well.channels["hookload_N"]
            raise InputError(f"the weight-on-bit column '{printable(wob.column)}' reads more "
                             f"than the hook-load column '{printable(hook.column)}' in "
                             f"{100 * self.wob_over / self.loaded:.0f} % of the rows (mean "
                             f"{self.wob_sum / self.loaded / 1e3:.4g} kN against "
                             f"{self.hook_sum / self.loaded / 1e3:.4g} kN): the hook carries "
                             "the block and the whole string, the bit only part of the "
                             "string's weight: the two columns look swapped", file=file,
                             fix=f"map them the other way round: [channels] "
                                 f'{wob.channel.key} = {{ column = "{printable(hook.column)}" }}'
                                 f', {hook.channel.key} = '
                                 f'{{ column = "{printable(wob.column)}" }} (with their units)')
        if self.turning and self.backwards > 0.9 * self.turning:
            m = self.well.channels["surface_rpm"]
            raise InputError(f"surface speed column '{printable(m.column)}' turns backwards in "
                             f"{100 * self.backwards / self.turning:.0f} % of the turning "
                             f"samples (min {self.rpm_min:.4g} RPM): the log's sign is the "
                             "opposite of drillfric's (forward rotation positive)",
                             file=file, fix=f"negate it: [channels] {m.channel.key} = "
                                            f'{{ column = "{printable(m.column)}", scale = -1 }}')

    def duplicates_note(self, duplicates: int) -> str | None:
        """A warning when more than 1 % of the rows repeated an earlier sample's time and
        values and were dropped (timestamps cut to whole seconds on a 20-Hz log dropped 95 %
        of it, silently), or None. Rows repeating a time with other values are the time
        base's :meth:`~drillfric.io.timebase.TimeTracker.conflicts_note`."""
        if duplicates <= 0.01 * (duplicates + self.rows):
            return None
        share = 100.0 * duplicates / (duplicates + self.rows)
        return (f"{self.well.files.data}: {duplicates} rows ({share:.0f} % of the log) repeat "
                "an earlier row's time and values and were dropped (one row of each time "
                "kept): are the timestamps cut to whole seconds or coarser than the logging? "
                "Log them to full resolution, or give a time_s column")

    def unit_hints(self, records) -> list[str]:
        """Warnings for a log that looks read in the wrong unit though nothing refused it
        (issue 30, ninth attack: the messages had been "the top drive never turns faster
        than ω_c" and "too short"): a speed column that never exceeds 20 RPM (rad/s read as
        RPM?), and rotations all too short though their samples are a whole fraction of a
        minute apart (minutes read as seconds?)."""
        out, file = [], self.well.files.data
        top = max(abs(self.rpm_min), abs(self.rpm_max))
        m = self.well.channels.get("surface_rpm")
        if m is not None and np.isfinite(top) and 0.5 < top <= 20.0:
            out.append(f"{file}: the surface speed column '{printable(m.column)}' reads at "
                       f"most {top:.3g} RPM, where a top drive turns at 30–250: if it is in "
                       f"rad/s ({top:.3g} rad/s = {top * 60.0 / (2.0 * np.pi):.3g} RPM), "
                       + _say_unit(m, "rad/s"))
        time = self.well.mappings.get("time")
        short = [r for r in records if str(r.message or "").startswith("too short")]
        dt = self.spacing_s
        if (time is not None and time.unit != CLOCK_UNIT and short
                and len(short) == len(records) and np.isfinite(dt)
                and 0.01 <= 60.0 * dt <= 60.0):
            longest = max(r.duration_s for r in short)
            minimum = self.well.config.segmentation.min_segment_s
            if 60.0 * longest >= minimum:
                out.append(f"{file}: every rotation is too short (the longest {longest:.3g} "
                           f"s < segmentation.min_segment_s = {minimum:g} s), its samples "
                           f"{dt:.3g} s apart: if the time column '{printable(time.column)}' "
                           f"is in minutes (the longest {60.0 * longest:.4g} s, samples "
                           f"{60.0 * dt:.3g} s apart), " + _say_unit(time, "min"))
        return out

    def time_unit_check(self, records) -> None:
        """Refuse a run that estimated nothing because its time column, unlabelled or
        labelled seconds, is in minutes or hours: samples less than
        :data:`FAST_SPACING_S` apart, no rotation long enough, and the unit in which the
        samples are 0.01–60 s apart and the longest turning stretch lasts
        ``segmentation.min_segment_s`` (issue 30, eleventh attack: a 1-Hz log in hours ended
        "the surface speed never exceeds 2 RPM … (highest: 62.2 RPM)", exit 0)."""
        time = self.well.mappings.get("time")
        dt = self.spacing_s
        if (time is None or time.unit == CLOCK_UNIT or not np.isfinite(dt)
                or not 0.0 < dt < FAST_SPACING_S or not self.turn_longest
                or any(not str(r.message or "").startswith("too short") for r in records)):
            return
        minimum = self.well.config.segmentation.min_segment_s
        for unit, name, scale in (("min", "minutes", 60.0), ("h", "hours", 3600.0)):
            spacing, longest = dt * scale, self.turn_longest * dt * scale
            if 0.01 <= spacing <= 60.0 and longest >= minimum:
                said = ("nothing in the file or the configuration says" if
                        time.source == "default" else f"from the {time.source}")
                raise InputError(
                    f"time column '{printable(time.column)}' read in "
                    f"'{printable(time.unit)}' ({said}) has samples {dt:.3g} s apart "
                    f"({1.0 / dt:.4g} Hz) and turns for {self.turn_longest * dt:.3g} s at "
                    f"most, so nothing could be estimated: is it in {name}? (samples "
                    f"{spacing:.3g} s apart, the longest rotation {longest:.4g} s)",
                    file=self.well.files.data,
                    fix=f"if the time is in {name}, " + _say_unit(time, unit))

    def hole_above_note(self) -> str | None:
        """A warning when the hole depth read above the bit depth (by more than
        ``segmentation.on_bottom_m``), which cannot be: the bit is never below the hole's
        bottom. Those rows were on or off bottom by their WOB alone (not by the depths,
        which put every rotation on bottom: issue 30, tenth attack), or None."""
        if not self.above:
            return None
        bit, hole = self.well.channels["bit_depth_m"], self.well.channels["hole_depth_m"]
        share = 100.0 * self.above / max(self.rows, 1)
        wob = "wob_N" in self.well.channels
        return (f"{self.well.files.data}: the hole depth (column '{printable(hole.column)}') "
                f"reads above the bit depth (column '{printable(bit.column)}') in "
                f"{self.above} rows ({share:.3g} % of the log, by up to "
                f"{self.above_max_m:.4g} m, the first at {self.above_first_s:.6g} s): the "
                "bit cannot be below the hole, so the hole-depth channel is wrong or lagging "
                "there and on or off bottom was "
                + ("judged from the WOB alone in those rows" if wob else
                   "not known in those rows (no WOB channel: rotation counted as off "
                   "bottom; drilling would put its bit torque into μ_k)")
                + " — check the hole-depth channel (its datum, its unit, whether it updates)")

    def nothing_found(self, segments: int) -> str | None:
        """Why a run found no rotating segment at all (a warning), or None."""
        if segments:
            return None
        threshold = self.well.config.segmentation.rotating_rpm
        top = f"{self.rpm_max:.4g} RPM" if np.isfinite(self.rpm_max) else "no value"
        if self.turn_longest:  # it does exceed it, never for long enough
            dt = self.spacing_s
            lasted = f" (at most {self.turn_longest * dt:.3g} s)" if np.isfinite(dt) else ""
            return (f"no rotating segment found: the surface speed exceeds "
                    f"segmentation.rotating_rpm = {threshold:.4g} RPM (highest: {top}) only "
                    f"for less than segmentation.min_rotation_s{lasted} — check the time "
                    "column's unit; nothing was estimated")
        return (f"no rotating segment found: the surface speed never exceeds "
                f"segmentation.rotating_rpm = {threshold:.4g} RPM for "
                f"segmentation.min_rotation_s (highest: {top}) — nothing was estimated")


def _say_unit(m, unit: str) -> str:
    """How to tell drillfric that mapping ``m``'s column is in ``unit``: the config line, or
    — where the file states the unit (the config cannot contradict it) — the file."""
    column = printable(m.column)
    if m.source in ("config", "default"):
        return (f'say so: [channels] {m.channel.key} = {{ column = "{column}", '
                f'unit = "{unit}" }}')
    return (f"the file's {m.source} says '{printable(m.unit)}': correct it to '{unit}' "
            f"(then drillfric converts)")
