"""Reading rig data into one in-memory representation of a well (SI units).

- :mod:`drillfric.io.channels` — the mnemonic table: which source column is which canonical
  channel, and in which unit.
- :mod:`drillfric.io.source` — :class:`RawSource`, the opened file every reader returns.
- :mod:`drillfric.io.readers` — format readers (Parquet, CSV, HDF5, LAS 2.0) yielding raw
  chunks with the units the file states; :mod:`drillfric.io.witsml` (WITSML 1.4.1 logs,
  trajectories, tubulars), :mod:`drillfric.io.dlis` and :mod:`drillfric.io.excel` for
  ``.xml``, ``.dlis`` and ``.xlsx``.
- :mod:`drillfric.io.timebase` — time base checks: order, duplicates, gaps, nominal rate.
- :mod:`drillfric.io.survey` — survey readers (MD, inclination, azimuth).
- :mod:`drillfric.io.well` — wells on disk (sidecars, HDF5 bundles, directories), ``load_well``
  and the chunked ``iter_surface``.
"""

from __future__ import annotations

__all__ = ["load_well", "iter_surface", "resolve_well", "WellData", "ChannelInfo", "TimeBase"]


def __getattr__(name: str):
    # Lazy: ``import drillfric.io.survey`` must not pull in pandas/pyarrow readers.
    if name in __all__:
        from drillfric.io import well

        return getattr(well, name)
    raise AttributeError(f"module 'drillfric.io' has no attribute {name!r}")
