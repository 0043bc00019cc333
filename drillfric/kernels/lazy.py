"""Compile a kernel with numba on first use, so that importing its module stays cheap.

Importing numba and loading a cached kernel cost ~0.6 s; commands that touch a few thousand
rows (``inspect`` of a small file, ``--help``) should not pay it. :func:`lazy_jit` keeps the
plain-Python function as the module's (it is the readable oracle and runs small inputs) and
compiles it, with the helpers it calls, the first time a large input needs the speed.
"""

from __future__ import annotations

import functools
import types
from collections.abc import Callable


def lazy_jit(fn: Callable, *helpers: Callable, cache: bool = True) -> Callable[[], Callable]:
    """A function returning ``fn`` compiled by numba (``njit(cache=cache)``), built once.

    ``helpers`` are the plain-Python functions ``fn`` calls by their names; they are
    compiled too and the compiled ``fn`` calls the compiled ones.

    Examples
    --------
    >>> def twice(x):
    ...     return 2 * x
    >>> def kernel(x):
    ...     return twice(x) + 1
    >>> compiled = lazy_jit(kernel, twice, cache=False)  # no file to cache beside here
    >>> compiled()(20), kernel(20)
    (41, 41)
    """

    @functools.cache
    def compiled() -> Callable:
        from numba import njit

        names = dict(fn.__globals__)
        names.update({h.__name__: njit(cache=cache)(h) for h in helpers})
        clone = types.FunctionType(fn.__code__, names, fn.__name__, fn.__defaults__,
                                   fn.__closure__)
        clone.__qualname__, clone.__module__ = fn.__qualname__, fn.__module__
        return njit(cache=cache)(clone)

    return compiled
