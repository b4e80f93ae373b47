"""A large dense compliance stored in single precision and applied in double.

A Krylov step reads the whole dense ``C`` once per iteration, so its cost is memory
traffic: stored in float32 and multiplied with float64 accumulation, a product reads
half the bytes (3.3 against 6.5 ms at 5,992 x 3,010).  The operator is then exactly the
float32-rounded ``C`` (3e-8 relative per entry) applied in double, a fixed linear map
the solver's residuals are computed with.  Measured on the paper case (5,766 cells,
500 steps): the load moves by 1e-8 and the films by 1.3e-6 relative, a thousand times
below tol = 1e-3.  docs/design.md section 3.
"""

from __future__ import annotations

import multiprocessing
import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
import scipy.sparse as sp

__all__ = ["SINGLE_MIN_ENTRIES", "SingleCompliance", "in_rows", "is_dense", "loop_threads", "stored"]

#: a dense compliance with at least this many entries is stored in single precision
#: (below it the products are cheap and the tests' small meshes keep it in double)
SINGLE_MIN_ENTRIES = 1 << 22
#: the sums may be reordered (vectorized) and fused; NaN and inf still propagate
_SUMS = {"reassoc", "contract"}


_PID = os.getpid()  # the process that imported femehl: its forks are companions or workers
_POOL: tuple | None = None  # (threads, executor) of the row loops, made at their first use


def loop_threads() -> int:
    """Threads for the compiled loops over a dense operator's rows (:func:`in_rows`: its
    build, its products): the CPUs this process may use, but one in a sweep's worker (a
    daemon process), a forked process (the automatic mode's companions) or off the main
    thread, where the parallelism is the processes' (docs/design.md section 16)."""
    if (
        os.getpid() != _PID
        or multiprocessing.current_process().daemon
        or threading.current_thread() is not threading.main_thread()
    ):
        return 1
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # no affinity on this platform
        return max(1, os.cpu_count() or 1)


def in_rows(work, n: int) -> None:
    """``work(i0, i1)`` over ``range(n)`` in :func:`loop_threads` contiguous blocks, one
    per thread (``work`` releases the GIL and writes rows of its own)."""
    k = min(loop_threads(), max(1, n // 64))
    if k == 1:
        work(0, n)
        return
    global _POOL
    if _POOL is None or _POOL[0] != k:
        if _POOL is not None:
            _POOL[1].shutdown(wait=False)
        _POOL = (k, ThreadPoolExecutor(k - 1, thread_name_prefix="femehl-rows"))
    bounds = [n * j // k for j in range(k + 1)]
    others = [_POOL[1].submit(work, a, b) for a, b in zip(bounds[1:-1], bounds[2:], strict=True)]
    work(0, bounds[1])  # the first block in this thread
    for f in others:
        f.result()


def is_dense(C) -> bool:
    """``C`` is a dense compliance (an ndarray or a :class:`SingleCompliance`)."""
    return isinstance(C, np.ndarray) or bool(getattr(C, "is_dense", False))


def stored(C):
    """``C`` as the solver keeps it: a large dense one as a :class:`SingleCompliance`."""
    if isinstance(C, np.ndarray) and C.ndim == 2 and C.size >= SINGLE_MIN_ENTRIES:
        return SingleCompliance(C)
    return C


class SingleCompliance:
    """A dense ``C`` (film points x unknowns) in float32, every product in float64.

    ``C @ x`` (a vector or the columns of a matrix), ``W @ C`` (dense or sparse ``W``) and
    ``C[key]`` (float64 rows or columns) are what the solver uses.
    """

    is_dense = True
    __array_ufunc__ = None  # ``ndarray @ C`` defers to __rmatmul__

    def __init__(self, C):
        self.a = np.ascontiguousarray(C, dtype=np.float32)
        self.shape = self.a.shape
        self.nbytes = self.a.nbytes
        self.dtype = np.dtype(np.float64)

    def __matmul__(self, x):
        x = np.asarray(x, dtype=np.float64)
        if x.ndim == 1:
            if x.shape[0] != self.shape[1]:
                raise ValueError(f"C @ x: x has {x.shape[0]} entries for {self.shape[1]} columns")
            y = np.empty(self.shape[0])
            in_rows(lambda i0, i1: _matvec(self.a, x, y, i0, i1), self.shape[0])
            return y
        return np.column_stack([self @ x[:, j] for j in range(x.shape[1])])

    def __rmatmul__(self, w):
        """``W C``: a film operator F (sparse, formed once per term) or the solver's probes
        (a few dense rows), through their nonzeros, with no double copy of C."""
        vector = not sp.issparse(w) and np.ndim(w) == 1
        w = sp.csr_matrix(np.atleast_2d(w) if not sp.issparse(w) else w, dtype=np.float64)
        out = _csr_rmatmul(w.indptr, w.indices, w.data, self.a, np.zeros((w.shape[0], self.shape[1])))
        return out[0] if vector else out

    def __getitem__(self, key):
        return np.asarray(self.a[key], dtype=np.float64)

    def add_product(self, w, out) -> None:
        """``out += W C`` in place for a sparse ``W`` (``out`` dense, float32 or float64)."""
        w = sp.csr_matrix(w, dtype=np.float64)
        _csr_rmatmul(w.indptr, w.indices, w.data, self.a, out)


@numba.njit(cache=True, nogil=True, fastmath=_SUMS, boundscheck=False)
def _matvec(A, x, y, i0, i1):  # pragma: no cover - compiled
    """Rows ``i0:i1`` of ``y = A x``, A float32, sums in float64; four rows at a time share
    the loads of x (no GIL held: rows split among threads)."""
    n = A.shape[1]
    i = i0
    while i + 4 <= i1:
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        s3 = 0.0
        for j in range(n):
            xj = x[j]
            s0 += A[i, j] * xj
            s1 += A[i + 1, j] * xj
            s2 += A[i + 2, j] * xj
            s3 += A[i + 3, j] * xj
        y[i], y[i + 1], y[i + 2], y[i + 3] = s0, s1, s2, s3
        i += 4
    while i < i1:
        s = 0.0
        for j in range(n):
            s += A[i, j] * x[j]
        y[i] = s
        i += 1
    return y


@numba.njit(cache=True, fastmath=_SUMS, boundscheck=False)
def _csr_rmatmul(indptr, indices, data, A, out):  # pragma: no cover - compiled
    """``out = W A`` for a CSR ``W`` (float64), A float32, sums in float64: a row of A
    times each nonzero of W, added into the row of out."""
    for r in range(out.shape[0]):
        for q in range(indptr[r], indptr[r + 1]):
            wi, i = data[q], indices[q]
            for j in range(A.shape[1]):
                out[r, j] += wi * A[i, j]
    return out
