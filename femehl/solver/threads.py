"""How many BLAS threads femehl's runs use: one, unless ``FEMEHL_BLAS_THREADS`` says otherwise.

Why one: docs/design.md section 16.  :func:`limited` wraps every entry point that builds
operators or steps (``femehl.solve``, ``steps``, ``make_stepper``, ``run_to_folder``,
the CLI); the caller's own limits are restored on the way out.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import os

from femehl.errors import SceneError

__all__ = ["ENV", "blas_threads", "limited", "one_blas_thread"]

#: environment variable: a positive number of BLAS threads, or ``"all"`` (no limit)
ENV = "FEMEHL_BLAS_THREADS"


def blas_threads() -> int | None:
    """The BLAS thread count femehl's runs use: 1 by default, ``None`` for no limit."""
    raw = os.environ.get(ENV, "").strip()
    if not raw:
        return 1
    if raw.lower() == "all":
        return None
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n < 1:
        raise SceneError(
            f"{ENV}={raw!r}: give a positive number of BLAS threads (1, the default, is fastest "
            "beside femehl's own loops), or 'all' to leave BLAS its own default."
        )
    return n


@contextlib.contextmanager
def limited():
    """Within: BLAS (OpenBLAS, MKL, BLIS) at :func:`blas_threads` threads."""
    n = blas_threads()
    if n is None:
        yield
        return
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=n, user_api="blas"):
        yield


def one_blas_thread(func):
    """Decorator: ``func`` (a function or a generator function) runs :func:`limited`."""
    if inspect.isgeneratorfunction(func):

        @functools.wraps(func)
        def gen(*args, **kwargs):
            with limited():
                yield from func(*args, **kwargs)

        return gen

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with limited():
            return func(*args, **kwargs)

    return wrapper
