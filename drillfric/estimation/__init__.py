"""Friction factors and bit speed of one segment: the estimation chain (docs/theory.md §5–§6).

- :mod:`.chain` — the declared chain of named steps for one segment;
- :mod:`.observer`, :mod:`.gains`, :mod:`.lumped` — the adaptive observer and its gain designs;
- :mod:`.batch`, :mod:`.creep` — the batch refinement (speed-driven fit) and where a record
  holds μ_s;
- :mod:`.diagnostics`, :mod:`.torque_scale` — per-window diagnostics and the torque-unit check.
"""
