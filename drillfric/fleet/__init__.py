"""The nightly fleet (docs/fleet.md): which wells a folder or manifest holds
(:mod:`~drillfric.fleet.discovery`), running them on local processes or a Dask cluster
(:mod:`~drillfric.fleet.run`, :mod:`~drillfric.fleet.scheduler`) and what changed since the
last night (:mod:`~drillfric.fleet.overnight`)."""
