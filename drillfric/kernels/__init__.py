"""Compiled time-stepping kernels and their plain-NumPy twins (docs/theory.md §3.1, §3.2, §5).

Each kernel module has a twin with the same argument list, written with whole-array NumPy
operations and a Python loop over time steps: the oracle of the kernel tests and the
baseline of the benchmarks (the stumpy pattern: private kernel, public wrapper, naive twin).

- :mod:`.plant` / :mod:`.plant_numpy` — the Courant-1 torsional plant (wrapped by
  :mod:`drillfric.torsional`);
- :mod:`.observer` / :mod:`.observer_numpy` — the adaptive observer (wrapped by
  :mod:`drillfric.estimation.observer`).

Both carry the friction profile (an estimated part μ·F_c and a fixed part of known
friction) and the step or Stribeck friction law of docs/theory.md §3.2. The observer runs
its members (starts, ensemble members) on numba's threads when asked (``parallel``); to
keep it on one thread call ``numba.set_num_threads(1)`` (or set ``NUMBA_NUM_THREADS=1``)
— fleet workers do (docs/performance.md).
"""
