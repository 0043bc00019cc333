"""Compile the kernels of a run ahead of it, on two cores at once (the first run).

A run compiles, on first use, the torsional plant (the batch fit), the observer (the starts
and the ensemble), the rig-state classifier, the hook-load plateau finder and the
torque-and-drag march. Compiled in the
run's own process they cost ~10 s of one core, in silence. :func:`warm_up` compiles the
observer in a short-lived child process while this process compiles the plant, classifier
and march itself — both through the same functions a run calls (so with the same types), on
a small built-in segment; numba writes the machine code to the per-user cache
(:mod:`drillfric.kernels.cache`), from which the run loads the observer. A subprocess, not
multiprocessing: a Dask worker's daemonic process cannot start multiprocessing children.

``python -m drillfric.runner.warmup PART`` compiles one part ("observer" or "plant").
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from collections.abc import Callable

from drillfric.kernels.cache import is_warm, mark_warm

PARTS = ("observer", "plant")
#: Name of the stamp :func:`warm_up` leaves in the cache (:func:`~drillfric.kernels.cache.is_warm`).
STAMP = "run"


def needed() -> bool:
    """Whether this installation's kernels still have to be compiled (no stamp in the cache)."""
    return not is_warm(STAMP)


def warm_up(tick: Callable[[float], None] | None = None, *, timeout_s: float = 600.0,
            poll_s: float = 0.25) -> bool:
    """Compile the run's kernels: the observer in a child process, the rest here, at once;
    ``tick(elapsed_s)`` is called about every ``poll_s`` meanwhile (from a thread while this
    process compiles). Returns True when both succeeded (and marks the cache warm); False
    otherwise — the run then compiles what it still needs itself."""
    env = dict(os.environ)  # NUMBA_CACHE_DIR as this process has it
    child = subprocess.Popen([sys.executable, "-m", "drillfric.runner.warmup", PARTS[0]],
                             stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL, env=env)
    t0, here = time.monotonic(), threading.Event()
    ticker = threading.Thread(target=_ticking, args=(tick, t0, poll_s, here), daemon=True)
    ticker.start()
    try:
        ok = _compile_here(PARTS[1])
        while child.poll() is None and time.monotonic() - t0 <= timeout_s:
            time.sleep(poll_s)
    finally:
        here.set()
        ticker.join()
        if child.poll() is None:
            child.kill()
            child.wait()
    if ok and child.returncode == 0:
        mark_warm(STAMP)
        return True
    return False


def load() -> None:
    """Load the compiled kernels into this process now (from the per-user cache; compiling
    what is missing), for a process that must not pause later: numba loads a kernel on its
    first call, holding the GIL ~0.5 s (``drillfric live`` writes live.json every 0.2 s)."""
    for part in PARTS:
        _compile(part)


def _ticking(tick, t0: float, poll_s: float, done: threading.Event) -> None:
    while tick is not None and not done.wait(poll_s):
        tick(time.monotonic() - t0)


def _compile_here(part: str) -> bool:
    """:func:`_compile` in this process; False when it failed (the run compiles then)."""
    try:
        _compile(part)
    except Exception:  # noqa: BLE001 — a warm-up that fails costs nothing but its time
        return False
    return True


def _segment():
    """A short off-bottom rotation (5 s at 100 Hz, 60 RPM, 8 kN·m) at 1000 m, default string."""
    import numpy as np

    from drillfric.estimation.segment_data import SegmentData

    time_s = np.arange(501) / 100.0
    return SegmentData(time_s, np.full(time_s.size, 60.0), np.full(time_s.size, 8e3), 1000.0)


def _compile(part: str) -> None:
    """Run the functions of ``part`` that a run compiles, on :func:`_segment`."""
    import numpy as np
    import pandas as pd

    from drillfric.config import config_from_dict
    from drillfric.estimation import chain
    from drillfric.estimation.settings import ChainSettings

    cfg = config_from_dict({})
    settings = ChainSettings.from_config(cfg)
    models = chain.build_models(settings, None, _segment())
    if part == "observer":
        chain.starts_pass(settings, models, None, 10.0)
        return
    from drillfric import torsional
    from drillfric.segmentation import _PLAIN_ROWS, classify

    drive = torsional.Drive("speed", np.full(10, 6.3), 1.0)  # the batch fit's plant kernel
    torsional.run(models.observer.plant, drive, 1.0, 10.0)

    rows = _PLAIN_ROWS + 1
    classify(pd.DataFrame({"time_s": np.arange(rows) / 100.0,
                           "surface_rpm": np.full(rows, 60.0)}), cfg)
    from drillfric import hookload  # the in-slips plateaus of a long chunk

    rows = hookload._PLAIN_ROWS + 1
    hookload.find_plateaus(pd.DataFrame({"time_s": np.arange(rows) / 100.0,
                                         "surface_rpm": np.zeros(rows),
                                         "hookload_N": np.full(rows, 1e5)}), cfg)
    from drillfric import hookload  # the in-slips plateaus of a long chunk

    rows = hookload._PLAIN_ROWS + 1
    hookload.find_plateaus(pd.DataFrame({"time_s": np.arange(rows) / 100.0,
                                         "surface_rpm": np.zeros(rows),
                                         "hookload_N": np.full(rows, 1e5)}), cfg)


if __name__ == "__main__":
    _compile(sys.argv[1])
