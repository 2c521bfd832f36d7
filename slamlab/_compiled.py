"""One place for compiled kernels (our addition, speed; issue 25).

The teaching implementations stay in numpy; where numpy cannot reach a measured speed bound, a kernel
compiled with numba sits beside the numpy version and is tested against it. Every kernel is compiled
through :func:`kernel` so that all share the same settings:

- ``cache=True``: the machine code is written next to the module (``__pycache__``) on the first call,
  so only the first process on a machine pays the compile time;
- ``nogil=True``: a kernel can run in :mod:`slamlab._threads`' shared pool;
- no ``fastmath``: floating-point operations keep the order and rounding written in the kernel (no
  reassociation, no implicit fused multiply-add contraction), so a kernel gives the same numbers on
  every CPU of our kind, whether it has AVX2 or AVX-512. Where a kernel reproduces a BLAS product that
  rounds a multiply-add once, it says so with an explicit ``fma`` (``slamlab.hough._kernels``).

Kernels load one by one: a kernel's machine code is compiled or read from the cache on its own first call,
so a process pays only for the kernels it calls (numba's import and LLVM, about 105 MiB, come with the first one);
:func:`loaded_kernels` names them.

``SLAMLAB_NO_NUMBA=1`` makes :func:`numba_enabled` false: callers then take the numpy path (a way to
compare the two, and a fallback where numba cannot be installed).
"""

from __future__ import annotations

import os
import threading

__all__ = ["jitable", "kernel", "loaded_kernels", "numba_enabled"]

#: helpers marked by :func:`jitable`, made callable from compiled code when the first kernel compiles
_JITABLE: list = []
_REGISTERED: set = set()
#: qualified names of the kernels compiled or loaded in this process, in order of first call
_LOADED: list = []
#: one first call at a time: two threads calling a kernel for the first time would both compile or load it
_FIRST_CALL = threading.Lock()


def numba_enabled() -> bool:
    """Whether compiled kernels are used: numba is importable and ``SLAMLAB_NO_NUMBA`` is not set.

    Returns
    -------
    bool
        True when the numba path should be taken.
    """
    if os.environ.get("SLAMLAB_NO_NUMBA", "") not in ("", "0"):
        return False
    try:
        import numba  # noqa: F401
    except ImportError:  # pragma: no cover - numba is a dependency; this is the fallback
        return False
    return True


def kernel(fn):
    """Compile ``fn`` with numba under the project's settings (see the module docstring), lazily.

    The function is compiled on its first call, not at import, so ``import slamlab`` stays light.

    Parameters
    ----------
    fn : callable
        A function written in the numba-supported subset of Python and numpy.

    Returns
    -------
    callable
        The compiled dispatcher (``numba.njit(cache=True, nogil=True)(fn)``), created on first use.
    """
    compiled = None

    def call(*args):
        nonlocal compiled
        if compiled is None:
            with _FIRST_CALL:
                if compiled is None:
                    import numba
                    from numba.extending import register_jitable

                    for helper in _JITABLE:  # before the first kernel compiles: the helpers it may call
                        if id(helper) not in _REGISTERED:
                            register_jitable(inline="always")(helper)
                            _REGISTERED.add(id(helper))
                    dispatcher = numba.njit(cache=True, nogil=True)(fn)
                    compiled = dispatcher
                    _LOADED.append(f"{fn.__module__}.{fn.__qualname__}")
        return compiled(*args)

    call.__name__ = fn.__name__
    call.__qualname__ = fn.__qualname__
    call.__doc__ = fn.__doc__
    call.__wrapped__ = fn
    call.py_func = fn
    return call


def jitable(fn):
    """Mark ``fn`` as a helper that kernels may call (one place for a few lines that several kernels share).

    ``fn`` stays a plain Python function, so importing its module does not import numba; when the first kernel
    compiles, numba's ``register_jitable(inline="always")`` makes it callable from compiled code, inlined into
    each caller (the same machine code as the lines written out in place).

    Parameters
    ----------
    fn : callable
        A function written in the numba-supported subset of Python and numpy.

    Returns
    -------
    callable
        ``fn`` itself.
    """
    _JITABLE.append(fn)
    return fn


def loaded_kernels() -> tuple[str, ...]:
    """Kernels this process has called, hence compiled or loaded from numba's cache (``module.name``).

    Returns
    -------
    tuple of str
        In the order of their first call.
    """
    return tuple(_LOADED)
