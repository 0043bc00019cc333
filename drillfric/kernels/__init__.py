"""Compiled time-stepping kernels and their plain-NumPy twins (docs/theory.md §3.1, §5).

Each kernel module has a twin with the same argument list, written with whole-array NumPy
operations and a Python loop over time steps: the oracle of the kernel tests and the
baseline of the benchmarks (the stumpy pattern: private kernel, public wrapper, naive twin).

- :mod:`.plant` / :mod:`.plant_numpy` — the Courant-1 torsional plant (wrapped by
  :mod:`drillfric.torsional`);
- :mod:`.observer` / :mod:`.observer_numpy` — the adaptive observer (wrapped by
  :mod:`drillfric.estimation.observer`).
"""
