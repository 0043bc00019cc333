"""drillfric — downhole friction factors and bit speed from rig surface data.

Implements the adaptive observer of Aarsnes, Auriol, Di Meglio & Shor, "Estimating
friction factors while drilling", J. Petroleum Science and Engineering 179 (2019) 80–91,
on top of a minimum-curvature well path and a soft-string torque-and-drag model
(docs/theory.md). The Python API (docs/api.md)::

    import drillfric
    well = drillfric.open_well("well.csv")       # or open_well(frame=df, survey=..., config=...)
    result = drillfric.run(well)                # nothing written; result.mu_k, .segments
    result = drillfric.run(well, out="results")  # results/NAME/ as `drillfric run` writes

Importing the package is cheap: the API's functions load what they need when called.
"""

import importlib.util as _util
import sys as _sys
from importlib.abc import MetaPathFinder as _Finder
from pathlib import Path as _Path

from drillfric._version import __version__
from drillfric.kernels.cache import configure as _configure_kernel_cache

__all__ = ["open_well", "run", "load_result", "torque_and_drag", "simulate", "Well",
           "WellResult", "RunProgress", "Engine", "__version__"]


class _CheckoutFolders(_Finder):
    """In a source checkout, ``drillfric.cli`` and ``drillfric.templates`` are the
    top-level cli/ and templates/ folders, as pyproject's package-dir installs them; nothing
    else of the repository root becomes part of the package."""

    def __init__(self, root: _Path):
        self.folders = {f"{__name__}.{name}": root / name for name in ("cli", "templates")}

    def find_spec(self, fullname, path=None, target=None):
        folder = self.folders.get(fullname)
        if folder is None:
            return None
        return _util.spec_from_file_location(fullname, folder / "__init__.py",
                                             submodule_search_locations=[str(folder)])


# Run from a source checkout (not installed, or installed elsewhere): map the two folders.
_TREE = _Path(__file__).resolve().parent.parent
if (_TREE / "pyproject.toml").is_file() and (_TREE / "cli" / "main.py").is_file() and not (
        _Path(__file__).parent / "cli").is_dir():
    _sys.meta_path.append(_CheckoutFolders(_TREE))


_configure_kernel_cache()  # compiled kernels in one per-user directory (docs/performance.md)


def __getattr__(name: str):
    if name in __all__:
        from drillfric import api

        return getattr(api, name)
    raise AttributeError(f"module 'drillfric' has no attribute {name!r}")


def __dir__() -> list[str]:
    """The public API (tab completion), not the module's internals."""
    return sorted(__all__)
