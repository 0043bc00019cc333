"""Batch refinement of the friction factors (the "speed-driven fit"), docs/theory.md §6.4.

The plant of docs/theory.md §3 is driven at x = 0 by the measured top-drive speed (lightly
smoothed, interpolated to the model step), α(0) = 2ω₀(t) − β(0), starting at rest with no
twist; its output is the string torque at the top τ(0) = ζ(ω₀ − β(0)), compared with the
measured string torque τ_s = τ_m − I_TD dω̄₀/dt. From that model:

- μ_k matches the **mean** string torque over the rotating samples (each run's start-up
  left out: until the top drive has turned the twist of the string wound to the run's
  highest torque, plus a wave round trip; data and model each averaged over whole torque
  cycles) by a secant root find with a bounded slope that
  returns a point it evaluated (the mean jitters between runs because stick-slip is
  chaotic), with the model in the data's regime (§6.4);
- μ_s is fitted only where the data hold it, on creep start-ups logged at ≥ 2 Hz
  (:mod:`drillfric.estimation.creep`, §6.3): a bounded 1-D minimisation of the smoothed
  torque misfit over the creep at Δx ≤ MD/1000, refitted with twice (then four times) the
  cells and reported only once it moves less than 3 % and passes its checks;
- otherwise μ_s is not identifiable; in stick-slip a lower bound comes from the stick-slip
  onset, the highest μ_s of a 0.02 grid below which the model's bit never sticks, and none
  is given where sticking is not monotone in μ_s ("bistable_regime", §6.2, §6.4).

Only the needed parts of a record are simulated: each rotating run (from just before its
start) for μ_k, the start-up and the next 60 s of one run for the onset scan, and each creep
(from the preceding rest) for μ_s. Everything is SI (rad/s, N·m, m, s).

Modules (docs/batch_refinement.md "Code"):

- :mod:`.settings` — :class:`BatchSettings` from the configuration and the fit's thresholds;
- :mod:`.harness` — the log on a uniform time base and the plant driven by it;
- :mod:`.kinetic` — the μ_k stage; :mod:`.creep_fit` — the creep stage;
  :mod:`.creep_checks` — what a creep fit must show; :mod:`.onset` — the onset bound;
- :mod:`.fit` — :func:`refine`, which wires the stages and assembles the result.
"""

from drillfric.estimation.batch.creep_checks import (
    CreepChecks,
    parabola_vertex,
    twist_walk_variance,
)
from drillfric.estimation.batch.fit import (
    BatchDetails,
    BatchResult,
    model_string_torque,
    refine,
)
from drillfric.estimation.batch.harness import measured_string_torque, whole_cycles
from drillfric.estimation.batch.settings import BatchSettings

__all__ = ["BatchDetails", "BatchResult", "BatchSettings", "CreepChecks",
           "measured_string_torque", "model_string_torque", "parabola_vertex", "refine",
           "twist_walk_variance", "whole_cycles"]
