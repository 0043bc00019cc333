"""drillfric — downhole friction factors and bit speed from rig surface data.

Implements the adaptive observer of Aarsnes, Auriol, Di Meglio & Shor, "Estimating
friction factors while drilling", J. Petroleum Science and Engineering 179 (2019) 80–91,
on top of a minimum-curvature well path and a soft-string torque-and-drag model
(docs/theory.md). The Python API (docs/api.md)::

    import drillfric
    well = drillfric.open_well("well.csv")
    result = drillfric.run(well)                # nothing written; result.segments, .summary
    result = drillfric.run(well, out="results")  # results/NAME/ as `drillfric run` writes

Importing the package is cheap: the API's functions load what they need when called.
"""

from pathlib import Path as _Path

from drillfric._version import __version__

__all__ = ["open_well", "run", "load_result", "torque_and_drag", "simulate", "__version__"]

# Run from a source checkout (not installed, or installed elsewhere): the top-level cli/ and
# templates/ folders are the drillfric.cli and drillfric.templates packages, as pyproject's
# package-dir maps them in every install.
_TREE = _Path(__file__).resolve().parent.parent
if (_TREE / "pyproject.toml").is_file() and (_TREE / "cli" / "main.py").is_file():
    __path__.append(str(_TREE))


def __getattr__(name: str):
    if name in __all__:
        from drillfric import api

        return getattr(api, name)
    raise AttributeError(f"module 'drillfric' has no attribute {name!r}")
